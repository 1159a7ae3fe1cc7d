//! The CLI's error type and its exit codes.

use std::fmt;

/// A failure reported to the user: bad input exits with 2, a runtime failure with 1.
#[derive(Debug)]
pub struct CliError {
    message: String,
    exit_code: u8,
}

impl CliError {
    /// Bad input from the user (a value, a file, a flag): exit code 2.
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            exit_code: 2,
        }
    }

    /// A failure while doing valid work (I/O, divergence): exit code 1.
    pub fn runtime(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            exit_code: 1,
        }
    }

    /// Stopped by `signal` (SIGINT, SIGTERM): exit code 128 + its number (130, 143).
    pub fn interrupted(signal: i32) -> Self {
        let name = match signal {
            2 => "SIGINT".to_string(),
            15 => "SIGTERM".to_string(),
            n => format!("signal {n}"),
        };
        Self {
            message: format!("interrupted by {name}: stopped, temporary files removed"),
            exit_code: u8::try_from(128 + signal).unwrap_or(1),
        }
    }

    /// The process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        self.exit_code
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// Result of a CLI command.
pub type CliResult = Result<(), CliError>;

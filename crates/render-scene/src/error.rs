//! [`RenderError`]: everything that can go wrong while loading, rendering or writing.

use std::fmt;
use std::path::PathBuf;

/// Why a scene could not be loaded, rendered or written.
#[derive(Debug, Clone, PartialEq)]
pub enum RenderError {
    /// A render setting is out of range.
    InvalidSetting {
        /// Name of the setting (`"width"`, `"samples"`, ...).
        name: &'static str,
        /// The rejected value, as text.
        value: String,
        /// What the value must be.
        expected: &'static str,
    },
    /// A scene element is malformed (mismatched lengths, NaN, bad index, ...).
    InvalidScene {
        /// Which element, e.g. `"bubble 2, vertex 17"`.
        what: String,
        /// What is wrong with it.
        problem: String,
    },
    /// An image file could not be read or decoded.
    ImageRead {
        /// The file.
        path: PathBuf,
        /// The decoder's or file system's message.
        message: String,
    },
    /// An output file could not be written.
    Write {
        /// The file.
        path: PathBuf,
        /// The encoder's or file system's message.
        message: String,
    },
    /// A Wavefront OBJ text is malformed.
    Obj {
        /// The file, if the text came from one.
        path: Option<PathBuf>,
        /// 1-based line number.
        line: usize,
        /// What is wrong on that line.
        message: String,
    },
}

impl RenderError {
    /// Shorthand for [`RenderError::InvalidScene`].
    pub fn scene(what: impl Into<String>, problem: impl Into<String>) -> Self {
        Self::InvalidScene {
            what: what.into(),
            problem: problem.into(),
        }
    }

    /// Shorthand for [`RenderError::InvalidSetting`].
    pub fn setting(name: &'static str, value: impl fmt::Display, expected: &'static str) -> Self {
        Self::InvalidSetting {
            name,
            value: value.to_string(),
            expected,
        }
    }
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidSetting {
                name,
                value,
                expected,
            } => write!(
                f,
                "setting `{name}` = {value} is invalid: expected {expected}"
            ),
            Self::InvalidScene { what, problem } => write!(f, "{what}: {problem}"),
            Self::ImageRead { path, message } => {
                write!(f, "cannot read image {}: {message}", path.display())
            }
            Self::Write { path, message } => {
                write!(f, "cannot write {}: {message}", path.display())
            }
            Self::Obj {
                path,
                line,
                message,
            } => match path {
                Some(p) => write!(f, "{}:{line}: {message}", p.display()),
                None => write!(f, "OBJ line {line}: {message}"),
            },
        }
    }
}

impl std::error::Error for RenderError {}

//! [`WaterError`]: a bad water parameter, named with its value.

use std::fmt;

/// A water parameter out of range: which one, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct WaterError {
    /// The parameter, e.g. `wave amplitude_m`.
    pub what: String,
    /// What is wrong with its value, naming the value.
    pub problem: String,
}

impl WaterError {
    pub(crate) fn new(what: impl Into<String>, problem: impl Into<String>) -> Self {
        Self {
            what: what.into(),
            problem: problem.into(),
        }
    }
}

impl fmt::Display for WaterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.what, self.problem)
    }
}

impl std::error::Error for WaterError {}

/// `Ok` when `value` is finite and `> 0`, else an error naming it.
pub(crate) fn check_positive(what: &str, value: f64) -> Result<(), WaterError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(WaterError::new(
            what,
            format!("{value} must be finite and > 0"),
        ))
    }
}

/// `Ok` when `value` is finite and `>= 0`, else an error naming it.
pub(crate) fn check_non_negative(what: &str, value: f64) -> Result<(), WaterError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(WaterError::new(
            what,
            format!("{value} must be finite and >= 0"),
        ))
    }
}

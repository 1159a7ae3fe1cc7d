//! What can go wrong before a map is made: every variant names the bad value.

use std::fmt;

/// Why [`crate::recover`] or a constructor refused its input.
#[derive(Clone, Debug, PartialEq)]
pub enum InverseError {
    /// A setting outside its range (its name, value and the allowed range in words).
    Setting {
        /// The setting, as the user named it (`thickness_max_nm`, `angle_deg`, …).
        name: &'static str,
        /// The value given, formatted.
        value: String,
        /// What would be accepted.
        allowed: String,
    },
    /// An array whose length does not match the photo.
    Size {
        /// What the array holds (`cos map`, `mask`, `pixels`).
        what: &'static str,
        /// Its length.
        len: usize,
        /// The length the photo needs.
        expected: usize,
    },
    /// A point or region outside the photo.
    Outside {
        /// What it is (`anchor`, `reference region`, …).
        what: &'static str,
        /// The point or region as given.
        value: String,
        /// The photo's size.
        width: u32,
        /// The photo's size.
        height: u32,
    },
    /// The photo cannot be inverted as a whole (saturated, dark, nothing usable).
    Photo(String),
    /// The optics refused the film (an index or illuminant outside the model's range).
    Optics(String),
}

impl fmt::Display for InverseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InverseError::Setting {
                name,
                value,
                allowed,
            } => write!(f, "{name} {value} is out of range: {allowed}"),
            InverseError::Size {
                what,
                len,
                expected,
            } => write!(
                f,
                "the {what} has {len} values but the photo needs {expected} (one per pixel)"
            ),
            InverseError::Outside {
                what,
                value,
                width,
                height,
            } => write!(
                f,
                "the {what} {value} is outside the {width}x{height} photo"
            ),
            InverseError::Photo(why) => write!(f, "{why}"),
            InverseError::Optics(why) => write!(f, "{why}"),
        }
    }
}

impl std::error::Error for InverseError {}

/// Formats a number for a message: short for ordinary values, scientific for extremes.
pub(crate) fn short(v: f64) -> String {
    if v != 0.0 && (v.abs() >= 1e6 || v.abs() < 1e-3) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

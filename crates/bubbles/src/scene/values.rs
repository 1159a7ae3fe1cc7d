//! Validated scalar and vector types for scene files.
//!
//! Validation happens inside deserialisation, so a bad value is reported by the TOML
//! parser with its line and column.

use serde::{Deserialize, Deserializer, de::Error as _};

/// A finite `f64` that is strictly positive.
///
/// # Guarantees
/// The value is finite and `> 0`.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Positive(f64);

/// A finite `f64` that is zero or positive.
///
/// # Guarantees
/// The value is finite and `>= 0`.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct NonNegative(f64);

/// A finite `f64`.
///
/// # Guarantees
/// The value is finite.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Finite(f64);

/// Three finite components.
///
/// # Guarantees
/// Every component is finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3([f64; 3]);

/// Three finite, non-negative components (a colour or radiance).
///
/// # Guarantees
/// Every component is finite and `>= 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rgb([f64; 3]);

/// A non-zero direction with finite components.
///
/// # Guarantees
/// Every component is finite and the length is `> 1e-12`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction([f64; 3]);

macro_rules! checked_scalar {
    ($name:ident, $ok:expr, $what:literal) => {
        impl $name {
            /// Checks `value`, returning `None` when it breaks the guarantee.
            pub fn new(value: f64) -> Option<Self> {
                let ok: fn(f64) -> bool = $ok;
                (value.is_finite() && ok(value)).then_some(Self(value))
            }

            /// The checked value.
            pub fn get(self) -> f64 {
                self.0
            }
        }

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let value = f64::deserialize(d)?;
                Self::new(value)
                    .ok_or_else(|| D::Error::custom(format!("{value} is not {}", $what)))
            }
        }
    };
}

checked_scalar!(Positive, |v| v > 0.0, "a finite number > 0");
checked_scalar!(NonNegative, |v| v >= 0.0, "a finite number >= 0");
checked_scalar!(Finite, |_| true, "a finite number");

macro_rules! checked_triple {
    ($name:ident, $ok:expr, $what:literal) => {
        impl $name {
            /// Checks `value`, returning `None` when it breaks the guarantee.
            pub fn new(value: [f64; 3]) -> Option<Self> {
                let ok: fn([f64; 3]) -> bool = $ok;
                (value.iter().all(|c| c.is_finite()) && ok(value)).then_some(Self(value))
            }

            /// The checked components.
            pub fn get(self) -> [f64; 3] {
                self.0
            }
        }

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let value = <[f64; 3]>::deserialize(d)?;
                Self::new(value)
                    .ok_or_else(|| D::Error::custom(format!("{value:?} is not {}", $what)))
            }
        }
    };
}

checked_triple!(Vec3, |_| true, "three finite numbers");
checked_triple!(
    Rgb,
    |v| v.iter().all(|c| *c >= 0.0),
    "three finite numbers >= 0"
);
checked_triple!(
    Direction,
    |v| v.iter().map(|c| c * c).sum::<f64>() > 1e-24,
    "a non-zero direction of three finite numbers"
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_what_the_guarantees_exclude() {
        assert!(Positive::new(0.0).is_none());
        assert!(Positive::new(f64::NAN).is_none());
        assert!(NonNegative::new(-1e-300).is_none());
        assert!(Finite::new(f64::INFINITY).is_none());
        assert!(Rgb::new([0.1, -0.1, 0.0]).is_none());
        assert!(Direction::new([0.0; 3]).is_none());
        assert_eq!(Positive::new(2.5).map(Positive::get), Some(2.5));
    }
}

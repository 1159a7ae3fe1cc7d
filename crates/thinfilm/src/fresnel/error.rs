//! The error of every fallible optics call: which value was bad, and what it was.

use num_complex::Complex64;
use std::fmt;

/// A rejected optics input, naming the parameter and its value.
#[derive(Clone, Debug, PartialEq)]
pub enum OpticsError {
    /// A real refractive index that is not finite and positive.
    Index {
        /// Which index.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A complex refractive index that is not finite with `Re > 0` and `Im ≥ 0`.
    ComplexIndex {
        /// Which index.
        what: &'static str,
        /// The rejected value.
        value: Complex64,
    },
    /// A cosine of an incidence angle outside [0, 1].
    Cosine {
        /// Which cosine.
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// An incidence angle (or its sine) outside its range.
    Angle {
        /// Which value: `angle_deg` (in [0, 90]) or `sin_theta` (in [0, 1]).
        what: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A wavelength that is not finite and positive.
    Wavelength {
        /// The rejected wavelength in nm.
        wavelength_nm: f64,
    },
    /// A thickness that is not finite and non-negative.
    Thickness {
        /// The rejected thickness in nm.
        thickness_nm: f64,
    },
    /// A dispersion model whose parameters are invalid (named in `reason`).
    Dispersion {
        /// What is wrong.
        reason: String,
    },
    /// A dispersion model that gives no finite positive index at this wavelength.
    IndexAtWavelength {
        /// The wavelength in nm.
        wavelength_nm: f64,
        /// What the model gave there.
        value: f64,
    },
    /// A wavelength outside the range an index model covers.
    OutOfRange {
        /// The model, e.g. "Sellmeier model".
        model: &'static str,
        /// The rejected wavelength in nm.
        wavelength_nm: f64,
        /// The model's range `[lo, hi]` in nm.
        range_nm: [f64; 2],
    },
    /// A tabulated index file or text that cannot be used (named in `reason`).
    Table {
        /// What is wrong, with the line number where there is one.
        reason: String,
    },
    /// Slices that must have equal lengths do not.
    Length {
        /// Which slice.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The length it must have.
        expected: usize,
    },
    /// A non-finite weight or sample value in a batch call.
    NotFinite {
        /// Which slice.
        what: &'static str,
        /// The index of the bad element.
        index: usize,
        /// The rejected value.
        value: f64,
    },
    /// A thickness fit's inputs that cannot be used (named in `reason`).
    Fit {
        /// What is wrong.
        reason: String,
    },
    /// A graded-index layer's tolerance that is invalid or not reached (named in `reason`).
    Graded {
        /// What is wrong.
        reason: String,
    },
    /// Amplitudes asked of a stack with an incoherent layer, which has only intensities.
    Incoherent {
        /// The first incoherent layer, 1-based.
        layer: usize,
    },
}

impl fmt::Display for OpticsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OpticsError::Index { what, value } => {
                write!(
                    f,
                    "{what} = {} is not a refractive index in [{}, {}]",
                    Num(*value),
                    Num(super::MIN_INDEX),
                    Num(super::MAX_INDEX)
                )
            }
            OpticsError::ComplexIndex { what, value } => write!(
                f,
                "{what} = {}{}{}i is not a complex index with real part in [{min}, {max}] \
                 and imaginary part in [0, {max}]",
                Num(value.re),
                if value.im.is_sign_negative() {
                    "-"
                } else {
                    "+"
                },
                Num(value.im.abs()),
                min = Num(super::MIN_INDEX),
                max = Num(super::MAX_INDEX)
            ),
            OpticsError::Cosine { what, value } => {
                write!(f, "{what} = {} is not a cosine in [0, 1]", Num(*value))
            }
            OpticsError::Angle { what, value } => {
                let range = if *what == "angle_deg" {
                    "[0, 90] degrees"
                } else {
                    "[0, 1]"
                };
                write!(f, "{what} = {} is not in {range}", Num(*value))
            }
            OpticsError::Wavelength { wavelength_nm } => {
                write!(
                    f,
                    "wavelength {} nm is not finite and > 0",
                    Num(*wavelength_nm)
                )
            }
            OpticsError::Thickness { thickness_nm } => write!(
                f,
                "thickness {} nm is not in [0, {}] nm",
                Num(*thickness_nm),
                Num(super::MAX_THICKNESS_NM)
            ),
            OpticsError::Dispersion { reason } => write!(f, "invalid dispersion model: {reason}"),
            OpticsError::IndexAtWavelength {
                wavelength_nm,
                value,
            } => write!(
                f,
                "dispersion model gives n = {} at {} nm (not in [{}, {}])",
                Num(*value),
                Num(*wavelength_nm),
                Num(super::MIN_INDEX),
                Num(super::MAX_INDEX)
            ),
            OpticsError::OutOfRange {
                model,
                wavelength_nm,
                range_nm: [lo, hi],
            } => write!(
                f,
                "wavelength {} nm is outside the {model}'s range [{lo}, {hi}] nm",
                Num(*wavelength_nm)
            ),
            OpticsError::Table { reason } => write!(f, "invalid n,k table: {reason}"),
            OpticsError::Length {
                what,
                len,
                expected,
            } => write!(f, "{what} has {len} elements, expected {expected}"),
            OpticsError::NotFinite { what, index, value } => {
                write!(f, "{what}[{index}] = {} is not a valid value", Num(*value))
            }
            OpticsError::Fit { reason } => write!(f, "thickness fit: {reason}"),
            OpticsError::Graded { reason } => write!(f, "graded layer: {reason}"),
            OpticsError::Incoherent { layer } => write!(
                f,
                "layer {layer} is incoherent: a stack with incoherent layers has intensities \
                 (R, T), not amplitudes"
            ),
        }
    }
}

impl std::error::Error for OpticsError {}

/// A number as a message shows it: the shortest decimal between 1e-4 and 1e7, and the
/// short exponent form (`1e-300`, `1e308`) outside, never hundreds of digits.
pub(crate) struct Num(pub(crate) f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        if v == 0.0 || !v.is_finite() || (1e-4..1e7).contains(&v.abs()) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
        }
    }
}

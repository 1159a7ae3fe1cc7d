//! The direction of incidence, held as both its cosine and its sine so that neither is
//! recovered from the other by a cancelling `sqrt(1 − x²)`: grazing incidence stays exact.
//!
//! ```
//! use thinfilm::{Incidence, ThinFilm};
//!
//! let grazing = Incidence::try_from_cos(1e-12).unwrap();
//! assert_eq!(grazing.cos(), 1e-12);
//! // A film of zero thickness is no film at all, even a hair from grazing.
//! let r = ThinFilm::soap(0.0).try_response_at(550.0, grazing).unwrap().r();
//! assert!(r < 1e-12, "R = {r}");
//! ```

use num_complex::Complex64;

use crate::fresnel::{OpticsError, check_cos};

/// An incidence direction: `cos θ` and `sin θ`, both in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incidence {
    cos: f64,
    sin: f64,
}

impl Incidence {
    /// Head-on incidence.
    pub const NORMAL: Incidence = Incidence { cos: 1.0, sin: 0.0 };

    /// From `cos θ` ∈ [0, 1]; `sin θ` is `sqrt((1 − c)(1 + c))`, exact near normal incidence.
    ///
    /// # Guarantees
    /// `cos` and `sin` are in [0, 1].
    pub fn try_from_cos(cos_theta: f64) -> Result<Incidence, OpticsError> {
        check_cos("cos_theta", cos_theta)?;
        Ok(Incidence {
            cos: cos_theta,
            sin: complement(cos_theta),
        })
    }

    /// From `sin θ` ∈ [0, 1]; `cos θ` is `sqrt((1 − s)(1 + s))`.
    ///
    /// # Guarantees
    /// `cos` and `sin` are in [0, 1].
    pub fn try_from_sin(sin_theta: f64) -> Result<Incidence, OpticsError> {
        if !(0.0..=1.0).contains(&sin_theta) {
            return Err(OpticsError::Angle {
                what: "sin_theta",
                value: sin_theta,
            });
        }
        Ok(Incidence {
            cos: complement(sin_theta),
            sin: sin_theta,
        })
    }

    /// From the angle in degrees, in [0, 90]. Above 45° the cosine is taken as the sine of
    /// the exact difference `90° − θ`, so 89.999999° gives `cos θ` to full precision.
    ///
    /// # Guarantees
    /// `cos` and `sin` are in [0, 1]; 90° gives `cos = 0` exactly.
    pub fn try_from_angle_deg(angle_deg: f64) -> Result<Incidence, OpticsError> {
        if !(0.0..=90.0).contains(&angle_deg) {
            return Err(OpticsError::Angle {
                what: "angle_deg",
                value: angle_deg,
            });
        }
        let (sin, cos) = if angle_deg <= 45.0 {
            angle_deg.to_radians().sin_cos()
        } else {
            let (cos, sin) = (90.0 - angle_deg).to_radians().sin_cos();
            (sin, cos)
        };
        Ok(Incidence {
            cos: cos.clamp(0.0, 1.0),
            sin: sin.clamp(0.0, 1.0),
        })
    }

    /// `cos θ`.
    pub fn cos(&self) -> f64 {
        self.cos
    }

    /// `sin θ`.
    pub fn sin(&self) -> f64 {
        self.sin
    }

    /// `n cos θ_n` inside a medium of index `n` for light arriving from a medium of real
    /// index `n0` in this direction (Snell), on the decaying/outgoing branch.
    ///
    /// `n² − n0² sin²θ` is formed as `(n − n0)(n + n0) + (n0 cos θ)²` near grazing, so a
    /// medium equal to the incident one gives exactly `n0 cos θ`, however small.
    pub fn normal_index(&self, n0: f64, n: Complex64) -> Complex64 {
        if n == Complex64::from(n0) {
            // Not squared: (n0 cos θ)² underflows for cos θ below ~1e-154.
            return Complex64::from(n0 * self.cos);
        }
        let q2 = if self.cos < self.sin {
            let n0_cos = n0 * self.cos;
            (n - n0) * (n + n0) + n0_cos * n0_cos
        } else {
            let n_sin = n0 * self.sin;
            n * n - n_sin * n_sin
        };
        decaying_root(q2)
    }
}

/// `sqrt((1 − x)(1 + x))`: `sqrt(1 − x²)` without the cancellation of `1 − x²` near 1.
fn complement(x: f64) -> f64 {
    ((1.0 - x) * (1.0 + x)).sqrt().clamp(0.0, 1.0)
}

/// The square root of `q2` with `Im ≥ 0`, and `Re ≥ 0` when it is real.
pub(crate) fn decaying_root(q2: Complex64) -> Complex64 {
    let root = q2.sqrt();
    // The principal root already has Re ≥ 0; a negative zero imaginary part (real
    // `n² < n_sin²` computed as `x − 0i`) would give −i·a, a growing wave.
    if root.im < 0.0 || (root.im == 0.0 && root.re < 0.0) {
        -root
    } else {
        root
    }
}

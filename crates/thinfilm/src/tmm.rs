//! General N-layer transfer-matrix method (characteristic matrices), s and p, complex
//! indices allowed: multilayer stacks (Hirayama et al.) and the independent cross-check
//! of the single-film Airy sum.
//!
//! Each layer maps the tangential fields at its back face to its front face by
//! `[[cos δ, −i sin δ / y], [−i y sin δ, cos δ]]` (for the `e^{−iωt}` convention),
//! with `δ = 2π q d / λ`, `q = n cos θ` and the layer's admittance `y = q` for s
//! and `y = q / n² = cos θ / n` for p (the p case works with `H_y` as its field, so no
//! admittance is ever infinite and grazing incidence stays finite). `sin δ / y` is
//! written as `(2π d / λ)(q / y) sinc δ`, finite even at a layer's critical angle where
//! `q = 0`.

use crate::fresnel::{self, Amplitudes, OpticsError, Response};
use num_complex::Complex64;

/// One homogeneous layer of a stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    /// Complex index `n + iκ` (`κ ≥ 0` absorbs).
    pub n: Complex64,
    /// Physical thickness in nm.
    pub thickness_nm: f64,
}

impl Layer {
    /// A lossless layer of real index `n`.
    pub fn lossless(n: f64, thickness_nm: f64) -> Layer {
        Layer {
            n: Complex64::new(n, 0.0),
            thickness_nm,
        }
    }
}

/// A stack: a lossless incident medium, layers in the order light meets them, a substrate.
#[derive(Clone, Debug, PartialEq)]
pub struct Stack {
    /// Real index of the incident medium.
    pub n_incident: f64,
    /// The layers, front to back.
    pub layers: Vec<Layer>,
    /// Complex index of the semi-infinite substrate.
    pub n_substrate: Complex64,
}

#[derive(Clone, Copy, PartialEq)]
enum Polarisation {
    S,
    P,
}

impl Stack {
    /// A validated stack.
    ///
    /// # Guarantees
    /// `n_incident` is finite and `> 0`; every layer index and `n_substrate` is finite with
    /// `Re > 0`, `Im ≥ 0`; every thickness is finite and `≥ 0`.
    pub fn new(
        n_incident: f64,
        layers: Vec<Layer>,
        n_substrate: Complex64,
    ) -> Result<Stack, OpticsError> {
        let stack = Stack {
            n_incident,
            layers,
            n_substrate,
        };
        stack.validate().map(|()| stack)
    }

    /// Checks a stack built from its fields, with the guarantees of [`Stack::new`].
    pub fn validate(&self) -> Result<(), OpticsError> {
        fresnel::check_real_index("n_incident", self.n_incident)?;
        fresnel::check_complex_index("n_substrate", self.n_substrate)?;
        for layer in &self.layers {
            fresnel::check_complex_index("layer index", layer.n)?;
            fresnel::check_thickness(layer.thickness_nm)?;
        }
        Ok(())
    }

    /// Amplitude coefficients at `wavelength_nm` and `cos_theta_incident` ∈ [0, 1].
    pub fn try_amplitudes(
        &self,
        wavelength_nm: f64,
        cos_theta_incident: f64,
    ) -> Result<Amplitudes, OpticsError> {
        self.check_query(wavelength_nm, cos_theta_incident)?;
        if cos_theta_incident == 0.0 {
            let same = self.all_media_equal();
            let (r_s, r_p, t) = if same {
                (0.0, 0.0, 1.0)
            } else {
                (-1.0, 1.0, 0.0)
            };
            return Ok(Amplitudes {
                r_s: r_s.into(),
                r_p: r_p.into(),
                t_s: t.into(),
                t_p: t.into(),
            });
        }
        let (r_s, t_s) = self
            .solve(Polarisation::S, wavelength_nm, cos_theta_incident)
            .0;
        let (r_h, t_h) = self
            .solve(Polarisation::P, wavelength_nm, cos_theta_incident)
            .0;
        // The p solve works with H_y: its r has the opposite sign and its t is scaled by
        // n_sub/n_0 relative to the electric-field convention of `fresnel`.
        Ok(Amplitudes {
            r_s,
            r_p: -r_h,
            t_s,
            t_p: t_h * self.n_incident / self.n_substrate,
        })
    }

    /// Intensity reflectance and transmittance at `wavelength_nm` and `cos_theta_incident`.
    pub fn try_response(
        &self,
        wavelength_nm: f64,
        cos_theta_incident: f64,
    ) -> Result<Response, OpticsError> {
        self.check_query(wavelength_nm, cos_theta_incident)?;
        if cos_theta_incident == 0.0 {
            return Ok(Response::grazing(self.all_media_equal()));
        }
        let ((r_s, _), t_s) = self.solve(Polarisation::S, wavelength_nm, cos_theta_incident);
        let ((r_p, _), t_p) = self.solve(Polarisation::P, wavelength_nm, cos_theta_incident);
        Ok(Response {
            r_s: r_s.norm_sqr(),
            r_p: r_p.norm_sqr(),
            t_s,
            t_p,
        })
    }

    /// [`Stack::try_response`] for known-good arguments.
    ///
    /// # Panics
    /// If the stack is invalid (see [`Stack::new`]), `wavelength_nm` is not finite and
    /// positive, or `cos_theta_incident` is not in [0, 1].
    pub fn response(&self, wavelength_nm: f64, cos_theta_incident: f64) -> Response {
        self.try_response(wavelength_nm, cos_theta_incident)
            .unwrap_or_else(|err| panic!("{err}"))
    }

    fn check_query(&self, wavelength_nm: f64, cos_theta_incident: f64) -> Result<(), OpticsError> {
        self.validate()?;
        fresnel::check_wavelength(wavelength_nm)?;
        fresnel::check_cos("cos_theta_incident", cos_theta_incident)
    }

    fn all_media_equal(&self) -> bool {
        let n0 = Complex64::new(self.n_incident, 0.0);
        self.n_substrate == n0 && self.layers.iter().all(|layer| layer.n == n0)
    }

    /// `((r, t), T)` for one polarisation, in the field of that polarisation's solve
    /// (`E_y` for s, `H_y` for p). Requires `cos_theta_incident > 0`.
    fn solve(
        &self,
        pol: Polarisation,
        wavelength_nm: f64,
        cos_theta_incident: f64,
    ) -> ((Complex64, Complex64), f64) {
        let n_sin = fresnel::n_sin(self.n_incident, cos_theta_incident);
        let k_per_nm = std::f64::consts::TAU / wavelength_nm;
        let admittance = |n: Complex64, q: Complex64| match pol {
            Polarisation::S => q,
            Polarisation::P => q / (n * n),
        };
        let n0 = Complex64::new(self.n_incident, 0.0);
        let y0 = admittance(n0, n0 * cos_theta_incident);
        let q_sub = fresnel::normal_index(self.n_substrate, n_sin);
        let y_sub = admittance(self.n_substrate, q_sub);
        // [B, C] = M_1 ⋯ M_N [1, y_sub], applied from the back layer forwards.
        let mut field = (Complex64::new(1.0, 0.0), y_sub);
        for layer in self.layers.iter().rev() {
            let q = fresnel::normal_index(layer.n, n_sin);
            let y = admittance(layer.n, q);
            let delta = k_per_nm * layer.thickness_nm * q;
            let q_over_y = match pol {
                Polarisation::S => Complex64::new(1.0, 0.0),
                Polarisation::P => layer.n * layer.n,
            };
            let sin_over_y = k_per_nm * layer.thickness_nm * q_over_y * sinc(delta);
            let (cos_d, sin_d) = (delta.cos(), delta.sin());
            let minus_i = Complex64::new(0.0, -1.0);
            field = (
                cos_d * field.0 + minus_i * sin_over_y * field.1,
                minus_i * y * sin_d * field.0 + cos_d * field.1,
            );
        }
        let (b, c) = field;
        let den = y0 * b + c;
        let r = (y0 * b - c) / den;
        let t = 2.0 * y0 / den;
        let transmittance = 4.0 * y0.re * y_sub.re / den.norm_sqr();
        ((r, t), transmittance)
    }
}

/// `sin z / z` for complex `z`, by its series near 0 where the quotient loses accuracy.
fn sinc(z: Complex64) -> Complex64 {
    if z.norm_sqr() < 1e-8 {
        let z2 = z * z;
        1.0 - z2 / 6.0 + z2 * z2 / 120.0
    } else {
        z.sin() / z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinc_series_meets_quotient_at_the_switch() {
        for z in [
            Complex64::new(1e-4, 0.0),
            Complex64::new(0.0, 1e-4),
            Complex64::new(7e-5, 7e-5),
        ] {
            let quotient = z.sin() / z;
            let series = sinc(z * 0.999_999);
            assert!((quotient - series).norm() < 1e-12, "{quotient} vs {series}");
        }
    }

    #[test]
    fn empty_stack_is_one_interface() {
        let stack = Stack::new(1.0, vec![], Complex64::new(1.5, 0.1)).unwrap();
        let surface = fresnel::Interface::new(1.0, Complex64::new(1.5, 0.1)).unwrap();
        for cos in [1.0, 0.7, 0.2, 0.01] {
            let a = stack.try_amplitudes(550.0, cos).unwrap();
            let b = surface.try_amplitudes(cos).unwrap();
            for (x, y) in [
                (a.r_s, b.r_s),
                (a.r_p, b.r_p),
                (a.t_s, b.t_s),
                (a.t_p, b.t_p),
            ] {
                assert!((x - y).norm() < 1e-14, "cos {cos}: {x} vs {y}");
            }
        }
    }
}

//! One film between two media, by the exact Airy sum of all multiple reflections.
//!
//! For s and p separately, with `β = 2π n_film d cos θ_t / λ` (θ_t the angle INSIDE the
//! film, so the round-trip phase is `δ = 2β`):
//! `r = (r01 + r12 e^{2iβ}) / (1 + r01 r12 e^{2iβ})`, `t = t01 t12 e^{iβ} / (1 + r01 r12 e^{2iβ})`,
//! and the unpolarised reflectance is the mean `(R_s + R_p)/2`.
//!
//! ```
//! use thinfilm::airy::ThinFilm;
//!
//! // A 500 nm soap film in air, seen head-on in green light.
//! let r = ThinFilm::soap(500.0).response(550.0, 1.0).r();
//! assert!(r > 0.0 && r < 0.16);
//! ```

use crate::dispersion::RefractiveIndex;
pub use crate::fresnel::Response;
use crate::fresnel::{self, Amplitudes, OpticsError};
use crate::incidence::Incidence;
use crate::tmm::{Layer, Stack};
use num_complex::Complex64;

/// Below this `|1 + r01 r12 e^{2iβ}|` the Airy quotient is a near 0/0 (a film exactly at its
/// own critical angle); the characteristic matrix, which has no such quotient, is used.
const AIRY_DENOMINATOR_FLOOR: f64 = 1e-6;

/// A film of thickness `thickness_nm` between a lossless outside medium and a substrate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinFilm {
    /// Real index of the medium the light comes from.
    pub n_outside: f64,
    /// Index of the (lossless) film, possibly dispersive.
    pub n_film: RefractiveIndex,
    /// Complex index `n + iκ` of the medium behind the film.
    pub n_substrate: Complex64,
    /// Film thickness in nm.
    pub thickness_nm: f64,
}

impl ThinFilm {
    /// A soap film in air: `1.0 | 1.33 | 1.0`. The thickness is checked when it is used.
    pub fn soap(thickness_nm: f64) -> ThinFilm {
        ThinFilm::symmetric(1.0, RefractiveIndex::SOAP, thickness_nm)
    }

    /// A free-standing film `n_outside | n_film | n_outside` (a bubble's wall in any medium).
    /// The values are checked when it is used.
    pub fn symmetric(n_outside: f64, n_film: RefractiveIndex, thickness_nm: f64) -> ThinFilm {
        ThinFilm {
            n_outside,
            n_film,
            n_substrate: Complex64::new(n_outside, 0.0),
            thickness_nm,
        }
    }

    /// A validated film.
    ///
    /// # Guarantees
    /// `n_outside` is finite and `> 0`; `n_film` passes [`RefractiveIndex::validate`];
    /// `n_substrate` is finite with `Re > 0`, `Im ≥ 0`; `thickness_nm` is finite and `≥ 0`.
    pub fn new(
        n_outside: f64,
        n_film: RefractiveIndex,
        n_substrate: Complex64,
        thickness_nm: f64,
    ) -> Result<ThinFilm, OpticsError> {
        let film = ThinFilm {
            n_outside,
            n_film,
            n_substrate,
            thickness_nm,
        };
        film.validate().map(|()| film)
    }

    /// Checks a film built from its fields, with the guarantees of [`ThinFilm::new`].
    pub fn validate(&self) -> Result<(), OpticsError> {
        fresnel::check_real_index("n_outside", self.n_outside)?;
        self.n_film.validate()?;
        fresnel::check_complex_index("n_substrate", self.n_substrate)?;
        fresnel::check_thickness(self.thickness_nm)
    }

    /// The equivalent one-layer [`Stack`] (the film keeps its dispersion model).
    pub fn try_stack(&self) -> Result<Stack, OpticsError> {
        Stack::new(
            self.n_outside,
            vec![Layer::new(self.n_film, self.thickness_nm)],
            self.n_substrate,
        )
    }

    /// Amplitude coefficients at `wavelength_nm` and `cos_theta_outside` ∈ [0, 1].
    pub fn try_amplitudes(
        &self,
        wavelength_nm: f64,
        cos_theta_outside: f64,
    ) -> Result<Amplitudes, OpticsError> {
        fresnel::check_cos("cos_theta_outside", cos_theta_outside)?;
        self.try_amplitudes_at(wavelength_nm, Incidence::try_from_cos(cos_theta_outside)?)
    }

    /// Amplitude coefficients at `wavelength_nm` in the direction `incidence`.
    pub fn try_amplitudes_at(
        &self,
        wavelength_nm: f64,
        incidence: Incidence,
    ) -> Result<Amplitudes, OpticsError> {
        let geometry = self.geometry(wavelength_nm, incidence)?;
        match geometry.airy() {
            Some(amplitudes) if incidence.cos() > 0.0 => Ok(amplitudes),
            _ => self
                .try_stack()?
                .try_amplitudes_at(wavelength_nm, incidence),
        }
    }

    /// Intensity reflectance and transmittance at `wavelength_nm` and `cos_theta_outside`.
    ///
    /// `T_s = Re(n_sub cos θ_sub)/(n_0 cos θ_0)·|t_s|²`, `T_p = Re(n_sub conj(cos θ_sub))/(n_0 cos θ_0)·|t_p|²`,
    /// computed from the transmitted amplitudes (not `1 − R`). Exactly grazing incidence
    /// gives its limit `R = 1`, `T = 0` (or nothing at all if every medium is the same).
    pub fn try_response(
        &self,
        wavelength_nm: f64,
        cos_theta_outside: f64,
    ) -> Result<Response, OpticsError> {
        fresnel::check_cos("cos_theta_outside", cos_theta_outside)?;
        self.try_response_at(wavelength_nm, Incidence::try_from_cos(cos_theta_outside)?)
    }

    /// Intensity reflectance and transmittance at `wavelength_nm` in the direction
    /// `incidence`; pass the angle or `sin θ` there to keep grazing incidence exact.
    pub fn try_response_at(
        &self,
        wavelength_nm: f64,
        incidence: Incidence,
    ) -> Result<Response, OpticsError> {
        let geometry = self.geometry(wavelength_nm, incidence)?;
        if incidence.cos() == 0.0 {
            let n0 = Complex64::new(self.n_outside, 0.0);
            return Ok(Response::grazing(
                geometry.n1 == n0 && self.n_substrate == n0,
            ));
        }
        match geometry.airy() {
            Some(amp) => Ok(geometry.intensities(&amp)),
            None => self.try_stack()?.try_response_at(wavelength_nm, incidence),
        }
    }

    /// [`ThinFilm::try_response`] for known-good arguments.
    ///
    /// # Panics
    /// If the film is invalid (see [`ThinFilm::new`]), `wavelength_nm` is not finite and
    /// positive (or outside the film's dispersion range), or `cos_theta_outside` is not in [0, 1].
    pub fn response(&self, wavelength_nm: f64, cos_theta_outside: f64) -> Response {
        self.try_response(wavelength_nm, cos_theta_outside)
            .unwrap_or_else(|err| panic!("{err}"))
    }

    fn geometry(&self, wavelength_nm: f64, incidence: Incidence) -> Result<Geometry, OpticsError> {
        self.validate()?;
        fresnel::check_wavelength(wavelength_nm)?;
        let n1 = Complex64::new(self.n_film.try_n_at(wavelength_nm)?, 0.0);
        let q1 = incidence.normal_index(self.n_outside, n1);
        let q2 = incidence.normal_index(self.n_outside, self.n_substrate);
        Ok(Geometry {
            n0: self.n_outside,
            cos0: incidence.cos(),
            n1,
            cos1: q1 / n1,
            n2: self.n_substrate,
            cos2: q2 / self.n_substrate,
            beta: std::f64::consts::TAU * self.thickness_nm * q1 / wavelength_nm,
        })
    }
}

/// Indices, complex cosines and the one-way film phase `β` of one query.
struct Geometry {
    n0: f64,
    cos0: f64,
    n1: Complex64,
    cos1: Complex64,
    n2: Complex64,
    cos2: Complex64,
    beta: Complex64,
}

impl Geometry {
    /// The Airy sum, or `None` where its denominator (nearly) vanishes.
    fn airy(&self) -> Option<Amplitudes> {
        let n0 = Complex64::new(self.n0, 0.0);
        let cos0 = Complex64::new(self.cos0, 0.0);
        let a01 = fresnel::amplitudes(n0, cos0, self.n1, self.cos1);
        let a12 = fresnel::amplitudes(self.n1, self.cos1, self.n2, self.cos2);
        let one_way = (Complex64::i() * self.beta).exp();
        let round_trip = one_way * one_way;
        let sum = |r01: Complex64, r12: Complex64, t01: Complex64, t12: Complex64| {
            let den = 1.0 + r01 * r12 * round_trip;
            (den.norm() >= AIRY_DENOMINATOR_FLOOR)
                .then(|| ((r01 + r12 * round_trip) / den, t01 * t12 * one_way / den))
        };
        let (r_s, t_s) = sum(a01.r_s, a12.r_s, a01.t_s, a12.t_s)?;
        let (r_p, t_p) = sum(a01.r_p, a12.r_p, a01.t_p, a12.t_p)?;
        let amplitudes = Amplitudes { r_s, r_p, t_s, t_p };
        let finite = [r_s, r_p, t_s, t_p].iter().all(|z| z.is_finite());
        finite.then_some(amplitudes)
    }

    fn intensities(&self, amp: &Amplitudes) -> Response {
        let flux_in = self.n0 * self.cos0;
        Response {
            r_s: amp.r_s.norm_sqr(),
            r_p: amp.r_p.norm_sqr(),
            t_s: (self.n2 * self.cos2).re / flux_in * amp.t_s.norm_sqr(),
            t_p: (self.n2 * self.cos2.conj()).re / flux_in * amp.t_p.norm_sqr(),
        }
    }
}

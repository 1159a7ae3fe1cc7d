//! Fresnel amplitude coefficients at one planar interface, Snell's law with complex
//! indices, and the result types shared by the single-film ([`crate::airy`]) and
//! multilayer ([`crate::tmm`]) solvers.
//!
//! Conventions (used throughout the crate):
//! * complex index `n + iκ` with `κ ≥ 0` for absorption (time dependence `e^{-iωt}`);
//! * `n cos θ` of every medium is taken on the branch with `Im ≥ 0` (a wave that decays
//!   away from the interface), and `Re ≥ 0` when it is real (a wave that leaves it), so
//!   total internal reflection gives `|r| = 1` and never a NaN;
//! * `r_p` uses the sign for which `r_p = r_s` at normal incidence:
//!   `r_p = (n_i cos θ_t − n_t cos θ_i) / (n_i cos θ_t + n_t cos θ_i)`;
//! * `t_s`, `t_p` are ratios of the full electric-field amplitudes.

use crate::incidence::Incidence;
use num_complex::Complex64;
use std::fmt;

mod error;
pub(crate) use error::Num;
pub use error::OpticsError;

/// Complex amplitude coefficients of a surface or a stack, for s and p polarisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Amplitudes {
    /// Reflected over incident field, s (perpendicular) polarisation.
    pub r_s: Complex64,
    /// Reflected over incident field, p (parallel) polarisation.
    pub r_p: Complex64,
    /// Transmitted over incident field, s polarisation.
    pub t_s: Complex64,
    /// Transmitted over incident field, p polarisation.
    pub t_p: Complex64,
}

/// Intensity reflectance and transmittance for s and p polarisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// Reflectance `|r_s|²`.
    pub r_s: f64,
    /// Reflectance `|r_p|²`.
    pub r_p: f64,
    /// Transmittance, s polarisation (power flux across the layers, not `1 − R`).
    pub t_s: f64,
    /// Transmittance, p polarisation (power flux across the layers, not `1 − R`).
    pub t_p: f64,
}

impl Response {
    /// Unpolarised reflectance: the MEAN `(R_s + R_p)/2` (seed 000 eq. 4 sums them, 2× too bright).
    pub fn r(&self) -> f64 {
        0.5 * (self.r_s + self.r_p)
    }

    /// Unpolarised transmittance `(T_s + T_p)/2`, computed from the transmitted amplitudes.
    pub fn t(&self) -> f64 {
        0.5 * (self.t_s + self.t_p)
    }

    /// Unpolarised absorptance `1 − R − T` (zero, up to rounding, for lossless stacks).
    pub fn absorptance(&self) -> f64 {
        1.0 - self.r() - self.t()
    }

    /// What a stack does at exactly grazing incidence (`cos θ = 0`): nothing at all if every
    /// medium is the same, otherwise it reflects everything (the limit θ → 90°).
    pub(crate) fn grazing(all_media_equal: bool) -> Response {
        let (r, t) = if all_media_equal {
            (0.0, 1.0)
        } else {
            (1.0, 0.0)
        };
        Response {
            r_s: r,
            r_p: r,
            t_s: t,
            t_p: t,
        }
    }
}

impl fmt::Display for Response {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "R_s={} R_p={} T_s={} T_p={}",
            self.r_s, self.r_p, self.t_s, self.t_p
        )
    }
}

/// `n cos θ` inside a medium of index `n`, for a wave whose tangential invariant is
/// `n_sin = n_0 sin θ_0` (Snell), on the decaying/outgoing branch.
///
/// Computed as `sqrt(n² − n_sin²)` so that it stays exact at the critical angle and in
/// absorbing media; `cos θ` itself is this divided by `n`.
/// Near grazing incidence prefer [`crate::Incidence::normal_index`], which needs no `n_sin`.
pub fn normal_index(n: Complex64, n_sin: f64) -> Complex64 {
    crate::incidence::decaying_root(n * n - n_sin * n_sin)
}

/// Complex `cos θ_t` in a medium of index `n_t` for light arriving at `cos_theta_i` from a
/// lossless medium of index `n_i`: `sqrt(1 − (n_i/n_t)² sin²θ_i)` on the decaying branch.
pub fn cos_transmitted(n_i: f64, n_t: Complex64, cos_theta_i: f64) -> Complex64 {
    normal_index(n_t, n_sin(n_i, cos_theta_i)) / n_t
}

/// The Snell invariant `n sin θ` of a ray in a medium of real index `n`.
pub(crate) fn n_sin(n: f64, cos_theta: f64) -> f64 {
    n * (1.0 - cos_theta * cos_theta).max(0.0).sqrt()
}

/// Fresnel amplitudes between media `i` and `t`, given each medium's index and its
/// complex `cos θ` (from [`cos_transmitted`] or [`normal_index`]).
///
/// A surface between identical media (`n_i == n_t`) has `r = 0`, `t = 1` even at grazing
/// incidence, where the general formula would be 0/0.
pub fn amplitudes(
    n_i: Complex64,
    cos_i: Complex64,
    n_t: Complex64,
    cos_t: Complex64,
) -> Amplitudes {
    if n_i == n_t {
        return Amplitudes {
            r_s: Complex64::new(0.0, 0.0),
            r_p: Complex64::new(0.0, 0.0),
            t_s: Complex64::new(1.0, 0.0),
            t_p: Complex64::new(1.0, 0.0),
        };
    }
    let (ni_ci, nt_ct) = (n_i * cos_i, n_t * cos_t);
    let (ni_ct, nt_ci) = (n_i * cos_t, n_t * cos_i);
    let den_s = ni_ci + nt_ct;
    let den_p = ni_ct + nt_ci;
    Amplitudes {
        r_s: (ni_ci - nt_ct) / den_s,
        r_p: (ni_ct - nt_ci) / den_p,
        t_s: 2.0 * ni_ci / den_s,
        t_p: 2.0 * ni_ci / den_p,
    }
}

/// One planar interface: light in a lossless medium `n_incident` meets a (possibly
/// absorbing) medium `n_transmitted` at `cos_theta_incident`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface {
    /// Real index of the incident medium.
    pub n_incident: f64,
    /// Complex index `n + iκ` of the transmitting medium.
    pub n_transmitted: Complex64,
}

impl Interface {
    /// A validated interface.
    ///
    /// # Guarantees
    /// `n_incident` is finite and `> 0`; `n_transmitted` is finite with `Re > 0`, `Im ≥ 0`.
    pub fn new(n_incident: f64, n_transmitted: Complex64) -> Result<Interface, OpticsError> {
        check_real_index("n_incident", n_incident)?;
        check_complex_index("n_transmitted", n_transmitted)?;
        Ok(Interface {
            n_incident,
            n_transmitted,
        })
    }

    /// Amplitude coefficients at `cos_theta_incident` ∈ [0, 1], or an error naming the bad value.
    pub fn try_amplitudes(&self, cos_theta_incident: f64) -> Result<Amplitudes, OpticsError> {
        check_cos("cos_theta_incident", cos_theta_incident)?;
        Ok(self.amplitudes_at(Incidence::try_from_cos(cos_theta_incident)?))
    }

    /// Amplitude coefficients in the direction `incidence`.
    pub fn amplitudes_at(&self, incidence: Incidence) -> Amplitudes {
        let n_i = Complex64::new(self.n_incident, 0.0);
        if incidence.cos() == 0.0 && n_i != self.n_transmitted {
            // Grazing: the formula's limit, written out to avoid 0/0 when cos_t is also 0.
            return Amplitudes {
                r_s: Complex64::new(-1.0, 0.0),
                r_p: Complex64::new(1.0, 0.0),
                t_s: Complex64::new(0.0, 0.0),
                t_p: Complex64::new(0.0, 0.0),
            };
        }
        let cos_t =
            incidence.normal_index(self.n_incident, self.n_transmitted) / self.n_transmitted;
        let cos_i = Complex64::new(incidence.cos(), 0.0);
        amplitudes(n_i, cos_i, self.n_transmitted, cos_t)
    }

    /// Intensity reflectance and transmittance at `cos_theta_incident` ∈ [0, 1].
    ///
    /// `T_s = Re(n_t cos θ_t)/(n_i cos θ_i)·|t_s|²` and `T_p = Re(n_t conj(cos θ_t))/(n_i cos θ_i)·|t_p|²`
    /// (power flux normal to the surface); exactly grazing incidence gives its limit
    /// `R = 1, T = 0` (or `R = 0, T = 1` between identical media), never 0/0.
    pub fn try_response(&self, cos_theta_incident: f64) -> Result<Response, OpticsError> {
        check_cos("cos_theta_incident", cos_theta_incident)?;
        Ok(self.response_at(Incidence::try_from_cos(cos_theta_incident)?))
    }

    /// Intensity reflectance and transmittance in the direction `incidence`
    /// (see [`Interface::try_response`]).
    pub fn response_at(&self, incidence: Incidence) -> Response {
        let amp = self.amplitudes_at(incidence);
        let n_i = self.n_incident;
        let n_t = self.n_transmitted;
        if incidence.cos() == 0.0 {
            return Response::grazing(Complex64::new(n_i, 0.0) == n_t);
        }
        let cos_t = incidence.normal_index(n_i, n_t) / n_t;
        let flux_in = n_i * incidence.cos();
        Response {
            r_s: amp.r_s.norm_sqr(),
            r_p: amp.r_p.norm_sqr(),
            t_s: (n_t * cos_t).re / flux_in * amp.t_s.norm_sqr(),
            t_p: (n_t * cos_t.conj()).re / flux_in * amp.t_p.norm_sqr(),
        }
    }

    /// [`Interface::try_response`] for a known-good angle.
    ///
    /// # Panics
    /// If `cos_theta_incident` is not in [0, 1].
    pub fn response(&self, cos_theta_incident: f64) -> Response {
        self.try_response(cos_theta_incident)
            .unwrap_or_else(|err| panic!("{err}"))
    }

    /// `cos θ` of Brewster's angle (`R_p = 0`), `n_i / sqrt(n_i² + n_t²)`, for a lossless
    /// transmitting medium; `None` if it absorbs.
    pub fn brewster_cos(&self) -> Option<f64> {
        (self.n_transmitted.im == 0.0).then(|| {
            let (n_i, n_t) = (self.n_incident, self.n_transmitted.re);
            n_i / n_i.hypot(n_t)
        })
    }

    /// `cos θ` of the critical angle, `sqrt(1 − (n_t/n_i)²)`, when the transmitting medium
    /// is lossless and optically thinner; `None` otherwise.
    pub fn critical_cos(&self) -> Option<f64> {
        let n_t = self.n_transmitted;
        (n_t.im == 0.0 && n_t.re < self.n_incident).then(|| {
            let ratio = n_t.re / self.n_incident;
            (1.0 - ratio * ratio).sqrt()
        })
    }
}

/// The largest index modulus accepted: far above any material's (metals in the far infrared
/// reach a few hundred), and small enough that `n²` and its products stay finite.
pub const MAX_INDEX: f64 = 1e6;

/// The smallest real part of an index accepted: far below any material's (the lowest,
/// silver's in the visible, are about 0.05), and large enough that the ratio of two
/// indices (at most `MAX_INDEX / MIN_INDEX = 1e9`) and its square stay finite.
pub const MIN_INDEX: f64 = 1e-3;

/// The largest layer thickness accepted, in nm (1 m): far beyond any film or slide, and
/// small enough that a layer's phase `2π n d cos θ / λ` stays finite and accurate.
pub const MAX_THICKNESS_NM: f64 = 1e9;

/// Checks a real refractive index: finite, `≥ MIN_INDEX` and `≤ MAX_INDEX`.
pub(crate) fn check_real_index(what: &'static str, n: f64) -> Result<(), OpticsError> {
    if n.is_finite() && (MIN_INDEX..=MAX_INDEX).contains(&n) {
        Ok(())
    } else {
        Err(OpticsError::Index { what, value: n })
    }
}

/// Checks a complex index: finite, `Re ≥ MIN_INDEX`, `Im ≥ 0` (absorbing, never
/// amplifying), both parts `≤ MAX_INDEX`.
pub(crate) fn check_complex_index(what: &'static str, n: Complex64) -> Result<(), OpticsError> {
    let bounded = n.re <= MAX_INDEX && n.im <= MAX_INDEX;
    if n.re.is_finite() && n.im.is_finite() && n.re >= MIN_INDEX && n.im >= 0.0 && bounded {
        Ok(())
    } else {
        Err(OpticsError::ComplexIndex { what, value: n })
    }
}

/// Checks a cosine of an incidence angle: in [0, 1].
pub(crate) fn check_cos(what: &'static str, cos_theta: f64) -> Result<(), OpticsError> {
    if (0.0..=1.0).contains(&cos_theta) {
        Ok(())
    } else {
        Err(OpticsError::Cosine {
            what,
            value: cos_theta,
        })
    }
}

/// Checks a wavelength: finite and `> 0` nm.
/// `Ok` if a slice `what` is `expected` long, else [`OpticsError::Length`].
pub(crate) fn check_len(
    what: &'static str,
    len: usize,
    expected: usize,
) -> Result<(), OpticsError> {
    if len == expected {
        Ok(())
    } else {
        Err(OpticsError::Length {
            what,
            len,
            expected,
        })
    }
}

pub(crate) fn check_wavelength(wavelength_nm: f64) -> Result<(), OpticsError> {
    if wavelength_nm.is_finite() && wavelength_nm > 0.0 {
        Ok(())
    } else {
        Err(OpticsError::Wavelength { wavelength_nm })
    }
}

/// Checks a layer thickness: in `0..=MAX_THICKNESS_NM` nm.
pub(crate) fn check_thickness(thickness_nm: f64) -> Result<(), OpticsError> {
    if (0.0..=MAX_THICKNESS_NM).contains(&thickness_nm) {
        Ok(())
    } else {
        Err(OpticsError::Thickness { thickness_nm })
    }
}

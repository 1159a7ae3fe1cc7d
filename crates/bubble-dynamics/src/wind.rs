//! The air's velocity field: uniform + seeded smooth gusts + a user closure.

use std::fmt;
use std::sync::Arc;

use glam::{DMat3, DVec3};

use crate::error::ParamError;
use crate::rng::SplitMix64;
use crate::validate::{finite_vec, non_negative, positive};

/// A user wind field: air velocity in m/s at a position (m) and time (s).
pub type WindFn = dyn Fn(DVec3, f64) -> DVec3 + Send + Sync;

/// Number of travelling waves that make up the gust field.
const GUST_MODES: usize = 8;

/// The wind the bubbles' drag is measured against.
pub struct Wind {
    /// Steady part, m/s.
    pub uniform_m_per_s: DVec3,
    /// Seeded, smooth, divergence-free gusts (off when the amplitude is zero).
    pub gusts: Gusts,
    /// Optional user field, added to the rest; evaluated at every vertex every substep.
    pub field: Option<Box<WindFn>>,
}

impl Default for Wind {
    fn default() -> Self {
        Self {
            uniform_m_per_s: DVec3::ZERO,
            gusts: Gusts::default(),
            field: None,
        }
    }
}

impl fmt::Debug for Wind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Wind")
            .field("uniform_m_per_s", &self.uniform_m_per_s)
            .field("gusts", &self.gusts)
            .field("field", &self.field.as_ref().map(|_| "<closure>"))
            .finish()
    }
}

impl Wind {
    /// A steady, uniform wind.
    pub fn uniform(velocity_m_per_s: DVec3) -> Self {
        Self {
            uniform_m_per_s: velocity_m_per_s,
            ..Self::default()
        }
    }

    /// This wind with `gusts` added.
    pub fn with_gusts(self, gusts: Gusts) -> Self {
        Self { gusts, ..self }
    }

    /// This wind with a user field added (position m, time s → velocity m/s).
    pub fn with_field(self, field: impl Fn(DVec3, f64) -> DVec3 + Send + Sync + 'static) -> Self {
        Self {
            field: Some(Box::new(field)),
            ..self
        }
    }

    pub(crate) fn validate(&self) -> Result<(), ParamError> {
        finite_vec("uniform_m_per_s", self.uniform_m_per_s)?;
        self.gusts.validate().map_err(|e| e.within("gusts"))
    }
}

/// Gusts: a sum of travelling plane waves with random directions, wavelengths around
/// `length_scale_m` and periods around `timescale_s`; each wave's velocity is
/// perpendicular to its wave vector, so the field is divergence-free like real
/// (incompressible) air.
#[derive(Clone, Debug, PartialEq)]
pub struct Gusts {
    /// RMS gust speed, m/s (0 = no gusts).
    pub amplitude_m_per_s: f64,
    /// Typical gust period, s.
    pub timescale_s: f64,
    /// Typical gust size, m.
    pub length_scale_m: f64,
    /// Seed of the wave directions and phases.
    pub seed: u64,
}

impl Default for Gusts {
    fn default() -> Self {
        Self {
            amplitude_m_per_s: 0.0,
            timescale_s: 2.0,
            length_scale_m: 1.0,
            seed: 0,
        }
    }
}

impl Gusts {
    fn validate(&self) -> Result<(), ParamError> {
        non_negative("amplitude_m_per_s", self.amplitude_m_per_s)?;
        positive("timescale_s", self.timescale_s)?;
        positive("length_scale_m", self.length_scale_m)
    }
}

#[derive(Clone, Debug)]
struct GustMode {
    wave_vector_per_m: DVec3,
    amplitude_m_per_s: DVec3,
    omega_per_s: f64,
    phase: f64,
}

/// The validated wind, gust waves drawn, closure shared so worlds can be cloned.
#[derive(Clone)]
pub(crate) struct WindField {
    uniform: DVec3,
    modes: Vec<GustMode>,
    field: Option<Arc<WindFn>>,
}

impl fmt::Debug for WindField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("WindField")
            .field("uniform", &self.uniform)
            .field("modes", &self.modes.len())
            .finish()
    }
}

impl WindField {
    pub(crate) fn new(wind: Wind) -> Self {
        Self {
            uniform: wind.uniform_m_per_s,
            modes: gust_modes(&wind.gusts),
            field: wind.field.map(Arc::from),
        }
    }

    /// The steady part, m/s.
    pub(crate) fn uniform_m_per_s(&self) -> DVec3 {
        self.uniform
    }

    /// Replaces the steady part (the gusts and the user field stay).
    pub(crate) fn set_uniform_m_per_s(&mut self, velocity_m_per_s: DVec3) {
        self.uniform = velocity_m_per_s;
    }

    /// True when the air is still everywhere, always.
    pub(crate) fn is_still(&self) -> bool {
        self.uniform == DVec3::ZERO && self.modes.is_empty() && self.field.is_none()
    }

    /// Uniform + gust velocity at `x` and its Jacobian ∂w/∂x (for a cheap first-order
    /// expansion over a bubble, which is small beside a gust).
    pub(crate) fn smooth_part(&self, x: DVec3, t_s: f64) -> (DVec3, DMat3) {
        let mut w = self.uniform;
        let mut jacobian = DMat3::ZERO;
        for m in &self.modes {
            let arg = m.wave_vector_per_m.dot(x) - m.omega_per_s * t_s + m.phase;
            let (s, c) = arg.sin_cos();
            w += m.amplitude_m_per_s * c;
            let k = m.wave_vector_per_m * -s;
            jacobian += DMat3::from_cols(
                m.amplitude_m_per_s * k.x,
                m.amplitude_m_per_s * k.y,
                m.amplitude_m_per_s * k.z,
            );
        }
        (w, jacobian)
    }

    /// The user closure, if any.
    pub(crate) fn user_field(&self) -> Option<&WindFn> {
        self.field.as_deref()
    }

    /// The exact wind velocity at `x`, time `t_s`.
    pub(crate) fn velocity(&self, x: DVec3, t_s: f64) -> DVec3 {
        let (w, _) = self.smooth_part(x, t_s);
        w + self.field.as_ref().map_or(DVec3::ZERO, |f| f(x, t_s))
    }
}

fn gust_modes(gusts: &Gusts) -> Vec<GustMode> {
    if gusts.amplitude_m_per_s == 0.0 {
        return Vec::new();
    }
    let mut rng = SplitMix64::new(gusts.seed ^ 0x6057_5EED);
    // Random phases make each mode contribute amplitude²/2 to the mean square.
    let per_mode = gusts.amplitude_m_per_s * (2.0 / GUST_MODES as f64).sqrt();
    (0..GUST_MODES)
        .map(|_| {
            let direction = rng.unit_vector();
            let wavenumber = std::f64::consts::TAU / (gusts.length_scale_m * rng.range(0.5, 2.0));
            let across = direction.any_orthonormal_vector();
            let turn = rng.range(0.0, std::f64::consts::TAU);
            let polarisation = across * turn.cos() + direction.cross(across) * turn.sin();
            GustMode {
                wave_vector_per_m: direction * wavenumber,
                amplitude_m_per_s: polarisation * per_mode,
                omega_per_s: std::f64::consts::TAU / (gusts.timescale_s * rng.range(0.5, 2.0)),
                phase: rng.range(0.0, std::f64::consts::TAU),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gusty() -> WindField {
        WindField::new(Wind::default().with_gusts(Gusts {
            amplitude_m_per_s: 1.5,
            seed: 11,
            ..Gusts::default()
        }))
    }

    #[test]
    fn gust_jacobian_matches_central_differences() {
        let w = gusty();
        let x = DVec3::new(0.3, -0.2, 0.7);
        let (_, j) = w.smooth_part(x, 1.3);
        let h = 1e-6;
        for axis in 0..3 {
            let e = DVec3::AXES[axis] * h;
            let fd = (w.smooth_part(x + e, 1.3).0 - w.smooth_part(x - e, 1.3).0) / (2.0 * h);
            let diff = (fd - j.col(axis)).length();
            assert!(
                diff < 1e-6,
                "axis {axis}: jacobian {:?} vs fd {fd:?}, diff {diff}",
                j.col(axis)
            );
        }
    }

    #[test]
    fn gusts_are_divergence_free_with_the_requested_rms() {
        let w = gusty();
        let mut rng = SplitMix64::new(5);
        let mut mean_square = 0.0;
        let n = 4000;
        for _ in 0..n {
            let x = rng.unit_vector() * rng.range(0.0, 20.0);
            let t = rng.range(0.0, 100.0);
            let (v, j) = w.smooth_part(x, t);
            let div = j.col(0).x + j.col(1).y + j.col(2).z;
            assert!(div.abs() < 1e-9, "divergence {div}");
            mean_square += v.length_squared() / n as f64;
        }
        let rms = mean_square.sqrt();
        assert!((rms - 1.5).abs() < 0.25, "rms gust = {rms}, expected ≈ 1.5");
    }
}

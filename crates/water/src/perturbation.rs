//! Seed 002's perturbations: directional sine waves (eq. 4) and circular ripples (eq. 5),
//! evaluated exactly in f64 (the reference the fast grid path is tested against).

use std::f64::consts::TAU;

use crate::dispersion::deep_water_omega_rad_per_s;
use crate::error::{WaterError, check_non_negative, check_positive};

/// A directional wave `y = a·sin(k(x·i + z·j) − ω t)` with `(i, j)` a unit vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wave {
    amplitude_m: f64,
    k_per_m: f64,
    omega_rad_per_s: f64,
    direction: [f64; 2],
}

impl Wave {
    /// A wave of `amplitude_m`, `wavelength_m`, travelling along `direction` (X, Z; any
    /// non-zero length: it is normalised), with angular speed `omega_rad_per_s` or, when
    /// `None`, the deep-water dispersion relation's.
    ///
    /// # Guarantees
    /// Amplitude finite and `>= 0`; wavenumber and ω finite and `> 0`; direction unit.
    pub fn try_new(
        amplitude_m: f64,
        wavelength_m: f64,
        direction: [f64; 2],
        omega_rad_per_s: Option<f64>,
    ) -> Result<Wave, WaterError> {
        check_non_negative("wave amplitude_m", amplitude_m)?;
        check_positive("wave wavelength_m", wavelength_m)?;
        let len = direction[0].hypot(direction[1]);
        if !(len.is_finite() && len > 0.0) {
            return Err(WaterError::new(
                "wave direction",
                format!("{direction:?} must be finite and non-zero"),
            ));
        }
        let k_per_m = TAU / wavelength_m;
        let omega = omega_or_dispersion("wave omega_rad_per_s", omega_rad_per_s, k_per_m)?;
        Ok(Wave {
            amplitude_m,
            k_per_m,
            omega_rad_per_s: omega,
            direction: [direction[0] / len, direction[1] / len],
        })
    }

    /// Amplitude in metres.
    pub fn amplitude_m(&self) -> f64 {
        self.amplitude_m
    }

    /// Wavenumber `k = 2π/λ` in rad/m.
    pub fn k_per_m(&self) -> f64 {
        self.k_per_m
    }

    /// Angular frequency ω in rad/s.
    pub fn omega_rad_per_s(&self) -> f64 {
        self.omega_rad_per_s
    }

    /// The unit direction of travel `(i, j)` on the XZ plane.
    pub fn direction(&self) -> [f64; 2] {
        self.direction
    }
}

/// A circular ripple `y = a·e^(−α r)·e^(−β t)·sin(k r − ω t)` around a centre, with
/// `r` the horizontal distance to it; `α` and `β` (0 for none) make it fade with
/// distance and with time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ripple {
    amplitude_m: f64,
    k_per_m: f64,
    omega_rad_per_s: f64,
    center_m: [f64; 2],
    decay_per_m: f64,
    decay_per_s: f64,
}

impl Ripple {
    /// A ripple of `amplitude_m` and `wavelength_m` around `center_m` (X, Z), fading by
    /// `e^(−decay_per_m·r)` and `e^(−decay_per_s·t)`, with angular speed `omega_rad_per_s`
    /// or, when `None`, the dispersion relation's.
    ///
    /// # Guarantees
    /// Amplitude and decays finite and `>= 0`; wavenumber and ω finite and `> 0`; centre finite.
    pub fn try_new(
        amplitude_m: f64,
        wavelength_m: f64,
        center_m: [f64; 2],
        omega_rad_per_s: Option<f64>,
        decay: [f64; 2],
    ) -> Result<Ripple, WaterError> {
        check_non_negative("ripple amplitude_m", amplitude_m)?;
        check_positive("ripple wavelength_m", wavelength_m)?;
        if !center_m.iter().all(|c| c.is_finite()) {
            return Err(WaterError::new(
                "ripple center_m",
                format!("{center_m:?} must be finite"),
            ));
        }
        check_non_negative("ripple decay_per_m", decay[0])?;
        check_non_negative("ripple decay_per_s", decay[1])?;
        let k_per_m = TAU / wavelength_m;
        let omega = omega_or_dispersion("ripple omega_rad_per_s", omega_rad_per_s, k_per_m)?;
        Ok(Ripple {
            amplitude_m,
            k_per_m,
            omega_rad_per_s: omega,
            center_m,
            decay_per_m: decay[0],
            decay_per_s: decay[1],
        })
    }

    /// Amplitude in metres (at the centre, at t = 0).
    pub fn amplitude_m(&self) -> f64 {
        self.amplitude_m
    }

    /// Wavenumber in rad/m.
    pub fn k_per_m(&self) -> f64 {
        self.k_per_m
    }

    /// Angular frequency in rad/s.
    pub fn omega_rad_per_s(&self) -> f64 {
        self.omega_rad_per_s
    }

    /// Centre (X, Z) in metres.
    pub fn center_m(&self) -> [f64; 2] {
        self.center_m
    }

    /// Decay with distance α, per metre.
    pub fn decay_per_m(&self) -> f64 {
        self.decay_per_m
    }

    /// Decay with time β, per second.
    pub fn decay_per_s(&self) -> f64 {
        self.decay_per_s
    }
}

fn omega_or_dispersion(what: &str, omega: Option<f64>, k_per_m: f64) -> Result<f64, WaterError> {
    match omega {
        Some(w) => check_positive(what, w).map(|()| w),
        None => Ok(deep_water_omega_rad_per_s(k_per_m)),
    }
}

/// One term of seed 002's sum of perturbations (eq. 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Perturbation {
    /// A directional sine wave.
    Wave(Wave),
    /// A circular ripple.
    Ripple(Ripple),
}

impl Perturbation {
    /// Height above the rest plane at `(x, z)` and time `t_s`, in metres.
    pub fn height_m(&self, x: f64, z: f64, t_s: f64) -> f64 {
        match self {
            Self::Wave(w) => w.amplitude_m * wave_phase(w, x, z, t_s).sin(),
            Self::Ripple(r) => {
                let (dist, envelope) = ripple_radius_envelope(r, x, z, t_s);
                envelope * (r.k_per_m * dist - r.omega_rad_per_s * t_s).sin()
            }
        }
    }

    /// Exact slope `(∂y/∂x, ∂y/∂z)` at `(x, z)` and time `t_s`; a ripple's cone tip at its
    /// centre takes slope 0 (the mean of its one-sided slopes).
    pub fn gradient(&self, x: f64, z: f64, t_s: f64) -> [f64; 2] {
        match self {
            Self::Wave(w) => {
                let s = w.amplitude_m * w.k_per_m * wave_phase(w, x, z, t_s).cos();
                [s * w.direction[0], s * w.direction[1]]
            }
            Self::Ripple(r) => {
                let (dist, envelope) = ripple_radius_envelope(r, x, z, t_s);
                if dist == 0.0 {
                    return [0.0; 2];
                }
                let phase = r.k_per_m * dist - r.omega_rad_per_s * t_s;
                let dy_dr = envelope * (r.k_per_m * phase.cos() - r.decay_per_m * phase.sin());
                let [dx, dz] = [x - r.center_m[0], z - r.center_m[1]];
                [dy_dr * dx / dist, dy_dr * dz / dist]
            }
        }
    }
}

fn wave_phase(w: &Wave, x: f64, z: f64, t_s: f64) -> f64 {
    w.k_per_m * (x * w.direction[0] + z * w.direction[1]) - w.omega_rad_per_s * t_s
}

/// Distance to the ripple's centre and its amplitude there at `t_s`.
fn ripple_radius_envelope(r: &Ripple, x: f64, z: f64, t_s: f64) -> (f64, f64) {
    let dist = (x - r.center_m[0]).hypot(z - r.center_m[1]);
    let envelope = r.amplitude_m * (-r.decay_per_m * dist - r.decay_per_s * t_s).exp();
    (dist, envelope)
}

//! A tiny deterministic generator (SplitMix64) and smooth random fields built from it.
//!
//! In-crate rather than `rand` so that a seed means the same numbers forever, on every
//! platform, whatever version of a dependency is resolved.

use glam::DVec3;

/// SplitMix64 (Steele, Lea & Flood 2014): 64-bit state, passes BigCrush, trivially seedable.
#[derive(Clone, Debug)]
pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator whose stream depends only on `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub(crate) fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// Uniform on the unit sphere (Archimedes: z uniform in [-1, 1]).
    pub(crate) fn unit_vector(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

/// One travelling wave `amplitude · sin(wavenumber · direction·u + phase + omega·t)`.
#[derive(Clone, Debug)]
pub(crate) struct Wave {
    pub(crate) direction: DVec3,
    pub(crate) wavenumber: f64,
    pub(crate) phase: f64,
    pub(crate) omega_per_s: f64,
    pub(crate) amplitude: f64,
}

/// A smooth random scalar field on the unit sphere, `f(u, t) = Σ waves`, with |f| ≤ 1.
#[derive(Clone, Debug)]
pub(crate) struct SphereField {
    pub(crate) waves: Vec<Wave>,
}

impl SphereField {
    /// `count` waves with wavenumbers in [1.5, 4] (a few lobes over the sphere) and
    /// angular frequencies in [0.5, 1.5]·`omega_per_s`; amplitudes sum to 1.
    pub(crate) fn new(seed: u64, count: usize, omega_per_s: f64) -> Self {
        Self::with_wavenumbers(seed, count, omega_per_s, (1.5, 4.0))
    }

    /// As [`SphereField::new`] with wavenumbers in `wavenumbers` (rad per unit length
    /// along the wave's direction: 30 puts about ten stripes across the sphere).
    pub(crate) fn with_wavenumbers(
        seed: u64,
        count: usize,
        omega_per_s: f64,
        wavenumbers: (f64, f64),
    ) -> Self {
        let mut rng = SplitMix64::new(seed);
        let mut waves: Vec<Wave> = (0..count)
            .map(|_| Wave {
                direction: rng.unit_vector(),
                wavenumber: rng.range(wavenumbers.0, wavenumbers.1),
                phase: rng.range(0.0, std::f64::consts::TAU),
                omega_per_s: omega_per_s * rng.range(0.5, 1.5),
                amplitude: rng.range(0.5, 1.0),
            })
            .collect();
        let total: f64 = waves.iter().map(|w| w.amplitude).sum();
        if total > 0.0 {
            waves.iter_mut().for_each(|w| w.amplitude /= total);
        }
        Self { waves }
    }

    /// The field at unit direction `u` and time `t_s`.
    pub(crate) fn value(&self, u: DVec3, t_s: f64) -> f64 {
        self.waves
            .iter()
            .map(|w| {
                w.amplitude
                    * (w.wavenumber * w.direction.dot(u) + w.phase + w.omega_per_s * t_s).sin()
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_stream_different_seed_different_stream() {
        let a: Vec<u64> = (0..4)
            .map({
                let mut r = SplitMix64::new(7);
                move |_| r.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..4)
            .map({
                let mut r = SplitMix64::new(7);
                move |_| r.next_u64()
            })
            .collect();
        let c = SplitMix64::new(8).next_u64();
        assert_eq!(a, b);
        assert_ne!(a[0], c);
    }

    #[test]
    fn unit_vectors_are_unit_and_uniform_in_mean() {
        let mut r = SplitMix64::new(1);
        let mut sum = DVec3::ZERO;
        for _ in 0..20_000 {
            let u = r.unit_vector();
            assert!(
                (u.length() - 1.0).abs() < 1e-12,
                "|u| - 1 = {}",
                u.length() - 1.0
            );
            sum += u;
        }
        // The mean of N uniform unit vectors has per-axis std 1/sqrt(3N) ≈ 0.004.
        assert!(
            (sum / 20_000.0).length() < 0.02,
            "mean = {:?}",
            sum / 20_000.0
        );
    }

    #[test]
    fn sphere_field_is_bounded_by_one() {
        let f = SphereField::new(3, 6, 1.0);
        let mut r = SplitMix64::new(9);
        for _ in 0..1000 {
            let v = f.value(r.unit_vector(), r.range(0.0, 10.0));
            assert!(v.abs() <= 1.0 + 1e-12, "|f| = {v}");
        }
    }
}

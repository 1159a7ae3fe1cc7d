//! [`Irradiance`]: light arriving from the environment at a surface of any orientation, as
//! order-2 spherical harmonics (Ramamoorthi & Hanrahan 2001), so the sky lights the ground
//! and the undersides of objects.

use glam::{DVec3, Vec3};

use crate::{Environment, Sky};

/// Directions of the projection quadrature (a Fibonacci sphere).
const QUADRATURE_DIRECTIONS: usize = 4096;

/// Cosine-convolved order-2 spherical harmonics of an environment: `diffuse(n)` is the
/// radiance a white Lambertian surface with normal `n` reflects when the environment
/// lights it unoccluded (its irradiance `E(n)` over π).
///
/// # Guarantees
/// `diffuse` returns finite, non-negative radiance for any input; a uniform environment
/// of radiance `L` gives exactly `L` in every direction (the white furnace).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Irradiance {
    /// Coefficients of `1, y, z, x, xy, yz, 3z² − 1, xz, x² − y²`, with the SH
    /// normalisation and the cosine lobe's `Â_l / π` (1, 2/3, 1/4) folded in.
    coeffs: [[f32; 3]; 9],
}

/// Real SH normalisation of the nine polynomials above.
const SH_NORM: [f64; 9] = [
    0.282_094_791_773_878_14,
    0.488_602_511_902_919_9,
    0.488_602_511_902_919_9,
    0.488_602_511_902_919_9,
    1.092_548_430_592_079_2,
    1.092_548_430_592_079_2,
    0.315_391_565_252_520_05,
    1.092_548_430_592_079_2,
    0.546_274_215_296_039_6,
];

/// `Â_l / π` of each coefficient's band.
const LOBE: [f64; 9] = [
    1.0,
    2.0 / 3.0,
    2.0 / 3.0,
    2.0 / 3.0,
    0.25,
    0.25,
    0.25,
    0.25,
    0.25,
];

fn polynomials(d: DVec3) -> [f64; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        1.0,
        y,
        z,
        x,
        x * y,
        y * z,
        3.0 * z * z - 1.0,
        x * z,
        x * x - y * y,
    ]
}

impl Irradiance {
    /// The same radiance `rgb` from every direction.
    pub fn uniform(rgb: [f32; 3]) -> Irradiance {
        let mut coeffs = [[0.0; 3]; 9];
        coeffs[0] = rgb;
        Irradiance { coeffs }
    }

    /// Projects `env` (a fixed 4096-direction quadrature; a sky's sun disc analytically).
    pub fn from_environment(env: &Environment) -> Irradiance {
        let mut sum = [[0.0f64; 3]; 9];
        let (env, sun) = match env {
            Environment::Uniform(rgb) => return Self::uniform(*rgb),
            Environment::Sky(sky) if sky.sun_rgb != [0.0; 3] => (
                // The disc is far smaller than the quadrature's spacing: add it exactly.
                Environment::Sky(Sky {
                    sun_rgb: [0.0; 3],
                    ..*sky
                }),
                Some(*sky),
            ),
            other => (other.clone(), None),
        };
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let n = QUADRATURE_DIRECTIONS as f64;
        let weight = 4.0 * std::f64::consts::PI / n;
        for k in 0..QUADRATURE_DIRECTIONS {
            let y = 1.0 - (k as f64 + 0.5) * 2.0 / n;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * k as f64;
            let d = DVec3::new(r * phi.cos(), y, r * phi.sin());
            let l = env.radiance(d.as_vec3());
            accumulate(&mut sum, d, l, weight);
        }
        if let Some(sky) = sun {
            let cos_r = f64::from(sky.sun_radius_deg).to_radians().cos();
            let solid_angle = 2.0 * std::f64::consts::PI * (1.0 - cos_r);
            let d = sky.sun_direction.normalize_or(Vec3::Y).as_dvec3();
            accumulate(&mut sum, d, sky.sun_rgb, solid_angle);
        }
        let mut coeffs = [[0.0f32; 3]; 9];
        for (i, (c, s)) in coeffs.iter_mut().zip(sum).enumerate() {
            let k = SH_NORM[i] * SH_NORM[i] * LOBE[i];
            *c = s.map(|v| (v * k) as f32);
        }
        Irradiance { coeffs }
    }

    /// The same plus a uniform radiance `rgb`.
    pub fn plus_uniform(mut self, rgb: [f32; 3]) -> Irradiance {
        for (c, a) in self.coeffs[0].iter_mut().zip(rgb) {
            *c += a;
        }
        self
    }

    /// Radiance reflected by a white Lambertian surface with normal `n` (any length; zero
    /// reads as +Y), clamped at 0 where order-2 ringing would make it negative.
    #[inline]
    pub fn diffuse(&self, n: Vec3) -> [f32; 3] {
        let n = n.normalize_or(Vec3::Y);
        let (x, y, z) = (n.x, n.y, n.z);
        let p = [
            y,
            z,
            x,
            x * y,
            y * z,
            3.0 * z * z - 1.0,
            x * z,
            x * x - y * y,
        ];
        let mut out = self.coeffs[0];
        for (c, w) in self.coeffs[1..].iter().zip(p) {
            for k in 0..3 {
                out[k] += c[k] * w;
            }
        }
        out.map(|v| if v > 0.0 { v } else { 0.0 })
    }
}

impl Irradiance {
    /// Whether every coefficient is finite (a huge environment can overflow f32).
    pub fn is_finite(&self) -> bool {
        self.coeffs.iter().flatten().all(|c| c.is_finite())
    }

    /// The nine coefficients in [`Irradiance::diffuse`]'s order (for the GPU backend).
    pub fn coeffs(&self) -> &[[f32; 3]; 9] {
        &self.coeffs
    }
}

fn accumulate(sum: &mut [[f64; 3]; 9], d: DVec3, radiance: [f32; 3], weight: f64) {
    for (s, p) in sum.iter_mut().zip(polynomials(d)) {
        for k in 0..3 {
            s[k] += f64::from(radiance[k]) * p * weight;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct cosine-weighted integral of `env` over the hemisphere around `n`, over π.
    fn brute_force(env: &Environment, n: Vec3) -> [f64; 3] {
        let (t, b) = n.any_orthonormal_pair();
        let steps = 400;
        let mut sum = [0.0f64; 3];
        for i in 0..steps {
            // Uniform in cos² θ: cosine-weighted sampling, each sample weight 1/steps².
            let u = (i as f64 + 0.5) / steps as f64;
            let (sin_t, cos_t) = (u.sqrt(), (1.0 - u).sqrt());
            for j in 0..steps {
                let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / steps as f64;
                let d = t.as_dvec3() * (sin_t * phi.cos())
                    + b.as_dvec3() * (sin_t * phi.sin())
                    + n.as_dvec3() * cos_t;
                let l = env.radiance(d.as_vec3());
                for k in 0..3 {
                    sum[k] += f64::from(l[k]);
                }
            }
        }
        sum.map(|s| s / (steps * steps) as f64)
    }

    #[test]
    fn uniform_environment_lights_every_normal_exactly() {
        let env = Environment::Uniform([0.25, 1.0, 3.5]);
        let irr = Irradiance::from_environment(&env);
        for n in [Vec3::Y, -Vec3::Y, Vec3::new(0.3, -0.2, 0.9), Vec3::ZERO] {
            assert_eq!(irr.diffuse(n), [0.25, 1.0, 3.5], "normal {n}");
        }
    }

    #[test]
    fn sky_irradiance_matches_a_direct_hemisphere_integral() {
        // Order 2 captures a smooth sky to within a few per cent (Ramamoorthi & Hanrahan:
        // ≤ 3 % on average for real environments); here the worst is 6.4 %, the zenith
        // normal's red channel, from the sharp horizon band.
        let env = Environment::Sky(Sky::default());
        let irr = Irradiance::from_environment(&env);
        for n in [
            Vec3::Y,
            -Vec3::Y,
            Vec3::X,
            Vec3::new(0.4, 0.8, -0.3),
            Vec3::new(-0.5, -0.5, 0.2),
        ] {
            let want = brute_force(&env, n.normalize());
            let got = irr.diffuse(n);
            for k in 0..3 {
                let err = (f64::from(got[k]) - want[k]).abs() / want[k];
                assert!(
                    err < 0.08,
                    "normal {n}, channel {k}: {} vs {}",
                    got[k],
                    want[k]
                );
            }
        }
        // The ground (normal +Y) under this sky sees mostly sky, far brighter than nadir.
        assert!(irr.diffuse(Vec3::Y)[2] > 2.0 * irr.diffuse(-Vec3::Y)[2]);
    }

    #[test]
    fn sun_disc_adds_its_cosine_weighted_irradiance() {
        let base = Sky::default();
        let sun = Sky {
            sun_rgb: [5000.0; 3],
            sun_direction: Vec3::Y,
            sun_radius_deg: 0.5,
            ..base
        };
        let with = Irradiance::from_environment(&Environment::Sky(sun)).diffuse(Vec3::Y);
        let without = Irradiance::from_environment(&Environment::Sky(base)).diffuse(Vec3::Y);
        // A small disc straight above, seen through order 2: by the addition theorem
        // L Ω Σ_l (2l + 1) (Â_l/π) / 4π (6 % above the exact L Ω / π).
        let omega = 2.0 * std::f64::consts::PI * (1.0 - 0.5f64.to_radians().cos());
        let sh_delta = (1.0 + 3.0 * 2.0 / 3.0 + 5.0 * 0.25) / (4.0 * std::f64::consts::PI);
        let want = 5000.0 * omega * sh_delta;
        let got = f64::from(with[0] - without[0]);
        assert!((got - want).abs() < 1e-3 * want, "{got} vs {want}");
    }
}

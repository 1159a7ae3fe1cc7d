//! How far a bilinear lookup strays from the exact colour: CIEDE2000 between
//! [`Lut::sample`](crate::Lut::sample) and direct f64 evaluation of the film
//! (`thinfilm::airy`, integrated by `SpectralIntegrator::film_xyz`, exact at grazing) at the
//! same (thickness, cos θ).
//!
//! The looked-up RGB is turned back into XYZ (undoing the reference-white normalisation
//! for reflectivity and transmittance) and both colours go to CIELAB relative to the
//! light's own white at Y = 1, so a dark film's error is judged as a dark colour.

use num_complex::Complex64;
use rayon::prelude::*;
use thinfilm::airy::ThinFilm;
use thinfilm::colorspace::{XYZ_FROM_SRGB, apply};
use thinfilm::integrate::SpectralIntegrator;
use thinfilm::lab::{ciede2000, lab_from_xyz};

use crate::config::N_OUTSIDE;
use crate::weights::linear_srgb_white;
use crate::{BakeConfig, LutSet};

/// The published accuracy of the default reflectivity table (2048 × 128): a bilinear
/// lookup stays within this CIEDE2000 of direct evaluation for every thickness in
/// `0..=2000` nm and every `cos θ >= BOUND_COS_THETA_MIN` (tested in `tests/error_bound.rs`;
/// docs/lut.md has the table against resolution).
pub const BOUND_DELTA_E: f64 = 0.5;

/// Smallest cos θ covered by [`BOUND_DELTA_E`] (θ ≤ 84.3°). Nearer grazing the film's
/// fringes sharpen without limit (their finesse grows as 1/cos²θ) and reflectance jumps
/// from 0 at d = 0 to 1 at cos θ = 0, which no uniform table resolves.
pub const BOUND_COS_THETA_MIN: f32 = 0.1;

/// Which table of a [`LutSet`] to check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Table {
    /// The reflectivity table.
    Reflectivity,
    /// The transmittance table.
    Transmittance,
    /// The light-source table of `config.lights()[k]`.
    Light(usize),
}

/// CIEDE2000 statistics of a table against direct evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorReport {
    /// Number of (thickness, cos θ) points compared.
    pub points: usize,
    /// Largest ΔE00 found.
    pub max_delta_e: f64,
    /// Mean ΔE00.
    pub mean_delta_e: f64,
    /// Thickness of the worst point, in nm.
    pub worst_thickness_nm: f32,
    /// cos θ of the worst point.
    pub worst_cos_theta: f32,
}

/// Compares table `table` of `set` (baked from `config`) with direct evaluation at `points`
/// (`(thickness_nm, cos_theta)` pairs).
///
/// # Panics
/// Panics if `table` is `Light(k)` with `k` out of range, or `points` is empty.
pub fn delta_e_report(
    config: &BakeConfig,
    set: &LutSet,
    table: Table,
    points: &[(f32, f32)],
) -> ErrorReport {
    assert!(!points.is_empty(), "no points to compare");
    let (lut, light, normalised) = match table {
        Table::Reflectivity => (&set.reflectivity, config.reference(), true),
        Table::Transmittance => (&set.transmittance, config.reference(), true),
        Table::Light(k) => (&set.lights[k].1, &config.lights()[k], false),
    };
    let integrator = config
        .integrator(light)
        .expect("BakeConfig guarantees every light integrates");
    let scale = if normalised {
        linear_srgb_white(&integrator)
    } else {
        [1.0; 3]
    };
    let white = integrator.white_xyz();
    let errors: Vec<f64> = points
        .par_iter()
        .map(|&(d, c)| {
            let rgb = lut.sample(d, c);
            let rgb = std::array::from_fn(|k| f64::from(rgb[k]) * scale[k]);
            let looked_up = apply(&XYZ_FROM_SRGB, rgb);
            let exact = direct_xyz(config, &integrator, table, d, c);
            ciede2000(lab_from_xyz(looked_up, white), lab_from_xyz(exact, white))
        })
        .collect();
    summarise(points, &errors)
}

fn summarise(points: &[(f32, f32)], errors: &[f64]) -> ErrorReport {
    // First maximum in point order, so the report is the same at any thread count.
    let worst = errors
        .iter()
        .enumerate()
        .fold(0, |best, (k, &e)| if e > errors[best] { k } else { best });
    ErrorReport {
        points: points.len(),
        max_delta_e: errors[worst],
        mean_delta_e: errors.iter().sum::<f64>() / errors.len() as f64,
        worst_thickness_nm: points[worst].0,
        worst_cos_theta: points[worst].1,
    }
}

/// XYZ of the film's reflection (or transmission) of the light, by the f64 Airy path.
fn direct_xyz(
    config: &BakeConfig,
    integrator: &SpectralIntegrator,
    table: Table,
    thickness_nm: f32,
    cos_theta: f32,
) -> [f64; 3] {
    let film = ThinFilm {
        n_outside: N_OUTSIDE,
        n_film: *config.film_index(),
        n_substrate: Complex64::new(N_OUTSIDE, 0.0),
        thickness_nm: f64::from(thickness_nm),
    };
    let cos_theta = f64::from(cos_theta);
    match table {
        Table::Transmittance => integrator.film_transmitted_xyz(&film, cos_theta),
        Table::Reflectivity | Table::Light(_) => integrator.film_xyz(&film, cos_theta),
    }
}

/// `count` points spread uniformly over `0..=thickness_max_nm × 0..=1` by a fixed
/// pseudo-random sequence (SplitMix64 from `seed`).
pub fn random_points(count: usize, thickness_max_nm: f32, seed: u64) -> Vec<(f32, f32)> {
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| {
            let d = (next() * f64::from(thickness_max_nm)) as f32;
            (d, next() as f32)
        })
        .collect()
}

/// The centre of every cell between four texels, where bilinear error peaks.
pub fn cell_centre_points(width: usize, height: usize, thickness_max_nm: f32) -> Vec<(f32, f32)> {
    let (w, h) = ((width - 1) as f64, (height - 1) as f64);
    (0..height - 1)
        .flat_map(|j| {
            (0..width - 1).map(move |i| {
                let d = (i as f64 + 0.5) / w * f64::from(thickness_max_nm);
                (d as f32, ((j as f64 + 0.5) / h) as f32)
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_points_stay_in_range_and_repeat() {
        let a = random_points(1000, 2000.0, 7);
        assert_eq!(a, random_points(1000, 2000.0, 7));
        assert!(
            a.iter()
                .all(|&(d, c)| (0.0..=2000.0).contains(&d) && (0.0..=1.0).contains(&c))
        );
        assert_ne!(a, random_points(1000, 2000.0, 8));
    }
}

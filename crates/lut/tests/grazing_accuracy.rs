//! Colour near grazing incidence against a fine integration of the spectrum written out
//! here, independent of thinfilm's integrator, its cells and its kernels.
//!
//! Truth: `X = ∫ E(λ) x̄(λ) R(λ) dλ / ∫ E(λ) ȳ(λ) dλ` over 360–830 nm, with E and x̄
//! linearly interpolated between their samples and R the closed-form Airy reflectance of
//! a free film, by the trapezoid rule on a step that resolves every spectral line: each
//! 1 nm cell is cut into pieces no wider than a quarter of the half-width of the film's
//! transmission lines there (or a 40th of a fringe, whichever is smaller).
//!
//! The goal (issue 14): every texel within 0.1 ΔE2000 up to 75° and within 0.5 at any angle.
//! `cargo test --release -p lut --test grazing_accuracy -- --ignored --nocapture` prints the
//! table of docs/physics.md.

use lut::{BakeConfig, Lut};
use rayon::prelude::*;
use thinfilm::airy::ThinFilm;
use thinfilm::cmf::Observer;
use thinfilm::colorspace::{SRGB_FROM_XYZ, XYZ_FROM_SRGB, apply};
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::SpectralIntegrator;
use thinfilm::lab::{ciede2000, lab_from_xyz};
use thinfilm::spectrum::Spectrum;

/// Index of the film in every check (the default soap film).
const N_FILM: f64 = 1.33;

/// `n cos θ_t` and the amplitude reflectances `(ρ_s, ρ_p)` of air | n.
fn fresnel(n: f64, cos_theta: f64) -> (f64, f64, f64) {
    let n_cos_t = (n * n - (1.0 - cos_theta * cos_theta)).sqrt();
    let rho_s = (cos_theta - n_cos_t) / (cos_theta + n_cos_t);
    let rho_p = (n * n * cos_theta - n_cos_t) / (n * n * cos_theta + n_cos_t);
    (n_cos_t, rho_s, rho_p)
}

/// Unpolarised reflectance of `1 | n | 1`, Airy's sum: `R = F s² / (1 + F s²)` per
/// polarisation, `F = 4ρ²/(1 − ρ²)²`, `s = sin(2π n cos θ_t d / λ)`.
fn airy_r(n: f64, thickness_nm: f64, cos_theta: f64, wavelength_nm: f64) -> f64 {
    if cos_theta == 0.0 {
        return 1.0;
    }
    let (n_cos_t, rho_s, rho_p) = fresnel(n, cos_theta);
    let s2 = (std::f64::consts::TAU * n_cos_t * thickness_nm / wavelength_nm)
        .sin()
        .powi(2);
    let r = |rho: f64| {
        let f = 4.0 * rho * rho / (1.0 - rho * rho).powi(2);
        f * s2 / (1.0 + f * s2)
    };
    0.5 * (r(rho_s) + r(rho_p))
}

/// XYZ of the film and of white (Y = 1), by the fine trapezoid rule of the module doc.
fn truth_xyz(light: &Spectrum, thickness_nm: f64, cos_theta: f64) -> ([f64; 3], [f64; 3]) {
    let (n_cos_t, rho_s, _) = fresnel(N_FILM, cos_theta);
    // Half-width of the s lines in periods of the phase; at most a 40th of a fringe.
    let width = (-(rho_s * rho_s).ln() / std::f64::consts::TAU).min(0.1);
    let observer = Observer::Cie1931;
    let (mut xyz, mut white) = ([0.0; 3], [0.0; 3]);
    for j in 360..830 {
        let lo = f64::from(j);
        let period_nm = lo * lo / (2.0 * n_cos_t * thickness_nm.max(1e-9));
        let pieces = (4.0 / (width * period_nm)).ceil().clamp(1.0, 1e6) as usize;
        let h = 1.0 / pieces as f64;
        for k in 0..=pieces {
            let wavelength_nm = lo + k as f64 * h;
            let end = if k == 0 || k == pieces { 0.5 } else { 1.0 };
            let e = light.value_at(wavelength_nm) * end * h;
            let cmf = observer.cmf(wavelength_nm);
            let r = airy_r(N_FILM, thickness_nm, cos_theta, wavelength_nm);
            for c in 0..3 {
                xyz[c] += e * cmf[c] * r;
                white[c] += e * cmf[c];
            }
        }
    }
    (xyz.map(|v| v / white[1]), white.map(|v| v / white[1]))
}

/// ΔE2000 of `xyz` (white `white`) against the truth at (d, cos θ).
fn delta_e(xyz: [f64; 3], white: [f64; 3], thickness_nm: f64, cos_theta: f64) -> f64 {
    let (truth, truth_white) = truth_xyz(&Illuminant::D65.spectrum(), thickness_nm, cos_theta);
    ciede2000(lab_from_xyz(xyz, white), lab_from_xyz(truth, truth_white))
}

/// The angle from the normal, in degrees, of `cos_theta`.
fn angle_deg(cos_theta: f64) -> f64 {
    cos_theta.clamp(0.0, 1.0).acos().to_degrees()
}

/// The ΔE2000 bound of issue 14 at `angle`.
fn bound(angle: f64) -> f64 {
    if angle <= 75.0 + 1e-9 { 0.1 } else { 0.5 }
}

/// ΔE2000 of every texel `(i, j)` (every `column_step`-th column) of a reflectivity table
/// baked from `config`, as `(angle°, d, ΔE)`.
fn texel_errors(config: &BakeConfig, table: &Lut, column_step: usize) -> Vec<(f64, f64, f64)> {
    let integrator = SpectralIntegrator::new(
        config.observer(),
        config.reference().spectrum(),
        config.step_nm(),
    )
    .expect("valid light");
    let white = integrator.white_xyz();
    let white_rgb = apply(&SRGB_FROM_XYZ, white);
    let texels: Vec<(usize, usize)> = (0..table.height())
        .flat_map(|j| (0..table.width()).step_by(column_step).map(move |i| (i, j)))
        .collect();
    texels
        .par_iter()
        .map(|&(i, j)| {
            let (d, c) = (table.thickness_nm_at(i), table.cos_theta_at(j));
            let rgb = table.texel(i, j);
            let rgb = std::array::from_fn(|k| f64::from(rgb[k]) * white_rgb[k]);
            let xyz = apply(&XYZ_FROM_SRGB, rgb);
            let (d, c) = (f64::from(d), f64::from(c));
            (angle_deg(c), d, delta_e(xyz, white, d, c))
        })
        .collect()
}

/// The first texel over its bound, if any.
fn over_bound(errors: &[(f64, f64, f64)]) -> Option<(f64, f64, f64)> {
    errors
        .iter()
        .copied()
        .find(|&(angle, _, e)| e > bound(angle))
}

fn small_table() -> BakeConfig {
    BakeConfig::builder()
        .resolution(64, 32)
        .lights(Vec::new())
        .build()
        .expect("valid config")
}

#[test]
fn every_texel_of_a_small_table_matches_a_fine_integration() {
    let config = small_table();
    let set = lut::bake(&config);
    let errors = texel_errors(&config, &set.reflectivity, 1);
    assert_eq!(errors.len(), 64 * 32);
    if let Some((angle, d, e)) = over_bound(&errors) {
        panic!(
            "texel at {angle:.2}°, d = {d} nm is off by ΔE2000 {e:.3} > {}",
            bound(angle)
        );
    }
}

#[test]
fn the_point_sampled_bake_misses_the_lines_so_the_check_can_fail() {
    let config = small_table();
    let set = lut::bake_point_sampled(&config);
    let errors = texel_errors(&config, &set.reflectivity, 1);
    let worst = errors.iter().map(|e| e.2).fold(0.0, f64::max);
    assert!(
        over_bound(&errors).is_some() && worst > 2.0,
        "point samples should miss the grazing lines, worst ΔE2000 only {worst:.3}"
    );
}

/// ΔE2000 of `SpectralIntegrator::film_xyz` at `step_nm` over angles × thicknesses.
fn film_xyz_errors(step_nm: f64, angles: &[f64], thickness_max_nm: f64) -> Vec<(f64, f64, f64)> {
    let integrator =
        SpectralIntegrator::new(Observer::Cie1931, &Illuminant::D65.spectrum(), step_nm)
            .expect("valid integrator");
    let points: Vec<(f64, f64)> = angles
        .iter()
        .flat_map(|&a| (0..=40).map(move |i| (a, thickness_max_nm * (f64::from(i) + 0.37) / 40.37)))
        .collect();
    points
        .par_iter()
        .map(|&(angle, d)| {
            let cos = angle.to_radians().cos();
            let xyz = integrator.film_xyz(&ThinFilm::soap(d), cos);
            (angle, d, delta_e(xyz, integrator.white_xyz(), d, cos))
        })
        .collect()
}

#[test]
fn film_xyz_matches_a_fine_integration_up_to_89_9_degrees() {
    let angles = [
        0.0, 60.0, 75.0, 78.0, 82.0, 85.0, 87.0, 88.0, 89.0, 89.5, 89.9,
    ];
    // The bake's step over its thickness range, and the integrator's default to 2 µm.
    for (step_nm, thickness_max_nm) in [(5.0, 4000.0), (thinfilm::DEFAULT_STEP_NM, 2000.0)] {
        let errors = film_xyz_errors(step_nm, &angles, thickness_max_nm);
        if let Some((angle, d, e)) = over_bound(&errors) {
            panic!("step {step_nm} nm: {angle}°, d = {d:.1} nm is off by ΔE2000 {e:.3}");
        }
    }
}

/// Rows of the docs table: `(lo°, hi°]` bands of incidence angle.
const BANDS: [(f64, f64); 6] = [
    (-1.0, 75.0),
    (75.0, 80.0),
    (80.0, 85.0),
    (85.0, 88.0),
    (88.0, 89.0),
    (89.0, 90.0),
];

fn band_stats(errors: &[(f64, f64, f64)], (lo, hi): (f64, f64)) -> (f64, f64) {
    let e: Vec<f64> = errors
        .iter()
        .filter(|&&(a, _, _)| a > lo && a <= hi)
        .map(|e| e.2)
        .collect();
    let max = e.iter().copied().fold(0.0, f64::max);
    (max, e.iter().sum::<f64>() / e.len().max(1) as f64)
}

#[test]
#[ignore = "prints the docs/physics.md table; about a minute in release"]
fn grazing_accuracy_table() {
    for (width, height, column_step) in [(4096, 128, 8), (128, 64, 1)] {
        let config = BakeConfig::builder()
            .resolution(width, height)
            .lights(Vec::new())
            .build()
            .expect("valid config");
        let before = texel_errors(
            &config,
            &lut::bake_point_sampled(&config).reflectivity,
            column_step,
        );
        let after = texel_errors(&config, &lut::bake(&config).reflectivity, column_step);
        println!("\n{width}x{height} (every {column_step} column(s)), D65, soap film, 0-4000 nm");
        println!("| θ band | texels | before: max | before: mean | after: max | after: mean |");
        println!("|---|---|---|---|---|---|");
        for band in BANDS {
            let (b_max, b_mean) = band_stats(&before, band);
            let (a_max, a_mean) = band_stats(&after, band);
            let count = after
                .iter()
                .filter(|e| e.0 > band.0 && e.0 <= band.1)
                .count();
            let lo = band.0.max(0.0);
            println!(
                "| {lo}–{}° | {count} | {b_max:.3} | {b_mean:.4} | {a_max:.3} | {a_mean:.4} |",
                band.1
            );
        }
    }
}

//! Colour at grazing incidence against a fine integration written out here.
//!
//! Truth: `X = ∫ E(λ) x̄(λ) R(λ) dλ / ∫ E(λ) ȳ(λ) dλ` over 360–830 nm, with E and x̄ linearly
//! interpolated between their 1 nm samples and R the closed-form Airy reflectance of a free
//! film, by the trapezoid rule on a step that resolves every fringe: each 1 nm cell is cut
//! into pieces no wider than a quarter of the narrowest feature of R there (its
//! transmission lines' half-width, from the finesse, or a 40th of a fringe).

use thinfilm::airy::ThinFilm;
use thinfilm::cmf::Observer;
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::SpectralIntegrator;
use thinfilm::lab::{ciede2000, lab_from_xyz};
use thinfilm::spectrum::Spectrum;

/// Unpolarised reflectance of `1 | n | 1`, Airy's sum: `R = F s² / (1 + F s²)` per
/// polarisation, `F = 4ρ²/(1 − ρ²)²`, `s = sin(2π n cos θ_t d / λ)`.
fn airy_r(n: f64, thickness_nm: f64, cos_theta: f64, wavelength_nm: f64) -> f64 {
    let n_cos_t = (n * n - (1.0 - cos_theta * cos_theta)).sqrt();
    let rho_s = (cos_theta - n_cos_t) / (cos_theta + n_cos_t);
    let rho_p = (n * n * cos_theta - n_cos_t) / (n * n * cos_theta + n_cos_t);
    let s2 = (2.0 * std::f64::consts::PI * n_cos_t * thickness_nm / wavelength_nm)
        .sin()
        .powi(2);
    let r = |rho: f64| {
        let f = 4.0 * rho * rho / (1.0 - rho * rho).powi(2);
        f * s2 / (1.0 + f * s2)
    };
    0.5 * (r(rho_s) + r(rho_p))
}

/// Half-width of the film's transmission lines in periods of the phase, `−ln ρ²/(2π)`, for
/// the sharper polarisation (s).
fn line_half_width_periods(n: f64, cos_theta: f64) -> f64 {
    let n_cos_t = (n * n - (1.0 - cos_theta * cos_theta)).sqrt();
    let rho_s = (cos_theta - n_cos_t) / (cos_theta + n_cos_t);
    -(rho_s * rho_s).ln() / (2.0 * std::f64::consts::PI)
}

/// XYZ (white Y = 1) of a free film by the fine trapezoid rule described in the module doc.
fn truth_xyz(
    observer: Observer,
    light: &Spectrum,
    n: f64,
    thickness_nm: f64,
    cos_theta: f64,
) -> ([f64; 3], [f64; 3]) {
    let n_cos_t = (n * n - (1.0 - cos_theta * cos_theta)).sqrt();
    let width = line_half_width_periods(n, cos_theta).min(0.1);
    let (mut xyz, mut white) = ([0.0; 3], [0.0; 3]);
    for j in 360..830 {
        let lo = f64::from(j);
        // nm per period at the cell's short end: λ² / (2 n cos θ_t d).
        let period_nm = lo * lo / (2.0 * n_cos_t * thickness_nm.max(1e-9));
        let pieces = (4.0 / (width * period_nm)).ceil().clamp(1.0, 1e6) as usize;
        let h = 1.0 / pieces as f64;
        for k in 0..=pieces {
            let wavelength_nm = lo + k as f64 * h;
            let end = if k == 0 || k == pieces { 0.5 } else { 1.0 };
            let e = light.value_at(wavelength_nm) * end * h;
            let cmf = observer.cmf(wavelength_nm);
            let r = if cos_theta == 0.0 {
                1.0
            } else {
                airy_r(n, thickness_nm, cos_theta, wavelength_nm)
            };
            for c in 0..3 {
                xyz[c] += e * cmf[c] * r;
                white[c] += e * cmf[c];
            }
        }
    }
    let norm = white[1];
    (xyz.map(|v| v / norm), white.map(|v| v / norm))
}

#[test]
#[ignore]
fn calibrate_steps() {
    let d65 = Illuminant::D65.spectrum();
    let angles = [
        0.0, 60.0, 70.0, 75.0, 78.0, 80.0, 83.0, 85.0, 87.0, 88.0, 89.0, 89.5, 89.9f64,
    ];
    let steps = [8.0, 5.0];
    for &angle in &angles {
        let cos = angle.to_radians().cos();
        let mut line = format!("{angle:5}°:");
        for &step in &steps {
            let integ = SpectralIntegrator::new(Observer::Cie1931, &d65, step).unwrap();
            let mut worst = [(0.0f64, 0.0); 2];
            for i in 0..=400 {
                let d = 4000.0 * i as f64 / 400.0 + 0.37;
                let (t, white) = truth_xyz(Observer::Cie1931, &d65, 1.33, d, cos);
                let film = ThinFilm::soap(d);
                let got = [
                    integ.xyz(|w| film.response(w, cos).r()),
                    integ.film_xyz(&film, cos),
                ];
                for k in 0..2 {
                    let e = ciede2000(
                        lab_from_xyz(got[k], integ.white_xyz()),
                        lab_from_xyz(t, white),
                    );
                    if e > worst[k].0 {
                        worst[k] = (e, d);
                    }
                }
            }
            line += &format!(
                "  h={step}: point {:.3} at {:.0}, cells {:.3} at {:.0}",
                worst[0].0, worst[0].1, worst[1].0, worst[1].1
            );
        }
        println!("{line}");
    }
}

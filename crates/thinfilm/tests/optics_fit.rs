//! Thickness fits on synthetic spectra from the exact model with noise, an offset and a
//! wavelength-calibration error: the true thickness inside the reported 95 % interval in
//! at least 95 % of 200 seeded trials from 10 nm to 5 µm.

mod optics_common;

use optics_common::Rng;
use thinfilm::fit::{Measurement, Search, fit_thickness};
use thinfilm::{Complex64, Incidence, Layer, OpticsError, Stack};

const SILICON: Complex64 = Complex64::new(3.88, 0.02);
const OXIDE: f64 = 1.46;

/// Silicon dioxide of thickness `d` on silicon, in air: the model with one unknown layer.
fn oxide_on_silicon(d: f64) -> Result<Stack, OpticsError> {
    Stack::new(1.0, vec![Layer::new(OXIDE, d)], SILICON)
}

/// The test's stated errors: Gaussian noise σ = 1e-3 in R, an offset uniform in ±0.01, a
/// wavelength calibration shifted by up to ±0.3 nm (the fit is told 0.3 nm).
const NOISE: f64 = 1e-3;
const OFFSET: f64 = 0.01;
const SHIFT_NM: f64 = 0.3;

#[test]
fn two_hundred_seeded_trials_recover_the_thickness_within_the_interval() {
    let wavelengths: Vec<f64> = (0..=200).map(|k| 400.0 + 2.0 * k as f64).collect();
    let incidence = Incidence::try_from_angle_deg(8.0).unwrap();
    let mut rng = Rng(26);
    let (mut inside, mut worst_relative) = (0, 0.0f64);
    let mut widths = Vec::new();
    let start = std::time::Instant::now();
    let trials = 200;
    for trial in 0..trials {
        // Log-uniform from 10 nm to 5 µm.
        let truth = 10.0 * 500f64.powf(rng.uniform());
        let offset = OFFSET * (2.0 * rng.uniform() - 1.0);
        let shift = SHIFT_NM * (2.0 * rng.uniform() - 1.0);
        let stack = oxide_on_silicon(truth).unwrap();
        // The instrument reads wavelength w where the light had w + shift.
        let measured: Vec<f64> = wavelengths
            .iter()
            .map(|&w| {
                stack.try_response_at(w + shift, incidence).unwrap().r()
                    + offset
                    + NOISE * rng.normal()
            })
            .collect();
        let fit = fit_thickness(
            oxide_on_silicon,
            &Measurement {
                wavelength_nm: &wavelengths,
                reflectance: &measured,
                incidence,
                wavelength_uncertainty_nm: SHIFT_NM,
            },
            Search {
                min_nm: 0.0,
                max_nm: 6000.0,
                n_max: OXIDE,
            },
        )
        .unwrap();
        let hit = fit.low_nm <= truth && truth <= fit.high_nm;
        inside += usize::from(hit);
        worst_relative = worst_relative.max((fit.thickness_nm - truth).abs() / truth);
        widths.push((fit.high_nm - fit.low_nm) / 2.0);
        if !hit {
            eprintln!("trial {trial}: truth {truth:.3} nm, fit {fit:?}");
        }
    }
    let per_second = trials as f64 / start.elapsed().as_secs_f64();
    widths.sort_by(f64::total_cmp);
    eprintln!(
        "{inside}/{trials} inside; worst |error|/d {worst_relative:.2e}; median half-width {:.3} nm; {per_second:.1} fits/s",
        widths[trials / 2]
    );
    assert!(inside * 100 >= 95 * trials, "{inside} of {trials} inside");
}

#[test]
fn a_noiseless_free_film_is_recovered_exactly() {
    let wavelengths: Vec<f64> = (0..=100).map(|k| 380.0 + 4.0 * k as f64).collect();
    let soap = |d: f64| Stack::new(1.0, vec![Layer::new(1.33, d)], 1.0);
    for truth in [37.0, 412.5, 2345.6] {
        let stack = soap(truth).unwrap();
        let r: Vec<f64> = wavelengths
            .iter()
            .map(|&w| stack.try_response_at(w, Incidence::NORMAL).unwrap().r())
            .collect();
        let fit = fit_thickness(
            soap,
            &Measurement {
                wavelength_nm: &wavelengths,
                reflectance: &r,
                incidence: Incidence::NORMAL,
                wavelength_uncertainty_nm: 0.0,
            },
            Search {
                min_nm: 0.0,
                max_nm: 5000.0,
                n_max: 1.33,
            },
        )
        .unwrap();
        assert!(
            (fit.thickness_nm - truth).abs() < 1e-3,
            "truth {truth}: {fit:?}"
        );
        // The golden-section search stops at a bracket of 1e-7 (1 + d): R moves by ~1e-8.
        assert!(fit.rms_residual < 1e-6, "{fit:?}");
    }
}

#[test]
fn bad_inputs_are_errors_naming_them() {
    let wl = [400.0, 500.0, 600.0];
    let r = [0.1, 0.2, f64::NAN];
    let search = Search {
        min_nm: 0.0,
        max_nm: 100.0,
        n_max: 1.5,
    };
    let m = |r: &'static [f64], u: f64| Measurement {
        wavelength_nm: &wl,
        reflectance: r,
        incidence: Incidence::NORMAL,
        wavelength_uncertainty_nm: u,
    };
    let err = |m: Measurement<'_>, s: Search| {
        fit_thickness(oxide_on_silicon, &m, s)
            .unwrap_err()
            .to_string()
    };
    assert!(err(m(&[0.1, 0.2, f64::NAN], 0.0), search).contains("reflectance[2] = NaN"));
    let _ = r;
    assert!(err(m(&[0.1, 0.2], 0.0), search).contains("reflectance has 2"));
    assert!(err(m(&[0.1, 0.2, 0.3], -1.0), search).contains("-1"));
    assert!(
        err(
            m(&[0.1, 0.2, 0.3], 0.0),
            Search {
                min_nm: 50.0,
                max_nm: 10.0,
                n_max: 1.5
            }
        )
        .contains("[50, 10]")
    );
}

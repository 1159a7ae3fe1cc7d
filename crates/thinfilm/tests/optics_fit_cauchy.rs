//! Thickness and Cauchy index fitted together on synthetic spectra of an oxide-like film
//! (`n = 1.46 + 3500/λ²`, λ in nm) on silicon, from the exact model with noise, an offset
//! and a wavelength-calibration error: the true thickness, `a` and `b` inside their
//! reported 95 % intervals in the share of seeded trials the test states.

mod optics_common;

use optics_common::Rng;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::fit::{CauchyRange, IndexFit, Measurement, fit_thickness_and_index};
use thinfilm::{Complex64, Incidence, Layer, OpticsError, Stack};

const SILICON: Complex64 = Complex64::new(3.88, 0.02);
const TRUE_A: f64 = 1.46;
const TRUE_B_NM2: f64 = 3500.0;
const NOISE: f64 = 1e-3;
const OFFSET: f64 = 0.01;
const SHIFT_NM: f64 = 0.3;

fn film_on_silicon(d: f64, index: RefractiveIndex) -> Result<Stack, OpticsError> {
    Stack::new(1.0, vec![Layer::new(index, d)], SILICON)
}

/// One seeded trial at thickness `truth`: the fit, or the error.
fn trial(rng: &mut Rng, truth: f64, wavelengths: &[f64]) -> IndexFit {
    let incidence = Incidence::try_from_angle_deg(8.0).unwrap();
    let offset = OFFSET * (2.0 * rng.uniform() - 1.0);
    let shift = SHIFT_NM * (2.0 * rng.uniform() - 1.0);
    let index = RefractiveIndex::cauchy_over(TRUE_A, TRUE_B_NM2, 0.0, [300.0, 900.0]).unwrap();
    let stack = film_on_silicon(truth, index).unwrap();
    let measured: Vec<f64> = wavelengths
        .iter()
        .map(|&w| {
            stack.try_response_at(w + shift, incidence).unwrap().r() + offset + NOISE * rng.normal()
        })
        .collect();
    fit_thickness_and_index(
        film_on_silicon,
        &Measurement {
            wavelength_nm: wavelengths,
            reflectance: &measured,
            incidence,
            wavelength_uncertainty_nm: SHIFT_NM,
        },
        0.0,
        6000.0,
        CauchyRange {
            a: [1.3, 1.7],
            b_nm2: [0.0, 10000.0],
        },
    )
    .unwrap()
}

#[test]
fn seeded_trials_recover_thickness_and_index_within_their_intervals() {
    // 60 trials, log-uniform from 300 nm to 5 µm (thinner films show less than a fringe,
    // where index and thickness trade off and only their product is measured). With 95 %
    // intervals, 60 trials land 54 or more inside 98 % of the time if the intervals are
    // honest; an interval that ignores the calibration error or the index's correlation
    // with the thickness misses far more often.
    let wavelengths: Vec<f64> = (0..=200).map(|k| 400.0 + 2.0 * k as f64).collect();
    let mut rng = Rng(2026);
    let trials = 60;
    let mut inside = [0; 3];
    let mut report = Vec::new();
    let start = std::time::Instant::now();
    for _ in 0..trials {
        let truth = 300.0 * (5000.0f64 / 300.0).powf(rng.uniform());
        let fit = trial(&mut rng, truth, &wavelengths);
        for (k, (estimate, value)) in [
            (fit.thickness_nm, truth),
            (fit.a, TRUE_A),
            (fit.b_nm2, TRUE_B_NM2),
        ]
        .into_iter()
        .enumerate()
        {
            inside[k] += usize::from(estimate.low <= value && value <= estimate.high);
        }
        report.push((truth, fit));
    }
    let seconds = start.elapsed().as_secs_f64();
    for (truth, fit) in report.iter().take(6) {
        println!(
            "d {truth:8.2}: fit {:8.2} ± {:.2} nm, a {:.4} ± {:.4}, b {:6.0} ± {:5.0} nm², rms {:.2e}",
            fit.thickness_nm.value,
            fit.thickness_nm.high - fit.thickness_nm.value,
            fit.a.value,
            fit.a.high - fit.a.value,
            fit.b_nm2.value,
            fit.b_nm2.high - fit.b_nm2.value,
            fit.rms_residual
        );
    }
    println!(
        "inside the 95 % interval: d {}/{trials}, a {}/{trials}, b {}/{trials}; {:.2} fits/s",
        inside[0],
        inside[1],
        inside[2],
        trials as f64 / seconds
    );
    for (name, count) in ["thickness", "a", "b"].iter().zip(inside) {
        assert!(
            count >= 54,
            "{name}: only {count} of {trials} inside the interval"
        );
    }
}

#[test]
fn a_fixed_index_range_is_the_thickness_fit() {
    // With the index pinned (a and b ranges of one value) only d is free: it must agree
    // with the truth as the plain thickness fit does, and the index must stay pinned.
    let wavelengths: Vec<f64> = (0..=200).map(|k| 400.0 + 2.0 * k as f64).collect();
    let incidence = Incidence::NORMAL;
    let index = RefractiveIndex::cauchy_over(TRUE_A, TRUE_B_NM2, 0.0, [300.0, 900.0]).unwrap();
    let stack = film_on_silicon(1234.5, index).unwrap();
    let measured: Vec<f64> = (wavelengths.iter())
        .map(|&w| stack.try_response_at(w, incidence).unwrap().r())
        .collect();
    let fit = fit_thickness_and_index(
        film_on_silicon,
        &Measurement {
            wavelength_nm: &wavelengths,
            reflectance: &measured,
            incidence,
            wavelength_uncertainty_nm: 0.0,
        },
        0.0,
        6000.0,
        CauchyRange {
            a: [TRUE_A, TRUE_A],
            b_nm2: [TRUE_B_NM2, TRUE_B_NM2],
        },
    )
    .unwrap();
    assert!((fit.thickness_nm.value - 1234.5).abs() < 1e-4, "{fit:?}");
    assert_eq!((fit.a.value, fit.b_nm2.value), (TRUE_A, TRUE_B_NM2));
}

#[test]
fn bad_ranges_are_named() {
    let wavelengths = [500.0, 550.0, 600.0, 650.0];
    let measured = [0.1, 0.2, 0.1, 0.2];
    let measurement = Measurement {
        wavelength_nm: &wavelengths,
        reflectance: &measured,
        incidence: Incidence::NORMAL,
        wavelength_uncertainty_nm: 0.0,
    };
    for (range, needle) in [
        (
            CauchyRange {
                a: [1.7, 1.3],
                b_nm2: [0.0, 1.0],
            },
            "Cauchy a range [1.7, 1.3]",
        ),
        (
            CauchyRange {
                a: [0.0, 1.3],
                b_nm2: [0.0, 1.0],
            },
            "Cauchy a range [0, 1.3]",
        ),
        (
            CauchyRange {
                a: [1.3, 1.5],
                b_nm2: [5.0, f64::NAN],
            },
            "Cauchy b range [5, NaN]",
        ),
    ] {
        let err = fit_thickness_and_index(film_on_silicon, &measurement, 0.0, 1000.0, range)
            .unwrap_err()
            .to_string();
        assert!(err.contains(needle), "{err}");
    }
}

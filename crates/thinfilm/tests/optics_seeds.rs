//! Regression tests for the seed texts' errors: each compares the seed's formula and ours
//! against the transfer-matrix method (an independent solver).

mod optics_common;

use optics_common::{as_stack, assert_close, film, re};
use thinfilm::airy::ThinFilm;
use thinfilm::fresnel::cos_transmitted;

const N_SOAP: f64 = 1.33;

/// The symmetric-film Airy term of the seeds, `2ρ²(1 − cos δ)/(1 + ρ⁴ − 2ρ² cos δ)`,
/// given the squared amplitude `rho2`.
fn seed_airy_term(rho2: f64, cos_delta: f64) -> f64 {
    2.0 * rho2 * (1.0 - cos_delta) / (1.0 + rho2 * rho2 - 2.0 * rho2 * cos_delta)
}

/// Interface amplitudes air → soap as seed 001 writes them, from its "effective cosine".
fn seed001_amplitudes(cos_i: f64, effective_cos: f64) -> (f64, f64) {
    let n = N_SOAP;
    let r_s = (cos_i - n * effective_cos) / (cos_i + n * effective_cos);
    let r_p = (effective_cos - n * cos_i) / (effective_cos + n * cos_i);
    (r_s, r_p)
}

fn true_cos_t(cos_i: f64) -> f64 {
    cos_transmitted(1.0, re(N_SOAP), cos_i).re
}

fn tmm_unpolarised(d: f64, l: f64, cos_i: f64) -> f64 {
    let f = ThinFilm::soap(d);
    let resp = as_stack(&f, l).response(l, cos_i);
    0.5 * (resp.r_s + resp.r_p)
}

#[test]
fn seed000_eq4_sum_is_twice_the_mean() {
    for (d, l, cos_i) in [
        (500.0, 550.0, 1.0),
        (310.0, 450.0, 0.8),
        (1200.0, 633.0, 0.35),
    ] {
        let cos_t = true_cos_t(cos_i);
        let (r_s, r_p) = seed001_amplitudes(cos_i, cos_t);
        let cos_delta = (4.0 * std::f64::consts::PI * N_SOAP * d * cos_t / l).cos();
        // Eq. 4 with the right phase and amplitudes: the sum of both polarisation terms.
        let eq4 = seed_airy_term(r_s * r_s, cos_delta) + seed_airy_term(r_p * r_p, cos_delta);
        let truth = tmm_unpolarised(d, l, cos_i);
        let ours = ThinFilm::soap(d).response(l, cos_i).r();
        assert_close("ours vs TMM", ours, truth, 1e-12);
        assert_close("eq. 4 vs 2 x TMM", eq4, 2.0 * truth, 1e-12);
        assert!(
            (eq4 - truth).abs() > 0.2 * truth,
            "eq. 4 {eq4} would be indistinguishable from {truth}"
        );
    }
}

#[test]
fn phase_uses_refracted_angle_not_incident() {
    let (d, l) = (400.0, 550.0);
    let cos_i = 0.5; // 60°
    let cos_t = true_cos_t(cos_i);
    assert_close(
        "cos θ_t at 60°",
        cos_t,
        (1.0 - 0.75 / (N_SOAP * N_SOAP)).sqrt(),
        1e-15,
    );
    let (r_s, r_p) = seed001_amplitudes(cos_i, cos_t);
    let mean = |cos_in_phase: f64| {
        let cos_delta = (4.0 * std::f64::consts::PI * N_SOAP * d * cos_in_phase / l).cos();
        0.5 * (seed_airy_term(r_s * r_s, cos_delta) + seed_airy_term(r_p * r_p, cos_delta))
    };
    let truth = tmm_unpolarised(d, l, cos_i);
    assert_close("phase with cos θ_t", mean(cos_t), truth, 1e-12);
    assert_close(
        "ours",
        ThinFilm::soap(d).response(l, cos_i).r(),
        truth,
        1e-12,
    );
    let seed = mean(cos_i);
    assert!(
        (seed - truth).abs() > 0.02,
        "phase with cos θ_i gives {seed}, truth {truth}: the test angle does not discriminate"
    );
}

#[test]
fn seed001_precedence_slip_would_make_cos_t_equal_cos_i() {
    let n = N_SOAP;
    for cos_i in [0.95f64, 0.7, 0.4, 0.1] {
        let sine = (1.0 - cos_i * cos_i).sqrt();
        // As written: `sqrt(1.0 - sine*sine / mRefractiveIndex * mRefractiveIndex)`.
        let as_written = (1.0 - sine * sine / n * n).sqrt();
        assert_close("seed 001 effective cosine", as_written, cos_i, 1e-15);
        // Intended: Snell's law, n_i sin θ_i = n_t sin θ_t.
        let cos_t = true_cos_t(cos_i);
        let sin_t = (1.0 - cos_t * cos_t).sqrt();
        assert_close("Snell", n * sin_t, sine, 1e-15);
        assert!((as_written - cos_t).abs() > 1e-3, "cos_i {cos_i}");
        // And the buggy cosine moves the interference away from the truth.
        let (d, l) = (600.0, 500.0);
        let (r_s, r_p) = seed001_amplitudes(cos_i, as_written);
        let cos_delta = (4.0 * std::f64::consts::PI * n * d * as_written / l).cos();
        let buggy =
            0.5 * (seed_airy_term(r_s * r_s, cos_delta) + seed_airy_term(r_p * r_p, cos_delta));
        let truth = tmm_unpolarised(d, l, cos_i);
        assert!(
            (buggy - truth).abs() > 1e-4,
            "cos_i {cos_i}: {buggy} vs {truth}"
        );
    }
}

#[test]
fn seed001_double_squared_amplitude_is_wrong() {
    for (d, l, cos_i) in [
        (500.0, 550.0, 1.0),
        (250.0, 480.0, 0.9),
        (900.0, 610.0, 0.6),
    ] {
        let cos_t = true_cos_t(cos_i);
        let (r_s, r_p) = seed001_amplitudes(cos_i, cos_t);
        let cos_delta = (4.0 * std::f64::consts::PI * N_SOAP * d * cos_t / l).cos();
        // Seed 001: reflectivityS = r_s², then the formula squares it again (r⁴ where r² belongs).
        let (refl_s, refl_p) = (r_s * r_s, r_p * r_p);
        let double_squared = 0.5
            * (seed_airy_term(refl_s * refl_s, cos_delta)
                + seed_airy_term(refl_p * refl_p, cos_delta));
        let once = 0.5 * (seed_airy_term(refl_s, cos_delta) + seed_airy_term(refl_p, cos_delta));
        let truth = tmm_unpolarised(d, l, cos_i);
        assert_close("ρ² in the Airy form", once, truth, 1e-12);
        assert!(
            double_squared < truth / 10.0,
            "double-squared {double_squared} should be far darker than {truth}"
        );
    }
}

#[test]
fn soap_film_is_the_documented_air_soap_air() {
    let f = ThinFilm::soap(321.0);
    assert_eq!(f, film(1.0, N_SOAP, re(1.0), 321.0));
}

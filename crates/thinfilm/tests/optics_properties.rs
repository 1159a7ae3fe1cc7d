//! Physical laws of the f64 optics, over random films (proptest).

mod optics_common;

use num_complex::Complex64;
use optics_common::{as_stack, assert_close, film, re};
use proptest::prelude::*;
use thinfilm::fresnel::Interface;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 96,
        ..ProptestConfig::default()
    }
}

/// A substrate: lossless (half the time) or absorbing, possibly metallic.
fn substrate() -> impl Strategy<Value = Complex64> {
    prop_oneof![
        (1.0..2.6f64).prop_map(re),
        (0.05..4.0f64, 0.0..6.0f64).prop_map(|(n, k)| Complex64::new(n, k)),
    ]
}

/// Tolerance on T = 1 for a vanishing film at incidence cosine `c`: the transmission
/// factors carry the cosine ratio, whose rounding grows as ε/c towards grazing (measured:
/// |1 − T| ≤ 2.1 ε/c for c < 1e-3 over 400 k random films of this test's ranges), so a
/// fixed 1e-12 failed at c = 1e-6 (CI, 2026-11-23).
fn grazing_t_tolerance(c: f64) -> f64 {
    1e-12 + 8.0 * f64::EPSILON / c
}

/// The case CI's proptest found: T = 1 − 3.0e-10 at cos θ = 1e-6, within ε/c's rounding.
#[test]
fn vanishing_film_at_grazing_incidence_transmits_all_within_rounding() {
    let c = 1e-6;
    let resp = film(1.0, 2.2866607251805418, re(1.0), 0.0).response(360.0, c);
    assert_close("R", resp.r(), 0.0, 1e-14);
    assert_close("T", resp.t(), 1.0, grazing_t_tolerance(c));
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn reflectance_and_transmittance_lie_in_unit_interval(
        n0 in 1.0..1.6f64, n1 in 1.0..2.6f64, n2 in substrate(),
        d in 0.0..3000.0f64, l in 360.0..830.0f64, c in 0.0..=1.0f64,
    ) {
        let resp = film(n0, n1, n2, d).response(l, c);
        for (name, v) in [("R_s", resp.r_s), ("R_p", resp.r_p), ("T_s", resp.t_s), ("T_p", resp.t_p)] {
            prop_assert!(v.is_finite() && (-1e-15..=1.0 + 1e-12).contains(&v), "{name} = {v}");
        }
    }

    #[test]
    fn lossless_film_conserves_energy(
        n0 in 1.0..1.6f64, n1 in 1.0..2.6f64, n2 in substrate(),
        d in 0.0..3000.0f64, l in 360.0..830.0f64, c in 0.0..=1.0f64,
    ) {
        // T is the flux entering the substrate, so R + T = 1 even when the substrate absorbs.
        let resp = film(n0, n1, n2, d).response(l, c);
        assert_close("R_s + T_s", resp.r_s + resp.t_s, 1.0, 1e-12);
        assert_close("R_p + T_p", resp.r_p + resp.t_p, 1.0, 1e-12);
    }

    #[test]
    fn airy_sum_equals_transfer_matrix(
        n0 in 1.0..1.6f64, n1 in 1.0..2.6f64, n2 in substrate(),
        d in 0.0..3000.0f64, l in 360.0..830.0f64, c in 0.0..=1.0f64,
    ) {
        let f = film(n0, n1, n2, d);
        let airy = f.response(l, c);
        let tmm = as_stack(&f, l).response(l, c);
        assert_close("R_s", airy.r_s, tmm.r_s, 1e-12);
        assert_close("R_p", airy.r_p, tmm.r_p, 1e-12);
        assert_close("T_s", airy.t_s, tmm.t_s, 1e-12);
        assert_close("T_p", airy.t_p, tmm.t_p, 1e-12);
        let a = f.try_amplitudes(l, c).unwrap();
        let b = as_stack(&f, l).try_amplitudes(l, c).unwrap();
        for (name, x, y) in [("r_s", a.r_s, b.r_s), ("r_p", a.r_p, b.r_p), ("t_s", a.t_s, b.t_s), ("t_p", a.t_p, b.t_p)] {
            prop_assert!((x - y).norm() <= 1e-12, "{name}: airy {x} vs tmm {y}");
        }
    }

    #[test]
    fn polarisations_agree_at_normal_incidence(
        n0 in 1.0..1.6f64, n1 in 1.0..2.6f64, n2 in substrate(),
        d in 0.0..3000.0f64, l in 360.0..830.0f64,
    ) {
        let resp = film(n0, n1, n2, d).response(l, 1.0);
        assert_close("R_s - R_p", resp.r_s, resp.r_p, 1e-14);
        assert_close("T_s - T_p", resp.t_s, resp.t_p, 1e-14);
    }

    #[test]
    fn vanishing_symmetric_film_reflects_nothing(
        n0 in 1.0..1.6f64, n1 in 1.0..2.6f64, l in 360.0..830.0f64, c in 1e-6..=1.0f64,
    ) {
        let resp = film(n0, n1, re(n0), 0.0).response(l, c);
        assert_close("R", resp.r(), 0.0, 1e-14);
        assert_close("T", resp.t(), 1.0, grazing_t_tolerance(c));
    }

    #[test]
    fn reflectance_is_periodic_in_thickness(
        n0 in 1.0..1.4f64, n1 in 1.4..2.6f64, n2 in substrate(),
        d in 0.0..2000.0f64, l in 360.0..830.0f64, c in 0.0..=1.0f64,
    ) {
        // Film denser than the outside: θ_t is real, the period is λ / (2 n cos θ_t).
        let sin_t = n0 / n1 * (1.0 - c * c).sqrt();
        let period = l / (2.0 * n1 * (1.0 - sin_t * sin_t).sqrt());
        let a = film(n0, n1, n2, d).response(l, c);
        let b = film(n0, n1, n2, d + period).response(l, c);
        let k = film(n0, n1, n2, d + 3.0 * period).response(l, c);
        assert_close("R(d + P)", b.r(), a.r(), 1e-11);
        assert_close("R(d + 3P)", k.r(), a.r(), 1e-11);
        assert_close("T(d + P)", b.t(), a.t(), 1e-11);
    }

    #[test]
    fn brewster_angle_extinguishes_p(n_i in 1.0..2.0f64, n_t in 1.0..3.0f64) {
        prop_assume!((n_i - n_t).abs() > 1e-3);
        let cos_b = (n_t / n_i).atan().cos();
        let resp = Interface::new(n_i, re(n_t)).unwrap().response(cos_b);
        assert_close("R_p at Brewster", resp.r_p, 0.0, 1e-14);
        prop_assert!(resp.r_s > 0.0, "R_s = {} (s is never extinguished)", resp.r_s);
    }

    #[test]
    fn quarter_wave_film_matches_closed_form(
        n0 in 1.0..1.6f64, n1 in 1.0..2.6f64, n2 in 1.0..2.6f64, l in 360.0..830.0f64,
        order in 0u32..4,
    ) {
        // Odd multiples of λ/4 in optical thickness.
        let d = (2 * order + 1) as f64 * l / (4.0 * n1);
        let expected = ((n0 * n2 - n1 * n1) / (n0 * n2 + n1 * n1)).powi(2);
        assert_close("quarter-wave R", film(n0, n1, re(n2), d).response(l, 1.0).r(), expected, 1e-12);
    }

    #[test]
    fn total_internal_reflection_is_total(
        n_t in 1.0..1.5f64, excess in 0.01..1.0f64, frac in 0.0..=1.0f64,
    ) {
        let n_i = n_t + excess;
        let surface = Interface::new(n_i, re(n_t)).unwrap();
        let cos_c = surface.critical_cos().unwrap();
        let resp = surface.response(cos_c * frac);
        assert_close("R_s beyond critical", resp.r_s, 1.0, 1e-12);
        assert_close("R_p beyond critical", resp.r_p, 1.0, 1e-12);
        assert_close("T beyond critical", resp.t(), 0.0, 1e-12);
    }
}

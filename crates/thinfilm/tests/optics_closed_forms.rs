//! The solvers against closed forms and against a third method (the explicit series of
//! multiple reflections).

mod optics_common;

use num_complex::Complex64;
use optics_common::{assert_close, assert_close_c, film, re};
use proptest::prelude::*;
use thinfilm::fresnel::{Interface, OpticsError, amplitudes, cos_transmitted};
use thinfilm::tmm::{Layer, Stack};

/// (r, t) of one polarisation, picked from a set of Fresnel amplitudes.
type Pick = fn(&thinfilm::fresnel::Amplitudes) -> (Complex64, Complex64);

/// `r` and `t` of a film by adding reflected orders one by one until they stop mattering:
/// `r = r01 + t01 t10 r12 e^{2iβ} Σ_m (r10 r12 e^{2iβ})^m`, with every coefficient from the
/// single-interface Fresnel formulas in both directions (no Stokes relations used), for
/// the polarisation `pick` selects.
fn series(
    (n0, n1, n2): (f64, f64, Complex64),
    d: f64,
    l: f64,
    cos0: f64,
    pick: Pick,
) -> (Complex64, Complex64) {
    let cos1 = cos_transmitted(n0, re(n1), cos0);
    let cos2 = cos_transmitted(n0, n2, cos0);
    let c0 = re(cos0);
    let (r01, t01) = pick(&amplitudes(re(n0), c0, re(n1), cos1));
    let (r10, t10) = pick(&amplitudes(re(n1), cos1, re(n0), c0));
    let (r12, t12) = pick(&amplitudes(re(n1), cos1, n2, cos2));
    let beta = std::f64::consts::TAU * n1 * d * cos1 / l;
    let one_way = (Complex64::i() * beta).exp();
    let round = r10 * r12 * one_way * one_way;
    let (mut r, mut t) = (r01, Complex64::new(0.0, 0.0));
    let mut bounce = Complex64::new(1.0, 0.0);
    for _ in 0..100_000 {
        r += t01 * t10 * r12 * one_way * one_way * bounce;
        t += t01 * t12 * one_way * bounce;
        bounce *= round;
        if bounce.norm() < 1e-17 {
            break;
        }
    }
    (r, t)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn airy_closed_form_is_the_sum_of_all_orders(
        n0 in 1.0..1.5f64, n1 in 1.5..2.5f64, n2r in 1.0..2.5f64, n2i in 0.0..2.0f64,
        d in 0.0..2000.0f64, l in 360.0..830.0f64, cos0 in 0.2..=1.0f64,
    ) {
        let n2 = Complex64::new(n2r, n2i);
        let amp = film(n0, n1, n2, d).try_amplitudes(l, cos0).unwrap();
        let (r_sum, t_sum) = series((n0, n1, n2), d, l, cos0, |a| (a.r_s, a.t_s));
        assert_close_c("r_s", amp.r_s, r_sum, 1e-10);
        assert_close_c("t_s", amp.t_s, t_sum, 1e-10);
        let (r_sum, t_sum) = series((n0, n1, n2), d, l, cos0, |a| (a.r_p, a.t_p));
        assert_close_c("r_p", amp.r_p, r_sum, 1e-10);
        assert_close_c("t_p", amp.t_p, t_sum, 1e-10);
    }

    #[test]
    fn lossless_stack_transmits_the_same_both_ways(
        n0 in 1.0..1.6f64, ns in 1.0..2.0f64,
        indices in prop::collection::vec(1.2..2.6f64, 1..6),
        thicknesses in prop::collection::vec(0.0..400.0f64, 6),
        l in 360.0..830.0f64, cos0 in 0.3..=1.0f64,
    ) {
        let layers: Vec<Layer> = indices.iter().zip(&thicknesses).map(|(&n, &d)| Layer::lossless(n, d)).collect();
        let forward = Stack::new(n0, layers.clone(), re(ns)).unwrap();
        let cos_sub = cos_transmitted(n0, re(ns), cos0);
        prop_assume!(cos_sub.im == 0.0 && cos_sub.re > 0.1);
        let backward = Stack::new(ns, layers.into_iter().rev().collect(), re(n0)).unwrap();
        let f = forward.response(l, cos0);
        let b = backward.response(l, cos_sub.re);
        assert_close("T_s both ways", f.t_s, b.t_s, 1e-12);
        assert_close("T_p both ways", f.t_p, b.t_p, 1e-12);
        assert_close("R + T", f.r() + f.t(), 1.0, 1e-12);
    }

    #[test]
    fn splitting_a_layer_changes_nothing(
        n in 1.2..2.6f64, k in 0.0..0.5f64, d in 0.0..800.0f64, split in 0.0..=1.0f64,
        l in 360.0..830.0f64, cos0 in 0.0..=1.0f64,
    ) {
        let index = Complex64::new(n, k);
        let whole = Stack::new(1.0, vec![Layer::new(index, d)], re(1.5)).unwrap();
        let halves = Stack::new(1.0, vec![
            Layer::new(index, d * split),
            Layer::new(index, d * (1.0 - split)),
        ], re(1.5)).unwrap();
        let (a, b) = (whole.response(l, cos0), halves.response(l, cos0));
        assert_close("R", a.r(), b.r(), 1e-12);
        assert_close("T", a.t(), b.t(), 1e-12);
    }
}

#[test]
fn quarter_wave_mirror_matches_closed_form() {
    // (HL)^N on glass at the design wavelength: the assembly's admittance is (n_H/n_L)^{2N} n_s.
    let (n0, n_h, n_l, n_s, l) = (1.0, 2.35, 1.38, 1.52, 550.0);
    for pairs in 1..=8 {
        let mut layers = Vec::new();
        for _ in 0..pairs {
            layers.push(Layer::lossless(n_h, l / (4.0 * n_h)));
            layers.push(Layer::lossless(n_l, l / (4.0 * n_l)));
        }
        let y = (n_h / n_l).powi(2 * pairs) * n_s;
        let expected = ((n0 - y) / (n0 + y)).powi(2);
        let resp = Stack::new(n0, layers, re(n_s)).unwrap().response(l, 1.0);
        assert_close(&format!("{pairs} pairs"), resp.r(), expected, 1e-12);
    }
}

#[test]
fn bare_metal_reflects_by_its_complex_index() {
    // Silver-like and gold-like indices at normal incidence: R = |(1 − N)/(1 + N)|².
    for index in [
        Complex64::new(0.05, 3.6),
        Complex64::new(0.27, 2.9),
        Complex64::new(1.2, 0.3),
    ] {
        let expected = ((1.0 - index) / (1.0 + index)).norm_sqr();
        let resp = Interface::new(1.0, index).unwrap().response(1.0);
        assert_close("R metal", resp.r(), expected, 1e-14);
        let resp = film(1.0, 1.4, index, 0.0).response(500.0, 1.0);
        assert_close("zero-thickness film on metal", resp.r(), expected, 1e-14);
    }
}

#[test]
fn absorbing_layer_follows_beer_lambert() {
    // An index-matched weakly absorbing slab: T ≈ exp(−4π κ d / λ); the interfaces reflect ~(κ/2n)².
    let (n, kappa, l) = (1.5, 1e-3, 500.0);
    for d in [1_000.0, 10_000.0, 50_000.0] {
        let stack = Stack::new(n, vec![Layer::new(Complex64::new(n, kappa), d)], re(n)).unwrap();
        let expected = (-4.0 * std::f64::consts::PI * kappa * d / l).exp();
        assert_close(
            &format!("T at {d} nm"),
            stack.response(l, 1.0).t(),
            expected,
            1e-6,
        );
    }
}

#[test]
fn evanescent_film_tunnels_and_conserves_energy() {
    // Frustrated total internal reflection: glass | air gap | glass beyond the critical angle.
    let cos0 = 0.5; // 60° in glass, critical angle 41.8°
    let mut last_t = 1.0;
    for d in [0.0, 20.0, 100.0, 300.0, 1000.0] {
        let resp = film(1.5, 1.0, re(1.5), d).response(600.0, cos0);
        assert!(
            resp.t() <= last_t + 1e-15,
            "T must fall as the gap widens: {resp}"
        );
        assert_close("R + T", resp.r() + resp.t(), 1.0, 1e-12);
        last_t = resp.t();
    }
    assert!(
        last_t < 1e-5,
        "a 1 µm gap should be nearly opaque, T = {last_t}"
    );
}

#[test]
fn film_exactly_at_its_critical_angle_is_finite() {
    // n0 sin θ0 = n1 exactly: cos θ1 = 0 and the Airy quotient is 0/0.
    let (n0, n1) = (2.0, 1.0);
    let cos0 = 0.75f64.sqrt();
    let f = film(n0, n1, re(n0), 150.0);
    let resp = f.response(500.0, cos0);
    let tmm = Stack::new(n0, vec![Layer::lossless(n1, 150.0)], re(n0))
        .unwrap()
        .response(500.0, cos0);
    assert!(resp.r().is_finite() && resp.t().is_finite(), "{resp}");
    assert_close("R + T", resp.r() + resp.t(), 1.0, 1e-9);
    assert_close("R vs TMM", resp.r(), tmm.r(), 1e-9);
}

#[test]
fn grazing_incidence_reflects_everything() {
    let resp = film(1.0, 1.33, re(1.0), 300.0).response(550.0, 0.0);
    assert_eq!((resp.r(), resp.t()), (1.0, 0.0));
    let resp = film(1.0, 1.0, re(1.0), 300.0).response(550.0, 0.0);
    assert_eq!((resp.r(), resp.t()), (0.0, 1.0), "no interface at all");
    let resp = Interface::new(1.0, re(1.5)).unwrap().response(0.0);
    assert_eq!((resp.r(), resp.t()), (1.0, 0.0));
}

#[test]
fn bad_queries_name_the_bad_value() {
    let f = film(1.0, 1.33, re(1.0), 300.0);
    assert!(
        matches!(f.try_response(550.0, 1.5), Err(OpticsError::Cosine { value, .. }) if value == 1.5)
    );
    assert!(matches!(
        f.try_response(550.0, -0.1),
        Err(OpticsError::Cosine { .. })
    ));
    assert!(matches!(
        f.try_response(f64::NAN, 1.0),
        Err(OpticsError::Wavelength { .. })
    ));
    assert!(matches!(
        f.try_response(0.0, 1.0),
        Err(OpticsError::Wavelength { .. })
    ));
    let thick = film(1.0, 1.33, re(1.0), -5.0);
    let err = thick.try_response(550.0, 1.0).unwrap_err();
    assert!(err.to_string().contains("-5"), "{err}");
    let gain = film(1.0, 1.33, Complex64::new(1.5, -0.1), 10.0);
    assert!(matches!(
        gain.try_response(550.0, 1.0),
        Err(OpticsError::ComplexIndex { .. })
    ));
    assert!(Interface::new(f64::INFINITY, re(1.0)).is_err());
    assert!(Stack::new(1.0, vec![Layer::lossless(1.4, f64::NAN)], re(1.0)).is_err());
}

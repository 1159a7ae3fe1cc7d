//! The transfer-matrix stack against an independent method: Rouard's recursion, which
//! folds the stack from the back one layer at a time, each step the sum of all orders of
//! multiple reflection inside one layer, with every interface coefficient from the
//! single-interface Fresnel formulas in both directions (no Stokes relations, no
//! characteristic matrices). Cases the single-film tests do not reach: thick absorbing
//! layers, evanescent gaps (frustrated total internal reflection) and oblique
//! multilayers, in both polarisations.

mod optics_common;

use num_complex::Complex64;
use optics_common::{assert_close, assert_close_c, re};
use proptest::prelude::*;
use thinfilm::fresnel::{Amplitudes, amplitudes, cos_transmitted};
use thinfilm::tmm::{Layer, Stack};

/// (r, t) of one polarisation, picked from a set of amplitudes.
type Pick = fn(&Amplitudes) -> (Complex64, Complex64);

fn s_pol(a: &Amplitudes) -> (Complex64, Complex64) {
    (a.r_s, a.t_s)
}

fn p_pol(a: &Amplitudes) -> (Complex64, Complex64) {
    (a.r_p, a.t_p)
}

/// Rouard's recursion for one polarisation: (r, t) of the whole stack.
fn rouard(stack: &Stack, wavelength_nm: f64, cos0: f64, pick: Pick) -> (Complex64, Complex64) {
    let n0 = stack.n_incident;
    let media: Vec<Complex64> = std::iter::once(re(n0))
        .chain(
            stack
                .layers
                .iter()
                .map(|l| l.index.try_n_at(wavelength_nm).unwrap()),
        )
        .chain(std::iter::once(
            stack.n_substrate.try_n_at(wavelength_nm).unwrap(),
        ))
        .collect();
    let cosines: Vec<Complex64> = media
        .iter()
        .map(|&n| cos_transmitted(n0, n, cos0))
        .collect();
    let interface =
        |i: usize, j: usize| pick(&amplitudes(media[i], cosines[i], media[j], cosines[j]));
    let last = media.len() - 1;
    let (mut r, mut t) = interface(last - 1, last);
    for j in (1..last).rev() {
        let layer = &stack.layers[j - 1];
        let beta =
            std::f64::consts::TAU * media[j] * cosines[j] * layer.thickness_nm / wavelength_nm;
        let one_way = (Complex64::i() * beta).exp();
        let (r_in, t_in) = interface(j - 1, j);
        let (r_back, t_back) = interface(j, j - 1);
        let loop_gain = r_back * r * one_way * one_way;
        let denominator = Complex64::new(1.0, 0.0) - loop_gain;
        (r, t) = (
            r_in + t_in * t_back * r * one_way * one_way / denominator,
            t_in * t * one_way / denominator,
        );
    }
    (r, t)
}

#[track_caller]
fn assert_stack_matches_rouard(stack: &Stack, wavelength_nm: f64, cos0: f64, tol: f64) {
    let amp = stack
        .try_amplitudes(wavelength_nm, cos0)
        .expect("valid query");
    let (r_s, t_s) = rouard(stack, wavelength_nm, cos0, s_pol);
    let (r_p, t_p) = rouard(stack, wavelength_nm, cos0, p_pol);
    assert_close_c("r_s", amp.r_s, r_s, tol);
    assert_close_c("t_s", amp.t_s, t_s, tol);
    assert_close_c("r_p", amp.r_p, r_p, tol);
    assert_close_c("t_p", amp.t_p, t_p, tol);
}

fn index() -> impl Strategy<Value = Complex64> {
    // Below the incident index (evanescent at oblique incidence), above it, absorbing.
    (
        1.0..2.6f64,
        prop_oneof![Just(0.0), 0.0..0.3f64, 0.5..3.0f64],
    )
        .prop_map(|(n, k)| Complex64::new(n, k))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn oblique_multilayers_match_rouard_in_both_polarisations(
        n0 in 1.0..1.8f64,
        layers in prop::collection::vec((index(), 0.0..600.0f64), 1..6),
        substrate in index(),
        l in 360.0..830.0f64,
        cos0 in 0.05..=1.0f64,
    ) {
        let layers = layers.into_iter().map(|(n, d)| Layer::new(n, d)).collect();
        let stack = Stack::new(n0, layers, substrate).unwrap();
        assert_stack_matches_rouard(&stack, l, cos0, 1e-9);
    }
}

/// Frustrated total internal reflection: glass | air gap | glass at 60° (beyond the
/// 41.8° critical angle). No gap transmits everything, a wide gap reflects everything,
/// between them the evanescent wave tunnels; lossless, so R + T = 1 throughout.
#[test]
fn evanescent_gap_tunnels_as_rouard_says() {
    let cos0 = 0.5;
    let mut last_t = f64::INFINITY;
    for gap_nm in [0.0, 20.0, 50.0, 100.0, 200.0, 400.0, 800.0, 2000.0] {
        let stack = Stack::new(1.5, vec![Layer::lossless(1.0, gap_nm)], re(1.5)).unwrap();
        assert_stack_matches_rouard(&stack, 550.0, cos0, 1e-12);
        let response = stack.response(550.0, cos0);
        assert_close("R + T", response.r() + response.t(), 1.0, 1e-12);
        assert!(response.t() < last_t, "T must fall as the gap widens");
        last_t = response.t();
    }
    assert!(
        last_t < 1e-6,
        "a 2 µm gap should reflect totally, T = {last_t}"
    );
}

/// An absorbing layer many absorption lengths thick at oblique incidence: its round trip
/// is negligible, so the stack is the front interface's reflection, and the transmitted
/// amplitude falls as e^(−Im β).
#[test]
fn thick_absorbing_layer_matches_rouard() {
    for thickness_nm in [1e3, 1e4, 5e4] {
        let layer = Layer::new(Complex64::new(1.5, 0.1), thickness_nm);
        let stack = Stack::new(1.0, vec![layer], re(1.5)).unwrap();
        for cos0 in [1.0, 0.6, 0.2] {
            let amp = stack.try_amplitudes(550.0, cos0).unwrap();
            let (r_s, t_s) = rouard(&stack, 550.0, cos0, s_pol);
            let (r_p, t_p) = rouard(&stack, 550.0, cos0, p_pol);
            assert_close_c("r_s", amp.r_s, r_s, 1e-12);
            assert_close_c("r_p", amp.r_p, r_p, 1e-12);
            // t spans many decades: compare relative to its size.
            assert_close("t_s / Rouard", (amp.t_s / t_s).norm(), 1.0, 1e-9);
            assert_close("t_p / Rouard", (amp.t_p / t_p).norm(), 1.0, 1e-9);
        }
    }
}

/// A layer thick enough that cosh(Im δ) overflows f64 (1 mm of a weak absorber): the
/// stack must still give the front interface's reflection and no transmission.
#[test]
fn very_thick_absorbing_layer_does_not_overflow() {
    let layer = Layer::new(Complex64::new(1.5, 0.1), 1e6);
    let stack = Stack::new(1.0, vec![layer], re(1.5)).unwrap();
    for cos0 in [1.0, 0.6, 0.2] {
        let amp = stack.try_amplitudes(550.0, cos0).unwrap();
        let (r_s, _) = rouard(&stack, 550.0, cos0, s_pol);
        let (r_p, _) = rouard(&stack, 550.0, cos0, p_pol);
        assert_close_c("r_s", amp.r_s, r_s, 1e-12);
        assert_close_c("r_p", amp.r_p, r_p, 1e-12);
        assert!(amp.t_s.norm() < 1e-100 && amp.t_p.norm() < 1e-100);
    }
}

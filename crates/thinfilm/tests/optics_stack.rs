//! The transfer matrix at any thickness, any incidence and with any index model: thick
//! absorbing and evanescent layers against their closed-form limits, grazing incidence,
//! model ranges, complex and tabulated indices.

mod optics_common;

use num_complex::Complex64;
use optics_common::{assert_close, re};
use proptest::prelude::*;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::{Incidence, IndexModel, Interface, Layer, NkTable, OpticsError, Stack, ThinFilm};

/// Asserts `ln(actual)` is within `tol` of `ln(expected)`: a relative check that spans
/// hundreds of decades.
#[track_caller]
fn assert_close_log(label: &str, actual: f64, expected: f64, tol: f64) {
    let diff = (actual.ln() - expected.ln()).abs();
    assert!(
        diff <= tol,
        "{label}: actual {actual:e} vs expected {expected:e}, |ln diff| = {diff:e} > tol {tol:e}"
    );
}

#[test]
fn thick_metal_layer_reflects_like_the_bare_metal() {
    // 10 µm of 0.2+3.5i: |Im δ| ≈ 4e2 per µm, so nothing reaches the glass behind it.
    let metal = Complex64::new(0.2, 3.5);
    let stack = Stack::new(1.0, vec![Layer::new(metal, 10_000.0)], re(1.5)).unwrap();
    let bare = Interface::new(1.0, metal).unwrap();
    for cos in [1.0, 0.6, 0.1] {
        let resp = stack.try_response(550.0, cos).unwrap();
        let expected = bare.response(cos);
        assert_close("R_s", resp.r_s, expected.r_s, 1e-13);
        assert_close("R_p", resp.r_p, expected.r_p, 1e-13);
        assert_eq!(resp.t(), 0.0, "cos {cos}: {resp}");
    }
}

#[test]
fn wide_evanescent_gap_totally_reflects() {
    // A 100 µm air gap in glass at 60° (critical angle 41.8°): total internal reflection.
    let stack = Stack::new(1.5, vec![Layer::lossless(1.0, 100_000.0)], re(1.5)).unwrap();
    let resp = stack.try_response(550.0, 0.5).unwrap();
    assert_close("R_s", resp.r_s, 1.0, 1e-14);
    assert_close("R_p", resp.r_p, 1.0, 1e-14);
    assert_eq!(resp.t(), 0.0, "{resp}");
    // The single film agrees (it uses the Airy sum here).
    let film = ThinFilm::symmetric(1.5, RefractiveIndex::Constant(1.0), 100_000.0);
    assert_close("Airy R", film.response(550.0, 0.5).r(), 1.0, 1e-14);
}

#[test]
fn centimetre_weak_absorber_follows_beer_lambert_to_underflow() {
    // κ = 0.01 index-matched slab: T = exp(−4πκd/λ) times the two interfaces' (1 − ~1e-5).
    let (n, kappa, l) = (1.5, 0.01, 550.0);
    for d in [1e5, 1e6, 2e6] {
        let stack = Stack::new(n, vec![Layer::new(Complex64::new(n, kappa), d)], re(n)).unwrap();
        let resp = stack.try_response(l, 1.0).unwrap();
        let beer = (-4.0 * std::f64::consts::PI * kappa * d / l).exp();
        assert_close_log(&format!("T at {d} nm"), resp.t(), beer, 1e-4);
    }
    // 10 mm: T is e^{-2285}, below the smallest double; R is the front face alone.
    let thick = Stack::new(n, vec![Layer::new(Complex64::new(n, kappa), 1e7)], re(n)).unwrap();
    let resp = thick.try_response(l, 1.0).unwrap();
    let face = Interface::new(n, Complex64::new(n, kappa))
        .unwrap()
        .response(1.0);
    assert_eq!(resp.t(), 0.0, "{resp}");
    assert_close("R", resp.r(), face.r(), 1e-18);
}

#[test]
fn many_thick_layers_stay_finite() {
    // Fifty 1 µm metal layers between dielectrics: the product would overflow without rescaling.
    let mut layers = Vec::new();
    for _ in 0..50 {
        layers.push(Layer::new(Complex64::new(0.2, 3.5), 1_000.0));
        layers.push(Layer::lossless(1.4, 100.0));
    }
    let stack = Stack::new(1.0, layers, re(1.5)).unwrap();
    let first = Interface::new(1.0, Complex64::new(0.2, 3.5)).unwrap();
    let resp = stack.try_response(600.0, 0.8).unwrap();
    assert_close("R", resp.r(), first.response(0.8).r(), 1e-12);
    assert_eq!(resp.t(), 0.0);
}

#[test]
fn zero_thickness_film_vanishes_a_hair_from_grazing() {
    for cos in [1e-6, 1e-9, 1e-12, 1e-200] {
        let incidence = Incidence::try_from_cos(cos).unwrap();
        let film = ThinFilm::soap(0.0)
            .try_response_at(550.0, incidence)
            .unwrap();
        assert!(film.r() < 1e-12, "Airy at cos {cos}: {film}");
        let stack = Stack::new(1.0, vec![Layer::lossless(1.33, 0.0)], re(1.0)).unwrap();
        let resp = stack.try_response_at(550.0, incidence).unwrap();
        assert!(resp.r() < 1e-12, "TMM at cos {cos}: {resp}");
        assert_close("T", resp.t(), 1.0, 1e-12);
    }
}

#[test]
fn sine_and_angle_give_the_same_incidence_as_the_cosine() {
    let from_angle = Incidence::try_from_angle_deg(60.0).unwrap();
    let from_sin = Incidence::try_from_sin(3f64.sqrt() / 2.0).unwrap();
    let from_cos = Incidence::try_from_cos(0.5).unwrap();
    for inc in [from_angle, from_sin] {
        assert_close("cos", inc.cos(), from_cos.cos(), 1e-15);
        assert_close("sin", inc.sin(), from_cos.sin(), 1e-15);
    }
    assert_eq!(Incidence::try_from_angle_deg(90.0).unwrap().cos(), 0.0);
    let err = Incidence::try_from_angle_deg(91.0).unwrap_err();
    assert!(err.to_string().contains("91"), "{err}");
    assert!(Incidence::try_from_sin(f64::NAN).is_err());
}

#[test]
fn sellmeier_with_its_own_range_works_beyond_the_visible() {
    // Germanium (Icenogle et al. 1976, λ in µm): n² = 9.28156 + 6.72880 λ²/(λ² − 0.44105)
    // + 0.21307 λ²/(λ² − 3870.1); a resonance at 664 nm, used over 2–12 µm.
    let b = [8.28156, 6.72880, 0.21307];
    let c_nm2 = [0.0, 0.44105e6, 3870.1e6];
    assert!(
        RefractiveIndex::sellmeier(b, c_nm2).is_err(),
        "664 nm lies in 360–830"
    );
    let ge = RefractiveIndex::sellmeier_over(b, c_nm2, [2_000.0, 12_000.0]).unwrap();
    assert_close("n(10 µm)", ge.n_at(10_000.0), 4.0043, 1e-3);
    let err = ge.try_n_at(550.0).unwrap_err();
    assert!(
        matches!(err, OpticsError::OutOfRange { wavelength_nm, range_nm: [2_000.0, 12_000.0], .. } if wavelength_nm == 550.0),
        "{err}"
    );
    let message = err.to_string();
    assert!(
        message.contains("550") && message.contains("12000"),
        "{message}"
    );
}

#[test]
fn constant_index_covers_ultraviolet_to_far_infrared() {
    let film = ThinFilm::soap(200.0);
    for l in [100.0, 350.0, 1064.0, 1550.0, 100_000.0] {
        assert!(film.try_response(l, 1.0).is_ok(), "{l} nm");
    }
    for l in [99.0, 100_001.0] {
        let err = film.try_response(l, 1.0).unwrap_err();
        assert!(
            matches!(err, OpticsError::OutOfRange { .. }),
            "{l} nm: {err}"
        );
    }
}

#[test]
fn nk_table_interpolates_and_names_bad_rows() {
    let csv = "# gold\nwavelength_nm,n,k\n400,1.5,1.9\n600,0.25,3.0\n1000,0.2,6.5\n";
    let table = NkTable::from_csv_str(csv).unwrap();
    assert_eq!(table.range_nm(), [400.0, 1000.0]);
    assert_eq!(table.try_n_at(600.0).unwrap(), Complex64::new(0.25, 3.0));
    let mid = table.try_n_at(800.0).unwrap();
    assert_close("n", mid.re, 0.225, 1e-15);
    assert_close("k", mid.im, 4.75, 1e-15);
    assert!(table.try_n_at(1000.5).is_err());
    for (bad, needle) in [
        ("wavelength_nm,n,k\n400,1,0\n", "at least 2"),
        ("wavelength_nm,n\n400,1\n500,1\n", "header"),
        ("wavelength_nm,n,k\n400,1,0\n500,x,0\n", "line 3"),
        ("wavelength_nm,n,k\n400,1,0\n500,1,-0.5\n", "-0.5"),
        ("wavelength_nm,n,k\n500,1,0\n400,1,0\n", "400"),
        ("wavelength_nm,n,k\n400,1e400,0\n500,1,0\n", "inf"),
    ] {
        let err = NkTable::from_csv_str(bad).unwrap_err().to_string();
        assert!(err.contains(needle), "`{bad}`: {err}");
    }
}

#[test]
fn film_on_tabulated_metal_matches_constant_index_at_a_node() {
    let gold = NkTable::from_csv_str("wavelength_nm,n,k\n500,0.97,1.87\n1550,0.52,10.7\n").unwrap();
    let on_table = Stack::new(1.0, vec![Layer::lossless(1.38, 100.0)], gold).unwrap();
    let on_constant = Stack::new(
        1.0,
        vec![Layer::lossless(1.38, 100.0)],
        Complex64::new(0.52, 10.7),
    )
    .unwrap();
    let (a, b) = (
        on_table.response(1550.0, 0.7),
        on_constant.response(1550.0, 0.7),
    );
    assert_eq!(a, b);
    assert_eq!(on_table.range_nm(), [500.0, 1550.0]);
    assert!(on_table.try_response(1600.0, 0.7).is_err());
}

#[test]
fn dispersive_layer_in_a_stack_matches_the_single_film() {
    let water = RefractiveIndex::Water;
    let stack = Stack::new(1.0, vec![Layer::new(water, 400.0)], re(1.0)).unwrap();
    let film = ThinFilm::symmetric(1.0, water, 400.0);
    for l in [250.0, 550.0, 1064.0] {
        assert_close(
            "R",
            stack.response(l, 0.3).r(),
            film.response(l, 0.3).r(),
            1e-13,
        );
    }
    assert!(matches!(
        Stack::new(1.0, vec![Layer::new(IndexModel::from(water), 1.0)], re(1.0))
            .unwrap()
            .try_response(1200.0, 1.0),
        Err(OpticsError::OutOfRange { .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn absorbing_stack_conserves_energy(
        n1 in 1.2..2.5f64, k1 in 0.0..4.0f64, d1 in 0.0..1e5f64,
        n2 in 0.1..2.5f64, k2 in 0.0..4.0f64, d2 in 0.0..1e5f64,
        l in 200.0..2000.0f64, cos in 0.0..=1.0f64,
    ) {
        let layers = vec![
            Layer::new(Complex64::new(n1, k1), d1),
            Layer::new(Complex64::new(n2, k2), d2),
        ];
        let resp = Stack::new(1.0, layers, re(1.5)).unwrap().response(l, cos);
        let a = resp.absorptance();
        prop_assert!(resp.r().is_finite() && resp.t().is_finite(), "{}", resp);
        prop_assert!(resp.r() >= 0.0 && resp.t() >= 0.0 && a >= -1e-12, "{}", resp);
        prop_assert!(resp.r() <= 1.0 + 1e-12, "{}", resp);
        if k1 == 0.0 && k2 == 0.0 {
            prop_assert!((resp.r() + resp.t() - 1.0).abs() < 1e-12, "{}", resp);
        }
    }
}

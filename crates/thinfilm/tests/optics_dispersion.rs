//! Dispersion models against published values and an independent fit.

mod optics_common;

use optics_common::{assert_close, re};
use thinfilm::airy::ThinFilm;
use thinfilm::dispersion::{RefractiveIndex, VALIDATED_RANGE_NM, water_iapws};
use thinfilm::fresnel::OpticsError;

/// Daimon & Masumura (2007) four-term Sellmeier fit for water at 20 °C (λ in µm): an
/// independent measurement to compare the IAPWS formulation with.
fn water_daimon_masumura(wavelength_nm: f64) -> f64 {
    let b = [
        5.684027565e-1,
        1.726177391e-1,
        2.086189578e-2,
        1.130748688e-1,
    ];
    let c_um2 = [
        5.101829712e-3,
        1.821153936e-2,
        2.620722293e-2,
        1.069792721e1,
    ];
    let l2 = (wavelength_nm / 1000.0).powi(2);
    (1.0 + b
        .iter()
        .zip(c_um2)
        .map(|(b, c)| b * l2 / (l2 - c))
        .sum::<f64>())
    .sqrt()
}

#[test]
fn iapws_formulation_reproduces_its_check_values() {
    // The release's check values at 25 °C and 0.1 MPa (ρ = 997.047435 kg/m³).
    assert_close(
        "226.5 nm",
        water_iapws(226.5, 298.15, 997.047435).unwrap(),
        1.39277824,
        1e-8,
    );
    assert_close(
        "589.3 nm",
        water_iapws(589.3, 298.15, 997.047435).unwrap(),
        1.33285819,
        1e-8,
    );
}

#[test]
fn water_at_sodium_d_line_is_the_handbook_value() {
    let n = RefractiveIndex::Water.n_at(589.3);
    assert_close("absolute n_D at 20 °C", n, 1.33335, 2e-5);
    // Handbooks quote n_D = 1.3330 relative to air (n_air = 1.000277 at 589 nm).
    assert_close("n_D relative to air", n / 1.000277, 1.3330, 1e-4);
}

#[test]
fn water_agrees_with_daimon_masumura_across_the_visible() {
    let mut worst = 0.0f64;
    for l in (360..=830).step_by(10) {
        let l = l as f64;
        worst = worst.max((RefractiveIndex::Water.n_at(l) - water_daimon_masumura(l)).abs());
    }
    assert!(worst < 1e-4, "worst |IAPWS − Daimon-Masumura| = {worst:e}");
}

#[test]
fn water_has_normal_dispersion() {
    let blue = RefractiveIndex::Water.n_at(400.0);
    let red = RefractiveIndex::Water.n_at(700.0);
    assert!(blue > red + 0.01, "n(400) = {blue}, n(700) = {red}");
}

#[test]
fn water_outside_its_range_is_an_error() {
    assert!(matches!(
        RefractiveIndex::Water.try_n_at(1500.0),
        Err(OpticsError::OutOfRange { wavelength_nm, range_nm: [200.0, 1100.0], .. }) if wavelength_nm == 1500.0
    ));
    assert!(water_iapws(550.0, 200.0, 998.0).is_err());
    assert!(water_iapws(550.0, 293.15, 2000.0).is_err());
}

#[test]
fn sellmeier_reproduces_schott_n_bk7() {
    // Schott N-BK7 catalogue coefficients (C in µm², here in nm²); catalogue n_d = 1.51680.
    let bk7 = RefractiveIndex::sellmeier(
        [1.03961212, 0.231792344, 1.01046945],
        [0.00600069867e6, 0.0200179144e6, 103.560653e6],
    )
    .unwrap();
    assert_close("n_d (587.56 nm)", bk7.n_at(587.5618), 1.51680, 1e-5);
    assert_close("n_F (486.13 nm)", bk7.n_at(486.1327), 1.52238, 1e-5);
    assert_close("n_C (656.27 nm)", bk7.n_at(656.2725), 1.51432, 1e-5);
}

#[test]
fn cauchy_is_its_formula() {
    let glass = RefractiveIndex::cauchy(1.5046, 4200.0, 0.0).unwrap();
    assert_close(
        "n(550)",
        glass.n_at(550.0),
        1.5046 + 4200.0 / 302_500.0,
        1e-15,
    );
    let with_c = RefractiveIndex::cauchy(1.45, 3000.0, 1e8).unwrap();
    let l: f64 = 400.0;
    assert_close(
        "n(400)",
        with_c.n_at(l),
        1.45 + 3000.0 / (l * l) + 1e8 / l.powi(4),
        1e-15,
    );
}

#[test]
fn invalid_models_are_rejected_with_the_value() {
    let err = RefractiveIndex::cauchy(0.5, -1e5, 0.0).unwrap_err();
    assert!(err.to_string().contains("Cauchy"), "{err}");
    // A negative dip at the vertex, positive at both ends of the range.
    // n = 1 + c (x − x_v)² − c x_v² in x = 1/λ², with its vertex x_v = 4e-6 nm⁻² (500 nm).
    let (c, x_v) = (1.01 / 16e-12, 4e-6);
    let dip = RefractiveIndex::Cauchy {
        a: 1.0,
        b_nm2: -2.0 * c * x_v,
        c_nm4: c,
        range_nm: VALIDATED_RANGE_NM,
    };
    assert!(dip.n_at(360.0) > 0.0 && dip.n_at(830.0) > 0.0);
    assert!(
        dip.try_n_at(500.0).is_err(),
        "n(500) = {:?}",
        dip.try_n_at(500.0)
    );
    assert!(dip.validate().is_err());
    let err = RefractiveIndex::sellmeier([1.0, 0.0, 0.0], [500.0 * 500.0, 0.0, 0.0]).unwrap_err();
    assert!(
        err.to_string().contains("500"),
        "resonance inside the range: {err}"
    );
    assert!(RefractiveIndex::sellmeier([-1.0, 0.0, 0.0], [0.0; 3]).is_err());
    assert!(RefractiveIndex::sellmeier([f64::NAN, 0.0, 0.0], [0.0; 3]).is_err());
    assert!(RefractiveIndex::constant(0.0).is_err());
    assert!(RefractiveIndex::constant(f64::INFINITY).is_err());
    assert!(RefractiveIndex::Constant(-1.0).try_n_at(500.0).is_err());
    assert_eq!(RefractiveIndex::SOAP, RefractiveIndex::Constant(1.33));
    assert_eq!(RefractiveIndex::SOAP.n_at(420.0), 1.33);
}

#[test]
fn dispersive_film_uses_the_index_at_each_wavelength() {
    let water = ThinFilm {
        n_outside: 1.0,
        n_film: RefractiveIndex::Water,
        n_substrate: re(1.0),
        thickness_nm: 420.0,
    };
    for l in [380.0, 500.0, 700.0] {
        let fixed = ThinFilm {
            n_film: RefractiveIndex::Constant(RefractiveIndex::Water.n_at(l)),
            ..water
        };
        assert_eq!(water.response(l, 0.8), fixed.response(l, 0.8));
    }
}

//! The spectral integrator against closed forms and a direct 1 nm summation.

use proptest::prelude::*;
use thinfilm::cmf::Observer;
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::{DEFAULT_STEP_NM, Quadrature, SpectralIntegrator};
use thinfilm::spectrum::Spectrum;

fn assert_xyz_close(actual: [f64; 3], expected: [f64; 3], tol: f64, what: &str) {
    for c in 0..3 {
        let diff = (actual[c] - expected[c]).abs();
        assert!(
            diff <= tol,
            "{what}[{c}]: got {actual:?}, expected {expected:?}, |diff| = {diff:e} > {tol:e}"
        );
    }
}

/// The CIE 1 nm summation written out directly, independent of the integrator.
fn direct_1nm(observer: Observer, e: &Spectrum, r: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    let mut norm = 0.0;
    for nm in 360..=830 {
        let w = f64::from(nm);
        let cmf = observer.cmf(w);
        let power = e.value_at(w);
        (0..3).for_each(|c| xyz[c] += r(w) * power * cmf[c]);
        norm += power * cmf[1];
    }
    for &(w, p) in e.lines() {
        let cmf = observer.cmf(w);
        (0..3).for_each(|c| xyz[c] += r(w) * p * cmf[c]);
        norm += p * cmf[1];
    }
    xyz.map(|v| v / norm)
}

const QUADRATURES: [Quadrature; 4] = [
    Quadrature::PointSample,
    Quadrature::Linear,
    Quadrature::Cubic,
    Quadrature::Quintic,
];

#[test]
fn one_nm_step_is_the_cie_summation_for_every_quadrature() {
    let r = |w: f64| 0.5 + 0.4 * (w / 17.0).sin();
    for observer in Observer::ALL {
        for illuminant in Illuminant::ALL {
            let e = illuminant.spectrum();
            let expected = direct_1nm(observer, &e, r);
            for q in QUADRATURES {
                let i = SpectralIntegrator::with_quadrature(observer, &e, 1.0, q).unwrap();
                assert_xyz_close(i.xyz(r), expected, 1e-12, &format!("{illuminant:?} {q:?}"));
            }
        }
    }
}

#[test]
fn perfect_reflector_has_y_one_and_the_reference_white() {
    for illuminant in Illuminant::ALL {
        let e = illuminant.spectrum();
        let reference = direct_1nm(Observer::Cie1931, &e, |_| 1.0);
        let i = SpectralIntegrator::new(Observer::Cie1931, &e, DEFAULT_STEP_NM).unwrap();
        assert_eq!(i.white_xyz(), i.xyz(|_| 1.0));
        assert!((i.white_xyz()[1] - 1.0).abs() < 1e-14, "{illuminant:?}");
        // The interpolating bases are partitions of unity, so white is exact.
        assert_xyz_close(i.white_xyz(), reference, 1e-13, illuminant.name());
    }
}

#[test]
fn equal_energy_white_is_the_ratio_of_cmf_sums() {
    // pbrt-style: under E, white XYZ is (∫x̄, ∫ȳ, ∫z̄)/∫ȳ.
    let table = Observer::Cie1931.table_1nm();
    let sums: Vec<f64> = (0..3).map(|c| table.iter().map(|r| r[c]).sum()).collect();
    let e = Illuminant::E.spectrum();
    let i = SpectralIntegrator::new(Observer::Cie1931, &e, DEFAULT_STEP_NM).unwrap();
    assert_xyz_close(
        i.white_xyz(),
        [sums[0] / sums[1], 1.0, sums[2] / sums[1]],
        1e-13,
        "E white",
    );
}

#[test]
fn interpolating_quadratures_are_exact_for_polynomial_reflectance() {
    // An interpolant of degree p − 1 reproduces such R exactly, so the only
    // difference from the 1 nm sum is rounding.
    let e = Illuminant::F11.spectrum();
    let x = |w: f64| (w - 600.0) / 250.0;
    type Case<'a> = (Quadrature, f64, &'a dyn Fn(f64) -> f64);
    let cases: [Case; 3] = [
        (Quadrature::Linear, 1.0, &|w| 0.3 + 0.2 * x(w)),
        (Quadrature::Cubic, 3.0, &|w| {
            0.3 + 0.2 * x(w) - 0.1 * x(w).powi(3)
        }),
        (Quadrature::Quintic, 5.0, &|w| {
            0.3 + 0.1 * x(w).powi(5) - 0.1 * x(w).powi(2)
        }),
    ];
    for (q, degree, r) in cases {
        let expected = direct_1nm(Observer::Cie1931, &e, r);
        for step in [7.0, 10.0, 23.5] {
            let i = SpectralIntegrator::with_quadrature(Observer::Cie1931, &e, step, q).unwrap();
            assert_xyz_close(
                i.xyz(r),
                expected,
                1e-13,
                &format!("{q:?} degree {degree} step {step}"),
            );
        }
    }
}

#[test]
fn sodium_lines_are_integrated_as_exact_delta_terms() {
    let e = Illuminant::Sodium.spectrum();
    let i = SpectralIntegrator::new(Observer::Cie1931, &e, DEFAULT_STEP_NM).unwrap();
    assert_eq!(i.wavelengths_nm(), &[589.0, 589.6]);
    let r = |w: f64| if w < 589.3 { 0.2 } else { 0.7 };
    let (c2, c1) = (Observer::Cie1931.cmf(589.0), Observer::Cie1931.cmf(589.6));
    let norm = 2.0 * c2[1] + c1[1];
    let expected = std::array::from_fn(|c| (2.0 * 0.2 * c2[c] + 0.7 * c1[c]) / norm);
    assert_xyz_close(i.xyz(r), expected, 1e-15, "sodium");
}

#[test]
fn a_line_on_a_continuum_adds_its_delta_term() {
    let continuum = Spectrum::try_from_samples(vec![380.0, 780.0], vec![50.0, 50.0]).unwrap();
    let mixed = continuum
        .clone()
        .try_with_lines(vec![(546.1, 300.0)])
        .unwrap();
    let r = |w: f64| 0.5 + 0.3 * (w / 40.0).cos();
    let expected = direct_1nm(Observer::Cie1964, &mixed, r);
    let i = SpectralIntegrator::new(Observer::Cie1964, &mixed, 1.0).unwrap();
    assert!(i.wavelengths_nm().contains(&546.1));
    assert_xyz_close(
        i.xyz(r),
        expected,
        1e-13,
        "mercury line on a flat continuum",
    );
    // The line makes the white greener than the bare continuum's.
    let bare = SpectralIntegrator::new(Observer::Cie1964, &continuum, 1.0).unwrap();
    let xy = |v: [f64; 3]| v[1] / (v[0] + v[1] + v[2]);
    assert!(xy(i.white_xyz()) > xy(bare.white_xyz()));
}

#[test]
fn samples_api_matches_closure_api() {
    let e = Illuminant::D65.spectrum();
    let i = SpectralIntegrator::new(Observer::Cie1931, &e, DEFAULT_STEP_NM).unwrap();
    let r = |w: f64| (w / 100.0).sin().abs();
    let samples: Vec<f64> = i.wavelengths_nm().iter().map(|&w| r(w)).collect();
    assert_eq!(i.xyz_from_samples(&samples), i.xyz(r));
    assert_eq!(i.weights().len(), i.wavelengths_nm().len());
}

proptest! {
    #[test]
    fn grey_reflector_scales_white(rho in 0.0f64..=1.0, step in 1.0f64..=50.0) {
        let e = Illuminant::A.spectrum();
        let i = SpectralIntegrator::new(Observer::Cie1931, &e, step).unwrap();
        let w = i.white_xyz();
        let xyz = i.xyz(|_| rho);
        for c in 0..3 {
            prop_assert!((xyz[c] - rho * w[c]).abs() <= 1e-14, "{xyz:?} vs {rho} × {w:?}");
        }
    }

    #[test]
    fn xyz_is_linear_in_reflectance(a in 0.0f64..2.0, b in 0.0f64..2.0, f in 5.0f64..60.0) {
        let e = Illuminant::F2.spectrum();
        let i = SpectralIntegrator::new(Observer::Cie1931, &e, DEFAULT_STEP_NM).unwrap();
        let r1 = |w: f64| (w / f).sin().powi(2);
        let r2 = |w: f64| w / 830.0;
        let lhs = i.xyz(|w| a * r1(w) + b * r2(w));
        let (x1, x2) = (i.xyz(r1), i.xyz(r2));
        for c in 0..3 {
            prop_assert!((lhs[c] - (a * x1[c] + b * x2[c])).abs() <= 1e-13);
        }
    }
}

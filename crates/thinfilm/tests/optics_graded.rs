//! Graded-index layers: a constant profile is the homogeneous layer, a linear ramp
//! converges at second order as slices double, the adaptive bound holds against a far finer
//! slicing, a CSV profile equals the ramp it tabulates, and Epstein's smooth step between
//! air and glass meets its published closed form.

mod optics_common;

use num_complex::Complex64;
use optics_common::assert_close;
use thinfilm::graded::{GradedLayer, Profile};
use thinfilm::{Incidence, Layer, OpticsError, Stack};

fn on_glass(layers: Vec<Layer>) -> Result<Stack, OpticsError> {
    let mut all = vec![Layer::new(1.38, 80.0)];
    all.extend(layers);
    Stack::new(1.0, all, 1.52)
}

#[test]
fn constant_profile_equals_the_homogeneous_layer() {
    let n = Complex64::new(2.1, 0.05);
    let flat = GradedLayer::try_new(Profile::Linear { front: n, back: n }, 333.0).unwrap();
    let table =
        GradedLayer::try_new(Profile::Table(vec![(0.0, n), (0.4, n), (1.0, n)]), 333.0).unwrap();
    let homogeneous = on_glass(vec![Layer::new(n, 333.0)]).unwrap();
    for angle in [0.0, 40.0, 80.0] {
        let incidence = Incidence::try_from_angle_deg(angle).unwrap();
        let expected = homogeneous.try_response_at(600.0, incidence).unwrap();
        for layer in [&flat, &table] {
            for count in [1, 7, 64] {
                let got = on_glass(layer.slices(count))
                    .unwrap()
                    .try_response_at(600.0, incidence)
                    .unwrap();
                assert_close("R_s", got.r_s, expected.r_s, 1e-12);
                assert_close("R_p", got.r_p, expected.r_p, 1e-12);
                assert_close("T_s", got.t_s, expected.t_s, 1e-12);
                assert_close("T_p", got.t_p, expected.t_p, 1e-12);
            }
        }
    }
}

#[test]
fn linear_ramp_converges_at_second_order() {
    // Errors against 8192 slices at N = 16 … 256: each doubling divides them by 4 (order
    // 2; measured 2.07, 2.015, 2.004, …; from N = 8 it is 2.38, not yet asymptotic).
    let ramp = GradedLayer::try_new(
        Profile::Linear {
            front: Complex64::new(1.2, 0.0),
            back: Complex64::new(2.4, 0.02),
        },
        700.0,
    )
    .unwrap();
    let incidence = Incidence::try_from_angle_deg(35.0).unwrap();
    let r = |count: usize| {
        on_glass(ramp.slices(count))
            .unwrap()
            .try_response_at(550.0, incidence)
            .unwrap()
            .r()
    };
    let reference = r(8192);
    let errors: Vec<f64> = [16, 32, 64, 128, 256]
        .iter()
        .map(|&n| (r(n) - reference).abs())
        .collect();
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!(
            (order - 2.0).abs() < 0.1,
            "observed order {order:.3} from errors {errors:?}"
        );
    }
}

#[test]
fn adaptive_bound_holds_against_a_far_finer_slicing() {
    let incidence = Incidence::try_from_angle_deg(20.0).unwrap();
    for (profile, d) in [
        (
            Profile::Linear {
                front: 1.0.into(),
                back: 1.52.into(),
            },
            400.0,
        ),
        (
            Profile::Exponential {
                front: 1.05,
                back: 2.3,
            },
            1200.0,
        ),
    ] {
        let layer = GradedLayer::try_new(profile, d).unwrap();
        for tolerance in [1e-6, 1e-9] {
            let out = layer
                .converged_response(on_glass, 500.0, incidence, tolerance)
                .unwrap();
            assert!(out.error_bound <= tolerance);
            let truth = on_glass(layer.slices(1 << 15))
                .unwrap()
                .try_response_at(500.0, incidence)
                .unwrap();
            let actual = (out.response.r() - truth.r())
                .abs()
                .max((out.response.t() - truth.t()).abs());
            assert!(
                actual <= 2.0 * tolerance,
                "tolerance {tolerance:e}: error {actual:e}, slices {}",
                out.slices
            );
        }
    }
}

#[test]
fn csv_profile_is_the_ramp_it_tabulates() {
    let (profile, d) =
        Profile::from_csv("z_nm,n,k\n0,1.2,0\n# middle\n250,1.8,0.01\n500,2.4,0.02\n").unwrap();
    assert_eq!(d, 500.0);
    let ramp = Profile::Linear {
        front: Complex64::new(1.2, 0.0),
        back: Complex64::new(2.4, 0.02),
    };
    for z in [0.0, 0.1, 0.5, 0.77, 1.0] {
        assert!(
            (profile.index_at(z) - ramp.index_at(z)).norm() < 1e-15,
            "z {z}"
        );
    }
    for (text, needle) in [
        ("z_nm,n,k\n0,1.2,0\n0,1.3,0\n", "line 3"),
        ("z_nm,n,k\n5,1.2,0\n9,1.3,0\n", "start at 0"),
        ("z_nm,n,k\n0,1.2,0\n9,-1.3,0\n", "-1.3"),
        ("z_nm,n,k\n0,1.2,0\n9,x,0\n", "`x`"),
        ("z_nm,n,k\n0,1.2,0\n", "two rows"),
    ] {
        let err = Profile::from_csv(text).unwrap_err().to_string();
        assert!(err.contains(needle), "{err:?} lacks {needle:?}");
    }
}

#[test]
fn bad_tolerance_and_unreachable_tolerance_are_errors() {
    let layer = GradedLayer::try_new(
        Profile::Linear {
            front: 1.0.into(),
            back: 3.0.into(),
        },
        5000.0,
    )
    .unwrap();
    let err = layer
        .converged_response(on_glass, 500.0, Incidence::NORMAL, f64::NAN)
        .unwrap_err();
    assert!(err.to_string().contains("NaN"), "{err}");
    let err = layer
        .converged_response(on_glass, 500.0, Incidence::NORMAL, 1e-30)
        .unwrap_err();
    assert!(err.to_string().contains("not converged"), "{err}");
    let err = GradedLayer::try_new(
        Profile::Exponential {
            front: 0.0,
            back: 1.0,
        },
        10.0,
    )
    .unwrap_err();
    assert!(err.to_string().contains("profile front"), "{err}");
}

/// Exact normal-incidence reflectance of `n0 | reciprocal profile (front → back, d) | ns`.
///
/// With `n(z) = 1/u`, `u = a + b z`, the wave equation `E'' + k² n² E = 0` is the
/// Cauchy–Euler equation `u² E_uu + (k/b)² E = 0`, solved by `u^m` with
/// `m = ½ ± √(¼ − (k/b)²)`. With `F = E'/(ik)` (`F = ±n E` for a plane wave), the substrate
/// gives `E(d) = 1`, `F(d) = ns`; the two solutions carry that to `z = 0`, where
/// `r = (n0 E − F)/(n0 E + F)`.
fn reciprocal_exact(n0: f64, front: f64, back: f64, d: f64, ns: f64, wavelength_nm: f64) -> f64 {
    let k = std::f64::consts::TAU / wavelength_nm;
    let (a, b) = (1.0 / front, (1.0 / back - 1.0 / front) / d);
    let root = Complex64::new(0.25 - (k / b).powi(2), 0.0).sqrt();
    let ms = [0.5 + root, 0.5 - root];
    let ik = Complex64::new(0.0, k);
    let phi = |m: Complex64, u: f64| Complex64::new(u, 0.0).powc(m);
    let dphi = |m: Complex64, u: f64| m * b * Complex64::new(u, 0.0).powc(m - 1.0) / ik;
    let (ud, u0) = (a + b * d, a);
    // c1 φ1(d) + c2 φ2(d) = 1, c1 φ1'(d)/(ik) + c2 φ2'(d)/(ik) = ns.
    let (p1, p2, q1, q2) = (
        phi(ms[0], ud),
        phi(ms[1], ud),
        dphi(ms[0], ud),
        dphi(ms[1], ud),
    );
    let det = p1 * q2 - p2 * q1;
    let c1 = (q2 - p2 * ns) / det;
    let c2 = (p1 * ns - q1) / det;
    let e0 = c1 * phi(ms[0], u0) + c2 * phi(ms[1], u0);
    let f0 = c1 * dphi(ms[0], u0) + c2 * dphi(ms[1], u0);
    ((n0 * e0 - f0) / (n0 * e0 + f0)).norm_sqr()
}

#[test]
fn reciprocal_profile_converges_to_its_closed_form() {
    // Air | 1/n linear from 1.2 to 2.4 over 600 nm | 1.5 at 500 nm: the adaptive result
    // is within its bound of the Cauchy–Euler solution, and plain slicing converges to it
    // at second order.
    let (front, back, d, ns, l) = (1.2, 2.4, 600.0, 1.5, 500.0);
    let exact = reciprocal_exact(1.0, front, back, d, ns, l);
    let layer = GradedLayer::try_new(Profile::Reciprocal { front, back }, d).unwrap();
    let stack = |layers: Vec<Layer>| Stack::new(1.0, layers, ns);
    let out = layer
        .converged_response(stack, l, Incidence::NORMAL, 1e-10)
        .unwrap();
    assert!(
        (out.response.r() - exact).abs() <= 2.0 * 1e-10,
        "R {} vs exact {exact}, bound {:e}",
        out.response.r(),
        out.error_bound
    );
    let r = |count: usize| {
        stack(layer.slices(count))
            .unwrap()
            .try_response_at(l, Incidence::NORMAL)
            .unwrap()
            .r()
    };
    let errors: Vec<f64> = [32, 64, 128, 256]
        .iter()
        .map(|&n| (r(n) - exact).abs())
        .collect();
    eprintln!(
        "exact R {exact}, adaptive {} ({} slices, bound {:e}), errors {errors:?}",
        out.response.r(),
        out.slices,
        out.error_bound
    );
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!(
            (order - 2.0).abs() < 0.1,
            "order {order:.3} from {errors:?}"
        );
    }
    // Sanity of the closed form itself: a constant profile is the homogeneous layer.
    let flat = reciprocal_exact(1.0, 1.7, 1.7 * (1.0 + 1e-9), d, ns, l);
    let homogeneous = Stack::new(1.0, vec![Layer::new(1.7, d)], ns)
        .unwrap()
        .try_response(l, 1.0)
        .unwrap()
        .r();
    assert!((flat - homogeneous).abs() < 1e-6, "{flat} vs {homogeneous}");
}

/// Epstein's smooth step, `n²(z) = n₁² + (n₂² − n₁²) / (1 + e^{−αz})`, tabulated over
/// `|z| ≤ L` with `e^{−αL} = e^{−24}` (the cut ends add a jump of 4e-11 in `n²`).
fn epstein_table(n1: f64, n2: f64, alpha_per_nm: f64, rows: usize) -> (Profile, f64) {
    let half_nm = 24.0 / alpha_per_nm;
    let table = (0..rows)
        .map(|k| {
            let frac = k as f64 / (rows - 1) as f64;
            let z = -half_nm + 2.0 * half_nm * frac;
            let eps = n1 * n1 + (n2 * n2 - n1 * n1) / (1.0 + (-alpha_per_nm * z).exp());
            (frac, Complex64::from(eps.sqrt()))
        })
        .collect();
    (Profile::Table(table), 2.0 * half_nm)
}

/// The published closed form for that step at normal incidence (Epstein, PNAS 16, 627,
/// 1930; Landau & Lifshitz, Quantum Mechanics, §25 problem 2, for the Schrödinger equation
/// the Helmholtz equation becomes): `R = [sinh(π(k₁ − k₂)/α) / sinh(π(k₁ + k₂)/α)]²`.
fn epstein_exact(n1: f64, n2: f64, alpha_per_nm: f64, wavelength_nm: f64) -> f64 {
    let k0 = std::f64::consts::TAU / wavelength_nm;
    let x = std::f64::consts::PI * k0 / alpha_per_nm;
    ((x * (n1 - n2)).sinh() / (x * (n1 + n2)).sinh()).powi(2)
}

#[test]
fn epsteins_smooth_step_from_air_to_glass_meets_its_closed_form() {
    // Steps 0.05 to 0.5 wave wide (10–90 % of n² over that optical width at 550 nm,
    // `Δz = 2 ln 9 / α`): the quarter-wave one cuts the glass's Fresnel 4.26 % to 1.06 %.
    // The layer is the step tabulated (linear between rows) and sliced until converged to
    // 1e-9; its remaining difference from the closed form is the table's, O(rows⁻²): it
    // must fall about fourfold from 2001 to 4001 rows and stay within 1e-5 of the Fresnel R.
    let (n1, n2, wavelength_nm): (f64, f64, f64) = (1.0, 1.52, 550.0);
    let fresnel = ((n2 - n1) / (n2 + n1)).powi(2);
    let mean_n = 0.5 * (n1 + n2);
    for optical_width in [0.05, 0.125, 0.25, 0.5] {
        let width_nm = optical_width * wavelength_nm / mean_n;
        let alpha = 2.0 * 9f64.ln() / width_nm;
        let exact = epstein_exact(n1, n2, alpha, wavelength_nm);
        assert!(
            exact < fresnel,
            "a gradual step reflects less than a sharp one"
        );
        let error = |rows: usize| {
            let (profile, thickness_nm) = epstein_table(n1, n2, alpha, rows);
            let layer = GradedLayer::try_new(profile, thickness_nm).unwrap();
            let stack = |layers| Stack::new(n1, layers, n2);
            let got =
                (layer.converged_response(stack, wavelength_nm, Incidence::NORMAL, 1e-9)).unwrap();
            got.response.r() - exact
        };
        let (coarse, fine) = (error(2001), error(4001));
        println!(
            "width λ×{optical_width}: exact R {exact:.6e} (Fresnel {fresnel:.4e}); table error \
             {coarse:.2e} at 2001 rows, {fine:.2e} at 4001"
        );
        assert!(
            fine.abs() <= 1e-5 * fresnel,
            "λ×{optical_width}: {fine:e} off {exact:e}"
        );
        let ratio = coarse / fine;
        assert!(
            (3.0..5.0).contains(&ratio),
            "λ×{optical_width}: the table error fell by {ratio}, not about 4"
        );
    }
}

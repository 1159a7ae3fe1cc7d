//! `stack_grid::StackGrid` (the real characteristic-matrix kernel and Rouard's recursion)
//! against the transfer matrix of `Stack`, point by point: random stacks with absorbing,
//! evanescent and thick layers, every polarisation, grazing incidence; energy
//! conservation; a Bragg mirror against its closed form; and the general path for
//! dispersive and incoherent stacks.

mod optics_common;

use num_complex::Complex64;
use optics_common::assert_close;
use proptest::prelude::*;
use thinfilm::grid::Polarisation;
use thinfilm::stack_grid::StackGrid;
use thinfilm::{Incidence, Layer, OpticsError, RefractiveIndex, Stack};

const POLS: [Polarisation; 3] = [Polarisation::S, Polarisation::P, Polarisation::Unpolarised];

fn filled(grid: &StackGrid, pol: Polarisation) -> (Vec<f64>, Vec<f64>) {
    let (mut r, mut t) = (vec![f64::NAN; grid.len()], vec![f64::NAN; grid.len()]);
    grid.try_fill(pol, &mut r, &mut t).unwrap();
    (r, t)
}

fn pick(pol: Polarisation, resp: &thinfilm::fresnel::Response) -> (f64, f64) {
    match pol {
        Polarisation::S => (resp.r_s, resp.t_s),
        Polarisation::P => (resp.r_p, resp.t_p),
        Polarisation::Unpolarised => (resp.r(), resp.t()),
    }
}

/// The stack with every thickness scaled by `scale`.
fn scaled(stack: &Stack, scale: f64) -> Stack {
    let mut out = stack.clone();
    for layer in &mut out.layers {
        layer.thickness_nm *= scale;
    }
    out
}

/// Every grid point against the transfer matrix. The two round each phase differently
/// (a few ε δ), which moves R by ε δ dR/dδ where fringes are sharp, so the tolerance
/// carries the condition number `|s dR/ds|` for a scale `s` of every thickness, by
/// central differences.
fn check_against_matrix(stack: &Stack, angles: &[f64], wavelengths: &[f64]) {
    let grid = StackGrid::try_new(stack, angles, wavelengths).unwrap();
    let h = 1e-6;
    let (up, down) = (scaled(stack, 1.0 + h), scaled(stack, 1.0 - h));
    for pol in POLS {
        let (r, t) = filled(&grid, pol);
        for (a, &angle) in angles.iter().enumerate() {
            let incidence = Incidence::try_from_angle_deg(angle).unwrap();
            for (w, &wavelength) in wavelengths.iter().enumerate() {
                let at = |s: &Stack| pick(pol, &s.try_response_at(wavelength, incidence).unwrap());
                let ((r_ref, t_ref), (r_up, t_up), (r_down, t_down)) =
                    (at(stack), at(&up), at(&down));
                let kr = (r_up - r_down).abs() / (2.0 * h);
                let kt = (t_up - t_down).abs() / (2.0 * h);
                let k = a * wavelengths.len() + w;
                let label = format!("{pol:?} at {angle}°, {wavelength} nm");
                assert_close(&label, r[k], r_ref, 1e-13 + 64.0 * f64::EPSILON * kr);
                assert_close(&label, t[k], t_ref, 1e-13 + 64.0 * f64::EPSILON * kt);
            }
        }
    }
}

fn index() -> impl Strategy<Value = Complex64> {
    prop_oneof![
        (1.0..3.5f64).prop_map(Complex64::from),
        (0.1..4.0f64, 0.0..5.0f64).prop_map(|(n, k)| Complex64::new(n, k)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn grid_equals_the_transfer_matrix(
        n_incident in 1.0..2.2f64,
        layers in prop::collection::vec((index(), 0.0..3000.0f64), 0..7),
        substrate in index(),
        angles in prop::collection::vec(0.0..=90.0f64, 1..4),
        wavelengths in prop::collection::vec(300.0..1600.0f64, 1..9),
    ) {
        let layers = layers.into_iter().map(|(n, d)| Layer::new(n, d)).collect();
        let stack = Stack::new(n_incident, layers, substrate).unwrap();
        check_against_matrix(&stack, &angles, &wavelengths);
    }

    #[test]
    fn lossless_grid_conserves_energy(
        n_incident in 1.0..2.2f64,
        above_critical in prop::collection::vec((0.001..2.5f64, 0.0..3000.0f64), 0..7),
        substrate in 1.0..3.5f64,
        angle in 0.0..=90.0f64,
    ) {
        // Every layer's index exceeds n0 sin θ: a layer past its critical angle can couple
        // a guided mode whose stored field multiplies every rounding error (both methods
        // then miss R + T = 1 by up to 1e-12 near it); `grid_equals_the_transfer_matrix`
        // covers such stacks against the matrix instead.
        let n_sin = n_incident * angle.to_radians().sin();
        let layers = (above_critical.into_iter())
            .map(|(extra, d)| Layer::lossless(n_sin.max(1.0) + extra, d))
            .collect();
        let stack = Stack::new(n_incident, layers, substrate).unwrap();
        let wavelengths: Vec<f64> = (0..64).map(|k| 360.0 + 7.3 * k as f64).collect();
        let grid_of = |s: &Stack| StackGrid::try_new(s, &[angle], &wavelengths).unwrap();
        let h = 1e-6;
        let (grid, up, down) = (grid_of(&stack), grid_of(&scaled(&stack, 1.0 + h)), grid_of(&scaled(&stack, 1.0 - h)));
        for pol in POLS {
            let ((r, t), (r_up, _), (r_down, _)) = (filled(&grid, pol), filled(&up, pol), filled(&down, pol));
            for k in 0..r.len() {
                // Rounding the phases moves a sharp fringe: R + T = 1 then holds to ε times
                // the condition number.
                let kappa = (r_up[k] - r_down[k]).abs() / (2.0 * h);
                assert_close("R + T", r[k] + t[k], 1.0, 1e-13 + 64.0 * f64::EPSILON * kappa);
            }
        }
    }
}

#[test]
fn colour_science_bench_stack_matches_the_matrix_on_its_whole_grid() {
    // The 5-layer stack of bench/vs_colour_multilayer.py on its λ × angle grid.
    let layers = [
        (1.38, 100.0),
        (2.1, 60.0),
        (1.46, 90.0),
        (2.1, 60.0),
        (1.38, 100.0),
    ]
    .map(|(n, d)| Layer::lossless(n, d))
    .to_vec();
    let stack = Stack::new(1.0, layers, 1.52).unwrap();
    let wavelengths: Vec<f64> = (360..=830).map(f64::from).collect();
    let angles: Vec<f64> = (0..=10).map(|k| 7.5 * k as f64).collect();
    check_against_matrix(&stack, &angles, &wavelengths);
}

#[test]
fn frustrated_total_reflection_and_a_thick_metal_are_exact() {
    // Glass prism, an air gap past the critical angle, a guiding layer, air: the gap is
    // evanescent; then a metal film thick enough that its decay underflows.
    let gap = Stack::new(
        1.5,
        vec![Layer::lossless(1.0, 300.0), Layer::lossless(2.0, 400.0)],
        1.0,
    )
    .unwrap();
    let angles: Vec<f64> = (0..=90).map(f64::from).collect();
    let wavelengths = [400.0, 550.0, 633.0, 1064.0];
    check_against_matrix(&gap, &angles, &wavelengths);
    let metal = Stack::new(1.0, vec![Layer::new(Complex64::new(0.2, 3.4), 1e6)], 1.52).unwrap();
    check_against_matrix(&metal, &[0.0, 60.0, 90.0], &wavelengths);
}

#[test]
fn dispersive_and_incoherent_stacks_take_the_exact_path() {
    let water = RefractiveIndex::Water;
    let dispersive = Stack::new(1.0, vec![Layer::new(water, 500.0)], 1.52).unwrap();
    check_against_matrix(&dispersive, &[0.0, 45.0], &[400.0, 500.0, 700.0]);
    let slide = Stack::new(
        1.0,
        vec![Layer::lossless(1.33, 300.0), Layer::incoherent(1.52, 1e6)],
        1.0,
    )
    .unwrap();
    check_against_matrix(&slide, &[0.0, 30.0, 89.0], &[400.0, 500.0, 700.0]);
}

#[test]
fn bad_wavelengths_angles_and_lengths_are_named() {
    let stack = Stack::new(1.0, vec![Layer::lossless(1.38, 100.0)], 1.52).unwrap();
    let err = StackGrid::try_new(&stack, &[0.0], &[550.0, -1.0]).unwrap_err();
    assert!(matches!(err, OpticsError::Wavelength { wavelength_nm } if wavelength_nm == -1.0));
    let err = StackGrid::try_new(&stack, &[91.0], &[550.0]).unwrap_err();
    assert!(err.to_string().contains("91"), "{err}");
    let err = StackGrid::try_new(&stack, &[0.0], &[50.0]).unwrap_err();
    assert!(err.to_string().contains("50"), "{err}");
    let grid = StackGrid::try_new(&stack, &[0.0, 10.0], &[550.0, 600.0]).unwrap();
    let (mut r, mut t) = (vec![0.0; 3], vec![0.0; 4]);
    let err = grid.try_fill(Polarisation::S, &mut r, &mut t).unwrap_err();
    assert!(err.to_string().contains('3'), "{err}");
    let (mut r, mut t) = (vec![0.0; 2], vec![0.0; 2]);
    assert!(
        grid.try_fill_row(2, Polarisation::S, &mut r, &mut t)
            .is_err()
    );
}

#[test]
fn spans_of_a_row_fill_what_the_row_fills() {
    let layers = vec![
        Layer::lossless(1.38, 100.0),
        Layer::new(Complex64::new(0.2, 3.0), 20.0),
    ];
    let stack = Stack::new(1.0, layers, 1.52).unwrap();
    let wavelengths: Vec<f64> = (0..37).map(|k| 380.0 + 11.0 * k as f64).collect();
    let grid = StackGrid::try_new(&stack, &[0.0, 50.0, 90.0], &wavelengths).unwrap();
    for pol in POLS {
        let (whole_r, whole_t) = filled(&grid, pol);
        for angle in 0..3 {
            let (mut r, mut t) = (vec![0.0; 37], vec![0.0; 37]);
            for (k, (r, t)) in r.chunks_mut(8).zip(t.chunks_mut(8)).enumerate() {
                grid.try_fill_span(angle, 8 * k, pol, r, t).unwrap();
            }
            assert_eq!(r, whole_r[37 * angle..37 * (angle + 1)]);
            assert_eq!(t, whole_t[37 * angle..37 * (angle + 1)]);
        }
    }
    let (mut r, mut t) = (vec![0.0; 8], vec![0.0; 8]);
    let err = grid
        .try_fill_span(0, 30, Polarisation::S, &mut r, &mut t)
        .unwrap_err();
    assert!(err.to_string().contains("38"), "{err}");
}

#[test]
fn a_quarter_wave_bragg_mirror_reflects_as_its_closed_form() {
    // (HL)⁶H at its design wavelength: each quarter-wave layer maps an admittance Y to
    // n²/Y, so the stack presents Y = (n_H/n_L)^12 n_H²/n_s and R = ((n₀ − Y)/(n₀ + Y))²
    // (Macleod, Thin-Film Optical Filters, §6.1). Its layers repeat two phases, which the
    // grid tabulates once each.
    let (n_h, n_l, n_s, design_nm) = (2.3, 1.38, 1.52, 550.0);
    let quarter = |n: f64| Layer::lossless(n, design_nm / (4.0 * n));
    let mut layers = Vec::new();
    for _ in 0..6 {
        layers.extend([quarter(n_h), quarter(n_l)]);
    }
    layers.push(quarter(n_h));
    let stack = Stack::new(1.0, layers, n_s).unwrap();
    let grid = StackGrid::try_new(&stack, &[0.0], &[500.0, design_nm, 600.0]).unwrap();
    let y = (n_h / n_l).powi(12) * n_h * n_h / n_s;
    let expected = ((1.0 - y) / (1.0 + y)).powi(2);
    for pol in POLS {
        let (r, t) = filled(&grid, pol);
        assert_close(&format!("{pol:?} R"), r[1], expected, 1e-13);
        assert_close(&format!("{pol:?} T"), t[1], 1.0 - expected, 1e-13);
    }
    let wavelengths: Vec<f64> = (400..=700).step_by(3).map(f64::from).collect();
    check_against_matrix(&stack, &[0.0, 20.0, 45.0, 70.0], &wavelengths);
}

#[test]
fn a_layer_too_thick_for_the_polynomial_sine_is_exact() {
    // 5 cm of glass: its phase at 360 nm (1.3e6 rad) is past the polynomial's range, so
    // its sine and cosine come from libm; beside it, a thin layer takes the polynomial.
    let layers = vec![Layer::lossless(1.38, 120.0), Layer::lossless(1.5, 5e7)];
    let stack = Stack::new(1.0, layers, 1.33).unwrap();
    check_against_matrix(&stack, &[0.0, 30.0], &[360.0, 361.0, 500.0, 830.0]);
}

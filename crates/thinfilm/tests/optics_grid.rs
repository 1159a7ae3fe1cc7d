//! `grid::FilmGrid` (closed-form symmetric film) against the transfer matrix and the Airy
//! sum, point by point, including evanescent films and grazing incidence.

mod optics_common;

use optics_common::assert_close;
use proptest::prelude::*;
use thinfilm::grid::{FilmGrid, Polarisation};
use thinfilm::{Incidence, Layer, OpticsError, Stack, ThinFilm};

fn grid_point(
    n_out: f64,
    n_film: f64,
    d: f64,
    angle: f64,
    l: f64,
    pol: Polarisation,
) -> (f64, f64) {
    let grid = FilmGrid::try_new(n_out, n_film, &[angle], &[l]).unwrap();
    let (mut r, mut t) = ([0.0], [0.0]);
    grid.try_fill(d, pol, &mut r, &mut t).unwrap();
    (r[0], t[0])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn grid_equals_the_transfer_matrix(
        n_out in 1.0..1.6f64, n_film in 0.8..3.5f64, d in 0.0..5000.0f64,
        angle in 0.0..=90.0f64, l in 300.0..1600.0f64,
    ) {
        let incidence = Incidence::try_from_angle_deg(angle).unwrap();
        let tmm = |d: f64| {
            let stack = Stack::new(n_out, vec![Layer::new(n_film, d)], n_out).unwrap();
            stack.try_response_at(l, incidence).unwrap()
        };
        let resp = tmm(d);
        // The phase β ∝ d rounds differently in the two methods (a few ε β): near grazing,
        // where fringes are sharp, that moves R by ε β dR/dβ, so the tolerance carries the
        // condition number κ = |β dR/dβ| = |d dR/dd|, by central differences.
        let h = 1e-6;
        let (up, down) = (tmm(d * (1.0 + h)), tmm(d * (1.0 - h)));
        let kappa = |f: fn(&thinfilm::fresnel::Response) -> f64| (f(&up) - f(&down)).abs() / (2.0 * h);
        for (pol, r_ref, t_ref, kr, kt) in [
            (Polarisation::S, resp.r_s, resp.t_s, kappa(|x| x.r_s), kappa(|x| x.t_s)),
            (Polarisation::P, resp.r_p, resp.t_p, kappa(|x| x.r_p), kappa(|x| x.t_p)),
            (Polarisation::Unpolarised, resp.r(), resp.t(), kappa(|x| x.r()), kappa(|x| x.t())),
        ] {
            let (r, t) = grid_point(n_out, n_film, d, angle, l, pol);
            assert_close("R vs TMM", r, r_ref, 1e-13 + 16.0 * f64::EPSILON * kr);
            assert_close("T vs TMM", t, t_ref, 1e-13 + 16.0 * f64::EPSILON * kt);
            // R and T each carry a few ulp of rounding, so their sum does too: a full run
            // drew 1 − (R + T) = 1.55e-15 (7 ε), past the 1e-15 first chosen here.
            assert_close("R + T", r + t, 1.0, 16.0 * f64::EPSILON);
        }
    }
}

#[test]
fn a_whole_grid_equals_the_airy_sum_point_by_point() {
    let angles: Vec<f64> = (0..=12).map(|k| 7.5 * k as f64).collect();
    let wavelengths: Vec<f64> = (360..=830).step_by(7).map(f64::from).collect();
    let grid = FilmGrid::try_new(1.0, 1.33, &angles, &wavelengths).unwrap();
    let mut r = vec![0.0; grid.len()];
    let mut t = vec![0.0; grid.len()];
    let mut worst = 0.0f64;
    for d in (0..=2000).step_by(10).map(f64::from) {
        grid.try_fill(d, Polarisation::Unpolarised, &mut r, &mut t)
            .unwrap();
        for (a, &angle) in angles.iter().enumerate() {
            for (w, &l) in wavelengths.iter().enumerate() {
                let incidence = Incidence::try_from_angle_deg(angle).unwrap();
                let film = ThinFilm::soap(d).try_response_at(l, incidence).unwrap();
                let k = a * wavelengths.len() + w;
                worst = worst
                    .max((r[k] - film.r()).abs())
                    .max((t[k] - film.t()).abs());
            }
        }
    }
    // Measured 1.1e-14: the phase rounds differently (β/nm · d against 2π d q / λ).
    assert!(worst < 1e-13, "worst |diff| {worst:e}");
}

#[test]
fn bad_inputs_are_errors_naming_the_value() {
    let err = |e: OpticsError| e.to_string();
    let e = FilmGrid::try_new(1.0, 1.33, &[0.0, 95.0], &[550.0]).unwrap_err();
    assert!(err(e.clone()).contains("95"), "{e}");
    let e = FilmGrid::try_new(1.0, 1.33, &[0.0], &[550.0, 50.0]).unwrap_err();
    assert!(err(e.clone()).contains("50"), "{e}");
    let e = FilmGrid::try_new(1.0, f64::NAN, &[0.0], &[550.0]).unwrap_err();
    assert!(err(e.clone()).contains("NaN"), "{e}");
    let grid = FilmGrid::try_new(1.0, 1.33, &[0.0], &[550.0]).unwrap();
    let (mut r, mut t) = ([0.0], [0.0]);
    let e = grid
        .try_fill(-5.0, Polarisation::S, &mut r, &mut t)
        .unwrap_err();
    assert!(err(e.clone()).contains("-5"), "{e}");
    let e = grid
        .try_fill(5.0, Polarisation::S, &mut r, &mut [0.0; 2])
        .unwrap_err();
    assert!(err(e.clone()).contains("t has 2"), "{e}");
}

#[test]
fn films_beyond_the_kernels_phase_range_take_libm_and_still_agree() {
    // β = 2π · 1.33 · 1e8 / 500 ≈ 1.7e6 > 8e5: the scalar path. The phase itself rounds
    // differently by ~β ε ≈ 4e-10 between the two computations, hence the tolerance.
    for d in [1e8, 3.3e8] {
        let (r, t) = grid_point(1.0, 1.33, d, 30.0, 500.0, Polarisation::Unpolarised);
        let incidence = Incidence::try_from_angle_deg(30.0).unwrap();
        let film = ThinFilm::soap(d).try_response_at(500.0, incidence).unwrap();
        assert_close("R", r, film.r(), 1e-8);
        assert_close("T", t, film.t(), 1e-8);
    }
}

/// Worst `|R − R_exact|` and `|T − T_exact|` of the f32 fill over the fast-path sweep, for
/// films up to 5 µm and for thicker ones (to 0.1 mm): soap, low-index (evanescent beyond
/// its critical angle) and high-index films, outside media 1 and 1.33, angles to 90°,
/// 300–1600 nm, every polarisation.
fn worst_fast_errors() -> (f64, f64) {
    let angles: Vec<f64> = (0..=60)
        .map(|k| 1.5 * k as f64)
        .chain([89.0, 89.5, 89.9, 90.0])
        .collect();
    let wavelengths: Vec<f64> = (0..=130).map(|k| 300.0 + 10.0 * k as f64 + 0.37).collect();
    let thicknesses: Vec<f64> = (0..=200)
        .map(|k| 25.0 * k as f64 + 0.3)
        .chain((0..=20).map(|k| 5e3 * 1.22f64.powi(k)))
        .chain([0.0, 1e5])
        .collect();
    let (mut thin, mut thick) = (0.0f64, 0.0f64);
    let films = [
        (1.0, 1.33),
        (1.0, 1.05),
        (1.0, 2.4),
        (1.0, 3.9),
        (1.33, 1.0),
        (1.5, 1.2),
    ];
    for (n_out, n_film) in films {
        let grid = FilmGrid::try_new(n_out, n_film, &angles, &wavelengths).unwrap();
        let n = grid.len();
        let (mut r, mut t) = (vec![0.0; n], vec![0.0; n]);
        let (mut r_fast, mut t_fast) = (vec![0.0; n], vec![0.0; n]);
        for &d in &thicknesses {
            let worst = if d <= 5e3 { &mut thin } else { &mut thick };
            for pol in [Polarisation::S, Polarisation::P, Polarisation::Unpolarised] {
                grid.try_fill(d, pol, &mut r, &mut t).unwrap();
                grid.try_fill_cells_fast(d, 0, pol, &mut r_fast, &mut t_fast)
                    .unwrap();
                for k in 0..n {
                    *worst = worst
                        .max((r_fast[k] - r[k]).abs())
                        .max((t_fast[k] - t[k]).abs());
                }
            }
        }
    }
    (thin, thick)
}

#[test]
fn the_fast_fill_is_within_its_bound_of_the_exact_fill() {
    let (thin, thick) = worst_fast_errors();
    eprintln!("worst |fast − exact|: {thin:e} to 5 µm, {thick:e} to 0.1 mm");
    // Measured 2.4e-7 and 1.8e-6: the f32 arithmetic, then the phase's rounding (about
    // q·d·2^-36 periods) times the fringes' slope, which thick films feel.
    assert!(thin < 5e-7, "worst |fast − exact| to 5 µm = {thin:e}");
    assert!(thick < 4e-6, "worst |fast − exact| to 0.1 mm = {thick:e}");
    // The fast fill is the f32 kernel, not the exact fill under another name.
    assert!(thin > 1e-10, "worst |fast − exact| to 5 µm = {thin:e}");
}
#[test]
fn the_fast_fill_of_part_of_a_grid_equals_its_whole_fill_there() {
    let angles = [0.0, 40.0, 89.95, 90.0];
    let wavelengths: Vec<f64> = (400..=700).step_by(3).map(f64::from).collect();
    let grid = FilmGrid::try_new(1.33, 1.0, &angles, &wavelengths).unwrap();
    let (mut r, mut t) = (vec![0.0; grid.len()], vec![0.0; grid.len()]);
    grid.try_fill_cells_fast(640.0, 0, Polarisation::P, &mut r, &mut t)
        .unwrap();
    let (first, len) = (wavelengths.len() + 7, 2 * wavelengths.len());
    let (mut r_part, mut t_part) = (vec![0.0; len], vec![0.0; len]);
    grid.try_fill_cells_fast(640.0, first, Polarisation::P, &mut r_part, &mut t_part)
        .unwrap();
    assert_eq!(r_part, r[first..first + len]);
    assert_eq!(t_part, t[first..first + len]);
    let e = grid
        .try_fill_cells_fast(
            640.0,
            first,
            Polarisation::P,
            &mut vec![0.0; grid.len()],
            &mut vec![0.0; grid.len()],
        )
        .unwrap_err();
    assert!(e.to_string().contains("cells from first"), "{e}");
}

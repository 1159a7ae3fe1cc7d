//! Wave physics: ripple heights, phase speeds against the dispersion relation's closed
//! forms, superposition, and the tabulated grid path against exact evaluation.

use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, TAU};
use water::{
    GRAVITY_M_PER_S2, Grid, Perturbation, Ripple, Surface, WATER_DENSITY_KG_PER_M3,
    WATER_SURFACE_TENSION_N_PER_M, Wave, deep_water_omega_rad_per_s,
};

fn assert_close(what: &str, got: f64, want: f64, tol: f64) {
    let diff = (got - want).abs();
    assert!(
        diff <= tol,
        "{what}: got {got}, want {want}, off by {diff} (tolerance {tol})"
    );
}

#[test]
fn ripple_height_at_its_centre_is_a_sin_of_minus_omega_t_faded() {
    let r = Ripple::try_new(0.01, 0.2, [0.3, -0.2], None, [2.0, 0.5]).unwrap();
    let p = Perturbation::Ripple(r);
    for t in [0.0f64, 0.1, 0.37, 1.3] {
        let want = 0.01 * (-0.5 * t).exp() * (-r.omega_rad_per_s() * t).sin();
        assert_close("centre height", p.height_m(0.3, -0.2, t), want, 1e-15);
    }
}

#[test]
fn ripple_crest_reaches_the_faded_amplitude() {
    let r = Ripple::try_new(0.02, 0.1, [0.0, 0.0], None, [3.0, 0.2]).unwrap();
    let p = Perturbation::Ripple(r);
    let t = 0.4;
    // Crest: k r − ω t = π/2 + 2π n, for the first n with r > 0.
    let n = ((r.omega_rad_per_s() * t - FRAC_PI_2) / TAU).floor() + 1.0;
    let crest_r = (FRAC_PI_2 + TAU * n + r.omega_rad_per_s() * t) / r.k_per_m();
    let want = 0.02 * (-3.0 * crest_r - 0.2 * t).exp();
    let (x, z) = (crest_r * 0.6, crest_r * 0.8);
    assert_close("crest height", p.height_m(x, z, t), want, 1e-15);
    // Nearby along r the surface is lower (the fade shifts the true maximum by atan(α/k)/k ≈ 0.8 mm).
    let dr = 4e-4;
    let at = |r: f64| p.height_m(r * 0.6, r * 0.8, t);
    assert!(at(crest_r) > at(crest_r - 10.0 * dr) && at(crest_r) > at(crest_r + 10.0 * dr));
}

/// Position of the up-crossing of `y(x, 0, t) = 0` nearest `x0`, by bisection.
fn up_crossing(p: &Perturbation, x0: f64, half_width: f64, t: f64) -> f64 {
    let (mut lo, mut hi) = (x0 - half_width, x0 + half_width);
    assert!(p.height_m(lo, 0.0, t) < 0.0 && p.height_m(hi, 0.0, t) > 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if p.height_m(mid, 0.0, t) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn a_one_second_deep_water_wave_is_1_56_m_long_and_runs_at_1_56_m_per_s() {
    // Deep-water gravity waves: λ = g T² / 2π, c = g T / 2π (capillary term ~1e-4 here).
    let period_s = 1.0;
    let wavelength_m = GRAVITY_M_PER_S2 * period_s * period_s / TAU;
    let wave = Wave::try_new(0.05, wavelength_m, [1.0, 0.0], None).unwrap();
    assert_close(
        "period",
        TAU / wave.omega_rad_per_s(),
        period_s,
        2e-4 * period_s,
    );
    let p = Perturbation::Wave(wave);
    let dt = 0.05;
    let x0 = up_crossing(&p, 0.0, 0.2 * wavelength_m, 0.0);
    let x1 = up_crossing(&p, x0 + 1.5 * dt, 0.2 * wavelength_m, dt);
    let speed = (x1 - x0) / dt;
    let want = GRAVITY_M_PER_S2 * period_s / TAU;
    assert_close("phase speed m/s", speed, want, 2e-4 * want);
}

#[test]
fn capillary_gravity_phase_speed_has_its_closed_form_minimum() {
    // c(k) = ω/k is least at k = √(ρg/σ), where c = (4 g σ / ρ)^¼ ≈ 0.231 m/s.
    let (g, s, rho) = (
        GRAVITY_M_PER_S2,
        WATER_SURFACE_TENSION_N_PER_M,
        WATER_DENSITY_KG_PER_M3,
    );
    let want_c = (4.0 * g * s / rho).powf(0.25);
    let want_wavelength = TAU * (s / (rho * g)).sqrt();
    let (mut best_c, mut best_wavelength) = (f64::INFINITY, 0.0);
    for i in 1..4000 {
        let wavelength = 1e-3 + 1e-5 * i as f64;
        let k = TAU / wavelength;
        let c = deep_water_omega_rad_per_s(k) / k;
        if c < best_c {
            (best_c, best_wavelength) = (c, wavelength);
        }
    }
    assert_close("minimum phase speed", best_c, want_c, 1e-6);
    assert_close(
        "wavelength at minimum",
        best_wavelength,
        want_wavelength,
        2e-5,
    );
    assert!((0.230..0.232).contains(&best_c), "c_min {best_c}");
}

#[test]
fn a_ripple_crest_moves_outwards_at_the_phase_speed() {
    let r = Ripple::try_new(0.01, 0.05, [0.0, 0.0], None, [0.0, 0.0]).unwrap();
    let p = Perturbation::Ripple(r);
    let dt = 0.01;
    let c = r.omega_rad_per_s() / r.k_per_m();
    let x0 = up_crossing(&p, 0.2, 0.01, 0.0);
    let x1 = up_crossing(&p, x0 + c * dt, 0.01, dt);
    assert_close("ripple speed", (x1 - x0) / dt, c, 1e-6 * c);
}

#[test]
fn a_given_omega_overrides_the_dispersion_relation() {
    let w = Wave::try_new(0.01, 1.0, [0.0, 1.0], Some(3.0)).unwrap();
    assert_eq!(w.omega_rad_per_s(), 3.0);
}

#[test]
fn wave_directions_are_normalised() {
    let w = Wave::try_new(0.01, 1.0, [3.0, 4.0], None).unwrap();
    assert_eq!(w.direction(), [0.6, 0.8]);
    let unit = Wave::try_new(0.01, 1.0, [0.6, 0.8], None).unwrap();
    let (a, b) = (Perturbation::Wave(w), Perturbation::Wave(unit));
    assert_close(
        "same wave",
        a.height_m(0.3, 0.7, 0.2),
        b.height_m(0.3, 0.7, 0.2),
        1e-15,
    );
}

#[test]
fn bad_parameters_name_the_value() {
    let e = Wave::try_new(0.01, -2.0, [1.0, 0.0], None).unwrap_err();
    assert!(
        e.to_string().contains("wavelength_m") && e.to_string().contains("-2"),
        "{e}"
    );
    let e = Wave::try_new(0.01, 1.0, [0.0, 0.0], None).unwrap_err();
    assert!(e.to_string().contains("direction"), "{e}");
    let e = Ripple::try_new(0.01, 1.0, [0.0, f64::NAN], None, [0.0; 2]).unwrap_err();
    assert!(e.to_string().contains("center_m"), "{e}");
    let e = Ripple::try_new(0.01, 1.0, [0.0; 2], Some(0.0), [0.0; 2]).unwrap_err();
    assert!(e.to_string().contains("omega"), "{e}");
    let e = Grid::try_new([0.0, 0.0], [1.0, 1.0], [0, 4], 0.0).unwrap_err();
    assert!(
        e.to_string().contains("slices") && e.to_string().contains('0'),
        "{e}"
    );
    let e = Grid::try_new([1.0, 0.0], [1.0, 1.0], [4, 4], 0.0).unwrap_err();
    assert!(e.to_string().contains("extent"), "{e}");
}

fn perturbation() -> impl Strategy<Value = Perturbation> {
    let wave = (
        0.0..0.02f64,
        0.05..2.0f64,
        -1.0..1.0f64,
        0.1..1.0f64,
        prop::option::of(0.5..20.0f64),
    )
        .prop_map(|(a, l, i, j, w)| Perturbation::Wave(Wave::try_new(a, l, [i, j], w).unwrap()));
    let ripple = (
        0.0..0.02f64,
        0.05..1.0f64,
        -1.5..1.5f64,
        -1.5..1.5f64,
        0.0..3.0f64,
        0.0..1.0f64,
    )
        .prop_map(|(a, l, x, z, dr, dt)| {
            Perturbation::Ripple(Ripple::try_new(a, l, [x, z], None, [dr, dt]).unwrap())
        });
    prop_oneof![wave, ripple]
}

fn grid(slices: usize) -> Grid {
    Grid::try_new([-1.0, -0.8], [1.2, 1.0], [slices, slices], 0.25).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn the_sum_of_perturbations_is_the_sum_of_their_surfaces(
        ps in prop::collection::vec(perturbation(), 1..5),
        t in 0.0..5.0f64,
    ) {
        let g = grid(24);
        let rest = g.rest_height_m() as f32;
        let mut together = Surface::new(g, ps.clone());
        let together = together.evaluate(t).clone();
        let mut sum = vec![0.0f32; together.positions.len()];
        for p in &ps {
            let mut alone = Surface::new(g, vec![*p]);
            for (s, v) in sum.iter_mut().zip(&alone.evaluate(t).positions) {
                *s += v.y - rest;
            }
        }
        for (k, (v, s)) in together.positions.iter().zip(&sum).enumerate() {
            let diff = (v.y - rest - s).abs();
            prop_assert!(diff < 1e-6, "vertex {}: {} vs {}, off by {}", k, v.y - rest, s, diff);
        }
    }

    #[test]
    fn the_tabulated_grid_matches_exact_evaluation(
        ps in prop::collection::vec(perturbation(), 0..4),
        t in 0.0..5.0f64,
    ) {
        let g = grid(16);
        let mut surface = Surface::new(g, ps);
        let mesh = surface.evaluate(t).clone();
        let [nx, _] = g.vertices();
        for (k, (p, n)) in mesh.positions.iter().zip(&mesh.normals).enumerate() {
            let (x, z) = (g.x_m(k % nx), g.z_m(k / nx));
            let want = surface.height_m(x, z, t);
            prop_assert!((p.y as f64 - want).abs() < 2e-6, "height {} vs {}", p.y, want);
            let [gx, gz] = surface.gradient(x, z, t);
            let exact = glam::DVec3::new(-gx, 1.0, -gz).normalize().as_vec3();
            prop_assert!((*n - exact).length() < 1e-5, "normal {} vs {}", n, exact);
            prop_assert!((n.length() - 1.0).abs() < 1e-6, "|n| = {}", n.length());
        }
    }
}

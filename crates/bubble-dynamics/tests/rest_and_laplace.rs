//! Statics: a bubble at rest stays put; the pressure at equilibrium obeys Laplace's law.

mod common;

use bubble_dynamics::{BubbleParams, DVec3};
use common::{assert_rel, centroid, isolated, plain_bubble, world};

const SIGMA_N_PER_M: f64 = 0.025;

#[test]
fn bubble_at_rest_stays_spherical_for_one_second() {
    // Default film (swirl, thickness pattern, elasticity), still air, no gravity.
    let r0 = 0.05;
    let bubble = BubbleParams {
        radius_m: r0,
        subdivisions: 3,
        ..BubbleParams::default()
    };
    let mut w = world(isolated(), vec![bubble]);
    let radii = |x: &[bubble_dynamics::DVec3]| {
        let c = centroid(x);
        x.iter().map(|p| p.distance(c)).collect::<Vec<f64>>()
    };
    let start = radii(w.bubbles()[0].positions_m());
    w.advance(1.0).expect("stable");
    let end = radii(w.bubbles()[0].positions_m());
    let worst = start
        .iter()
        .zip(&end)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= 1e-3 * r0,
        "largest radius change {worst:.3e} m > 1e-3·R0 = {:.1e} m",
        1e-3 * r0
    );
    // The discrete rest mesh deviates from the ideal sphere only by its faceting.
    let sphere = end.iter().map(|r| (r - r0).abs()).fold(0.0, f64::max);
    assert!(
        sphere <= 4e-3 * r0,
        "largest |r − R0| = {sphere:.3e} m at level 3"
    );
    assert_rel(
        "volume",
        w.bubbles()[0].volume_m3(),
        4.0 / 3.0 * std::f64::consts::PI * r0.powi(3),
        1e-6,
    );
}

#[test]
fn rest_pressure_obeys_laplace_for_several_radii() {
    for r0 in [0.002, 0.01, 0.05, 0.25] {
        let w = world(isolated(), vec![plain_bubble(r0, 3)]);
        let b = &w.bubbles()[0];
        assert_rel(
            &format!("Δp at R0 = {r0} m"),
            b.pressure_excess_pa(),
            4.0 * SIGMA_N_PER_M / b.radius_m(),
            0.01,
        );
        assert_rel("volume-equivalent radius", b.radius_m(), r0, 1e-9);
    }
}

/// Squeeze a bubble into an ellipsoid, let it ring down, and read the pressure again.
#[test]
fn relaxed_bubble_obeys_laplace_after_a_squeeze() {
    for r0 in [0.005, 0.02, 0.06] {
        let bubble = BubbleParams {
            initial_scale: DVec3::new(1.08, 0.94, 1.0),
            deformation_damping_per_s: 40.0,
            ..plain_bubble(r0, 2)
        };
        let mut w = world(isolated(), vec![bubble]);
        let disturbed = w.bubbles()[0].pressure_excess_pa();
        w.advance(0.5).expect("stable");
        let b = &w.bubbles()[0];
        let laplace = 4.0 * SIGMA_N_PER_M / b.radius_m();
        assert!(
            (disturbed - laplace).abs() > 0.05 * laplace,
            "the squeeze should disturb the pressure: {disturbed} vs {laplace}"
        );
        assert_rel(
            &format!("relaxed Δp at R0 = {r0} m"),
            b.pressure_excess_pa(),
            laplace,
            0.01,
        );
        assert!(
            b.kinetic_energy_j() < 1e-6 * 2.0 * SIGMA_N_PER_M * b.area_m2(),
            "still ringing: {} J",
            b.kinetic_energy_j()
        );
    }
}

/// Seed 000 eq. 2: thickness is film mass over area, so stretching thins the film.
#[test]
fn stretching_thins_the_film_in_proportion_to_the_area() {
    let rest = world(isolated(), vec![plain_bubble(0.04, 3)]);
    let stretched = world(
        isolated(),
        vec![BubbleParams {
            initial_scale: DVec3::new(1.3, 1.0, 1.0),
            ..plain_bubble(0.04, 3)
        }],
    );
    let (a, b) = (&rest.bubbles()[0], &stretched.bubbles()[0]);
    assert_rel("rest mean thickness", a.mean_thickness_nm(), 500.0, 1e-12);
    assert_rel("film mass", b.film_mass_kg(), a.film_mass_kg(), 1e-12);
    assert_rel(
        "stretched mean thickness",
        b.mean_thickness_nm(),
        500.0 * a.area_m2() / b.area_m2(),
        1e-12,
    );
    // Uniform rest film: every vertex starts at the configured thickness.
    for d in a.thickness_nm() {
        assert_rel("rest vertex thickness", *d, 500.0, 1e-9);
    }
    // x ↦ 1.3x scales a surface element by 1.3·|n_x|·… : not at all where the normal is
    // along x (the x poles), by 1.3 where it is across x (the y–z great circle).
    let near = |dir: DVec3| {
        let x = b.positions_m();
        let i = (0..x.len())
            .max_by(|&i, &j| {
                x[i].normalize()
                    .dot(dir)
                    .total_cmp(&x[j].normalize().dot(dir))
            })
            .expect("vertices");
        b.thickness_nm()[i]
    };
    assert_rel("thickness at the x pole", near(DVec3::X), 500.0, 0.03);
    assert_rel(
        "thickness on the y–z circle",
        near(DVec3::Y),
        500.0 / 1.3,
        0.03,
    );
}

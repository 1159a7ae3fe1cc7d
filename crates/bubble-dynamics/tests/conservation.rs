//! Conservation laws: volume (isothermal gas), momentum, angular momentum, film mass.

mod common;

use bubble_dynamics::{BubbleParams, Collider, DVec3, WorldParams};
use common::{assert_abs, assert_rel, isolated, plain_bubble, world};

#[test]
fn volume_is_conserved_under_internal_forces_after_a_perturbation() {
    // A volume-preserving squeeze (1.1 × 1/1.1 × 1) sets the bubble ringing.
    let bubble = BubbleParams {
        initial_scale: DVec3::new(1.1, 1.0 / 1.1, 1.0),
        deformation_damping_per_s: 0.0,
        ..BubbleParams {
            subdivisions: 2,
            ..BubbleParams::default()
        }
    };
    let mut w = world(isolated(), vec![bubble]);
    let v0 = w.bubbles()[0].volume_m3();
    // The isothermal gas turns a pressure change δp into δV/V = −δp/p. The film can
    // change the pressure by no more than a few times its Laplace pressure 4σ/R (2 Pa
    // here): allow 10× that, 2e-4, where the old 1e-3 allowed 100 Pa. Measured 7.4e-5.
    // (Even a factor 2 in the tension moves the volume by only 2e-5: the tension itself is
    // checked by tests/shape_oscillation.rs and by the relaxation tests.)
    let p_in = w.bubbles()[0].pressure_in_pa();
    let tolerance = 10.0 * 4.0 * 0.025 / 0.05 / p_in;
    let mut max_ke: f64 = 0.0;
    for _ in 0..120 {
        w.step().expect("stable");
        let b = &w.bubbles()[0];
        max_ke = max_ke.max(b.kinetic_energy_j());
        assert_rel("volume", b.volume_m3(), v0, tolerance);
    }
    assert!(max_ke > 1e-9, "the bubble never moved: KE {max_ke:.3e} J");
}

#[test]
fn momentum_is_conserved_without_external_forces() {
    let bubbles = vec![
        BubbleParams {
            center_m: DVec3::new(-0.06, 0.0, 0.0),
            velocity_m_per_s: DVec3::new(0.8, 0.1, 0.0),
            initial_scale: DVec3::new(1.1, 0.95, 1.0),
            subdivisions: 2,
            radius_m: 0.04,
            seed: 1,
            ..BubbleParams::default()
        },
        BubbleParams {
            center_m: DVec3::new(0.06, 0.01, 0.0),
            velocity_m_per_s: DVec3::new(-0.5, 0.0, 0.05),
            subdivisions: 2,
            radius_m: 0.04,
            seed: 2,
            ..BubbleParams::default()
        },
    ];
    let mut w = world(isolated(), bubbles);
    let total = |w: &bubble_dynamics::World| {
        w.bubbles()
            .iter()
            .map(|b| b.momentum_kg_m_per_s())
            .sum::<DVec3>()
    };
    let p0 = total(&w);
    let mut touched = false;
    for _ in 0..60 {
        w.step().expect("stable");
        let (a, b) = (&w.bubbles()[0], &w.bubbles()[1]);
        touched |= a.center_m().distance(b.center_m()) < a.radius_m() + b.radius_m();
        assert_abs(
            "|ΔP| / |P0|",
            (total(&w) - p0).length() / p0.length(),
            0.0,
            1e-12,
        );
    }
    assert!(
        touched,
        "the bubbles never met, so the contact went untested"
    );
}

#[test]
fn angular_momentum_is_conserved_without_external_forces() {
    // No swirl: moving film mass between vertices moves its moment arm.
    let bubble = BubbleParams {
        center_m: DVec3::new(0.1, 0.2, -0.05),
        velocity_m_per_s: DVec3::new(0.2, -0.1, 0.3),
        initial_scale: DVec3::new(1.1, 0.95, 1.0),
        ..plain_bubble(0.03, 2)
    };
    let mut w = world(isolated(), vec![bubble]);
    let l0 = w.bubbles()[0].angular_momentum_kg_m2_per_s();
    w.advance(0.2).expect("stable");
    let l = w.bubbles()[0].angular_momentum_kg_m2_per_s();
    assert_abs("|ΔL| / |L0|", (l - l0).length() / l0.length(), 0.0, 1e-10);
}

/// A bubble sitting on the ground drains: tops thin, bottoms thicken, and the film mass
/// only moves (antisymmetric edge fluxes).
#[test]
fn drainage_conserves_film_mass_and_thins_the_top() {
    let r = 0.03;
    let params = WorldParams {
        colliders: vec![Collider::ground(0.0)],
        ..WorldParams::default()
    };
    let bubble = BubbleParams {
        center_m: DVec3::new(0.0, 1.02 * r, 0.0),
        ..plain_bubble(r, 2)
    };
    let mut w = world(params, vec![bubble]);
    let m0 = w.bubbles()[0].film_mass_kg();
    let cap = |w: &bubble_dynamics::World, top: bool| {
        let b = &w.bubbles()[0];
        let c = b.center_m();
        let picked: Vec<f64> = b
            .positions_m()
            .iter()
            .zip(b.thickness_nm())
            .filter(|(x, _)| {
                if top {
                    x.y - c.y > 0.8 * r
                } else {
                    x.y - c.y < -0.8 * r
                }
            })
            .map(|(_, d)| *d)
            .collect();
        picked.iter().sum::<f64>() / picked.len() as f64
    };
    w.advance(3.0).expect("stable");
    assert_rel("film mass", w.bubbles()[0].film_mass_kg(), m0, 1e-9);
    let (top, bottom) = (cap(&w, true), cap(&w, false));
    assert!(top < 0.9 * 500.0, "top cap {top:.1} nm did not thin");
    assert!(
        bottom > 1.1 * 500.0,
        "bottom cap {bottom:.1} nm did not thicken"
    );
}

#[test]
fn swirl_moves_the_pattern_but_not_the_mass() {
    let bubble = BubbleParams {
        slosh_speed_m_per_s: 0.01,
        subdivisions: 2,
        ..BubbleParams::default()
    };
    let mut w = world(isolated(), vec![bubble]);
    let m0 = w.bubbles()[0].film_mass_kg();
    let d0 = w.bubbles()[0].thickness_nm().to_vec();
    w.advance(1.0).expect("stable");
    let b = &w.bubbles()[0];
    assert_rel("film mass", b.film_mass_kg(), m0, 1e-12);
    let moved = d0
        .iter()
        .zip(b.thickness_nm())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        moved > 5.0,
        "the swirl changed no thickness by more than {moved:.3} nm"
    );
}

#[test]
fn swirl_leaves_a_uniform_film_uniform() {
    // The swirl is divergence-free, so a uniform film has nothing to move.
    let bubble = BubbleParams {
        slosh_speed_m_per_s: 0.01,
        ..plain_bubble(0.04, 2)
    };
    let mut w = world(isolated(), vec![bubble]);
    w.advance(0.5).expect("stable");
    let b = &w.bubbles()[0];
    let (lo, hi) = (b.min_thickness_nm(), b.max_thickness_nm());
    assert!(hi - lo < 1e-6 * 500.0, "uniform film became {lo}..{hi} nm");
}

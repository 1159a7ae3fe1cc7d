//! The restitution a bubble achieves bouncing on a plane, against the configured one.

mod common;

use bubble_dynamics::{BubbleParams, Collider, DVec3, World, WorldParams};
use common::{isolated, plain_bubble, world};

/// Throws a bubble at the ground at `speed` with no gravity and no air, and returns the
/// ratio of its centre-of-mass speed leaving the ground to the one it arrived with.
fn achieved_restitution(restitution: f64, speed_m_per_s: f64, damping_per_s: f64) -> f64 {
    let r = 0.03;
    let params = WorldParams {
        colliders: vec![Collider::Plane {
            point_m: DVec3::ZERO,
            normal: DVec3::Y,
            restitution,
            friction: 0.0,
        }],
        ..isolated()
    };
    let bubble = BubbleParams {
        center_m: DVec3::new(0.0, 1.2 * r, 0.0),
        velocity_m_per_s: DVec3::new(0.0, -speed_m_per_s, 0.0),
        deformation_damping_per_s: damping_per_s,
        ..plain_bubble(r, 2)
    };
    let mut w: World = world(params, vec![bubble]);
    let v_in = w.bubbles()[0].velocity_m_per_s().y;
    let mut v_out = f64::NAN;
    for _ in 0..240 {
        w.step().expect("stable");
        let b = &w.bubbles()[0];
        let lowest = b
            .positions_m()
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        if b.velocity_m_per_s().y > 0.0 && lowest > 1e-4 * r {
            v_out = b.velocity_m_per_s().y;
            break;
        }
    }
    -v_out / v_in
}

/// Even with a perfectly elastic ground and no damping, a bounce gives back no more
/// than the bubble brought: measured 0.963 at 0.2 m/s and 0.843 at 1 m/s (the rest stays
/// in the wobble).
#[test]
fn elastic_bounce_without_damping_returns_no_more_than_it_receives() {
    for speed in [0.2, 1.0] {
        let e = achieved_restitution(1.0, speed, 0.0);
        assert!(
            (0.5..=1.0).contains(&e),
            "achieved restitution {e:.4} at {speed} m/s"
        );
    }
}

/// The collider's restitution is applied per vertex; a bubble bounces on its film and gas
/// instead, so the coefficient barely matters. Measured at 1 m/s, no damping: achieved
/// 0.855 with e = 0, 0.853 with 0.3, 0.845 with 0.6, 0.843 with 1 (0.969 … 0.963 at
/// 0.2 m/s). The requirement stands and fails today.
#[test]
#[ignore = "configured restitution is not achieved (issue 15 finding, docs/dynamics.md)"]
fn achieved_restitution_follows_the_configured_coefficient() {
    for e in [0.0, 0.3, 0.6] {
        let achieved = achieved_restitution(e, 1.0, 0.0);
        assert!(
            (achieved - e).abs() < 0.1,
            "configured {e}, achieved {achieved:.4}"
        );
    }
}

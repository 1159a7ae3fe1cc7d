//! The restitution a bubble achieves bouncing on a plane and on another bubble, against
//! the configured one: the normal velocity of the centre of mass after contact is −e
//! times that before (the definition of the coefficient, which is the truth here).

mod common;

use bubble_dynamics::{BubbleParams, Collider, DVec3, World, WorldParams};
use common::{isolated, plain_bubble, world};

/// What one bounce on the ground did.
struct Bounce {
    /// Centre-of-mass normal velocity after the contact over the one before.
    achieved: f64,
    /// Lowest vertex height over the whole run, in units of the radius.
    lowest_per_r: f64,
    /// Whether the bubble was clear of the ground at the end.
    left_ground: bool,
    /// |film mass after − before| / before.
    film_mass_drift: f64,
    /// Kinetic energy of the particles at the end over that at the start.
    kinetic_ratio: f64,
}

/// Throws a bubble straight down at the ground at `speed_m_per_s` with no gravity and no
/// air, steps for one second (240 steps; the contact is over after a few of them), and
/// measures the centre of mass's vertical velocity at the end against the one it arrived
/// with.
fn bounce_on_ground(restitution: f64, speed_m_per_s: f64, damping_per_s: f64) -> Bounce {
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
    let film_mass_before = w.bubbles()[0].film_mass_kg();
    let kinetic_before = w.bubbles()[0].kinetic_energy_j();
    let lowest_of = |w: &World| {
        w.bubbles()[0]
            .positions_m()
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min)
    };
    let mut lowest = f64::INFINITY;
    for _ in 0..240 {
        w.step().expect("stable");
        lowest = lowest.min(lowest_of(&w));
    }
    let b = &w.bubbles()[0];
    Bounce {
        achieved: -b.velocity_m_per_s().y / v_in,
        lowest_per_r: lowest / r,
        left_ground: lowest_of(&w) > 1e-3 * r,
        film_mass_drift: (b.film_mass_kg() - film_mass_before).abs() / film_mass_before,
        kinetic_ratio: b.kinetic_energy_j() / kinetic_before,
    }
}

/// Even with a perfectly elastic ground and no damping, the centre of mass leaves no
/// faster than it came; the kinetic energy of the particles gains at most the top-up the
/// contact adds when the spring gives back less than e asks (measured 1.1 to 1.4 %: the
/// wobble keeps its potential energy).
#[test]
fn elastic_bounce_without_damping_returns_no_more_than_it_receives() {
    for speed in [0.2, 1.0] {
        let b = bounce_on_ground(1.0, speed, 0.0);
        assert!(
            (0.5..=1.0 + 1e-9).contains(&b.achieved),
            "achieved restitution {:.6} at {speed} m/s",
            b.achieved
        );
        assert!(
            b.kinetic_ratio <= 1.02,
            "kinetic energy grew by {:.2} % at {speed} m/s",
            100.0 * (b.kinetic_ratio - 1.0)
        );
    }
}

/// The centre of mass leaves the ground at e times its arrival speed, within 0.05 of the
/// arrival speed, for e = 0, 0.5 and 1, slow and fast, with and without wobble damping;
/// no vertex goes below the ground by more than 1 % of the radius and the film mass is
/// untouched. (Before the contact model acted on the centre of mass, the achieved value
/// was 0.855 with e = 0 and 0.843 with e = 1 at 1 m/s.)
#[test]
fn achieved_restitution_follows_the_configured_coefficient() {
    for damping_per_s in [0.0, 10.0] {
        for speed in [0.2, 1.0] {
            for e in [0.0, 0.5, 1.0] {
                let b = bounce_on_ground(e, speed, damping_per_s);
                println!(
                    "e = {e}, {speed} m/s, damping {damping_per_s}/s: achieved {:.4}, lowest {:.2e} R, kinetic energy after/before {:.4}",
                    b.achieved, b.lowest_per_r, b.kinetic_ratio
                );
                assert!(
                    (b.achieved - e).abs() <= 0.05,
                    "configured {e}, achieved {:.4} at {speed} m/s, damping {damping_per_s}/s",
                    b.achieved
                );
                assert!(
                    b.left_ground || e == 0.0,
                    "e = {e} at {speed} m/s: still on the ground at the end"
                );
                assert!(
                    b.lowest_per_r >= -0.01,
                    "e = {e} at {speed} m/s: a vertex reached {:.3e} R below the ground",
                    b.lowest_per_r
                );
                assert!(
                    b.film_mass_drift <= 1e-12,
                    "e = {e}: film mass drifted by {:.2e}",
                    b.film_mass_drift
                );
            }
        }
    }
}

/// Two equal bubbles thrown head-on at ±`speed_m_per_s` (no air, no gravity) with
/// `bubble_restitution` = `e`: their relative velocity along the line of centres one
/// second later (the contact is long over) over the one before.
fn head_on(e: f64, speed_m_per_s: f64) -> f64 {
    let r = 0.03;
    let thrown = |x: f64, v: f64, seed: u64| BubbleParams {
        center_m: DVec3::new(x, 0.0, 0.0),
        velocity_m_per_s: DVec3::new(v, 0.0, 0.0),
        seed,
        ..plain_bubble(r, 2)
    };
    let params = WorldParams {
        bubble_restitution: e,
        bubble_friction: 0.0,
        ..isolated()
    };
    let bubbles = vec![
        thrown(-1.2 * r, speed_m_per_s, 1),
        thrown(1.2 * r, -speed_m_per_s, 2),
    ];
    let mut w = world(params, bubbles);
    let relative =
        |w: &World| w.bubbles()[1].velocity_m_per_s().x - w.bubbles()[0].velocity_m_per_s().x;
    let before = relative(&w);
    for _ in 0..240 {
        w.step().expect("stable");
    }
    -relative(&w) / before
}

/// Bubble–bubble contacts honour `bubble_restitution` the same way, within 0.05.
#[test]
fn bubble_pairs_bounce_with_the_configured_restitution() {
    for speed in [0.2, 1.0] {
        for e in [0.0, 0.5, 1.0] {
            let achieved = head_on(e, speed);
            println!("pair, e = {e}, ±{speed} m/s: achieved {achieved:.4}");
            assert!(
                (achieved - e).abs() <= 0.05,
                "bubble_restitution {e}, achieved {achieved:.4} at ±{speed} m/s"
            );
        }
    }
}

/// A bubble that landed on the default ground (e = 0.3) is not held there once its
/// impact is over: an updraft (air drag, no gravity) lifts it off again. (At e = 0
/// exactly it is: docs/dynamics.md.)
#[test]
fn a_bubble_that_landed_can_leave_the_ground_again() {
    let r = 0.03;
    let params = WorldParams {
        colliders: vec![Collider::Plane {
            point_m: DVec3::ZERO,
            normal: DVec3::Y,
            restitution: bubble_dynamics::DEFAULT_RESTITUTION,
            friction: 0.0,
        }],
        air_density_kg_per_m3: 1.2,
        wind: bubble_dynamics::Wind::uniform(DVec3::new(0.0, 0.3, 0.0)),
        ..isolated()
    };
    let bubble = BubbleParams {
        center_m: DVec3::new(0.0, 1.2 * r, 0.0),
        velocity_m_per_s: DVec3::new(0.0, -1.0, 0.0),
        ..plain_bubble(r, 2)
    };
    let mut w = world(params, vec![bubble]);
    let mut landed = false;
    for _ in 0..480 {
        w.step().expect("stable");
        let lowest = w.bubbles()[0]
            .positions_m()
            .iter()
            .map(|x| x.y)
            .fold(f64::INFINITY, f64::min);
        landed |= lowest < 1e-6 * r;
    }
    let b = &w.bubbles()[0];
    assert!(landed, "the bubble never reached the ground");
    assert!(
        b.center_m().y > 2.0 * r && b.velocity_m_per_s().y > 0.0,
        "held down: centre at {:.4} m, rising at {:.4} m/s",
        b.center_m().y,
        b.velocity_m_per_s().y
    );
}

//! Contacts: no interpenetration (judged by independent winding numbers and distances),
//! bounces, and a crowd resolved through the broad phase.

mod common;

use bubble_dynamics::{Bubble, BubbleParams, Collider, DVec3, World, WorldParams};
use common::{isolated, penetration_depth, plain_bubble, world};

/// Deepest vertex of `a` inside `b`, m.
fn deepest(a: &Bubble, b: &Bubble) -> f64 {
    let reach = b
        .positions_m()
        .iter()
        .map(|x| x.distance(b.center_m()))
        .fold(0.0, f64::max);
    a.positions_m()
        .iter()
        .filter(|p| p.distance(b.center_m()) < reach)
        .map(|p| penetration_depth(*p, b.positions_m(), b.triangles()))
        .fold(0.0, f64::max)
}

fn worst_overlap(w: &World) -> f64 {
    let b = w.bubbles();
    let mut worst: f64 = 0.0;
    for i in 0..b.len() {
        for j in 0..b.len() {
            if i != j
                && b[i].center_m().distance(b[j].center_m())
                    < 1.2 * (b[i].radius_m() + b[j].radius_m())
            {
                worst = worst.max(deepest(&b[i], &b[j]) / b[j].radius_m());
            }
        }
    }
    worst
}

#[test]
fn bubbles_thrown_at_each_other_do_not_interpenetrate_and_bounce() {
    let r = 0.03;
    let bubbles = vec![
        BubbleParams {
            center_m: DVec3::new(-1.3 * r, 0.0, 0.0),
            velocity_m_per_s: DVec3::new(1.0, 0.0, 0.0),
            seed: 1,
            ..plain_bubble(r, 2)
        },
        BubbleParams {
            center_m: DVec3::new(1.3 * r, 0.2 * r, 0.0),
            velocity_m_per_s: DVec3::new(-1.0, 0.0, 0.0),
            seed: 2,
            ..plain_bubble(r, 2)
        },
    ];
    let params = WorldParams {
        air_density_kg_per_m3: 1.204,
        ..isolated()
    };
    let mut w = world(params, bubbles);
    let mut worst: f64 = 0.0;
    let mut touched = false;
    for _ in 0..48 {
        w.step().expect("stable");
        worst = worst.max(worst_overlap(&w));
        let (a, b) = (&w.bubbles()[0], &w.bubbles()[1]);
        // Met: their vertices' bounding spheres overlapped (the contact now bounces the
        // centres of mass rigidly, so they no longer squash to 1.9 R apart).
        let reach = |x: &Bubble| {
            x.positions_m()
                .iter()
                .map(|p| p.distance(x.center_m()))
                .fold(0.0, f64::max)
        };
        touched |= a.center_m().distance(b.center_m()) < reach(a) + reach(b);
    }
    assert!(touched, "the bubbles never met");
    println!("thrown pair: deepest vertex {worst:.2e} R inside the other bubble");
    assert!(
        worst <= 0.01,
        "a vertex went {:.3} % of R into the other bubble",
        100.0 * worst
    );
    let (a, b) = (&w.bubbles()[0], &w.bubbles()[1]);
    assert!(
        a.velocity_m_per_s().x < 0.0 && b.velocity_m_per_s().x > 0.0,
        "no bounce: {:?} {:?}",
        a.velocity_m_per_s(),
        b.velocity_m_per_s()
    );
}

#[test]
fn bubble_dropped_on_a_plane_stays_above_it_and_bounces() {
    let r = 0.03;
    let params = WorldParams {
        colliders: vec![Collider::ground(0.0)],
        ..WorldParams::default()
    };
    let bubble = BubbleParams {
        center_m: DVec3::new(0.0, 1.5 * r, 0.0),
        velocity_m_per_s: DVec3::new(0.3, -1.5, 0.0),
        ..plain_bubble(r, 2)
    };
    let mut w = world(params, vec![bubble]);
    let mut lowest: f64 = 0.0;
    let mut rose = false;
    for _ in 0..120 {
        w.step().expect("stable");
        let b = &w.bubbles()[0];
        lowest = lowest.min(
            b.positions_m()
                .iter()
                .map(|x| x.y)
                .fold(f64::INFINITY, f64::min),
        );
        rose |= b.velocity_m_per_s().y > 0.05;
    }
    assert!(
        lowest >= -0.01 * r,
        "a vertex reached y = {lowest:.3e} m below the ground"
    );
    assert!(rose, "the bubble never bounced");
}

#[test]
fn walls_solid_spheres_and_boxes_keep_the_bubble_out() {
    let r = 0.02;
    let cases = [
        (
            Collider::plane(DVec3::new(0.1, 0.0, 0.0), DVec3::new(-1.0, 0.0, 0.0)),
            "wall",
        ),
        (
            Collider::sphere(DVec3::new(0.1 + 0.03, 0.0, 0.0), 0.03),
            "sphere",
        ),
        (
            Collider::cuboid(DVec3::new(0.1, -0.05, -0.05), DVec3::new(0.2, 0.05, 0.05)),
            "box",
        ),
    ];
    for (collider, name) in cases {
        // Independent inside tests, written out here rather than borrowed from the crate.
        let depth = |p: DVec3| -> f64 {
            match name {
                "wall" => (p.x - 0.1).max(0.0),
                "sphere" => (0.03 - p.distance(DVec3::new(0.13, 0.0, 0.0))).max(0.0),
                _ => {
                    let inside = p.x > 0.1 && p.x < 0.2 && p.y.abs() < 0.05 && p.z.abs() < 0.05;
                    if inside {
                        (p.x - 0.1)
                            .min(0.2 - p.x)
                            .min(0.05 - p.y.abs())
                            .min(0.05 - p.z.abs())
                    } else {
                        0.0
                    }
                }
            }
        };
        let params = WorldParams {
            colliders: vec![collider],
            ..isolated()
        };
        let bubble = BubbleParams {
            velocity_m_per_s: DVec3::new(2.0, 0.0, 0.0),
            ..plain_bubble(r, 2)
        };
        let mut w = world(params, vec![bubble]);
        let mut worst: f64 = 0.0;
        for _ in 0..60 {
            w.step().expect("stable");
            worst = worst.max(
                w.bubbles()[0]
                    .positions_m()
                    .iter()
                    .map(|p| depth(*p))
                    .fold(0.0, f64::max),
            );
        }
        assert!(
            worst <= 0.01 * r,
            "{name}: a vertex went {worst:.3e} m inside"
        );
        assert!(
            w.bubbles()[0].velocity_m_per_s().x < 0.0,
            "{name}: the bubble did not bounce back"
        );
    }
}

#[test]
fn a_crowd_of_bubbles_in_a_box_settles_without_interpenetrating() {
    let r = 0.02;
    let walls = vec![
        Collider::ground(0.0),
        Collider::plane(DVec3::new(-0.1, 0.0, 0.0), DVec3::X),
        Collider::plane(DVec3::new(0.1, 0.0, 0.0), -DVec3::X),
        Collider::plane(DVec3::new(0.0, 0.0, -0.1), DVec3::Z),
        Collider::plane(DVec3::new(0.0, 0.0, 0.1), -DVec3::Z),
    ];
    let bubbles = (0..18)
        .map(|i| BubbleParams {
            center_m: DVec3::new(
                -0.06 + 0.06 * (i % 3) as f64,
                0.03 + 0.05 * (i / 6) as f64,
                -0.045 + 0.045 * ((i / 3) % 2) as f64 * 2.0,
            ),
            velocity_m_per_s: DVec3::new(
                0.3 * ((i * 7) % 5) as f64 - 0.6,
                0.0,
                0.2 * ((i * 3) % 4) as f64 - 0.3,
            ),
            seed: i as u64,
            ..plain_bubble(r, 1)
        })
        .collect();
    let params = WorldParams {
        gravity_m_per_s2: DVec3::new(0.0, -30.0, 0.0),
        colliders: walls,
        ..WorldParams::default()
    };
    let mut w = world(params, bubbles);
    let mut worst: f64 = 0.0;
    for step in 0..120 {
        w.step().expect("stable");
        if step % 10 == 9 {
            worst = worst.max(worst_overlap(&w));
        }
    }
    assert_eq!(w.bubbles().len(), 18, "bubbles lost");
    println!("18 bubbles in a box: deepest overlap {worst:.2e} R");
    assert!(worst <= 0.01, "deepest overlap {:.3} % of R", 100.0 * worst);
    for b in w.bubbles() {
        assert!(
            b.center_m().y > 0.5 * r && b.center_m().y < 0.3,
            "bubble {} escaped to {:?}",
            b.id(),
            b.center_m()
        );
    }
}

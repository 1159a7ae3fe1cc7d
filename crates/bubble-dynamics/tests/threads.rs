//! Bubbles are integrated in parallel: the state after colliding, gusty, draining steps
//! must be bit-for-bit the same on 1, 2 and 3 threads.

use bubble_dynamics::{BubbleParams, Collider, DVec3, Gusts, Wind, World, WorldParams};

/// Three level-4 bubbles (enough triangles to take the parallel path) thrown at each
/// other just above the ground in gusts, with swirl and drainage.
fn scene() -> World {
    let params = WorldParams {
        colliders: vec![Collider::ground(0.0)],
        wind: Wind::uniform(DVec3::new(0.2, 0.0, 0.1)).with_gusts(Gusts {
            amplitude_m_per_s: 1.0,
            seed: 3,
            ..Gusts::default()
        }),
        ..WorldParams::default()
    };
    let bubbles = (0..3)
        .map(|i| BubbleParams {
            center_m: DVec3::new(0.11 * i as f64, 0.07, 0.01 * i as f64),
            velocity_m_per_s: DVec3::new(0.5 - 0.5 * i as f64, -0.3, 0.0),
            radius_m: 0.05,
            subdivisions: 4,
            seed: i,
            ..BubbleParams::default()
        })
        .collect();
    World::try_new(params, bubbles).expect("valid scene")
}

/// Every bit of every bubble's state after 16 steps, plus the substeps of each step.
fn run_on(threads: usize) -> (Vec<u64>, Vec<u32>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mut world = scene();
        let mut substeps = Vec::new();
        for _ in 0..16 {
            world.step().expect("stable");
            substeps.push(world.last_substeps());
        }
        let mut bits = Vec::new();
        for b in world.bubbles() {
            for (x, v) in b.positions_m().iter().zip(b.velocities_m_per_s()) {
                bits.extend([x.x, x.y, x.z, v.x, v.y, v.z].map(f64::to_bits));
            }
            bits.extend(b.film_masses_kg().iter().map(|m| m.to_bits()));
            bits.extend(b.thickness_nm().iter().map(|h| h.to_bits()));
            bits.push(b.volume_m3().to_bits());
        }
        (bits, substeps)
    })
}

#[test]
fn parallel_bubbles_give_bit_identical_states_on_1_2_and_3_threads() {
    let (one, substeps) = run_on(1);
    // The scene must exercise contacts: bubbles 0 and 1 meet within the 16 steps (they
    // bounce apart again with the pair's restitution).
    let mut w = scene();
    let mut closest = f64::INFINITY;
    for _ in 0..16 {
        w.step().expect("stable");
        let [a, b, ..] = w.bubbles() else {
            panic!("bubbles burst")
        };
        closest = closest.min(a.center_m().distance(b.center_m()) - a.radius_m() - b.radius_m());
    }
    assert!(
        closest < 0.005,
        "bubbles 0 and 1 never touched: gap {closest} m"
    );
    for threads in [2, 3] {
        let (bits, steps) = run_on(threads);
        assert_eq!(
            steps, substeps,
            "substep counts differ on {threads} threads"
        );
        let first_difference = one.iter().zip(&bits).position(|(p, q)| p != q);
        assert!(
            bits.len() == one.len() && first_difference.is_none(),
            "state on {threads} threads differs from 1 thread at word {first_difference:?} \
             (lengths {} vs {})",
            bits.len(),
            one.len()
        );
    }
}

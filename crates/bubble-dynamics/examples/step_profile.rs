//! Runs the bench's 2-bubble scene for a given number of steps and prints a fingerprint
//! of the final state (for callgrind instruction counts and bit-exactness checks).
//!
//! `cargo run --release -p bubble-dynamics --example step_profile -- STEPS [SCENE]`,
//! SCENE = `fall` (the bench scene, default) or `clash` (two bubbles thrown at each
//! other in gusts, onto the ground).

use bubble_dynamics::{BubbleParams, Collider, DVec3, Gusts, Wind, World, WorldParams};

fn fall() -> World {
    let bubbles = (0..2)
        .map(|i| BubbleParams {
            center_m: DVec3::new(0.12 * i as f64, 1.0, 0.0),
            seed: i as u64,
            ..BubbleParams::default()
        })
        .collect();
    let params = WorldParams {
        colliders: vec![Collider::ground(0.0)],
        ..WorldParams::default()
    };
    let mut world = World::try_new(params, bubbles).expect("valid scene");
    world.advance(0.05).expect("stable");
    world
}

fn clash() -> World {
    let bubble = |x: f64, v: f64, seed: u64| BubbleParams {
        center_m: DVec3::new(x, 0.2, 0.0),
        velocity_m_per_s: DVec3::new(v, 0.0, 0.0),
        seed,
        ..BubbleParams::default()
    };
    let params = WorldParams {
        colliders: vec![Collider::ground(0.0)],
        wind: Wind::default().with_gusts(Gusts {
            amplitude_m_per_s: 1.0,
            ..Gusts::default()
        }),
        ..WorldParams::default()
    };
    World::try_new(params, vec![bubble(-0.12, 1.0, 1), bubble(0.12, -1.0, 2)]).expect("valid scene")
}

fn main() {
    let mut args = std::env::args().skip(1);
    let steps: u64 = args.next().map_or(20, |s| s.parse().expect("STEPS"));
    let mut world = match args.next().as_deref() {
        None | Some("fall") => fall(),
        Some("clash") => clash(),
        Some(other) => panic!("unknown scene {other}"),
    };
    for _ in 0..steps {
        world.step().expect("stable");
    }
    // FNV-1a over every bit of the state.
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: f64| {
        for byte in x.to_bits().to_le_bytes() {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    for b in world.bubbles() {
        for (x, v) in b.positions_m().iter().zip(b.velocities_m_per_s()) {
            [x.x, x.y, x.z, v.x, v.y, v.z]
                .into_iter()
                .for_each(&mut eat);
        }
        b.thickness_nm().iter().copied().for_each(&mut eat);
        b.film_masses_kg().iter().copied().for_each(&mut eat);
        eat(b.volume_m3());
    }
    for b in world.bubbles() {
        let x = b.positions_m();
        println!(
            "bubble {}: x0 {:.15e} {:.15e} {:.15e} v0 {:.15e} ke {:.15e} vol {:.15e} h {:.15e} {:.15e}",
            b.id(),
            x[0].x,
            x[0].y,
            x[0].z,
            b.velocities_m_per_s()[0].y,
            b.kinetic_energy_j(),
            b.volume_m3(),
            b.min_thickness_nm(),
            b.max_thickness_nm()
        );
    }
    println!(
        "steps {} substeps {} bubbles {} fingerprint {hash:016x}",
        world.steps(),
        world.last_substeps(),
        world.bubbles().len()
    );
}

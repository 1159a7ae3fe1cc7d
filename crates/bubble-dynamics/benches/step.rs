//! Criterion benches: one `World::step` (a fixed dt with its substeps) for 2, 10 and 100
//! bubbles of 642 vertices, and one substep-sized step for the 2-bubble scene.

use bubble_dynamics::{BubbleParams, Collider, DVec3, World, WorldParams};
use criterion::{BatchSize, Criterion, criterion_group, criterion_main};

/// `count` level-3 bubbles of radius 5 cm on a square grid 1 m above the ground, 12 cm
/// apart (not touching), seeded differently.
fn grid_world(count: usize, dt_s: f64) -> World {
    let side = (count as f64).sqrt().ceil() as usize;
    let bubbles = (0..count)
        .map(|i| BubbleParams {
            center_m: DVec3::new(0.12 * (i % side) as f64, 1.0, 0.12 * (i / side) as f64),
            seed: i as u64,
            ..BubbleParams::default()
        })
        .collect();
    let params = WorldParams {
        dt_s,
        colliders: vec![Collider::ground(0.0)],
        ..WorldParams::default()
    };
    let mut world = World::try_new(params, bubbles).expect("valid bench scene");
    // Let the start-up transient pass so the bench sees steady falling bubbles.
    world.advance(0.05).expect("stable");
    world
}

fn bench_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("world_step");
    for count in [2usize, 10, 100] {
        let world = grid_world(count, WorldParams::default().dt_s);
        group.bench_function(format!("{count}_bubbles_x642_dt_1_240"), |b| {
            b.iter_batched(
                || world.clone(),
                |mut w| w.step().expect("stable"),
                BatchSize::LargeInput,
            )
        });
    }
    let world = grid_world(2, 1.0 / 1000.0);
    group.bench_function("2_bubbles_x642_dt_1_1000", |b| {
        b.iter_batched(
            || world.clone(),
            |mut w| w.step().expect("stable"),
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);

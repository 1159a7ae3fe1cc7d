//! Criterion bench: one film-flow step (1/60 s: gravity, viscosity, air shear, the
//! implicit Marangoni solve, transport) of a 5 cm bubble's film at n = 32, 64, 128 and 256
//! cells a face, on one core: the `swirl` scene's film (drainage μ 1e-6 Pa·s,
//! evaporation 40 nm/s), 600 nm ± 5 %, hovering in gravity in still air.
//!
//! And `film_step/scene_n64`: a scene's film, the first of `crowd`'s bubbles (2.67 cm,
//! 600 nm with the world's streaks, a scene's drainage μ 1e-6 Pa·s) with a grid of 64,
//! one second after it was dropped onto the ground, stepped hovering as above. The
//! solve takes more iterations on it than on the swirl film (docs/performance.md,
//! "Fifteenth round").

#[path = "common/scene_film.rs"]
mod scene_film;
#[path = "common/swirl_film.rs"]
mod swirl_film;

use bubble_dynamics::DVec3;
use bubble_dynamics::film_flow::{FilmGradient, Forcing};
use criterion::{BatchSize, Criterion, criterion_group, criterion_main};

use scene_film::scene_film;
use swirl_film::swirl_film;

fn bench_film_step(c: &mut Criterion) {
    let forcing = Forcing {
        g_eff_m_per_s2: DVec3::new(0.0, -9.81, 0.0),
        air_m_per_s: DVec3::ZERO,
    };
    let mut group = c.benchmark_group("film_step");
    for n in [32, 64, 128, 256] {
        let mut f = swirl_film(n, 0.0, FilmGradient::TwoPoint);
        // Past the start-up transient: the film sags onto its Marangoni balance.
        for _ in 0..30 {
            f.step(1.0 / 60.0, &forcing);
        }
        // Every timed step starts from this same state (a copy, made outside the timing):
        // stepping one film on and on let it evaporate towards rupture during the
        // measurement, so a faster build timed a thinner, costlier film.
        group.bench_function(format!("n{n}"), |b| {
            b.iter_batched(
                || f.clone(),
                |mut f| {
                    f.step(1.0 / 60.0, &forcing);
                    f
                },
                BatchSize::LargeInput,
            )
        });
    }
    let scene = scene_film();
    group.bench_function("scene_n64", |b| {
        b.iter_batched(
            || scene.clone(),
            |mut f| {
                f.step(1.0 / 60.0, &forcing);
                f
            },
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench_film_step
}
criterion_main!(benches);

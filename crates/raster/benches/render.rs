//! Criterion benches: the paper-like scene (2 level-3 bubbles, checker ground, sky, one
//! light, dynamic 128² cube maps) at 400×400 and 1920×1080, plus the other reflection modes.
//!
//! `CARGO_TARGET_DIR=/work/targets/raster cargo bench -p raster -- --warm-up-time 1 --measurement-time 3`

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use raster::{FilmTables, ReflectionMode, RenderSettings, Renderer};

fn bench_paper(c: &mut Criterion) {
    let scene = common::paper_scene();
    let tables = FilmTables::from_reflectivity(common::synthetic_reflectivity());
    let cases = [
        (
            "paper_400x400_dynamic128_1spp",
            400,
            400,
            1,
            ReflectionMode::DynamicCubeMap { face_size: 128 },
        ),
        (
            "paper_400x400_dynamic128_4spp",
            400,
            400,
            4,
            ReflectionMode::DynamicCubeMap { face_size: 128 },
        ),
        (
            "paper_400x400_static_4spp",
            400,
            400,
            4,
            ReflectionMode::StaticEnvironment,
        ),
        (
            "paper_1920x1080_dynamic128_4spp",
            1920,
            1080,
            4,
            ReflectionMode::DynamicCubeMap { face_size: 128 },
        ),
    ];
    for (name, width, height, samples, reflection) in cases {
        let settings = RenderSettings {
            width,
            height,
            samples,
            reflection,
            ..RenderSettings::default()
        };
        let mut renderer = Renderer::new();
        renderer.render(&scene, &tables, &settings).unwrap();
        c.bench_function(name, |b| {
            b.iter(|| renderer.render(&scene, &tables, &settings).unwrap().width())
        });
        let t = renderer.frame().timings;
        eprintln!(
            "{name}: last frame setup {:.2} ms, cube maps {:.2} ms, opaque {:.2} ms, bubbles {:.2} ms, resolve {:.2} ms",
            t.setup_s * 1e3,
            t.cube_maps_s * 1e3,
            t.opaque_s * 1e3,
            t.bubbles_s * 1e3,
            t.resolve_s * 1e3
        );
    }
}

/// The paper scene with and without a film field on both bubbles (N = 64, the draining
/// film's thickness, full coverage): the per-pixel film lookup's cost (issue 22 asks that
/// the film keep at least 80 % of the frame rate).
///
/// `cargo bench -p raster --bench render -- paper_400x400_film --warm-up-time 1 --measurement-time 5`
fn bench_film(c: &mut Criterion) {
    let plain = common::paper_scene();
    let mut film = plain.clone();
    for b in &mut film.bubbles {
        *b = common::with_film(
            b.clone(),
            common::film_field(64, |d| (common::draining(d), 1.0)),
        );
    }
    let tables = FilmTables::from_reflectivity(common::synthetic_reflectivity());
    let settings = RenderSettings {
        width: 400,
        height: 400,
        samples: 4,
        reflection: ReflectionMode::DynamicCubeMap { face_size: 128 },
        ..RenderSettings::default()
    };
    for (name, scene) in [
        ("paper_400x400_film_none", &plain),
        ("paper_400x400_film_64", &film),
    ] {
        let mut renderer = Renderer::new();
        renderer.render(scene, &tables, &settings).unwrap();
        c.bench_function(name, |b| {
            b.iter(|| renderer.render(scene, &tables, &settings).unwrap().width())
        });
        // The bubble pass alone and the whole frame, the fastest of many frames (the
        // least disturbed by other work on a shared machine) and their median.
        let frames = 60;
        let (mut pass, mut whole) = (Vec::new(), Vec::new());
        for _ in 0..frames {
            let start = std::time::Instant::now();
            let t = renderer.render(scene, &tables, &settings).unwrap().timings;
            whole.push(start.elapsed().as_secs_f64() * 1e3);
            pass.push(t.bubbles_s * 1e3);
        }
        for v in [&mut pass, &mut whole] {
            v.sort_by(f64::total_cmp);
        }
        eprintln!(
            "{name}: bubble pass min {:.3} ms median {:.3} ms; frame min {:.3} ms median {:.3} ms ({frames} frames)",
            pass[0],
            pass[frames / 2],
            whole[0],
            whole[frames / 2]
        );
    }
}

criterion_group!(benches, bench_paper, bench_film);
criterion_main!(benches);

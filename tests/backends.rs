//! Laws every renderer backend must keep, each written once and run on every backend that
//! was built: the CPU renderer (the specification), the wgpu backend (`--features wgpu`,
//! skipped without it or without an adapter) and the spectral reference tracer.
//!
//! `cargo test -p integration-tests --test backends` runs CPU and reference;
//! `cargo test -p integration-tests --features wgpu --test backends` adds the GPU.

use raster::Renderer;
use reference_tracer::{FilmSpec, ReferenceSettings, render_reference};
use render_scene::{
    Camera, Environment, FilmTables, Frame, Lut, RenderScene, RenderSettings, Vec3,
};
use thinfilm::{Illuminant, Observer, RefractiveIndex};

// The scene fixtures the renderer's own tests draw (icosphere bubbles, synthetic tables).
#[path = "../crates/raster/tests/common/mod.rs"]
mod common;

use common::{bubble, lossless_tables};

/// A renderer backend.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Backend {
    Cpu,
    Gpu,
    Reference,
}

const BACKENDS: [Backend; 3] = [Backend::Cpu, Backend::Gpu, Backend::Reference];

/// `scene` drawn by `backend` at `width × height`, or `None` when that backend was not
/// built or finds no adapter (said on stderr).
fn render(
    backend: Backend,
    scene: &RenderScene,
    tables: &FilmTables,
    (width, height): (usize, usize),
) -> Option<Frame> {
    let settings = RenderSettings {
        width,
        height,
        samples: 4,
        ..RenderSettings::default()
    };
    match backend {
        Backend::Cpu => Some(
            Renderer::new()
                .render(scene, tables, &settings)
                .unwrap()
                .clone(),
        ),
        Backend::Gpu => render_gpu(scene, tables, &settings),
        Backend::Reference => {
            let spec = FilmSpec {
                n_outside: 1.0,
                n_film: RefractiveIndex::SOAP,
                observer: Observer::Cie1931,
                reference: Illuminant::D65.spectrum(),
                light_spectra: vec![None; scene.lights.len()],
            };
            let settings = ReferenceSettings {
                width,
                height,
                samples_per_side: 2,
                step_nm: 25.0,
                ..ReferenceSettings::default()
            };
            Some(render_reference(scene, &spec, &settings, &|| {}).unwrap())
        }
    }
}

#[cfg(feature = "wgpu")]
fn render_gpu(
    scene: &RenderScene,
    tables: &FilmTables,
    settings: &RenderSettings,
) -> Option<Frame> {
    use raster::gpu::{GpuError, GpuOptions, GpuRenderer};
    match GpuRenderer::new(GpuOptions::default()) {
        Ok(mut gpu) => Some(gpu.render(scene, tables, settings).unwrap().clone()),
        Err(e @ GpuError::NoAdapter { .. }) => {
            eprintln!("skipping the wgpu backend: {e}");
            None
        }
        Err(e) => panic!("wgpu backend: {e}"),
    }
}

#[cfg(not(feature = "wgpu"))]
fn render_gpu(_: &RenderScene, _: &FilmTables, _: &RenderSettings) -> Option<Frame> {
    eprintln!("skipping the wgpu backend: built without the wgpu feature");
    None
}

/// Runs `law` on every backend that renders; at least the CPU and the reference do.
fn on_every_backend(mut law: impl FnMut(Backend) -> bool) {
    let ran: Vec<Backend> = BACKENDS.into_iter().filter(|&b| law(b)).collect();
    assert!(
        ran.contains(&Backend::Cpu) && ran.contains(&Backend::Reference),
        "ran on {ran:?}"
    );
}

/// Tables of constant `R` and `T`.
fn constant_tables(r: f32, t: f32) -> FilmTables {
    let constant = |v: f32| Lut::try_from_fn(8, 8, 1500.0, move |_, _| [v; 3]).unwrap();
    FilmTables {
        reflectivity: constant(r),
        transmittance: Some(constant(t)),
        lights: Vec::new(),
    }
}

fn camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.1, 1.2), Vec3::ZERO, Vec3::Y, 45.0)
}

#[test]
fn an_empty_scene_shows_its_environment_on_every_backend() {
    let scene = RenderScene::new(camera(), Environment::Uniform([0.25, 0.5, 0.75]));
    on_every_backend(|backend| {
        let Some(frame) = render(backend, &scene, &constant_tables(0.3, 0.7), (24, 16)) else {
            return false;
        };
        assert_eq!((frame.width(), frame.height()), (24, 16), "{backend:?}");
        for (k, p) in frame.rgb().iter().enumerate() {
            for (c, want) in p.iter().zip([0.25, 0.5, 0.75]) {
                assert!(
                    (c - want).abs() <= 2e-3,
                    "{backend:?} pixel {k}: {p:?}, want the environment"
                );
            }
        }
        true
    });
}

#[test]
fn in_a_white_furnace_a_lossless_film_is_invisible_on_every_backend() {
    // R + T = 1 (the synthetic tables, which vary R over thickness and angle; the exact
    // lossless Airy film in the reference): a film
    // in a uniform white environment passes on exactly the light it does not reflect.
    let mut scene = RenderScene::new(camera(), Environment::Uniform([1.0; 3]));
    scene.bubbles = vec![
        bubble(Vec3::new(-0.15, 0.0, 0.0), 0.25, 3, |_| 350.0),
        bubble(Vec3::new(0.2, 0.05, -0.3), 0.2, 3, |n| {
            300.0 + 500.0 * n.y.abs()
        }),
    ];
    on_every_backend(|backend| {
        let Some(frame) = render(backend, &scene, &lossless_tables(), (32, 24)) else {
            return false;
        };
        let worst = frame
            .rgb()
            .iter()
            .flatten()
            .map(|c| (c - 1.0).abs())
            .fold(0.0f32, f32::max);
        assert!(
            worst <= 1.0 / 255.0,
            "{backend:?}: a channel is {worst} off the white environment"
        );
        true
    });
}

#[test]
fn a_lossy_film_blends_as_seed_000_says_on_the_raster_backends() {
    // R = 0.3, T = 0.5 in a uniform sky of 1: the back face leaves 1·T + R = 0.8, the
    // front 0.8·T + R = 0.7. A backend that dropped a face, the transmittance or the
    // reflection would be off by at least 0.1. (The reference traces the physical film,
    // not these tables, so it is not asked.)
    let mut scene = RenderScene::new(camera(), Environment::Uniform([1.0; 3]));
    scene.bubbles = vec![bubble(Vec3::ZERO, 0.3, 3, |_| 500.0)];
    let tables = constant_tables(0.3, 0.5);
    let cpu = render(Backend::Cpu, &scene, &tables, (32, 24)).unwrap();
    let centre = cpu.rgb()[12 * 32 + 16];
    for c in centre {
        assert!((c - 0.7).abs() < 0.01, "CPU centre {centre:?}, want 0.7");
    }
    if let Some(gpu) = render(Backend::Gpu, &scene, &tables, (32, 24)) {
        let g = gpu.rgb()[12 * 32 + 16];
        for (a, b) in g.iter().zip(centre) {
            assert!((a - b).abs() < 0.01, "GPU centre {g:?} vs CPU {centre:?}");
        }
    }
}

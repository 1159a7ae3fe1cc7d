//! End-to-end laws: white furnace (R + T = 1), zero thickness is invisible, the exact
//! two-face blend, thread-count independence and NaN-freedom.

mod common;
mod threads;

use std::sync::Arc;

use common::{bubble, draining, lossless_tables, paper_scene, settings, synthetic_reflectivity};
use proptest::prelude::*;
use raster::{
    Camera, Environment, FilmTables, Frame, Ground, Light, Lut, Material, Object, PartialShading,
    ReflectionMode, RenderScene, RenderSettings, Renderer, SphereMap, ToneMap, TriMesh, Vec3,
};
use threads::on_threads;

fn render(scene: &RenderScene, tables: &FilmTables, settings: &RenderSettings) -> Frame {
    Renderer::new()
        .render(scene, tables, settings)
        .unwrap()
        .clone()
}

/// Largest per-channel difference between two frames, and where.
fn max_diff(a: &Frame, b: &Frame) -> (f32, usize) {
    a.rgb()
        .iter()
        .zip(b.rgb())
        .enumerate()
        .map(|(k, (p, q))| ((0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f32::max), k))
        .fold((0.0, 0), |m, x| if x.0 > m.0 { x } else { m })
}

fn white_furnace_scene() -> RenderScene {
    let camera = Camera::look_at(Vec3::new(0.0, 0.3, 2.5), Vec3::ZERO, Vec3::Y, 50.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([1.0; 3]));
    scene
        .bubbles
        .push(bubble(Vec3::new(-0.3, 0.0, 0.0), 0.6, 3, draining));
    scene
        .bubbles
        .push(bubble(Vec3::new(0.5, 0.2, -0.8), 0.5, 2, |n| {
            100.0 + 900.0 * n.x.abs()
        }));
    scene
}

/// Every reflection mode, the sphere map generated from `env`.
fn modes_for(env: &Environment) -> Vec<ReflectionMode> {
    let map = SphereMap::from_environment(env, 16, raster::Mat3::IDENTITY).unwrap();
    vec![
        ReflectionMode::DynamicCubeMap { face_size: 16 },
        ReflectionMode::StaticEnvironment,
        ReflectionMode::SphereMap(Arc::new(map)),
    ]
}

fn all_modes() -> Vec<ReflectionMode> {
    modes_for(&Environment::Uniform([1.0; 3]))
}

/// A short label for a mode (its Debug form would print whole textures).
fn name(mode: &ReflectionMode) -> &'static str {
    match mode {
        ReflectionMode::DynamicCubeMap { .. } => "dynamic cube map",
        ReflectionMode::StaticEnvironment => "static environment",
        ReflectionMode::SphereMap(_) => "sphere map",
    }
}

fn assert_white(frame: &Frame, label: &str) {
    for (k, p) in frame.rgb().iter().enumerate() {
        for c in p {
            assert!(
                (c - 1.0).abs() <= 1.0 / 255.0,
                "{label}: pixel {k} channel off white by {}",
                c - 1.0
            );
        }
    }
    let bytes = frame.to_srgb8(0.0, ToneMap::Clamp);
    assert!(
        bytes.iter().all(|&b| b == 255),
        "{label}: 8-bit output not all 255"
    );
}

#[test]
fn white_furnace_lossless_table_pair_is_invisible() {
    let scene = white_furnace_scene();
    let tables = lossless_tables();
    for mode in all_modes() {
        for samples in [1, 4] {
            let frame = render(&scene, &tables, &settings(48, 40, samples, mode.clone()));
            assert_white(&frame, &format!("{} {samples} spp", name(&mode)));
        }
    }
}

#[test]
fn white_furnace_default_one_minus_r_path_is_invisible() {
    let scene = white_furnace_scene();
    let mut tables = lossless_tables();
    tables.transmittance = None;
    for mode in all_modes() {
        let frame = render(&scene, &tables, &settings(48, 40, 4, mode.clone()));
        assert_white(&frame, &format!("{} 1 − R", name(&mode)));
    }
}

#[test]
fn bubble_of_zero_thickness_is_invisible() {
    // R(0, cos θ) = 0 exactly, as for a real film (the two reflections cancel).
    let r = Lut::try_from_fn(32, 8, 1000.0, |d, c| {
        let s = (std::f32::consts::PI * d / 500.0).sin();
        [0.3 * s * s, 0.2 * s * s * c, 0.25 * s * s]
    })
    .unwrap();
    let tables = FilmTables::from_reflectivity(r);
    let mut scene = paper_scene();
    scene.objects.push(Object::Box {
        center: Vec3::new(0.0, 0.25, -1.0),
        half_extents_m: Vec3::splat(0.25),
        material: Material::matte([0.7, 0.2, 0.1]),
    });
    let without = {
        let mut s = scene.clone();
        s.bubbles.clear();
        s
    };
    for b in &mut scene.bubbles {
        b.thickness_nm.fill(0.0);
    }
    for mode in all_modes() {
        let st = settings(64, 48, 4, mode.clone());
        let a = render(&scene, &tables, &st);
        let b = render(&without, &tables, &st);
        let (d, k) = max_diff(&a, &b);
        assert!(d == 0.0, "{}: pixel {k} differs by {d}", name(&mode));
    }
}

#[test]
fn two_faces_blend_exactly_once_each() {
    // Constant R = ρ and T = τ (not 1 − ρ) over a uniform environment E: inside the
    // silhouette every pixel is ((E τ + ρ E) τ + ρ E) — back face, then front face, once each.
    let (rho, tau, e) = (0.2f32, 0.7f32, 0.8f32);
    let flat = |v: f32| Lut::try_from_fn(4, 4, 1000.0, |_, _| [v; 3]).unwrap();
    let tables = FilmTables {
        reflectivity: flat(rho),
        transmittance: Some(flat(tau)),
        lights: Vec::new(),
    };
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 40.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([e; 3]));
    scene.bubbles.push(bubble(Vec3::ZERO, 0.8, 3, |_| 500.0));
    let want = (e * tau + rho * e) * tau + rho * e;
    for mode in modes_for(&scene.environment) {
        let frame = render(&scene, &tables, &settings(40, 40, 4, mode.clone()));
        // Pixels well inside the silhouette (radius ~ 0.8 / (3 tan 20°) · 20 px ≈ 14.6 px).
        for y in 12..28 {
            for x in 12..28 {
                let p = frame.pixel(x, y);
                let err = (p[0] - want).abs();
                assert!(
                    err < 1e-5,
                    "{} ({x},{y}): {} vs {want}, off by {err}",
                    name(&mode),
                    p[0]
                );
            }
        }
        // And the corners see only the environment.
        assert_eq!(frame.pixel(0, 0), [e; 3]);
    }
}

#[test]
fn output_is_bit_identical_at_1_2_and_3_threads() {
    let mut scene = paper_scene();
    scene.objects.push(Object::Sphere {
        center: Vec3::new(0.0, 0.3, -1.5),
        radius_m: 0.3,
        material: Material {
            specular: [0.5; 3],
            shininess: 40.0,
            ..Material::matte([0.2, 0.5, 0.8])
        },
    });
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    let st = settings(96, 72, 4, ReflectionMode::DynamicCubeMap { face_size: 24 });
    let frames: Vec<Frame> = [1, 2, 3]
        .iter()
        .map(|&n| on_threads(n, || render(&scene, &tables, &st)))
        .collect();
    for (n, f) in [2, 3].iter().zip(&frames[1..]) {
        let same = f
            .rgb()
            .iter()
            .zip(frames[0].rgb())
            .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
        let (d, k) = max_diff(f, &frames[0]);
        assert!(same, "{n} threads differ from 1 thread: pixel {k} by {d}");
    }
}

#[test]
fn renderer_reuse_gives_the_same_frame() {
    let scene = paper_scene();
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    let st = settings(64, 48, 4, ReflectionMode::DynamicCubeMap { face_size: 16 });
    let mut r = Renderer::new();
    let first = r.render(&scene, &tables, &st).unwrap().clone();
    // A different frame in between must leave no trace.
    r.render(
        &white_furnace_scene(),
        &tables,
        &settings(30, 70, 9, ReflectionMode::StaticEnvironment),
    )
    .unwrap();
    let again = r.render(&scene, &tables, &st).unwrap();
    assert_eq!(first.rgb(), again.rgb());
}

fn all_finite(frame: &Frame) -> Result<(), String> {
    match frame
        .rgb()
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        None => Ok(()),
        Some(k) => Err(format!("pixel {k} = {:?}", frame.rgb()[k])),
    }
}

#[test]
fn camera_inside_a_bubble_gives_no_nan_and_sees_the_film() {
    let mut scene = paper_scene();
    let inside = scene.bubbles[0].center();
    scene.camera = Camera::look_at(inside, inside + Vec3::new(0.3, -0.2, -1.0), Vec3::Y, 70.0);
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    for mode in all_modes() {
        let frame = render(&scene, &tables, &settings(48, 48, 4, mode.clone()));
        all_finite(&frame).unwrap();
        let mut no_bubbles = scene.clone();
        no_bubbles.bubbles.clear();
        let bare = render(&no_bubbles, &tables, &settings(48, 48, 4, mode.clone()));
        assert!(
            max_diff(&frame, &bare).0 > 0.0,
            "{}: film invisible from inside",
            name(&mode)
        );
    }
}

#[test]
fn degenerate_and_near_plane_crossing_geometry_gives_no_nan() {
    let mut scene = paper_scene();
    // Camera just above the ground, close to a box: triangles cross the near plane.
    scene.camera = Camera::look_at(
        Vec3::new(0.0, 0.02, 0.6),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        90.0,
    );
    scene.objects.push(Object::Box {
        center: Vec3::new(0.0, 0.2, 0.4),
        half_extents_m: Vec3::new(1.0, 0.2, 0.3),
        material: Material::checker([0.9; 3], [0.2; 3], 0.1),
    });
    // A mesh of degenerate triangles: repeated vertices, collinear points, zero normals.
    let mesh = TriMesh {
        positions: vec![
            Vec3::ZERO,
            Vec3::ZERO,
            Vec3::X,
            Vec3::X * 2.0,
            Vec3::new(0.0, 0.5, -0.5),
        ],
        normals: vec![Vec3::ZERO, Vec3::Y, Vec3::Y, Vec3::Y, Vec3::ZERO],
        uvs: Vec::new(),
        triangles: vec![[0, 1, 2], [0, 2, 3], [0, 0, 0], [0, 2, 4]],
    };
    scene.objects.push(Object::Mesh {
        mesh,
        material: Material::matte([0.5; 3]),
    });
    // A bubble with degenerate triangles and zero normals, crossing the camera's near plane.
    let mut b = bubble(Vec3::new(0.0, 0.1, 0.6), 0.15, 2, draining);
    b.triangles.push([0, 0, 1]);
    b.normals[3] = Vec3::ZERO;
    scene.bubbles.push(b);
    scene.lights[0].position = Vec3::new(0.0, 0.3, 0.55);
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    for mode in all_modes() {
        for samples in [1, 8, 16] {
            let frame = render(&scene, &tables, &settings(40, 30, samples, mode.clone()));
            all_finite(&frame).unwrap_or_else(|e| panic!("{} {samples} spp: {e}", name(&mode)));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_viewpoints_give_finite_frames(
        eye in (-3.0f32..3.0, -0.5f32..3.0, -3.0f32..3.0),
        target in (-1.0f32..1.0, 0.0f32..1.5, -1.0f32..1.0),
        vfov in 10.0f32..150.0,
        samples in prop::sample::select(vec![1u32, 4, 9]),
    ) {
        let mut scene = paper_scene();
        let eye = Vec3::new(eye.0, eye.1, eye.2);
        let target = Vec3::new(target.0, target.1, target.2);
        prop_assume!((eye - target).length() > 0.1);
        prop_assume!((eye - target).normalize().cross(Vec3::Y).length() > 0.05);
        scene.camera = Camera::look_at(eye, target, Vec3::Y, vfov);
        scene.ground = Some(Ground { height_m: 0.0, material: Material::checker([0.8; 3], [0.1; 3], 0.3) });
        scene.lights.push(Light { position: target, radius_m: 0.05, radiance: [50.0; 3], light_lut: None });
        let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
        let frame = render(&scene, &tables, &settings(24, 20, samples, ReflectionMode::DynamicCubeMap { face_size: 8 }));
        prop_assert!(all_finite(&frame).is_ok(), "{:?}", all_finite(&frame));
    }
}

/// Renders `scene` with partly covered pixels shaded per surface and per triangle.
fn both_partial_shadings(scene: &RenderScene, settings: &RenderSettings) -> (Frame, Frame) {
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    let mut renderer = Renderer::new();
    let shared = renderer.render(scene, &tables, settings).unwrap().clone();
    renderer.set_partial_shading(PartialShading::PerTriangle);
    let per_triangle = renderer.render(scene, &tables, settings).unwrap().clone();
    (shared, per_triangle)
}

#[test]
fn one_sample_has_no_partly_covered_pixels_so_both_partial_shadings_agree_exactly() {
    let mode = ReflectionMode::DynamicCubeMap { face_size: 32 };
    let (shared, per_triangle) = both_partial_shadings(&paper_scene(), &settings(96, 96, 1, mode));
    assert_eq!(max_diff(&shared, &per_triangle).0, 0.0);
}

#[test]
fn per_surface_shading_changes_only_bubble_edge_pixels_and_little() {
    let scene = paper_scene();
    let s = settings(
        160,
        160,
        4,
        ReflectionMode::DynamicCubeMap { face_size: 32 },
    );
    let (shared, per_triangle) = both_partial_shadings(&scene, &s);
    let mut no_bubbles = scene.clone();
    no_bubbles.bubbles.clear();
    let background = render(&no_bubbles, &lossless_tables(), &s);
    let (mut changed, mut rel_sum) = (0usize, 0.0f64);
    for k in 0..shared.rgb().len() {
        let (a, b) = (shared.rgb()[k], per_triangle.rgb()[k]);
        if a == b {
            continue;
        }
        // Only pixels a bubble covers may change.
        assert_ne!(
            per_triangle.rgb()[k],
            background.rgb()[k],
            "pixel ({}, {}) changed but shows no bubble",
            k % 160,
            k / 160
        );
        changed += 1;
        let luminance = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        rel_sum += f64::from((luminance(a) - luminance(b)).abs() / luminance(b).max(1e-3));
    }
    let mean_rel = rel_sum / changed.max(1) as f64;
    eprintln!("{changed} pixels changed, mean relative luminance change {mean_rel:.4}");
    // Shading is shared at all (most bubble pixels at these sizes are edge pixels) ...
    assert!(changed > 300, "only {changed} pixels changed");
    // ... and each shared shading sits less than a pixel from the one it replaces.
    assert!(mean_rel < 0.02, "mean relative luminance change {mean_rel}");
}

/// Two flat films facing the camera (which looks straight down), one behind the other, in
/// one mesh: a fold, so both sheets are the same bubble layer. The far one (listed first, so
/// blended first) is 300 nm thick, the near one 550 nm; each square is two triangles split
/// along the same diagonal. A dark ground shows through them and the bright zenith sky is
/// what they reflect, so the two sheets' films look different.
fn folded_film_scene() -> RenderScene {
    let camera = Camera::look_at(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 40.0);
    let mut scene = RenderScene::new(camera, Environment::Sky(raster::Sky::default()));
    scene.ground = Some(Ground {
        height_m: 0.0,
        material: Material::checker([0.02; 3], [0.02; 3], 1.0),
    });
    let mut film = raster::BubbleMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        thickness_nm: Vec::new(),
        triangles: Vec::new(),
        film: None,
    };
    for (y, thickness_nm) in [(0.5, 300.0), (1.0, 550.0)] {
        let first = film.positions.len() as u32;
        for (x, z) in [(-0.6, -0.6), (0.6, -0.6), (0.6, 0.6), (-0.6, 0.6)] {
            film.positions.push(Vec3::new(x, y, z));
            film.normals.push(Vec3::Y);
            film.thickness_nm.push(thickness_nm);
        }
        film.triangles.push([first, first + 1, first + 2]);
        film.triangles.push([first, first + 2, first + 3]);
    }
    scene.bubbles.push(film);
    scene
}

#[test]
fn a_fold_within_one_layer_is_shaded_per_sheet_not_shared_across_it() {
    let s = settings(120, 120, 4, ReflectionMode::StaticEnvironment);
    let (shared, per_triangle) = both_partial_shadings(&folded_film_scene(), &s);
    // Within one flat sheet of uniform thickness the shading barely varies across a pixel;
    // the other sheet's shading differs by far more (its film is another colour).
    let (worst, at) = max_diff(&shared, &per_triangle);
    assert!(
        worst < 2e-3,
        "pixel ({}, {}) differs by {worst}: a sheet reused the other sheet's shading",
        at % 120,
        at / 120
    );
}

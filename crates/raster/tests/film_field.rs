//! Bubbles with a film field (`BubbleMesh::film`): the field's thickness replaces the
//! vertex thickness, read per pixel so a stripe two texels wide reaches the screen
//! unblurred, and its coverage blends the film in (0: as if the bubble were not there).

mod common;
mod threads;

use common::{
    bubble, draining, film_field, paper_scene, settings, synthetic_reflectivity, with_film,
};
use raster::{
    Camera, Environment, FilmTables, Frame, Material, Object, ReflectionMode, RenderScene,
    RenderSettings, Renderer, Sky, Vec3,
};
use threads::on_threads;

fn render(scene: &RenderScene, tables: &FilmTables, settings: &RenderSettings) -> Frame {
    Renderer::new()
        .render(scene, tables, settings)
        .unwrap()
        .clone()
}

fn tables() -> FilmTables {
    FilmTables::from_reflectivity(synthetic_reflectivity())
}

/// Largest per-channel difference between two frames.
fn max_diff(a: &Frame, b: &Frame) -> f32 {
    a.rgb()
        .iter()
        .zip(b.rgb())
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
        .fold(0.0, f32::max)
}

fn bits(f: &Frame) -> Vec<[u32; 3]> {
    f.rgb().iter().map(|p| p.map(f32::to_bits)).collect()
}

#[test]
fn the_field_thickness_replaces_the_vertex_thickness() {
    let st = settings(64, 48, 4, ReflectionMode::DynamicCubeMap { face_size: 16 });
    let tables = tables();
    let mut by_field = paper_scene();
    by_field.bubbles[0] = with_film(
        bubble(Vec3::new(-0.55, 0.6, 0.0), 0.5, 3, |_| 300.0),
        film_field(8, |_| (650.0, 1.0)),
    );
    let mut by_vertex = paper_scene();
    by_vertex.bubbles[0] = bubble(Vec3::new(-0.55, 0.6, 0.0), 0.5, 3, |_| 650.0);
    let mut vertex_300 = paper_scene();
    vertex_300.bubbles[0] = bubble(Vec3::new(-0.55, 0.6, 0.0), 0.5, 3, |_| 300.0);
    let field = render(&by_field, &tables, &st);
    let vertex = render(&by_vertex, &tables, &st);
    let d = max_diff(&field, &vertex);
    assert!(d < 1e-4, "field 650 nm vs vertex 650 nm differ by {d}");
    // The vertex thickness would show: the test sees the difference.
    let d300 = max_diff(&field, &render(&vertex_300, &tables, &st));
    assert!(d300 > 0.05, "300 nm and 650 nm films look alike ({d300})");
}

/// A black box behind the origin: what shows through a film is dark, so its reflection
/// (of the sky) shows.
fn black_wall() -> Object {
    Object::Box {
        center: Vec3::new(0.0, 0.0, -2.0),
        half_extents_m: Vec3::new(10.0, 10.0, 0.5),
        material: Material::matte([0.0; 3]),
    }
}

/// Texels of the stripe on face +Z (face 4): columns 128 and 129 of 256.
const STRIPE: [usize; 2] = [128, 129];
const N: usize = 256;
const BASE_NM: f32 = 300.0;
const STRIPE_NM: f32 = 700.0;

/// Column coordinate (texel units, texel i centred at i) of `dir` on face +Z, if there.
fn face_z_column(dir: Vec3) -> Option<f32> {
    let (face, s, _) = render_scene::cubemap::face_coordinates(dir);
    (face == 4).then_some((s + 1.0) * 0.5 * N as f32 - 0.5)
}

#[test]
fn a_stripe_two_texels_wide_reaches_the_screen_unblurred() {
    // A bubble of radius 0.5 m filling the view from +Z: about 2 mm a pixel, the stripe
    // (2 texels of 2/256 rad on a 0.5 m sphere: 7.8 mm) is about four pixels wide, while
    // the level-5 mesh's vertices are 17 mm apart.
    let (w, h) = (256, 128);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 6.0);
    let sky = Environment::Uniform([1.0; 3]);
    let scene_with = |f: &dyn Fn(Vec3) -> f32| {
        let mut scene = RenderScene::new(camera, sky.clone());
        scene.objects = vec![black_wall()];
        let field = film_field(N, |d| (f(d), 1.0));
        scene.bubbles = vec![with_film(bubble(Vec3::ZERO, 0.5, 5, |_| 0.0), field)];
        scene
    };
    let in_stripe = |d: Vec3| {
        face_z_column(d)
            .is_some_and(|x| (x.round() as usize) == STRIPE[0] || x.round() as usize == STRIPE[1])
    };
    let st = settings(w, h, 1, ReflectionMode::StaticEnvironment);
    let tables = tables();
    let stripe = render(
        &scene_with(&|d| if in_stripe(d) { STRIPE_NM } else { BASE_NM }),
        &tables,
        &st,
    );
    let all_base = render(&scene_with(&|_| BASE_NM), &tables, &st);
    let face_stripe = render(
        &scene_with(&|d| {
            if face_z_column(d).is_some() {
                STRIPE_NM
            } else {
                BASE_NM
            }
        }),
        &tables,
        &st,
    );
    let view = camera.view(w, h);
    let (mut core, mut outside) = (0, 0);
    for py in 0..h {
        for px in 0..w {
            // Where the pixel centre's ray meets the sphere first.
            let d = view.ray(px as f32 + 0.5, py as f32 + 0.5).normalize();
            let o = view.eye;
            let b = o.dot(d);
            let disc = b * b - (o.length_squared() - 0.25);
            if disc <= 0.0 {
                continue;
            }
            let hit = o + d * (-b - disc.sqrt());
            let Some(x) = face_z_column(hit) else {
                continue;
            };
            let k = py * w + px;
            let (got, base, full) = (stripe.rgb()[k], all_base.rgb()[k], face_stripe.rgb()[k]);
            let diff =
                |a: [f32; 3], b: [f32; 3]| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max);
            // Within the stripe's two texel centres (margin for the mesh's flat
            // triangles): only stripe texels are read.
            if x > STRIPE[0] as f32 + 0.1 && x < STRIPE[1] as f32 - 0.1 {
                core += 1;
                assert!(
                    diff(full, base) > 0.02,
                    "pixel ({px}, {py}): the films look alike: {full:?} {base:?}"
                );
                let d = diff(got, full);
                assert!(
                    d < 1e-4,
                    "stripe pixel ({px}, {py}) at column {x} is off by {d}"
                );
            } else if x < STRIPE[0] as f32 - 1.1 || x > STRIPE[1] as f32 + 1.1 {
                // Beyond the bilinear reach of the stripe: the base film exactly.
                outside += 1;
                let d = diff(got, base);
                assert!(
                    d < 1e-4,
                    "pixel ({px}, {py}) at column {x} shows the stripe by {d}"
                );
            }
        }
    }
    assert!(core >= 2 * h, "only {core} pixels inside the stripe");
    assert!(outside > w * h / 4, "only {outside} pixels beside it");
}

#[test]
fn coverage_zero_is_no_film_and_coverage_half_is_the_analytic_blend() {
    let tables = tables();
    // Coverage 0 everywhere: exactly the scene without that bubble.
    let st = settings(64, 48, 4, ReflectionMode::DynamicCubeMap { face_size: 16 });
    let mut hole = paper_scene();
    hole.bubbles[0] = with_film(hole.bubbles[0].clone(), film_field(8, |_| (500.0, 0.0)));
    let mut without = paper_scene();
    without.bubbles.remove(0);
    assert_eq!(
        bits(&render(&hole, &tables, &st)),
        bits(&render(&without, &tables, &st))
    );
    let with_bubble = render(&paper_scene(), &tables, &st);
    assert!(max_diff(&with_bubble, &render(&without, &tables, &st)) > 0.05);

    // One flat layer over a background B: coverage 1 gives F = B·T + add, coverage 1/2
    // gives B·(1 − (1 − T)/2) + add/2 = (B + F)/2.
    let camera = Camera::look_at(Vec3::new(0.2, 0.3, 2.0), Vec3::ZERO, Vec3::Y, 40.0);
    let mut flat = RenderScene::new(camera, Environment::Sky(Sky::default()));
    // A lit checker wall behind: what shows through the film is neither black nor the sky.
    flat.ambient_rgb = [1.0; 3];
    flat.objects = vec![Object::Box {
        center: Vec3::new(0.0, 0.0, -2.0),
        half_extents_m: Vec3::new(10.0, 10.0, 0.5),
        material: Material::checker([0.9; 3], [0.2; 3], 0.1),
    }];
    let quad = raster::BubbleMesh {
        positions: vec![
            Vec3::new(-0.5, -0.4, 0.0),
            Vec3::new(0.5, -0.4, 0.0),
            Vec3::new(0.5, 0.4, 0.0),
            Vec3::new(-0.5, 0.4, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        thickness_nm: vec![100.0; 4],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        film: None,
    };
    let st = settings(48, 40, 4, ReflectionMode::StaticEnvironment);
    let background = render(&flat, &tables, &st);
    let frame_at = |coverage: f32, flat: &mut RenderScene| {
        // Thickness varies over the quad (material directions spread over face +Z).
        let mut q = quad.clone();
        q.film = Some(raster::BubbleFilm {
            field: std::sync::Arc::new(film_field(16, |d| (400.0 + 300.0 * d.x, coverage))),
            material_dirs: q.positions.iter().map(|p| *p + Vec3::Z).collect(),
        });
        flat.bubbles = vec![q];
        render(flat, &tables, &st)
    };
    let full = frame_at(1.0, &mut flat);
    let half = frame_at(0.5, &mut flat);
    let mut worst = 0.0f32;
    for k in 0..full.rgb().len() {
        for c in 0..3 {
            let want = 0.5 * (background.rgb()[k][c] + full.rgb()[k][c]);
            worst = worst.max((half.rgb()[k][c] - want).abs() / want.max(1e-3));
        }
    }
    assert!(
        worst < 1e-5,
        "coverage 1/2 is off the blend by {worst} (relative)"
    );
    assert!(
        max_diff(&full, &background) > 0.05,
        "the film is invisible: {}",
        max_diff(&full, &background)
    );
}

#[test]
fn film_fields_render_bit_identically_at_1_2_and_3_threads() {
    let mut scene = paper_scene();
    // Swirly thickness, partial coverage and holes.
    let swirl = |d: Vec3| {
        let h = 350.0 + 250.0 * (7.0 * d.x + 3.0 * d.y * d.z).sin();
        let c = ((d.y - 0.6) * 8.0).clamp(-1.0, 0.0) + 1.0;
        (h, c.clamp(0.0, 1.0))
    };
    scene.bubbles[0] = with_film(scene.bubbles[0].clone(), film_field(32, swirl));
    scene.bubbles[1] = with_film(
        bubble(Vec3::new(0.6, 1.1, -0.6), 0.5, 3, draining),
        film_field(5, |d| (600.0 + 100.0 * d.z, 0.7)),
    );
    let tables = tables();
    let st = settings(96, 72, 4, ReflectionMode::DynamicCubeMap { face_size: 24 });
    let frames: Vec<Vec<[u32; 3]>> = [1, 2, 3]
        .iter()
        .map(|&n| bits(&on_threads(n, || render(&scene, &tables, &st))))
        .collect();
    assert!(frames[1] == frames[0], "2 threads differ from 1");
    assert!(frames[2] == frames[0], "3 threads differ from 1");
}

#[test]
fn a_film_with_mismatched_material_directions_is_refused_naming_the_bubble() {
    let mut scene = paper_scene();
    let mut b = with_film(scene.bubbles[1].clone(), film_field(2, |_| (500.0, 1.0)));
    if let Some(f) = &mut b.film {
        f.material_dirs.pop();
    }
    scene.bubbles[1] = b.clone();
    let st = settings(16, 16, 1, ReflectionMode::StaticEnvironment);
    let err = Renderer::new()
        .render(&scene, &tables(), &st)
        .unwrap_err()
        .to_string();
    assert!(err.contains("bubble 1, film"), "{err}");
    if let Some(f) = &mut b.film {
        f.material_dirs.push(Vec3::ZERO);
    }
    scene.bubbles[1] = b;
    let err = Renderer::new()
        .render(&scene, &tables(), &st)
        .unwrap_err()
        .to_string();
    assert!(err.contains("bubble 1, film, vertex"), "{err}");
    assert!(err.contains("non-zero"), "{err}");
}

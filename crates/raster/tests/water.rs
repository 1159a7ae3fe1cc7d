//! Water optics through the public API: seed 002's sphere-map coordinates, Snell's law,
//! total internal reflection, and whole frames with a water surface.

mod threads;

use proptest::prelude::*;
use raster::{
    Camera, Environment, FilmTables, Light, Lut, Material, ReflectionMode, RenderScene,
    RenderSettings, Renderer, Sky, ToneMap, Vec3, WATER_IOR, WaterSurface, refract,
    sphere_map_direction, sphere_map_uv,
};
use threads::on_threads;

/// Asserts `|got − want| <= tol`, printing the difference.
fn assert_close(what: &str, got: f32, want: f32, tol: f32) {
    let diff = (got - want).abs();
    assert!(
        diff <= tol,
        "{what}: {got} vs {want} (off by {diff:e}, tol {tol:e})"
    );
}

proptest! {
    #[test]
    fn sphere_map_uv_stays_in_the_unit_square_for_every_direction(
        x in prop::num::f32::ANY,
        y in prop::num::f32::ANY,
        z in prop::num::f32::ANY,
    ) {
        let [u, v] = sphere_map_uv(Vec3::new(x, y, z));
        prop_assert!((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v), "({x}, {y}, {z}) -> ({u}, {v})");
    }

    #[test]
    fn sphere_map_direction_inverts_uv_on_the_far_side(
        x in -1.0f32..1.0,
        y in -1.0f32..1.0,
        z in -1.0f32..-0.05,
    ) {
        let r = Vec3::new(x, y, z).normalize();
        let back = sphere_map_direction(sphere_map_uv(r));
        prop_assert!((back - r).length() < 2e-3, "{r} -> {back}");
    }
}

#[test]
fn sphere_map_uv_is_seed_002s_linear_map() {
    assert_eq!(sphere_map_uv(Vec3::new(0.0, 0.0, -1.0)), [0.5, 0.5]);
    assert_eq!(sphere_map_uv(Vec3::new(3.0, 0.0, 0.0)), [1.0, 0.5]);
    assert_eq!(sphere_map_uv(Vec3::new(0.0, -2.0, 0.0)), [0.5, 0.0]);
    let [u, v] = sphere_map_uv(Vec3::new(0.6, 0.8, 0.0));
    assert_close("u", u, 0.8, 1e-6);
    assert_close("v", v, 0.9, 1e-6);
}

#[test]
fn snell_holds_at_several_angles_both_ways() {
    for (n1, n2) in [(1.0, WATER_IOR), (WATER_IOR, 1.0), (1.0, 1.5)] {
        let critical = if n1 > n2 {
            (n2 / n1).asin()
        } else {
            f32::INFINITY
        };
        for deg in [0.0f32, 5.0, 15.0, 30.0, 45.0, 48.0, 60.0, 75.0, 89.0] {
            let a = deg.to_radians();
            // Incident from above, in the XY plane, onto a surface with normal +Y.
            let d = Vec3::new(a.sin(), -a.cos(), 0.0);
            let t = refract(d, Vec3::Y, n1 / n2);
            if a > critical {
                assert!(
                    t.is_none(),
                    "{n1}->{n2} at {deg}°: {t:?} beyond the critical angle"
                );
                continue;
            }
            let t = t.unwrap_or_else(|| panic!("{n1}->{n2} at {deg}°: no refracted ray"));
            assert_close("|t|", t.length(), 1.0, 1e-5);
            assert_close("t.z (plane of incidence)", t.z, 0.0, 1e-6);
            assert!(
                t.y < 0.0,
                "{n1}->{n2} at {deg}°: {t} does not cross the surface"
            );
            let sin_t = t.x.hypot(t.z);
            let what = format!("{n1}->{n2} at {deg}°: n1 sin θ1 vs n2 sin θ2");
            assert_close(&what, n1 * a.sin(), n2 * sin_t, 2e-6);
        }
    }
}

/// A flat water grid of `n × n` quads over `[-half, half]²` at height 0.
fn flat_water(n: u32, half: f32, floor: Material) -> WaterSurface {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let s = |k: u32| -half + 2.0 * half * k as f32 / n as f32;
            positions.push(Vec3::new(s(i), 0.0, s(j)));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            triangles.push([v, v + n + 1, v + 1]);
            triangles.push([v + 1, v + n + 1, v + n + 2]);
        }
    }
    WaterSurface {
        normals: vec![Vec3::Y; positions.len()],
        positions,
        triangles,
        rest_height_m: 0.0,
        ior: WATER_IOR,
        floor_depth_m: 0.4,
        floor,
        absorption_per_m: [0.45, 0.06, 0.02],
    }
}

fn render(camera: Camera, water: WaterSurface, reflection: ReflectionMode) -> Vec<[f32; 3]> {
    let mut scene = RenderScene::new(camera, Environment::Sky(Sky::default()));
    scene.ambient_rgb = [0.3; 3];
    scene.water = Some(water);
    render_scene(&scene, reflection, (48, 36))
}

fn render_scene(
    scene: &RenderScene,
    reflection: ReflectionMode,
    (width, height): (usize, usize),
) -> Vec<[f32; 3]> {
    let lut = Lut::try_from_fn(8, 4, 1000.0, |_, _| [0.04; 3]).unwrap();
    let tables = FilmTables::from_reflectivity(lut);
    let settings = RenderSettings {
        width,
        height,
        samples: 1,
        reflection,
        exposure_ev: 0.0,
        tonemap: ToneMap::Clamp,
        draw_lights: true,
    };
    let mut renderer = Renderer::new();
    let frame = renderer.render(scene, &tables, &settings).unwrap();
    frame.rgb().to_vec()
}

#[test]
fn a_camera_under_the_water_sees_finite_pixels_in_every_reflection_mode() {
    let floor = Material::checker([0.8, 0.7, 0.5], [0.1, 0.2, 0.3], 0.1);
    // Looking up at the surface from 20 cm below: most of it beyond the critical angle.
    let camera = Camera::look_at(
        Vec3::new(0.0, -0.2, 0.5),
        Vec3::new(0.0, 0.2, -1.0),
        Vec3::Y,
        70.0,
    );
    for mode in [
        ReflectionMode::DynamicCubeMap { face_size: 8 },
        ReflectionMode::StaticEnvironment,
    ] {
        let pixels = render(camera, flat_water(16, 3.0, floor.clone()), mode.clone());
        let bad = pixels
            .iter()
            .filter(|p| !p.iter().all(|c| c.is_finite()))
            .count();
        assert_eq!(bad, 0, "{mode:?}: {bad} non-finite pixels");
        assert!(pixels.iter().any(|p| p[0] > 0.0), "{mode:?}: all black");
    }
}

#[test]
fn water_seen_from_above_shows_the_floor_through_it() {
    // Straight down on clear shallow water over a white floor: the floor (times the
    // transmitted 98 %) dominates the faint sky reflection (2 %).
    let mut water = flat_water(8, 2.0, Material::matte([1.0; 3]));
    water.absorption_per_m = [0.0; 3];
    let camera = Camera::look_at(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, Vec3::Z, 30.0);
    let white = render(camera, water.clone(), ReflectionMode::StaticEnvironment);
    water.floor = Material::matte([0.0; 3]);
    let black = render(camera, water, ReflectionMode::StaticEnvironment);
    let centre = 18 * 48 + 24;
    assert!(
        white[centre][1] > 10.0 * black[centre][1],
        "white floor {:?} vs black floor {:?}",
        white[centre],
        black[centre]
    );
}

#[test]
fn with_nothing_to_reflect_the_mirrored_cube_map_reflects_the_environment() {
    // No objects, no bubbles: the water's cube map holds only the sky, so the dynamic
    // mode must give the static mode's image (up to the cube map's texel filtering).
    let mut water = flat_water(8, 3.0, Material::matte([0.0; 3]));
    water.absorption_per_m = [0.0; 3];
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.3, 1.5),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        50.0,
    );
    let dynamic = render(
        camera,
        water.clone(),
        ReflectionMode::DynamicCubeMap { face_size: 64 },
    );
    let fixed = render(camera, water, ReflectionMode::StaticEnvironment);
    for (k, (d, s)) in dynamic.iter().zip(&fixed).enumerate() {
        for c in 0..3 {
            assert!(
                (d[c] - s[c]).abs() <= 0.03 * s[c].max(0.05),
                "pixel ({}, {}): dynamic {d:?} vs static {s:?}",
                k % 48,
                k / 48
            );
        }
    }
}

#[test]
fn a_lamp_shows_in_the_water_where_a_plane_mirror_puts_it() {
    // Independent truth: the reflection of a lamp at L in flat water at y = 0 lies where
    // the line from the eye to L mirrored (L.y → −L.y) crosses the water.
    let lamp = Vec3::new(0.0, 0.5, -1.0);
    let eye = Vec3::new(0.0, 0.3, 1.5);
    let camera = Camera::look_at(eye, Vec3::new(0.0, 0.0, 0.0), Vec3::Y, 50.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([0.01; 3]));
    let mut water = flat_water(8, 3.0, Material::matte([0.0; 3]));
    water.absorption_per_m = [0.0; 3];
    scene.water = Some(water);
    scene.lights.push(Light {
        position: lamp,
        radius_m: 0.1,
        radiance: [100.0; 3],
        light_lut: None,
    });
    let (w, h) = (96, 72);
    let image = render_scene(
        &scene,
        ReflectionMode::DynamicCubeMap { face_size: 64 },
        (w, h),
    );
    let mirrored = Vec3::new(lamp.x, -lamp.y, lamp.z);
    let hit = eye + (mirrored - eye) * (eye.y / (eye.y - mirrored.y));
    // The pixel row of `hit` (column: the centre, as everything lies in x = 0).
    let d = hit - eye;
    let ndc_y =
        d.dot(camera.up()) / d.dot(camera.forward()) / (camera.vfov_deg().to_radians() * 0.5).tan();
    let row = ((1.0 - ndc_y) * 0.5 * h as f32) as usize;
    let brightness = |r: usize| image[r * w + w / 2][1];
    assert!(
        brightness(row) > 5.0,
        "row {row}: {} where the lamp's mirror image should be",
        brightness(row)
    );
    for far in [row - 10, row + 10] {
        assert!(
            brightness(far) < 1.0,
            "row {far}: {} away from it",
            brightness(far)
        );
    }
    // The static mode has only the environment to reflect: no lamp.
    let plain = render_scene(&scene, ReflectionMode::StaticEnvironment, (w, h));
    assert!(
        plain[row * w + w / 2][1] < 1.0,
        "static mode: {:?}",
        plain[row * w + w / 2]
    );
}

#[test]
fn a_large_wavy_pond_renders_the_same_at_any_thread_count() {
    // 2·120² triangles: several of the set-up's parallel chunks, some clipped at the edges.
    let mut water = flat_water(120, 1.5, Material::checker([0.8; 3], [0.2; 3], 0.1));
    for (p, n) in water.positions.iter_mut().zip(&mut water.normals) {
        let phase = 9.0 * p.x + 5.0 * p.z;
        p.y = 0.01 * phase.sin();
        *n = Vec3::new(-0.09 * phase.cos(), 1.0, -0.05 * phase.cos()).normalize();
    }
    let camera = Camera::look_at(
        Vec3::new(0.2, 0.6, 1.2),
        Vec3::new(0.0, 0.0, -0.3),
        Vec3::Y,
        60.0,
    );
    let mut scene = RenderScene::new(camera, Environment::Sky(Sky::default()));
    scene.water = Some(water);
    let frames: Vec<Vec<[f32; 3]>> = [1, 2, 3]
        .iter()
        .map(|&n| {
            on_threads(n, || {
                render_scene(&scene, ReflectionMode::StaticEnvironment, (64, 48))
            })
        })
        .collect();
    for (threads, frame) in [2, 3].iter().zip(&frames[1..]) {
        let same = frame
            .iter()
            .zip(&frames[0])
            .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
        assert!(same, "{threads} threads differ from one");
    }
    let lit = frames[0].iter().filter(|c| c[0] > 0.0).count();
    assert!(lit > 64 * 48 / 2, "only {lit} pixels drawn");
}

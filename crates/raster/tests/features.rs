//! Feature checks against independent truths: cube-map contents, agreement between the
//! reflection modes, highlight placement, loaders and error messages.

mod common;

use std::sync::Arc;

use common::{bubble, settings, synthetic_reflectivity};
use raster::{
    Camera, CubeMap, Environment, FilmTables, Frame, Ground, Light, Lut, Material, Object,
    ReflectionFilter, ReflectionMode, RenderError, RenderScene, RenderSettings, Renderer, Sky,
    SphereMap, Texture, Vec3,
};

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

#[test]
fn dynamic_cube_map_sees_ground_object_and_sky() {
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.0, 4.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::Y,
        40.0,
    );
    let sky = [0.3, 0.5, 0.9];
    let mut scene = RenderScene::new(camera, Environment::Uniform(sky));
    scene.ambient_rgb = [0.5, 0.4, 0.3];
    scene.ground = Some(Ground {
        height_m: 0.0,
        material: Material::matte([0.6, 0.6, 0.2]),
    });
    scene.objects.push(Object::Box {
        center: Vec3::new(2.0, 1.0, 0.0),
        half_extents_m: Vec3::new(0.2, 0.5, 0.5),
        material: Material::matte([0.9, 0.1, 0.1]),
    });
    scene
        .bubbles
        .push(bubble(Vec3::new(0.0, 1.0, 0.0), 0.4, 2, |_| 500.0));
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    let mut r = Renderer::new();
    r.render(
        &scene,
        &tables,
        &settings(16, 16, 1, ReflectionMode::DynamicCubeMap { face_size: 32 }),
    )
    .unwrap();
    let cube = r.cube_map(0).expect("cube map of bubble 0");
    // Straight down: the ground, lit by the ambient only (albedo ⊙ ambient).
    let ground = [0.6 * 0.5, 0.6 * 0.4, 0.2 * 0.3];
    assert!(
        close(cube.sample(-Vec3::Y), ground, 1e-6),
        "down: {:?} vs {ground:?}",
        cube.sample(-Vec3::Y)
    );
    assert!(
        close(cube.sample(Vec3::Y), sky, 1e-6),
        "up: {:?}",
        cube.sample(Vec3::Y)
    );
    // +X: the box face 1.8 m away, a Lambertian lit by the ambient too.
    let red = [0.9 * 0.5, 0.1 * 0.4, 0.1 * 0.3];
    assert!(
        close(cube.sample(Vec3::X), red, 1e-6),
        "+x: {:?} vs {red:?}",
        cube.sample(Vec3::X)
    );
    // −X: nothing but sky above the horizon.
    assert!(close(cube.sample(Vec3::new(-1.0, 0.2, 0.0)), sky, 1e-6));
    // The bubble itself never appears in its own (or any) cube map.
    assert!(close(cube.sample(-Vec3::Z), sky, 1e-6) || cube.sample(-Vec3::Z)[0] != 0.0);
}

fn mean_abs_diff(a: &Frame, b: &Frame) -> f32 {
    let sum: f32 = a
        .rgb()
        .iter()
        .zip(b.rgb())
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).sum::<f32>())
        .sum();
    sum / (3 * a.rgb().len()) as f32
}

#[test]
fn reflection_modes_agree_when_only_the_environment_is_reflected() {
    // With no ground or objects, a cube map from the bubble centre holds the environment, and
    // a view-aligned sphere map holds it too: all three modes must give nearly the same image.
    let camera = Camera::look_at(Vec3::new(0.3, 0.4, 2.4), Vec3::ZERO, Vec3::Y, 45.0);
    let env = Environment::Sky(Sky {
        sun_rgb: [0.0; 3],
        ..Sky::default()
    });
    let mut scene = RenderScene::new(camera, env.clone());
    scene
        .bubbles
        .push(bubble(Vec3::ZERO, 0.7, 3, |n| 300.0 + 400.0 * (1.0 - n.y)));
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    // The cube map's content is compared with the point-sampled environment, so it is
    // read point-sampled too (its footprint filter blurs the rims: 4e-4 here).
    let render = |mode| {
        let mut r = Renderer::new();
        r.set_reflection_filter(ReflectionFilter::Bilinear);
        r.render(&scene, &tables, &settings(64, 64, 4, mode))
            .unwrap()
            .clone()
    };
    let stat = render(ReflectionMode::StaticEnvironment);
    let cube = render(ReflectionMode::DynamicCubeMap { face_size: 64 });
    let map = SphereMap::from_environment(&env, 512, camera.world_from_eye()).unwrap();
    let sphere = render(ReflectionMode::SphereMap(Arc::new(map)));
    let (dc, ds) = (mean_abs_diff(&stat, &cube), mean_abs_diff(&stat, &sphere));
    assert!(dc < 2e-4, "cube map vs environment: mean difference {dc}");
    assert!(ds < 2e-3, "sphere map vs environment: mean difference {ds}");
    // And the bubble is actually there: the frames differ from the bare sky.
    let mut bare = scene.clone();
    bare.bubbles.clear();
    let sky = Renderer::new()
        .render(
            &bare,
            &tables,
            &settings(64, 64, 4, ReflectionMode::StaticEnvironment),
        )
        .unwrap()
        .clone();
    assert!(mean_abs_diff(&stat, &sky) > 1e-3, "bubble invisible");
}

#[test]
fn highlight_sits_at_the_mirror_point_of_the_light() {
    let (center, radius) = (Vec3::ZERO, 0.8f32);
    let eye = Vec3::new(0.0, 0.0, 4.0);
    let light = Light {
        position: Vec3::new(2.0, 2.5, 3.0),
        radius_m: 0.2,
        radiance: [50.0; 3],
        light_lut: None,
    };
    let camera = Camera::look_at(eye, center, Vec3::Y, 40.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([0.0; 3]));
    scene.lights.push(light);
    scene.bubbles.push(bubble(center, radius, 4, |_| 500.0));
    let flat = |v: f32| Lut::try_from_fn(4, 4, 1000.0, |_, _| [v; 3]).unwrap();
    let tables = FilmTables::from_reflectivity(flat(0.5));
    let st = RenderSettings {
        draw_lights: false,
        ..settings(96, 96, 4, ReflectionMode::StaticEnvironment)
    };
    let frame = Renderer::new()
        .render(&scene, &tables, &st)
        .unwrap()
        .clone();
    // Mirror point on the front of the sphere: its normal bisects the directions to eye and light.
    let mut best = (f32::MAX, Vec3::ZERO);
    for i in 0..=400 {
        for j in 0..=400 {
            let (th, ph) = (
                std::f32::consts::PI * i as f32 / 400.0,
                std::f32::consts::TAU * j as f32 / 400.0,
            );
            let n = Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
            let p = center + n * radius;
            let bisector = ((eye - p).normalize() + (light.position - p).normalize()).normalize();
            let err = 1.0 - bisector.dot(n);
            if err < best.0 && (eye - p).dot(n) > 0.0 {
                best = (err, p);
            }
        }
    }
    // Project the mirror point to pixels.
    let p = best.1;
    let rel = p - eye;
    let tan_half = (20f32).to_radians().tan();
    let (f, r, u) = (camera.forward(), camera.right(), camera.up());
    let (x, y) = (
        rel.dot(r) / rel.dot(f) / tan_half,
        rel.dot(u) / rel.dot(f) / tan_half,
    );
    let (px, py) = ((x + 1.0) * 48.0, (1.0 - y) * 48.0);
    let (k, _) = frame
        .rgb()
        .iter()
        .enumerate()
        .fold((0, 0.0), |m, (k, c)| if c[0] > m.1 { (k, c[0]) } else { m });
    let (bx, by) = ((k % 96) as f32 + 0.5, (k / 96) as f32 + 0.5);
    let dist = ((bx - px).powi(2) + (by - py).powi(2)).sqrt();
    assert!(
        dist < 1.5,
        "brightest pixel at ({bx}, {by}), mirror point at ({px:.2}, {py:.2}): {dist:.2} px apart"
    );
    // Energy: a brute-force ray tracer (true sphere, 32 × 32 rays per pixel) must see the same
    // total highlight radiance over the image, front face (R·L) plus back face seen through
    // the front film (T·R·L). The sum covers every pixel the renderer lit, plus a border.
    let lit_pixels: Vec<usize> = (0..96 * 96).filter(|&k| frame.rgb()[k][0] > 0.0).collect();
    assert!(!lit_pixels.is_empty());
    let mut window = std::collections::BTreeSet::new();
    for &k in &lit_pixels {
        let (x, y) = ((k % 96) as i64, (k / 96) as i64);
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (0..96).contains(&(x + dx)) && (0..96).contains(&(y + dy)) {
                    window.insert(((y + dy) * 96 + x + dx) as usize);
                }
            }
        }
    }
    let sees_light = |p: Vec3, dir: Vec3| {
        let oc = p - light.position;
        let b = oc.dot(dir);
        let c = oc.length_squared() - light.radius_m * light.radius_m;
        b * b - c > 0.0 && -b > 0.0
    };
    let (rho, tau, l) = (0.5f32, 0.5f32, 50.0f32);
    let mut traced = 0.0f64;
    let n_sub = 32;
    for &k in &window {
        let (x, y) = ((k % 96) as f32, (k / 96) as f32);
        let mut sum = 0.0f32;
        for sy in 0..n_sub {
            for sx in 0..n_sub {
                let (px, py) = (
                    x + (sx as f32 + 0.5) / n_sub as f32,
                    y + (sy as f32 + 0.5) / n_sub as f32,
                );
                let ndc = (2.0 * px / 96.0 - 1.0, 1.0 - 2.0 * py / 96.0);
                let d = (f + r * (ndc.0 * tan_half) + u * (ndc.1 * tan_half)).normalize();
                let oc = eye - center;
                let b = oc.dot(d);
                let disc = b * b - (oc.length_squared() - radius * radius);
                if disc <= 0.0 {
                    continue;
                }
                let (t1, t2) = (-b - disc.sqrt(), -b + disc.sqrt());
                let p1 = eye + d * t1;
                let n1 = (p1 - center) / radius;
                if sees_light(p1, d - n1 * (2.0 * d.dot(n1))) {
                    sum += rho * l;
                }
                let p2 = eye + d * t2;
                let n2 = -(p2 - center) / radius;
                if sees_light(p2, d - n2 * (2.0 * d.dot(n2))) {
                    sum += tau * rho * l;
                }
            }
        }
        traced += f64::from(sum / (n_sub * n_sub) as f32);
    }
    let rendered: f64 = window.iter().map(|&k| f64::from(frame.rgb()[k][0])).sum();
    let rel = (rendered - traced).abs() / traced;
    assert!(
        traced > 0.0 && rel < 0.08,
        "rendered highlight sum {rendered:.3}, ray traced {traced:.3} ({:.1}% off)",
        rel * 100.0
    );
}

#[test]
fn settings_errors_name_the_setting() {
    let scene = common::paper_scene();
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    let cases: Vec<(RenderSettings, &str)> = vec![
        (
            RenderSettings {
                width: 0,
                ..RenderSettings::default()
            },
            "width",
        ),
        (
            RenderSettings {
                height: 20_000,
                ..RenderSettings::default()
            },
            "height",
        ),
        (
            RenderSettings {
                samples: 3,
                ..RenderSettings::default()
            },
            "samples",
        ),
        (
            RenderSettings {
                reflection: ReflectionMode::DynamicCubeMap { face_size: 0 },
                ..RenderSettings::default()
            },
            "face_size",
        ),
        (
            RenderSettings {
                exposure_ev: f32::NAN,
                ..RenderSettings::default()
            },
            "exposure_ev",
        ),
    ];
    for (st, name) in cases {
        let err = Renderer::new().render(&scene, &tables, &st).unwrap_err();
        assert!(
            matches!(&err, RenderError::InvalidSetting { name: n, .. } if *n == name),
            "{name}: {err}"
        );
        assert!(err.to_string().contains(name), "{err}");
    }
}

#[test]
fn scene_errors_name_the_element() {
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    let st = settings(8, 8, 1, ReflectionMode::StaticEnvironment);
    let check = |scene: &RenderScene, needle: &str| {
        let msg = Renderer::new()
            .render(scene, &tables, &st)
            .unwrap_err()
            .to_string();
        assert!(msg.contains(needle), "expected `{needle}` in: {msg}");
    };
    let mut s = common::paper_scene();
    s.bubbles[1].thickness_nm[5] = f32::NAN;
    check(&s, "bubble 1, vertex 5");
    let mut s = common::paper_scene();
    s.bubbles[0].thickness_nm[7] = -3.0;
    check(&s, "bubble 0, vertex 7");
    let mut s = common::paper_scene();
    s.bubbles[0].normals.pop();
    check(&s, "bubble 0");
    let mut s = common::paper_scene();
    s.bubbles[0].triangles[9] = [0, 1, 100_000];
    check(&s, "bubble 0, triangle 9");
    let mut s = common::paper_scene();
    s.lights[0].light_lut = Some(2);
    check(&s, "light 0");
    let mut s = common::paper_scene();
    s.lights[0].radius_m = 0.0;
    check(&s, "light 0");
    let mut s = common::paper_scene();
    s.ambient_rgb = [0.1, f32::INFINITY, 0.0];
    check(&s, "ambient_rgb");
    let mut s = common::paper_scene();
    s.objects.push(Object::Sphere {
        center: Vec3::ZERO,
        radius_m: -1.0,
        material: Material::matte([0.5; 3]),
    });
    check(&s, "object 0");
    let mut s = common::paper_scene();
    s.ground = Some(Ground {
        height_m: 0.0,
        material: Material::checker([0.5; 3], [0.1; 3], 0.0),
    });
    check(&s, "ground");
}

#[test]
fn loaders_read_images_and_name_bad_paths() {
    let dir = tempfile::tempdir().unwrap();
    // A 2 × 1 PNG: sRGB 255 and 128 decode to linear 1.0 and 0.2158.
    let png = dir.path().join("pano.png");
    image::RgbImage::from_raw(2, 1, vec![255, 255, 255, 128, 128, 128])
        .unwrap()
        .save(&png)
        .unwrap();
    let tex = Texture::load(&png).unwrap();
    assert_eq!(tex.texels()[0], [1.0; 3]);
    assert!(
        (tex.texels()[1][0] - 0.215_861).abs() < 1e-4,
        "{:?}",
        tex.texels()[1]
    );
    assert!(matches!(
        Environment::load_equirect(&png).unwrap(),
        Environment::Equirect(_)
    ));
    // EXR stays linear, including values above 1.
    let exr = dir.path().join("face.exr");
    image::Rgb32FImage::from_raw(2, 2, vec![2.5; 12])
        .unwrap()
        .save(&exr)
        .unwrap();
    assert_eq!(Texture::load(&exr).unwrap().texels()[3], [2.5; 3]);
    let faces = [&exr, &exr, &exr, &exr, &exr, &exr];
    let cube = CubeMap::load_faces(faces).unwrap();
    assert!(close(
        cube.sample(Vec3::new(0.3, -1.0, 0.2)),
        [2.5; 3],
        1e-6
    ));
    // Errors name the offending file.
    let missing = dir.path().join("missing.png");
    for msg in [
        Texture::load(&missing).unwrap_err().to_string(),
        SphereMap::load(&missing, raster::Mat3::IDENTITY)
            .unwrap_err()
            .to_string(),
        CubeMap::load_faces([&exr, &exr, &missing, &exr, &exr, &exr])
            .unwrap_err()
            .to_string(),
    ] {
        assert!(msg.contains("missing.png"), "{msg}");
    }
    let not_square = CubeMap::load_faces([&exr, &exr, &exr, &png, &exr, &exr])
        .unwrap_err()
        .to_string();
    assert!(
        not_square.contains("pano.png") && not_square.contains("not square"),
        "{not_square}"
    );
    let garbage = dir.path().join("garbage.png");
    std::fs::write(&garbage, b"not an image").unwrap();
    assert!(
        Texture::load(&garbage)
            .unwrap_err()
            .to_string()
            .contains("garbage.png")
    );
}

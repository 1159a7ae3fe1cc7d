//! Golden images of small scenes, compared byte for byte after tone mapping.
//!
//! Regenerate with `BLESS=1 cargo test -p raster --test goldens` and look at the PNGs
//! under `tests/images/` before committing them.

mod common;

use std::path::PathBuf;
use std::sync::Arc;

use common::{bubble, draining, paper_scene, settings, synthetic_reflectivity};
use raster::{
    Camera, CubeMap, Environment, FilmTables, Ground, Light, Lut, Material, Object, Pattern,
    ReflectionMode, RenderScene, RenderSettings, Renderer, Sky, SphereMap, Texture, ToneMap,
    TriMesh, Vec3,
};

fn check_golden(name: &str, scene: &RenderScene, tables: &FilmTables, settings: &RenderSettings) {
    let frame = Renderer::new()
        .render(scene, tables, settings)
        .unwrap()
        .clone();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/images")
        .join(format!("{name}.png"));
    if std::env::var_os("BLESS").is_some() {
        frame
            .write_png(&path, settings.exposure_ev, settings.tonemap)
            .unwrap();
        return;
    }
    assert!(
        path.exists(),
        "golden image {} is missing: run `BLESS=1 cargo test -p raster --test goldens`, inspect it, and commit it",
        path.display()
    );
    let want = image::open(&path).unwrap().to_rgb8();
    let got = frame.to_srgb8(settings.exposure_ev, settings.tonemap);
    assert_eq!(
        (want.width() as usize, want.height() as usize),
        (frame.width(), frame.height()),
        "{name}: size changed"
    );
    let diffs: Vec<usize> = got
        .iter()
        .zip(want.as_raw())
        .enumerate()
        .filter(|(_, (a, b))| a != b)
        .map(|(k, _)| k / 3)
        .collect();
    if let Some(&first) = diffs.first() {
        let worst = got
            .iter()
            .zip(want.as_raw())
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0);
        let out = std::env::temp_dir().join(format!("raster-{name}-actual.png"));
        let _ = frame.write_png(&out, settings.exposure_ev, settings.tonemap);
        panic!(
            "{name}: {} pixels differ from {} (first at x={}, y={}; worst channel off by {worst}/255); actual image written to {}",
            diffs.len(),
            path.display(),
            first % frame.width(),
            first / frame.width(),
            out.display()
        );
    }
}

/// A small procedural albedo image: stripes and a dot.
fn stripes() -> Texture {
    let n = 16;
    let texels = (0..n * n)
        .map(|k| {
            let (x, y) = (k % n, k / n);
            let r2 = (x as f32 - 7.5).powi(2) + (y as f32 - 7.5).powi(2);
            if r2 < 9.0 {
                [0.8, 0.1, 0.1]
            } else if (x / 4) % 2 == 0 {
                [0.7, 0.7, 0.6]
            } else {
                [0.2, 0.3, 0.2]
            }
        })
        .collect();
    Texture::try_new(n, n, texels).unwrap()
}

#[test]
fn golden_paper_scene_dynamic_cube_maps() {
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    check_golden(
        "paper_96x96_dynamic_4spp",
        &paper_scene(),
        &tables,
        &settings(96, 96, 4, ReflectionMode::DynamicCubeMap { face_size: 32 }),
    );
}

#[test]
fn golden_objects_static_environment() {
    let camera = Camera::look_at(
        Vec3::new(1.5, 1.4, 3.0),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::Y,
        50.0,
    );
    let sky = Sky {
        sun_rgb: [30.0, 28.0, 25.0],
        sun_direction: Vec3::new(-0.4, 0.5, -1.0),
        sun_radius_deg: 3.0,
        ..Sky::default()
    };
    let mut scene = RenderScene::new(camera, Environment::Sky(sky));
    scene.ambient_rgb = [0.4, 0.45, 0.5];
    scene.ground = Some(Ground {
        height_m: 0.0,
        material: Material {
            pattern: Pattern::Textured {
                texture: stripes(),
                scale_m: 0.8,
            },
            specular: [0.0; 3],
            shininess: 1.0,
        },
    });
    scene.objects.push(Object::Sphere {
        center: Vec3::new(-0.8, 0.35, -0.4),
        radius_m: 0.35,
        material: Material {
            specular: [0.6; 3],
            shininess: 60.0,
            ..Material::matte([0.1, 0.3, 0.8])
        },
    });
    scene.objects.push(Object::Box {
        center: Vec3::new(0.9, 0.3, -0.6),
        half_extents_m: Vec3::new(0.3, 0.3, 0.3),
        material: Material::checker([0.9, 0.8, 0.2], [0.2, 0.1, 0.05], 0.15),
    });
    let tetra = TriMesh::parse_obj(
        "v 0 0.9 0\nv -0.3 0.3 0.3\nv 0.3 0.3 0.3\nv 0 0.3 -0.3\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n",
    )
    .unwrap();
    scene.objects.push(Object::Mesh {
        mesh: tetra,
        material: Material::matte([0.2, 0.8, 0.3]),
    });
    scene.lights.push(Light {
        position: Vec3::new(1.0, 2.5, 1.5),
        radius_m: 0.1,
        radiance: [300.0; 3],
        light_lut: None,
    });
    scene
        .bubbles
        .push(bubble(Vec3::new(0.1, 0.9, 0.6), 0.45, 3, draining));
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    let mut st = settings(96, 72, 9, ReflectionMode::StaticEnvironment);
    st.tonemap = ToneMap::Reinhard;
    check_golden("objects_96x72_static_9spp", &scene, &tables, &st);
}

#[test]
fn golden_sphere_map_over_equirect_with_light_table() {
    let camera = Camera::look_at(Vec3::new(0.0, 0.2, 2.2), Vec3::ZERO, Vec3::Y, 45.0);
    let pano = Texture::try_new(
        32,
        16,
        (0..512)
            .map(|k| {
                // 16 × 8 checker cells of 2 × 2 texels: sharp features to reflect.
                let (x, y) = (k % 32 / 2, k / 32 / 2);
                if (x + y) % 2 == 0 {
                    [1.2, 0.6, 0.2]
                } else {
                    [0.05, 0.1, 0.4]
                }
            })
            .collect(),
    )
    .unwrap();
    let env = Environment::Equirect(pano);
    let map = SphereMap::from_environment(&env, 64, camera.world_from_eye()).unwrap();
    let mut scene = RenderScene::new(camera, env);
    scene.bubbles.push(bubble(Vec3::ZERO, 0.6, 3, |n| {
        200.0 + 600.0 * (1.0 - n.y) * 0.5
    }));
    scene.lights.push(Light {
        position: Vec3::new(1.0, 1.5, 2.0),
        radius_m: 0.1,
        radiance: [1.0; 3],
        light_lut: Some(0),
    });
    // A sodium-like light table: only the red-green channels answer.
    let light_table = Lut::try_from_fn(32, 8, 1000.0, |d, _| {
        let s = (d / 1000.0 * 9.0).sin();
        [400.0 * s * s, 250.0 * s * s, 0.0]
    })
    .unwrap();
    let tables = FilmTables {
        reflectivity: synthetic_reflectivity(),
        transmittance: None,
        lights: vec![light_table],
    };
    let mut st = settings(64, 64, 1, ReflectionMode::SphereMap(Arc::new(map)));
    st.tonemap = ToneMap::AcesFitted;
    st.exposure_ev = 0.5;
    check_golden("spheremap_64x64_equirect_1spp", &scene, &tables, &st);
}

#[test]
fn golden_cube_face_environment_16spp() {
    let n = 8;
    let colours = [
        [1.0, 0.3, 0.3],
        [0.3, 1.0, 0.3],
        [0.9, 0.9, 1.0],
        [0.2, 0.15, 0.1],
        [0.3, 0.3, 1.0],
        [1.0, 1.0, 0.3],
    ];
    let faces = colours.map(|c| {
        (0..n * n)
            .map(|k| c.map(|v| v * (0.5 + (k % n) as f32 / n as f32)))
            .collect()
    });
    let env = Environment::CubeFaces(CubeMap::try_from_faces(n, faces).unwrap());
    let camera = Camera::look_at(Vec3::new(0.4, 0.5, 2.0), Vec3::ZERO, Vec3::Y, 55.0);
    let mut scene = RenderScene::new(camera, env);
    scene.ambient_rgb = [0.5; 3];
    scene.objects.push(Object::Box {
        center: Vec3::new(0.0, -0.9, 0.0),
        half_extents_m: Vec3::new(1.0, 0.2, 1.0),
        material: Material::matte([0.6; 3]),
    });
    scene
        .bubbles
        .push(bubble(Vec3::new(0.0, 0.05, 0.0), 0.5, 3, draining));
    scene
        .bubbles
        .push(bubble(Vec3::new(-0.6, 0.4, -1.0), 0.35, 2, |n| {
            400.0 + 300.0 * n.x
        }));
    let tables = FilmTables::from_reflectivity(synthetic_reflectivity());
    check_golden(
        "cubefaces_64x48_dynamic_16spp",
        &scene,
        &tables,
        &settings(64, 48, 16, ReflectionMode::DynamicCubeMap { face_size: 16 }),
    );
}

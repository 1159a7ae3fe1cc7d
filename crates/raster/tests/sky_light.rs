//! The environment lights opaque surfaces ([`Irradiance`]): a ground under a bright sky
//! stays lit into the distance, and a white furnace of opaque Lambertian surfaces stays
//! exactly the furnace's radiance.

mod common;

use common::{lossless_tables, settings};
use raster::{
    Camera, Environment, Ground, Irradiance, Material, Object, ReflectionMode, RenderScene,
    Renderer, Sky, Vec3,
};

#[test]
fn far_ground_under_the_sky_is_lit_by_it() {
    // Looking at the horizon: the rows just below it are ground tens of metres away,
    // where no point light reaches (they were exactly black before the sky lit them).
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::new(0.0, 0.5, -10.0),
        Vec3::Y,
        40.0,
    );
    let env = Environment::Sky(Sky::default());
    let mut scene = RenderScene::new(camera, env.clone());
    scene.irradiance = Irradiance::from_environment(&env);
    let albedo = [0.5, 0.4, 0.3];
    scene.ground = Some(Ground {
        height_m: 0.0,
        material: Material::matte(albedo),
    });
    let mut r = Renderer::new();
    let frame = r
        .render(
            &scene,
            &lossless_tables(),
            &settings(32, 32, 1, ReflectionMode::StaticEnvironment),
        )
        .unwrap();
    let sky_light = scene.irradiance.diffuse(Vec3::Y);
    let want: [f32; 3] = std::array::from_fn(|k| albedo[k] * sky_light[k]);
    assert!(want.iter().all(|c| *c > 0.05), "a bright sky: {want:?}");
    // Every row below the horizon (row 16 is the horizon at mid-height).
    for y in 17..32 {
        for x in [0, 15, 31] {
            let got = frame.rgb()[y * 32 + x];
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() <= 1e-6 * want[k],
                    "({x},{y}) channel {k}: {} vs {} (off by {})",
                    got[k],
                    want[k],
                    got[k] - want[k]
                );
            }
        }
    }
}

#[test]
fn white_furnace_of_opaque_lambertian_surfaces_is_exact() {
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.0, 3.0),
        Vec3::new(0.0, 0.3, 0.0),
        Vec3::Y,
        50.0,
    );
    let env = Environment::Uniform([0.75; 3]);
    let mut scene = RenderScene::new(camera, env.clone());
    scene.irradiance = Irradiance::from_environment(&env);
    scene.ground = Some(Ground {
        height_m: 0.0,
        material: Material::matte([1.0; 3]),
    });
    scene.objects.push(Object::Sphere {
        center: Vec3::new(0.0, 0.5, 0.0),
        radius_m: 0.4,
        material: Material::matte([1.0; 3]),
    });
    let mut r = Renderer::new();
    for reflection in [
        ReflectionMode::StaticEnvironment,
        ReflectionMode::DynamicCubeMap { face_size: 16 },
    ] {
        let frame = r
            .render(&scene, &lossless_tables(), &settings(48, 48, 4, reflection))
            .unwrap();
        for (i, px) in frame.rgb().iter().enumerate() {
            assert_eq!(*px, [0.75; 3], "pixel {i}");
        }
    }
}

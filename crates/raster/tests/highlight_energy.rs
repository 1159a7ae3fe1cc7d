//! A light's highlight on a bubble keeps its energy whatever the light's size: lights of
//! equal power (radiance × radius² constant) leave the same total highlight in the image.

mod common;

use common::{bubble, settings};
use raster::{
    Camera, Environment, FilmTables, Light, Lut, ReflectionMode, RenderScene, RenderSettings,
    Renderer, Vec3,
};

/// Sum of the red channel over the image: a bubble of constant reflectivity 0.1 in the
/// dark, lit by one light of radius `radius_m` and power `radiance × radius²` = 1.
fn highlight_energy(radius_m: f32, light_direction: Vec3) -> f64 {
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Vec3::Y, 30.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([0.0; 3]));
    scene.bubbles.push(bubble(Vec3::ZERO, 0.3, 4, |_| 500.0));
    scene.lights.push(Light {
        position: light_direction.normalize() * 2.0,
        radius_m,
        radiance: [1.0 / (radius_m * radius_m); 3],
        light_lut: None,
    });
    let tables =
        FilmTables::from_reflectivity(Lut::try_from_fn(4, 4, 1000.0, |_, _| [0.1; 3]).unwrap());
    let settings = RenderSettings {
        draw_lights: false,
        ..settings(200, 200, 4, ReflectionMode::StaticEnvironment)
    };
    let mut r = Renderer::new();
    let frame = r.render(&scene, &tables, &settings).unwrap();
    frame.rgb().iter().map(|p| f64::from(p[0])).sum()
}

#[test]
fn highlight_energy_is_independent_of_the_light_radius_at_equal_power() {
    for direction in [Vec3::new(0.3, 0.4, 1.0), Vec3::new(-1.0, 0.2, 0.6)] {
        let energies: Vec<f64> = [0.05, 0.01, 0.002]
            .iter()
            .map(|&r| highlight_energy(r, direction))
            .collect();
        let (lo, hi) = energies
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &e| {
                (lo.min(e), hi.max(e))
            });
        assert!(lo > 0.0, "no highlight: {energies:?}");
        assert!(
            hi / lo < 1.03,
            "light {direction}: energies {energies:?} for radii 5 cm, 1 cm, 2 mm differ by {:.3}×",
            hi / lo
        );
    }
}

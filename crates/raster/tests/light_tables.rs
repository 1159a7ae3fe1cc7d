//! Light-source tables (seed 000 §4.2.1) carry the light's colour themselves.

use lut::Lut;
use raster::{
    BubbleMesh, Camera, Environment, FilmTables, Light, ReflectionMode, RenderScene,
    RenderSettings, Renderer, ToneMap, TriMesh, Vec3,
};

fn flat(rgb: [f32; 3]) -> Lut {
    Lut::try_from_fn(4, 4, 2000.0, |_, _| rgb).unwrap()
}

/// Regression: the highlight was `table ⊙ radiance`, colouring a sodium light twice.
#[test]
fn light_table_highlight_is_not_coloured_twice() {
    // A yellow light: its table holds its colour at luminance 1, its radiance the same hue.
    let hue = [2.0f32, 1.0, 0.0];
    let y = 0.2126 * hue[0] + 0.7152 * hue[1];
    let table = hue.map(|c| c / y);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 0.3), Vec3::ZERO, Vec3::Y, 30.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([0.0; 3]));
    let mesh = TriMesh::uv_sphere(Vec3::ZERO, 0.05, 64, 32);
    scene.bubbles.push(BubbleMesh {
        thickness_nm: vec![300.0; mesh.positions.len()],
        positions: mesh.positions,
        normals: mesh.normals,
        triangles: mesh.triangles,
        film: None,
    });
    scene.lights.push(Light {
        position: Vec3::new(0.0, 0.0, 2.0),
        // Wider (0.25 rad) than the highlight filter's 2σ at this resolution, so the
        // centre pixel sees the whole light, not its energy spread over a sub-pixel spot.
        radius_m: 0.5,
        radiance: hue.map(|c| c * 5.0),
        light_lut: Some(0),
    });
    let tables = FilmTables {
        reflectivity: flat([0.04; 3]),
        transmittance: None,
        lights: vec![flat(table)],
    };
    let settings = RenderSettings {
        width: 65,
        height: 65,
        samples: 1,
        reflection: ReflectionMode::StaticEnvironment,
        exposure_ev: 0.0,
        tonemap: ToneMap::Clamp,
        draw_lights: false,
    };
    let mut renderer = Renderer::new();
    let frame = renderer.render(&scene, &tables, &settings).unwrap();
    let brightest = frame
        .rgb()
        .iter()
        .copied()
        .max_by(|a, b| a[0].total_cmp(&b[0]))
        .unwrap();
    assert!(brightest[0] > 0.0, "no highlight");
    // Luminance 5 light seen through the table: exactly the table's colour times 5·y/y.
    let ratio = brightest[0] / brightest[1];
    assert!(
        (ratio - 2.0).abs() < 1e-3,
        "red/green {ratio}, want the light's 2"
    );
    // Head-on, both films reflect the light: the back film's highlight passes the front
    // film (T = 1 − 0.04) and the front adds its own, so at most table · 5y · 1.96
    // (the back film's soft visibility edge may trim a little).
    let want_red = table[0] * 5.0 * y * (1.0 + (1.0 - 0.04));
    let rel = (brightest[0] - want_red).abs() / want_red;
    assert!(rel < 0.05, "red {} vs {want_red} ({rel:e})", brightest[0]);
}

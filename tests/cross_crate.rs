//! Cross-crate tests: laws that hold end to end across thinfilm, lut, dynamics and raster.

use bubble_dynamics::{BubbleParams, World, WorldParams};
use lut::{BakeConfig, LutSet};
use raster::{
    BubbleMesh, Camera, Environment, FilmTables, Material, Object, ReflectionMode, RenderScene,
    RenderSettings, Renderer, ToneMap, TriMesh, Vec3,
};
use thinfilm::cells::cell_threshold_nm;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply};
use thinfilm::{Observer, SpectralIntegrator, ThinFilm};

fn tables(set: &LutSet) -> FilmTables {
    FilmTables {
        reflectivity: set.reflectivity.clone(),
        transmittance: Some(set.transmittance.clone()),
        lights: Vec::new(),
    }
}

/// Reflectivity texel value computed straight from the f64 optics: the film's reflected
/// D65 colour divided channel by channel by a perfect reflector's.
fn reflectivity_rgb(config: &BakeConfig, thickness_nm: f64, cos_theta: f64) -> [f64; 3] {
    let integrator = SpectralIntegrator::new(
        Observer::Cie1931,
        config.reference().spectrum(),
        config.step_nm(),
    )
    .unwrap();
    let film = ThinFilm::soap(thickness_nm);
    let rgb = apply(
        &SRGB_FROM_XYZ,
        integrator.xyz(|l| film.response(l, cos_theta).r()),
    );
    let white = apply(&SRGB_FROM_XYZ, integrator.white_xyz());
    [rgb[0] / white[0], rgb[1] / white[1], rgb[2] / white[2]]
}

fn sphere_bubble(center: Vec3, radius_m: f32, thickness_nm: f32) -> BubbleMesh {
    let mesh = TriMesh::uv_sphere(center, radius_m, 96, 48);
    BubbleMesh {
        thickness_nm: vec![thickness_nm; mesh.positions.len()],
        positions: mesh.positions,
        normals: mesh.normals,
        triangles: mesh.triangles,
        film: None,
    }
}

fn settings(width: usize, height: usize) -> RenderSettings {
    RenderSettings {
        width,
        height,
        samples: 1,
        reflection: ReflectionMode::DynamicCubeMap { face_size: 32 },
        exposure_ev: 0.0,
        tonemap: ToneMap::Clamp,
        draw_lights: false,
    }
}

/// Head-on through a bubble towards a black object in a white world: the back film
/// reflects R of the white behind the viewer, the front film passes T of that and adds
/// its own R, so the centre pixel is R·T + R, from spectrum to pixel.
#[test]
fn centre_pixel_matches_the_films_airy_colour() {
    let config = BakeConfig::default();
    let set = lut::bake(&config);
    let i = set.reflectivity.width() / 4;
    let d = set.reflectivity.thickness_nm_at(i);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 0.3), Vec3::ZERO, Vec3::Y, 30.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([1.0; 3]));
    scene.objects.push(Object::Sphere {
        center: Vec3::new(0.0, 0.0, -0.25),
        radius_m: 0.12,
        material: Material::matte([0.0; 3]),
    });
    scene.bubbles.push(sphere_bubble(Vec3::ZERO, 0.05, d));
    let mut renderer = Renderer::new();
    let frame = renderer
        .render(&scene, &tables(&set), &settings(33, 33))
        .unwrap();
    let got = frame.pixel(16, 16);
    let r = reflectivity_rgb(&config, f64::from(d), 1.0);
    for c in 0..3 {
        let want = r[c] * (1.0 - r[c]) + r[c];
        let diff = (f64::from(got[c]) - want).abs();
        assert!(
            diff < 1e-3,
            "channel {c}: pixel {} vs optics {want} (diff {diff:e})",
            got[c]
        );
    }
}

/// R + T = 1 from the spectral optics through the baked tables to the framebuffer:
/// a simulated, deformed, unevenly thick bubble in a white furnace is invisible.
#[test]
fn simulated_bubble_in_white_furnace_is_invisible() {
    let set = lut::bake(&BakeConfig::default());
    let bubble = BubbleParams {
        velocity_m_per_s: bubble_dynamics::DVec3::new(0.3, 0.0, 0.0),
        radius_m: 0.03,
        subdivisions: 3,
        seed: 5,
        ..BubbleParams::default()
    };
    let mut world = World::try_new(WorldParams::default(), vec![bubble]).unwrap();
    world.advance(0.05).unwrap();
    let b = &world.bubbles()[0];
    let camera = Camera::look_at(
        b.center_m().as_vec3() + Vec3::new(0.0, 0.0, 0.2),
        b.center_m().as_vec3(),
        Vec3::Y,
        30.0,
    );
    let mut scene = RenderScene::new(camera, Environment::Uniform([1.0; 3]));
    scene.bubbles.push(BubbleMesh {
        positions: b.positions_m().iter().map(|p| p.as_vec3()).collect(),
        normals: b.vertex_normals().iter().map(|n| n.as_vec3()).collect(),
        thickness_nm: b.thickness_nm().iter().map(|&t| t as f32).collect(),
        triangles: b.triangles().to_vec(),
        film: None,
    });
    let mut renderer = Renderer::new();
    let frame = renderer
        .render(&scene, &tables(&set), &settings(64, 64))
        .unwrap();
    let worst = frame
        .rgb()
        .iter()
        .flat_map(|p| p.iter().map(|c| (c - 1.0).abs()))
        .fold(0f32, f32::max);
    assert!(worst <= 1.0 / 255.0, "worst pixel deviates by {worst}");
}

/// Energy end to end: the renderer takes T = 1 − R from the reflectivity table. Here T is
/// integrated from the film's own transmittance spectrum (the Airy transmitted amplitudes,
/// not 1 − R) for a grid of texels, and must equal the 1 − R the renderer uses. A film
/// model that lost or made energy, or a bake that weighted R wrongly, fails here; the
/// white-furnace tests then check only that the compositing applies R and 1 − R.
#[test]
fn renderer_transmittance_equals_the_films_own_integrated_transmittance() {
    let config = BakeConfig::builder().resolution(64, 16).build().unwrap();
    let set = lut::bake(&config);
    let integrator = SpectralIntegrator::new(
        Observer::Cie1931,
        config.reference().spectrum(),
        config.step_nm(),
    )
    .unwrap();
    let white = apply(&SRGB_FROM_XYZ, integrator.white_xyz());
    let table = &set.reflectivity;
    // Near grazing the bake integrates thick films by cell means, the closed-form mean of
    // the Airy T over each cell (R = 1 − T there by construction); point samples of T would
    // miss the film's narrow lines. Those texels are checked against a fine integration in
    // crates/lut/tests/grazing_accuracy.rs; here the point-sampled ones.
    let cells = integrator.cells().unwrap();
    let point_sampled = |d: f32, c: f32| {
        cell_threshold_nm(cells, 1.0, config.film_index(), f64::from(c))
            .is_none_or(|t| f64::from(d) < t)
    };
    let (mut worst, mut checked) = (0f64, 0);
    for j in (0..table.height()).step_by(3) {
        for i in (0..table.width()).step_by(7) {
            let (d, c) = (table.thickness_nm_at(i), table.cos_theta_at(j));
            if !point_sampled(d, c) {
                continue;
            }
            checked += 1;
            let film = ThinFilm::soap(f64::from(d));
            let t = apply(
                &SRGB_FROM_XYZ,
                integrator.xyz(|l| film.response(l, f64::from(c)).t()),
            );
            for k in 0..3 {
                let renderer_t = 1.0 - f64::from(table.texel(i, j)[k]);
                worst = worst.max((renderer_t - t[k] / white[k]).abs());
            }
        }
    }
    assert!(checked > 50, "only {checked} texels checked");
    assert!(
        worst < 2e-5,
        "1 − R (renderer) differs from the integrated T spectrum by up to {worst:e}"
    );
}

/// The film-flow solver's cells and the renderers' film cube map are one layout: every
/// solver cell's centre, sampled through `FilmField`, reads back that cell's value (a
/// field that numbers its cells), and the two crates' texel directions agree.
#[test]
fn the_film_flow_grid_is_the_renderers_film_cube_map() {
    use bubble_dynamics::film_flow::{CubeSphere, grid::texel_direction};
    for n in [1, 4, 16] {
        let grid = CubeSphere::new(n);
        let cells = grid.cells();
        let thickness: Vec<f32> = (0..cells).map(|k| k as f32).collect();
        let field = raster::FilmField::try_new(n, thickness, vec![1.0; cells]).unwrap();
        for (k, centre) in grid.centres().iter().enumerate() {
            let (face, rest) = (k / (n * n), k % (n * n));
            let (y, x) = (rest / n, rest % n);
            let theirs = raster::FilmField::texel_direction(n, face, x, y);
            let ours = texel_direction(n, face, x, y).as_vec3();
            assert!(
                (theirs - ours).length() < 1e-6,
                "n {n} cell {k}: {ours} vs {theirs}"
            );
            let read = field.sample(centre.as_vec3()).thickness_nm;
            assert!(
                (read - k as f32).abs() < 1e-3,
                "n {n} cell {k} reads {read}"
            );
        }
    }
}

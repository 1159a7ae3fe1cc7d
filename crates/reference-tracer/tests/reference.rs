//! The spectral reference tracer against independent truth: the white furnace (R + T = 1
//! end to end), a flat film against `thinfilm`'s own colour, and determinism across
//! thread counts. Energy at every hit is a debug assertion inside the tracer, exercised
//! by every render here (tests build with debug assertions).

// The scene fixtures the CPU renderer's tests use, so both draw the same scenes.
#[path = "../../raster/tests/common/mod.rs"]
mod common;

use reference_tracer::{FilmSpec, ReferenceSettings, render_reference};
use render_scene::{BubbleMesh, Camera, Environment, Frame, Material, Object, RenderScene, Vec3};
use thinfilm::colorspace::{SRGB_FROM_XYZ, XYZ_FROM_SRGB, apply};
use thinfilm::{
    Illuminant, Observer, RefractiveIndex, SpectralIntegrator, ThinFilm, ciede2000, lab_from_xyz,
};

fn soap_spec(lights: usize) -> FilmSpec {
    FilmSpec {
        n_outside: 1.0,
        n_film: RefractiveIndex::SOAP,
        observer: Observer::Cie1931,
        reference: Illuminant::D65.spectrum(),
        light_spectra: vec![None; lights],
    }
}

/// Small and coarse enough for CI: few pixels, 25 nm wavelength spacing (20 wavelengths).
fn small(width: usize, height: usize) -> ReferenceSettings {
    ReferenceSettings {
        width,
        height,
        samples_per_side: 1,
        step_nm: 25.0,
        ..ReferenceSettings::default()
    }
}

fn render(scene: &RenderScene, settings: &ReferenceSettings) -> Frame {
    render_reference(scene, &soap_spec(scene.lights.len()), settings, &|| {}).unwrap()
}

#[test]
fn reference_white_furnace_is_uniform_within_one_level() {
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 0.3), Vec3::ZERO, Vec3::Y, 40.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([1.0; 3]));
    scene.bubbles = vec![
        common::bubble(Vec3::ZERO, 0.05, 3, common::draining),
        common::bubble(Vec3::new(0.03, 0.02, -0.08), 0.04, 2, |_| 650.0),
    ];
    let frame = render(&scene, &small(32, 32));
    let srgb = frame.to_srgb8(0.0, render_scene::ToneMap::Clamp);
    let worst = srgb.iter().map(|&v| 255 - i32::from(v)).max().unwrap();
    assert!(
        worst <= 1,
        "a pixel is {worst}/255 below the white background"
    );
    // The bubbles are there: some linear value is below 1 by more than rounding.
    let darkest = frame
        .rgb()
        .iter()
        .flatten()
        .fold(f32::INFINITY, |a, &b| a.min(b));
    assert!(
        darkest < 1.0 - 1e-6,
        "darkest channel {darkest}: no film was hit"
    );
}

/// A flat film square at the origin facing +Z, a black box behind it, a white sky in front.
fn flat_film_scene(thickness_nm: f32, angle_deg: f32) -> RenderScene {
    let a = angle_deg.to_radians();
    let eye = Vec3::new(0.0, a.sin(), a.cos());
    let camera = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 1.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([1.0; 3]));
    let s = 0.2;
    scene.bubbles = vec![BubbleMesh {
        positions: vec![
            Vec3::new(-s, -s, 0.0),
            Vec3::new(s, -s, 0.0),
            Vec3::new(s, s, 0.0),
            Vec3::new(-s, s, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        thickness_nm: vec![thickness_nm; 4],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        film: None,
    }];
    scene.objects = vec![Object::Box {
        center: Vec3::new(0.0, 0.0, -1.0),
        half_extents_m: Vec3::new(5.0, 5.0, 0.5),
        material: Material::matte([0.0; 3]),
    }];
    scene
}

/// `thinfilm`'s reflected colour of the film under D65 (its own 8 nm cubic quadrature),
/// in the renderer's white-divided linear sRGB.
fn thinfilm_colour(thickness_nm: f64, cos_theta: f64) -> [f64; 3] {
    let d65 = Illuminant::D65.spectrum();
    let integrator = SpectralIntegrator::new(Observer::Cie1931, &d65, 8.0).unwrap();
    let film = ThinFilm::soap(thickness_nm);
    let xyz = integrator.xyz(|w| film.response(w, cos_theta).r());
    let rgb = apply(&SRGB_FROM_XYZ, xyz);
    let white = apply(&SRGB_FROM_XYZ, integrator.white_xyz());
    [0, 1, 2].map(|c| rgb[c] / white[c])
}

fn delta_e(a: [f64; 3], b: [f64; 3]) -> f64 {
    let white = apply(&XYZ_FROM_SRGB, [1.0; 3]);
    let lab = |rgb| lab_from_xyz(apply(&XYZ_FROM_SRGB, rgb), white);
    ciede2000(lab(a), lab(b))
}

#[test]
fn flat_film_matches_thinfilm_colour_within_half_a_delta_e() {
    for (thickness_nm, angle_deg) in [(300.0f64, 0.0f64), (300.0, 60.0), (520.0, 35.0)] {
        let scene = flat_film_scene(thickness_nm as f32, angle_deg as f32);
        let frame = render(&scene, &small(3, 3));
        let got = frame.pixel(1, 1).map(f64::from);
        let want = thinfilm_colour(thickness_nm, angle_deg.to_radians().cos());
        let de = delta_e(got, want);
        assert!(
            de < 0.5,
            "{thickness_nm} nm at {angle_deg}°: reference {got:?} vs thinfilm {want:?}, ΔE {de}"
        );
    }
}

#[test]
fn rgb_mode_matches_the_spectral_film_on_white_light() {
    // On a white environment the LUT's RGB projection is exact, so the two modes agree up
    // to the uplift of white, which is flat only to about 1e-3 (Smits' white basis).
    let scene = flat_film_scene(400.0, 45.0);
    let spectral = render(&scene, &small(3, 3)).pixel(1, 1).map(f64::from);
    let rgb_mode = ReferenceSettings {
        spectral: false,
        ..small(3, 3)
    };
    let rgb = render(&scene, &rgb_mode).pixel(1, 1).map(f64::from);
    let de = delta_e(spectral, rgb);
    assert!(de < 1e-2, "{spectral:?} vs {rgb:?}: ΔE {de}");
}

#[test]
fn same_image_at_one_and_two_threads() {
    let scene = common::paper_scene();
    let settings = ReferenceSettings {
        samples_per_side: 2,
        ..small(12, 12)
    };
    let at = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, &settings))
    };
    assert_eq!(at(1).rgb(), at(2).rgb());
}

#[test]
fn bad_settings_are_named() {
    let scene = flat_film_scene(300.0, 0.0);
    let bad = ReferenceSettings {
        samples_per_side: 0,
        ..small(3, 3)
    };
    let err = render_reference(&scene, &soap_spec(0), &bad, &|| {}).unwrap_err();
    assert!(err.to_string().contains("samples_per_side"), "{err}");
    let err = render_reference(&scene, &soap_spec(2), &small(3, 3), &|| {}).unwrap_err();
    assert!(err.to_string().contains("light spectra"), "{err}");
}

#[test]
fn unpolarised_chord_product_overestimates_the_polarised_one_at_60_degrees() {
    // Issue 13's figure: a 300 nm film at 60°, 450 nm. Along a chord the s and p axes are
    // shared, so the light reflected off the back film and sent through the front one is
    // (R_s T_s + R_p T_p)/2, not the product of the unpolarised means the CPU composites.
    let r = ThinFilm::soap(300.0).response(450.0, 60f64.to_radians().cos());
    let polarised = 0.5 * (r.r_s * r.t_s + r.r_p * r.t_p);
    let unpolarised = r.r() * r.t();
    let excess = unpolarised / polarised - 1.0;
    assert!(
        (0.1..0.4).contains(&excess),
        "unpolarised product {unpolarised} vs polarised {polarised}: {:.1} % brighter",
        100.0 * excess
    );
}

fn max_diff(a: &Frame, b: &Frame) -> f32 {
    a.rgb()
        .iter()
        .zip(b.rgb())
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
        .fold(0.0, f32::max)
}

#[test]
fn reference_reads_the_film_field_thickness_over_the_vertex_thickness() {
    let settings = small(8, 8);
    let mut by_field = flat_film_scene(300.0, 20.0);
    let quad = &mut by_field.bubbles[0];
    quad.film = Some(render_scene::BubbleFilm {
        field: std::sync::Arc::new(common::film_field(4, |_| (650.0, 1.0))),
        material_dirs: quad.positions.iter().map(|p| *p + Vec3::Z).collect(),
    });
    let field = render(&by_field, &settings);
    let vertex = render(&flat_film_scene(650.0, 20.0), &settings);
    let d = max_diff(&field, &vertex);
    assert!(d < 1e-4, "field 650 nm vs vertex 650 nm differ by {d}");
    let d300 = max_diff(&field, &render(&flat_film_scene(300.0, 20.0), &settings));
    assert!(d300 > 0.02, "300 nm and 650 nm films look alike ({d300})");
}

#[test]
fn reference_coverage_zero_is_no_film_and_coverage_half_the_blend() {
    let settings = small(12, 12);
    let mut scene = common::paper_scene();
    scene.ground = None;
    let mut hole = scene.clone();
    hole.bubbles[0] = common::with_film(
        hole.bubbles[0].clone(),
        common::film_field(4, |_| (500.0, 0.0)),
    );
    let mut without = scene.clone();
    without.bubbles.remove(0);
    let (hole, without, with) = (
        render(&hole, &settings),
        render(&without, &settings),
        render(&scene, &settings),
    );
    let d = max_diff(&hole, &without);
    assert!(d < 1e-4, "a film of coverage 0 shows by {d}");
    assert!(max_diff(&with, &without) > 0.02, "the bubble is invisible");

    // One flat film over a lit grey box under a white sky: coverage c gives
    // (1 − c)·B + c·F (the box is not black, so the film's transmittance shows).
    let settings = small(6, 6);
    let mut bare = flat_film_scene(400.0, 20.0);
    bare.ambient_rgb = [1.0; 3];
    if let Object::Box { material, .. } = &mut bare.objects[0] {
        *material = Material::matte([0.6; 3]);
    }
    let film = bare.bubbles.remove(0);
    let background = render(&bare, &settings);
    let at = |coverage: f32| {
        let mut s = bare.clone();
        let mut f = film.clone();
        f.film = Some(render_scene::BubbleFilm {
            field: std::sync::Arc::new(common::film_field(4, move |_| (400.0, coverage))),
            material_dirs: f.positions.iter().map(|p| *p + Vec3::Z).collect(),
        });
        s.bubbles = vec![f];
        render(&s, &settings)
    };
    let (full, half) = (at(1.0), at(0.5));
    for k in 0..full.rgb().len() {
        for c in 0..3 {
            let want = 0.5 * (background.rgb()[k][c] + full.rgb()[k][c]);
            let got = half.rgb()[k][c];
            assert!(
                (got - want).abs() < 1e-5 * want.max(1.0),
                "pixel {k}: {got} vs {want}"
            );
        }
    }
    assert!(max_diff(&full, &background) > 0.02, "the film is invisible");
}

/// Mean and 95th percentile (nearest rank) of the per-pixel ΔE2000 between two frames as
/// `bubbles compare` sees them: 8-bit sRGB after the ACES curve, then CIELAB.
fn displayed_delta_e(a: &Frame, b: &Frame) -> (f64, f64) {
    let lab = |f: &Frame| -> Vec<thinfilm::Lab> {
        let srgb = f.to_srgb8(0.0, render_scene::ToneMap::AcesFitted);
        let white = apply(&XYZ_FROM_SRGB, [1.0; 3]);
        srgb.chunks(3)
            .map(|p| {
                let lin = [0, 1, 2].map(|c| decode_srgb(f64::from(p[c]) / 255.0));
                lab_from_xyz(apply(&XYZ_FROM_SRGB, lin), white)
            })
            .collect()
    };
    let mut de: Vec<f64> = lab(a)
        .into_iter()
        .zip(lab(b))
        .map(|(p, q)| ciede2000(p, q))
        .collect();
    de.sort_by(f64::total_cmp);
    let mean = de.iter().sum::<f64>() / de.len() as f64;
    let rank = (0.95 * de.len() as f64).ceil() as usize;
    (mean, de[rank.clamp(1, de.len()) - 1])
}

/// The sRGB transfer function's inverse.
fn decode_srgb(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Mean ΔE2000 two seeds of the converged test image may differ by.
const MEAN_BOUND: f64 = 0.25;
/// 95th-percentile ΔE2000 two seeds of the converged test image may differ by.
const P95_BOUND: f64 = 1.2;

/// Two sampling seeds of the paper scene with `settings` otherwise.
fn two_seeds(settings: &ReferenceSettings) -> (f64, f64) {
    let scene = common::paper_scene();
    let seed = |seed| {
        render(
            &scene,
            &ReferenceSettings {
                seed,
                ..settings.clone()
            },
        )
    };
    displayed_delta_e(&seed(0), &seed(1))
}

/// The converged reference: two seeds agree (0.196 / 0.907 here) where the old sampling
/// (16 point-sampled rays, no refinement) misses the bound by far (1.683 / 6.836), so the
/// bound tells converged from not; a tolerance of 0.3, at most 64 rays or no texture
/// filtering each miss it too. 24 × 24, 25 nm wavelengths and 2 films a path, for CI's
/// time: the sampling is what is tested. (Issue 25 asks mean ≤ 0.05 and p95 ≤ 0.5 of the
/// 400 × 400 image, whose pixels each hold far less detail.)
#[test]
fn two_seeds_agree_as_a_converged_reference_must() {
    let converged = ReferenceSettings {
        width: 24,
        height: 24,
        step_nm: 25.0,
        max_depth: 2,
        ..ReferenceSettings::default()
    };
    let old = ReferenceSettings {
        max_samples: 16,
        filter_textures: false,
        ..converged.clone()
    };
    let (mean, p95) = two_seeds(&converged);
    let (old_mean, old_p95) = two_seeds(&old);
    eprintln!(
        "two seeds differ by mean {mean:.3}, p95 {p95:.3}; with the old sampling by mean \
         {old_mean:.3}, p95 {old_p95:.3}"
    );
    assert!(
        mean <= MEAN_BOUND && p95 <= P95_BOUND,
        "two seeds differ by mean {mean:.3}, p95 {p95:.3}"
    );
    assert!(
        old_mean > MEAN_BOUND && old_p95 > P95_BOUND,
        "the old sampling meets the bound too: mean {old_mean:.3}, p95 {old_p95:.3}"
    );
}

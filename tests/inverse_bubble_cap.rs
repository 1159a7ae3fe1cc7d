//! A bubble's cap with swirls from our own film solver, photographed through the exact
//! spectrum and a faulty camera, then recovered by `film_inverse` with the sphere's
//! per-pixel viewing angle (the second synthetic case).
//!
//! `cargo test --release -p integration-tests --test inverse_bubble_cap -- --nocapture`
//! prints the errors.

use std::sync::Arc;

use bubble_dynamics::film_flow::{CubeSphere, FilmFlow, FlowParams, Forcing, Hierarchy};
use film_inverse::synth::{CameraModel, film_colours, nominal_exposure, photograph8};
use film_inverse::{Camera, FilmModel, Photo, Settings, Viewing, recover};
use glam::{DVec3, Vec3};
use render_scene::film_field::FilmField;
use thinfilm::Illuminant;

/// Image size and the disc the bubble fills.
const SIZE: u32 = 160;
const RADIUS_PX: f64 = 76.0;

/// A 5 cm bubble's film, 250 nm at the top to 950 nm at the bottom, stirred by a vortex
/// and drained under gravity with a side wind for 2 s.
fn swirled_film() -> FilmField {
    let grid = Arc::new(CubeSphere::new(32));
    let hierarchy = Arc::new(Hierarchy::new(&grid));
    let mut params = FlowParams::water_film(0.05);
    params.burst.rupture_thickness_nm = 0.0;
    params.burst.black_threshold_nm = 0.0;
    let mut film = FilmFlow::new(grid.clone(), hierarchy, params, |d| {
        (600.0 - 350.0 * d.y) * 1e-9
    });
    film.set_velocity(|d| 0.02 * DVec3::new(-d.y, d.x, 0.0) + 0.015 * DVec3::new(0.0, -d.z, d.y));
    let forcing = Forcing {
        g_eff_m_per_s2: DVec3::new(0.0, -9.81, 0.0),
        air_m_per_s: DVec3::new(0.05, 0.0, 0.0),
    };
    for _ in 0..120 {
        film.step(1.0 / 60.0, &forcing);
    }
    let thickness: Vec<f32> = film
        .thickness_m()
        .iter()
        .map(|h| (h * 1e9) as f32)
        .collect();
    let coverage = vec![1.0; thickness.len()];
    FilmField::try_new(32, thickness, coverage).unwrap()
}

/// Per pixel of the image: the film's thickness and cos θ where the cap is seen, and
/// `None` outside the disc (the convention of `Viewing::Sphere`: pixel centres).
fn cap(field: &FilmField) -> Vec<Option<(f32, f32)>> {
    let c = f64::from(SIZE) / 2.0;
    (0..SIZE * SIZE)
        .map(|i| {
            let x = (f64::from(i % SIZE) + 0.5 - c) / RADIUS_PX;
            let y = (f64::from(i / SIZE) + 0.5 - c) / RADIUS_PX;
            let s2 = x * x + y * y;
            (s2 < 1.0).then(|| {
                let n = Vec3::new(x as f32, -y as f32, (1.0 - s2).sqrt() as f32);
                (field.sample(n).thickness_nm, n.z)
            })
        })
        .collect()
}

#[test]
fn a_swirled_bubble_cap_is_recovered_within_20_nm_with_no_order_errors() {
    let field = swirled_film();
    let pixels = cap(&field);
    let truth: Vec<f32> = pixels.iter().map(|p| p.map_or(0.0, |p| p.0)).collect();
    let cos: Vec<f32> = pixels.iter().map(|p| p.map_or(1.0, |p| p.1)).collect();
    let model = FilmModel::soap(&Illuminant::D65.spectrum());
    let mut colours = film_colours(&model, &truth, &cos, true);
    for (c, p) in colours.iter_mut().zip(&pixels) {
        if p.is_none() {
            *c = [0.0; 3]; // black background around the bubble
        }
    }
    // Exposed for the brighter, more oblique rim: the head-on nominal exposure × 0.35,
    // then off by +10 % and ±5 % white balance.
    let camera = Camera {
        exposure: nominal_exposure(&model) * 0.35 * 1.1,
        gains: [1.05, 1.0, 0.95],
    };
    let px = photograph8(
        &colours,
        &CameraModel {
            camera,
            noise: 0.02,
            seed: 11,
        },
    );
    let photo = Photo::try_from_srgb8(SIZE, SIZE, &px).unwrap();
    let viewing = Viewing::Sphere {
        centre_px: [f64::from(SIZE) / 2.0; 2],
        radius_px: RADIUS_PX,
    };
    let map = recover(
        &photo,
        &model,
        &Settings {
            viewing,
            ..Settings::default()
        },
    )
    .unwrap();

    let e = film_inverse::synth::errors(&map, &truth);
    let fitted = map.summary.fitted;
    let inside = pixels.iter().filter(|p| p.is_some()).count();
    let (rms, order_errors) = (e.rms_nm, e.order_errors);
    let (lo, hi) = truth
        .iter()
        .zip(&pixels)
        .filter(|(_, p)| p.is_some())
        .fold((f32::MAX, 0f32), |(l, h), (t, _)| (l.min(*t), h.max(*t)));
    println!(
        "cap {lo:.0}–{hi:.0} nm: RMS {rms:.2} nm, order errors {:.3} %, fitted {fitted} of {inside}, {:?}",
        order_errors * 100.0,
        map.summary
    );
    assert!(
        hi - lo > 300.0,
        "the cap spans more than an order: {lo}–{hi}"
    );
    assert!(rms <= 20.0, "RMS {rms:.2} nm");
    assert!(order_errors <= 0.01, "order errors {order_errors:.4}");
    // The rim reflects up to everything at grazing incidence, so some of it saturates
    // at any exposure that shows the cap: those pixels are refused, not fitted.
    let unsaturated = inside - map.summary.saturated;
    assert!(
        fitted as f64 >= 0.95 * unsaturated as f64,
        "fitted {fitted} of {unsaturated} unsaturated"
    );
}

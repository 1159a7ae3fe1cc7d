//! `bubbles thickness`: a synthetic photo of a draining film through the CLI (EXR map
//! against the truth, the figures, the JSON summary), and bad input refused with exit 2.

use std::path::Path;
use std::process::Output;

mod common;
use common::{bubbles, json_field};

use film_inverse::synth::{
    CameraModel, draining_film, film_colours, nominal_exposure, photograph8,
};
use film_inverse::{Camera, FilmModel};
use thinfilm::Illuminant;

const W: u32 = 80;
const H: u32 = 120;

/// Writes the tests' standard shot (exposure +10 %, white balance ±5 %, 2 % shot noise)
/// of a film draining from black film to `max_nm`; returns the truth.
fn write_photo(path: &Path, max_nm: f64) -> Vec<f32> {
    let model = FilmModel::soap(&Illuminant::D65.spectrum());
    let truth = draining_film(W, H, max_nm);
    let colours = film_colours(&model, &truth, &vec![1.0; truth.len()], true);
    let camera = Camera {
        exposure: nominal_exposure(&model) * 1.1,
        gains: [1.05, 1.0, 0.95],
    };
    let px = photograph8(
        &colours,
        &CameraModel {
            camera,
            noise: 0.02,
            seed: 3,
        },
    );
    image::RgbImage::from_raw(W, H, px)
        .unwrap()
        .save(path)
        .unwrap();
    truth
}

#[track_caller]
fn assert_refused(out: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "{needle:?} missing from: {stderr}");
    }
}

#[test]
fn a_photo_of_a_draining_film_gives_its_thickness_map_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let truth = write_photo(&dir.path().join("film.png"), 1100.0);
    let out = bubbles(
        &["thickness", "film.png", "--out", "map.exr", "--json"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = String::from_utf8(out.stdout).unwrap();
    assert_eq!(json_field(&json, "width"), f64::from(W));
    assert!(json_field(&json, "residual_mean_de") < 3.0, "{json}");
    let map = image::open(dir.path().join("map.exr"))
        .unwrap()
        .to_rgba32f();
    let (mut sum2, mut n, mut wrong) = (0.0, 0usize, 0usize);
    for (p, t) in map.pixels().zip(&truth) {
        if p[3] == 1.0 {
            let e = f64::from(p[0] - t);
            if e.abs() > 100.0 {
                wrong += 1
            } else {
                sum2 += e * e
            }
            n += 1;
            assert!(p[1] > 0.0 && p[1].is_finite(), "uncertainty {}", p[1]);
        } else {
            assert_eq!(
                (p[0], p[1], p[2]),
                (0.0, 0.0, 0.0),
                "a masked pixel has no values"
            );
        }
    }
    assert!(n as f64 >= 0.9 * truth.len() as f64, "fitted {n}");
    assert!(wrong == 0, "{wrong} order errors");
    assert!(
        (sum2 / n as f64).sqrt() < 20.0,
        "RMS {}",
        (sum2 / n as f64).sqrt()
    );
    for figure in ["map.png", "map.rerender.png", "map.residual.png"] {
        let img = image::open(dir.path().join(figure)).unwrap();
        assert!(
            img.width() >= W && img.height() == H,
            "{figure} is {}x{}",
            img.width(),
            img.height()
        );
    }
    assert_eq!(
        image::open(dir.path().join("map.rerender.png"))
            .unwrap()
            .width(),
        2 * W
    );
}

#[test]
fn an_anchor_outside_the_photo_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    write_photo(&dir.path().join("film.png"), 600.0);
    let out = bubbles(
        &[
            "thickness",
            "film.png",
            "--out",
            "m.exr",
            "--anchor",
            "500,3=300",
        ],
        dir.path(),
    );
    assert_refused(&out, &["anchor 500,3=300", "outside the 80x120 photo"]);
    assert!(!dir.path().join("m.exr").exists());
}

#[test]
fn an_angle_map_of_the_wrong_size_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    write_photo(&dir.path().join("film.png"), 600.0);
    image::Rgb32FImage::from_pixel(10, 10, image::Rgb([30.0, 0.0, 0.0]))
        .save(dir.path().join("angles.exr"))
        .unwrap();
    let out = bubbles(
        &[
            "thickness",
            "film.png",
            "--out",
            "m.exr",
            "--angle-map",
            "angles.exr",
        ],
        dir.path(),
    );
    assert_refused(
        &out,
        &["angle map angles.exr is 10x10 but the photo is 80x120"],
    );
}

#[test]
fn an_unwritable_output_is_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    write_photo(&dir.path().join("film.png"), 600.0);
    std::fs::create_dir(dir.path().join("map.png")).unwrap();
    let out = bubbles(&["thickness", "film.png", "--out", "map.exr"], dir.path());
    assert_refused(&out, &["--out map.png: is a directory"]);
    let out = bubbles(
        &["thickness", "film.png", "--out", "no/such/dir/m.exr"],
        dir.path(),
    );
    assert_refused(&out, &["does not exist"]);
    assert!(!dir.path().join("map.exr").exists(), "nothing is written");
}

#[test]
fn an_output_that_would_overwrite_the_photo_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    write_photo(&dir.path().join("map.png"), 600.0);
    let before = std::fs::read(dir.path().join("map.png")).unwrap();
    let out = bubbles(&["thickness", "map.png", "--out", "./map.exr"], dir.path());
    assert_refused(&out, &["--out ./map.png is the input map.png"]);
    assert_eq!(std::fs::read(dir.path().join("map.png")).unwrap(), before);
}

#[test]
fn a_saturated_photo_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(20, 20, image::Rgb([255, 255, 240]))
        .save(dir.path().join("white.png"))
        .unwrap();
    let out = bubbles(&["thickness", "white.png", "--out", "m.exr"], dir.path());
    assert_refused(&out, &["the photo is saturated: 400 of 400"]);
}

#[test]
fn an_unreadable_photo_and_out_of_range_settings_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("junk.png"), b"not a png").unwrap();
    assert_refused(
        &bubbles(&["thickness", "junk.png", "--out", "m.exr"], dir.path()),
        &["junk.png"],
    );
    write_photo(&dir.path().join("film.png"), 600.0);
    let cases: [(&[&str], &str); 6] = [
        (&["--thickness-max-nm", "1e308"], "thickness_max_nm 1e308"),
        (&["--n-outside", "1e-300"], "n_outside 1e-300"),
        (&["--n-film", "glass"], "--n-film `glass`"),
        (
            &["--white", "70,100,20,30"],
            "white region 70,100,20,30 is outside",
        ),
        (&["--exposure", "-1"], "exposure -1"),
        (&["--sphere", "40,60"], "--sphere `40,60` is not 3"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["thickness", "film.png", "--out", "m.exr"];
        args.extend_from_slice(extra);
        assert_refused(&bubbles(&args, dir.path()), &[needle]);
    }
    assert_refused(
        &bubbles(&["thickness", "film.png", "--out", "m.png"], dir.path()),
        &["is an EXR file"],
    );
}

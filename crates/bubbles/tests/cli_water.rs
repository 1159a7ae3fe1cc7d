//! The `[water]` scene section end to end (issue 11): bad values are refused naming their
//! key, the waves move with `--time-s`, a camera under the water renders without NaN,
//! and golden images of the built-in `pond` at two times.
//!
//! Regenerate the goldens with `BLESS=1 cargo test -p bubbles --test cli_water` and look
//! at the PNGs under `tests/images/` before committing them.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{bubbles, stderr};

const CAMERA: &str = "[camera]\neye_m = [0.0, 0.4, 1.2]\ntarget_m = [0.0, 0.0, 0.0]\n";

const WATER: &str = "[water]\nmin_m = [-2.0, -2.0]\nmax_m = [2.0, 2.0]\nslices = [48, 48]\n\
                     [[water.waves]]\namplitude_m = 0.02\nwavelength_m = 0.4\ndirection = [1.0, 0.0]\n";

/// Writes `text` as `s.toml` in a new directory.
fn scene(text: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), text).unwrap();
    dir
}

fn render(dir: &Path, scene: &str, out: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        scene,
        "--out",
        out,
        "--width",
        "48",
        "--height",
        "36",
        "--samples",
        "1",
        "--cube-map-size",
        "8",
    ];
    args.extend(extra);
    bubbles(&args, dir)
}

/// Asserts exit code 2, no output file, and that stderr names every one of `needles`.
fn refused(text: &str, needles: &[&str]) {
    let dir = scene(text);
    let out = render(dir.path(), "s.toml", "x.png", &[]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{text}\nstderr: {err}");
    assert!(
        !dir.path().join("x.png").exists(),
        "refused run wrote a file"
    );
    for needle in needles {
        assert!(err.contains(needle), "{needle:?} missing from: {err}");
    }
}

#[test]
fn bad_water_values_are_refused_naming_the_key_and_value() {
    let cases: [(&str, &str, &[&str]); 9] = [
        (
            "slices = [48, 48]",
            "slices = [100000, 4]",
            &["slices", "100000"],
        ),
        ("slices = [48, 48]", "slices = [0, 4]", &["slices", "0"]),
        (
            "max_m = [2.0, 2.0]",
            "max_m = [-3.0, 2.0]",
            &["min_m", "max_m"],
        ),
        (
            "min_m = [-2.0, -2.0]",
            "min_m = [-2.0, nan]",
            &["min_m", "NaN"],
        ),
        (
            "amplitude_m = 0.02",
            "amplitude_m = 1e300",
            &["amplitude_m", "1e300"],
        ),
        (
            "wavelength_m = 0.4",
            "wavelength_m = 0.0",
            &["wavelength_m", "0"],
        ),
        (
            "direction = [1.0, 0.0]",
            "direction = [0.0, 0.0]",
            &["direction", "[0, 0]"],
        ),
        (
            "direction = [1.0, 0.0]",
            "direction = [1.0, 0.0]\nomega_rad_per_s = -2.0",
            &["omega_rad_per_s", "-2"],
        ),
        (
            "slices = [48, 48]",
            "slices = [48, 48]\nior = inf",
            &["ior", "inf"],
        ),
    ];
    for (from, to, needles) in cases {
        assert!(WATER.contains(from), "{from}");
        refused(&format!("{CAMERA}{}", WATER.replace(from, to)), needles);
    }
}

#[test]
fn too_many_waves_are_refused() {
    let wave = "[[water.waves]]\namplitude_m = 0.001\nwavelength_m = 0.4\ndirection = [1.0, 0.0]\n";
    let text = format!("{CAMERA}{WATER}{}", wave.repeat(64));
    refused(&text, &["65 waves and ripples", "64"]);
}

#[test]
fn waves_move_with_time() {
    let dir = scene(&format!("{CAMERA}{WATER}"));
    let frames: Vec<Vec<u8>> = ["0", "0", "0.3"]
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let name = format!("t{k}.png");
            let out = render(dir.path(), "s.toml", &name, &["--time-s", t]);
            assert!(out.status.success(), "{}", stderr(&out));
            image::open(dir.path().join(name))
                .unwrap()
                .to_rgb8()
                .into_raw()
        })
        .collect();
    assert_eq!(frames[0], frames[1], "the same time renders the same image");
    let changed = frames[0]
        .iter()
        .zip(&frames[2])
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        changed > frames[0].len() / 10,
        "only {changed} of {} channels changed after 0.3 s",
        frames[0].len()
    );
}

#[test]
fn a_camera_under_the_water_renders_finite_pixels() {
    // Looking up at the surface from below: total internal reflection beyond 48.6°.
    let text = format!("[camera]\neye_m = [0.0, -0.2, 0.8]\ntarget_m = [0.0, 0.3, -1.0]\n{WATER}");
    let dir = scene(&text);
    let out = render(dir.path(), "s.toml", "u.exr", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.path().join("u.exr")).unwrap().to_rgb32f();
    let bad = img
        .pixels()
        .filter(|p| !p.0.iter().all(|c| c.is_finite()))
        .count();
    assert_eq!(bad, 0, "{bad} non-finite pixels");
    assert!(img.pixels().any(|p| p.0[0] > 0.0), "an all-black frame");
}

#[test]
fn a_bubble_thrown_down_bounces_on_the_waters_rest_plane() {
    // Thrown down at 0.5 m/s from 3 cm above contact with a rest plane at y = 0.05 (the
    // floor is 0.5 m deeper): with the rest-plane collider its centre never gets below
    // the plane, and it comes close; without it, it sinks through within 0.2 s.
    let text = format!(
        "{CAMERA}{}\n[[bubbles]]\ncenter_m = [0.0, 0.12, 0.0]\nradius_m = 0.04\n\
         velocity_m_per_s = [0.0, -0.5, 0.0]\n",
        WATER.replace("slices = [48, 48]", "slices = [8, 8]\nrest_height_m = 0.05")
    );
    let dir = scene(&text);
    let centre_y = |seconds: &str| {
        let args = ["simulate", "s.toml", "--seconds", seconds, "--json"];
        let out = bubbles(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        json["bubbles"][0]["center_m"][1].as_f64().unwrap()
    };
    let heights: Vec<f64> = ["0.05", "0.1", "0.2", "0.4"].map(centre_y).to_vec();
    let lowest = heights.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        lowest > 0.05 + 0.02,
        "centre heights {heights:?}: below the rest plane at 0.05 m plus half a radius"
    );
    assert!(
        lowest < 0.05 + 0.05,
        "centre heights {heights:?}: never near the plane"
    );
}

#[test]
fn the_reference_backend_refuses_water() {
    let dir = scene(&format!("{CAMERA}{WATER}"));
    let out = render(dir.path(), "s.toml", "x.png", &["--backend", "reference"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("water"), "{}", stderr(&out));
}

/// Renders `pond` at `time_s` and compares it byte for byte with its golden PNG.
fn check_pond_golden(time_s: &str) {
    let name = format!("pond_96x72_t{time_s}s.png");
    let golden = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/images")
        .join(&name);
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(
        &[
            "render",
            "pond",
            "--out",
            &name,
            "--time-s",
            time_s,
            "--width",
            "96",
            "--height",
            "72",
            "--samples",
            "4",
            "--cube-map-size",
            "32",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let got = image::open(dir.path().join(&name)).unwrap().to_rgb8();
    if std::env::var_os("BLESS").is_some() {
        std::fs::create_dir_all(golden.parent().unwrap()).unwrap();
        std::fs::copy(dir.path().join(&name), &golden).unwrap();
        return;
    }
    let want = image::open(&golden)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e}; run `BLESS=1 cargo test -p bubbles --test cli_water`, look at it, commit it",
                golden.display()
            )
        })
        .to_rgb8();
    assert_eq!(want.dimensions(), got.dimensions(), "{name}: size changed");
    let diffs = want
        .as_raw()
        .iter()
        .zip(got.as_raw())
        .filter(|(a, b)| a != b)
        .count();
    if diffs > 0 {
        let actual = std::env::temp_dir().join(format!("bubbles-{name}"));
        let _ = std::fs::copy(dir.path().join(&name), &actual);
        panic!(
            "{name}: {diffs} channels differ from {}; actual image at {}",
            golden.display(),
            actual.display()
        );
    }
}

#[test]
fn golden_pond_at_half_a_second() {
    check_pond_golden("0.5");
}

#[test]
fn golden_pond_at_two_seconds() {
    check_pond_golden("2");
}

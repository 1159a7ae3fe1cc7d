//! `bubbles render` and `bubbles bench` end to end: invariants of the whole pipeline
//! (scene → solver → baked tables → renderer → file) and bad-input handling.

use std::path::Path;
use std::process::Command;

mod common;
use common::{bubbles, stderr};

fn rgb8(path: &Path) -> image::RgbImage {
    image::open(path).expect("output decodes").to_rgb8()
}

#[test]
fn white_furnace_bubble_is_invisible_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(
        &[
            "render",
            "white-furnace",
            "--out",
            "wf.png",
            "--width",
            "96",
            "--height",
            "96",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let img = rgb8(&dir.path().join("wf.png"));
    let background = *img.get_pixel(0, 0);
    let worst = img
        .pixels()
        .flat_map(|p| (0..3).map(move |c| (i32::from(p[c]) - i32::from(background[c])).abs()))
        .max()
        .unwrap();
    assert!(
        worst <= 1,
        "a pixel differs from the background by {worst}/255"
    );
}

#[test]
fn paper_scene_shows_coloured_bubbles_over_the_ground() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(
        &[
            "render",
            "--out",
            "paper.exr",
            "--width",
            "120",
            "--height",
            "120",
            "--samples",
            "1",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.path().join("paper.exr"))
        .unwrap()
        .to_rgb32f();
    assert!(img.pixels().all(|p| p.0.iter().all(|c| c.is_finite())));
    // Interference colours can lie outside the sRGB gamut (`bubbles color` gives
    // r_lin < 0 at d = 460 nm), so unclamped linear channels may be negative; the
    // luminance, a physical radiance, may not.
    let worst_y = img
        .pixels()
        .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2])
        .fold(f32::MAX, f32::min);
    assert!(worst_y >= -1e-6, "negative luminance {worst_y}");
    // Thin-film interference must tint the bubbles: some pixels have clearly unequal channels.
    let tinted = img
        .pixels()
        .filter(|p| {
            let (lo, hi) =
                p.0.iter()
                    .fold((f32::MAX, 0f32), |(l, h), c| (l.min(*c), h.max(*c)));
            hi > 0.05 && hi > 1.5 * lo.max(1e-3)
        })
        .count();
    assert!(tinted > 20, "only {tinted} tinted pixels");
}

#[test]
fn same_image_at_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let mut images = Vec::new();
    for threads in ["1", "2", "3"] {
        let name = format!("t{threads}.exr");
        let out = Command::new(env!("CARGO_BIN_EXE_bubbles"))
            .args([
                "render", "--out", &name, "--width", "80", "--height", "64", "--time-s", "0.02",
            ])
            .env("RAYON_NUM_THREADS", threads)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        images.push(std::fs::read(dir.path().join(&name)).unwrap());
    }
    assert_eq!(images[0], images[1], "1 vs 2 threads");
    assert_eq!(images[0], images[2], "1 vs 3 threads");
}

#[test]
fn bad_output_extension_is_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(&["render", "--out", "x.jpg"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("x.jpg"), "{}", stderr(&out));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn cube_map_reuse_past_half_a_texel_is_exit_2_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for bad in ["0.7", "-0.1", "NaN"] {
        let flag = format!("--cube-map-reuse={bad}");
        let out = bubbles(
            &["bench", "--frames", "1", "--size", "8x8", &flag],
            dir.path(),
        );
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("--cube-map-reuse") && stderr(&out).contains(bad),
            "{}",
            stderr(&out)
        );
    }
}

/// Found by `cli_extreme_numbers`' proptest: a radius too large for its bubble's height
/// was refused naming only the centre and the ground, not the radius that caused it.
#[test]
fn a_radius_too_large_for_its_height_is_refused_naming_radius_m() {
    let dir = tempfile::tempdir().unwrap();
    let paper =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper.toml"))
            .unwrap()
            // The first bubble's radius (the light before it has one too).
            .replacen(
                "radius_m = 0.05\nmean_thickness_nm",
                "radius_m = 0.5\nmean_thickness_nm",
                1,
            );
    std::fs::write(dir.path().join("s.toml"), paper).unwrap();
    let out = bubbles(&["render", "s.toml", "--out", "x.png"], dir.path());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let msg = stderr(&out);
    assert!(
        msg.contains("radius_m 0.5") && msg.contains("center_m"),
        "{msg}"
    );
}

#[test]
fn missing_output_directory_is_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(&["render", "--out", "no/such/dir/x.png"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("no/such/dir"), "{}", stderr(&out));
}

#[test]
fn unknown_scene_lists_the_builtins() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(&["render", "nosuch", "--out", "x.png"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    let msg = stderr(&out);
    assert!(
        msg.contains("paper") && msg.contains("white-furnace"),
        "{msg}"
    );
}

#[test]
fn scene_error_gives_line_and_column_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.toml"),
        "[camera]\neye_m = [0.0, 0.1, 0.4]\ntarget_m = [0.0, 0.0, 0.0]\n\n[[bubbles]]\ncenter_m = [0.0, 0.1, 0.0]\nradius_m = 0.05\nthickness = 3\n",
    )
    .unwrap();
    let out = bubbles(&["render", "bad.toml", "--out", "x.png"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    let msg = stderr(&out);
    assert!(msg.contains("bad.toml:8:1"), "{msg}");
    assert!(!dir.path().join("x.png").exists());
}

#[test]
fn bad_numbers_are_exit_2_naming_the_value() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, value) in [
        ("--samples", "3"),
        ("--width", "0"),
        ("--time-s", "-1"),
        ("--exposure", "-2"),
    ] {
        let out = bubbles(&["render", "--out", "x.png", flag, value], dir.path());
        assert_eq!(
            out.status.code(),
            Some(2),
            "{flag} {value}: {}",
            stderr(&out)
        );
        assert!(
            stderr(&out).contains(value),
            "{flag} {value}: {}",
            stderr(&out)
        );
        assert!(!dir.path().join("x.png").exists());
    }
}

#[test]
fn bench_prints_a_breakdown_per_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(
        &[
            "bench",
            "--frames",
            "1",
            "--size",
            "64x48",
            "--samples",
            "1",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("fps") && text.contains("64x48"), "{text}");
}

/// The film flow's step cost is its own column, part of the simulation's: zero for a
/// scene without film flow, above zero and at most the simulation's for `swirl`; baking
/// the solver's state for the renderer is another, and the parts add up to the frame.
#[test]
fn bench_shows_the_film_steps_and_the_bake_as_their_own_columns() {
    let dir = tempfile::tempdir().unwrap();
    let column = |scene: &str| {
        let args = [
            "bench",
            scene,
            "--frames",
            "4",
            "--size",
            "32x24",
            "--samples",
            "1",
        ];
        let out = bubbles(&args, dir.path());
        assert!(out.status.success(), "{}", stderr(&out));
        let text = String::from_utf8(out.stdout).unwrap();
        let header: Vec<&str> = text
            .lines()
            .find(|l| l.starts_with("size"))
            .unwrap()
            .split_whitespace()
            .collect();
        let row: Vec<&str> = text
            .lines()
            .find(|l| l.starts_with("32x24"))
            .unwrap()
            .split_whitespace()
            .collect();
        let at = |name: &str| -> f64 {
            let k = header
                .iter()
                .position(|h| *h == name)
                .unwrap_or_else(|| panic!("{text}"));
            row[k].parse().unwrap()
        };
        // The parts add up to the frame (each printed to 1 µs).
        let parts = [
            "sim_ms",
            "bake_ms",
            "cube_ms",
            "setup_ms",
            "opaque_ms",
            "bubbles_ms",
            "other_ms",
        ];
        let sum: f64 = parts.iter().map(|p| at(p)).sum();
        assert!((sum - at("frame_ms")).abs() <= 0.004, "{text}");
        (at("sim_ms"), at("film_ms"), at("bake_ms"))
    };
    // `paper` with the per-vertex film (scene bubbles flow unless told not to).
    let paper = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper.toml"),
    )
    .unwrap()
    .replace("[[bubbles]]\n", "[[bubbles]]\nfilm_grid = 0\n");
    std::fs::write(dir.path().join("still.toml"), paper).unwrap();
    let (_, film_free, bake_meshes) = column("still.toml");
    assert_eq!(film_free, 0.0);
    // Two bubbles' films step in parallel: the column is their wall time, within the
    // simulation's (a sum of each bubble's time exceeded it on two threads).
    let (sim, film, _) = column("paper");
    assert!(
        film > 0.0 && film <= sim,
        "paper: film {film} ms, simulation {sim} ms"
    );
    let (sim, film, bake_field) = column("swirl");
    assert!(
        film > 0.0 && film <= sim,
        "film {film} ms, simulation {sim} ms"
    );
    // Every frame bakes the meshes; swirl also bakes its 6·64² film field.
    assert!(
        bake_meshes > 0.0 && bake_field > 0.0,
        "{bake_meshes} {bake_field}"
    );
}

#[cfg(not(feature = "wgpu"))]
#[test]
fn backend_wgpu_without_the_feature_says_how_to_rebuild() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(
        &["render", "--backend", "wgpu", "--out", "x.png"],
        dir.path(),
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--features wgpu") && err.contains("--backend cpu"),
        "{err}"
    );
    assert!(!dir.path().join("x.png").exists());
}

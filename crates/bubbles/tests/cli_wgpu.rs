//! `--backend wgpu` end to end against the CPU backend (the specification), issue 12.
//!
//! Runs with `cargo test -p bubbles --features wgpu --test cli_wgpu`. Without an adapter
//! the image tests skip with a message, except under `CI=true`, where they fail.
#![cfg(feature = "wgpu")]

use std::path::Path;

mod common;
use common::{bubbles, json_field, stderr};

/// Renders built-in `scene` at 400×400 to `out` with `backend`; `false` (skip) outside CI
/// when the wgpu backend finds no adapter.
fn render(scene: &str, backend: &str, out: &str, dir: &Path) -> bool {
    render_with(scene, backend, out, dir, &[])
}

/// [`render`] with extra flags.
fn render_with(scene: &str, backend: &str, out: &str, dir: &Path, extra: &[&str]) -> bool {
    let mut args = vec![
        "render",
        scene,
        "--backend",
        backend,
        "--width",
        "400",
        "--height",
        "400",
        "--out",
        out,
    ];
    args.extend(extra);
    let Some((run, err)) = run_unless_no_adapter(&args, dir) else {
        return false;
    };
    assert!(run.status.success(), "{backend}: {err}");
    true
}

/// Runs `bubbles args` in `dir`: its output and stderr, or `None` (said on stderr) when
/// no wgpu adapter is found outside CI, where the wgpu tests are skipped.
fn run_unless_no_adapter(args: &[&str], dir: &Path) -> Option<(std::process::Output, String)> {
    let run = bubbles(args, dir);
    let err = stderr(&run);
    if !run.status.success() && err.contains("no wgpu adapter") && std::env::var_os("CI").is_none()
    {
        eprintln!("skipped: {err}");
        return None;
    }
    Some((run, err))
}

/// Renders `scene` through wgpu and through the CPU with per-triangle partial shading
/// (like for like: the GPU shades a partly covered pixel once per triangle) into `dir`;
/// returns their mean and 99th-percentile ΔE2000, or `None` when no adapter was found.
fn wgpu_against_cpu(scene: &str, dir: &Path) -> Option<(f64, f64)> {
    if !render(scene, "wgpu", "gpu.png", dir) {
        return None;
    }
    let per_triangle = ["--partial-shading", "per-triangle"];
    assert!(render_with(scene, "cpu", "cpu.png", dir, &per_triangle));
    Some(compare(dir, "cpu.png", "gpu.png"))
}

#[test]
fn paper_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    let Some((mean, p99)) = wgpu_against_cpu("paper", dir.path()) else {
        return;
    };
    // With the cube footprint filter ported the rims agree too: lavapipe measured mean
    // 0.053, p99 0.76; the GPU's taps all at level 0 gave p99 0.94, one level-0 tap 1.95.
    assert!(mean <= 0.25, "mean ΔE2000 {mean} > 0.25");
    assert!(p99 <= 0.9, "99th percentile ΔE2000 {p99} > 0.9");
    // The CPU's default shares a partly covered pixel's shading across its layer: the
    // backends then differ at bubble edges (lavapipe: mean 0.083, p99 1.25).
    assert!(render("paper", "cpu", "cpu-shared.png", dir.path()));
    let (mean, p99) = compare(dir.path(), "cpu-shared.png", "gpu.png");
    assert!(mean <= 0.25, "per-surface CPU: mean ΔE2000 {mean} > 0.25");
    assert!(
        p99 <= 1.6,
        "per-surface CPU: 99th percentile ΔE2000 {p99} > 1.6"
    );
}

/// `swirl`: one bubble whose film flow reaches the renderers as a film field (thickness
/// and coverage per pixel, black spots included), drawn by the GPU as by the CPU.
#[test]
fn swirl_film_field_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    let Some((mean, p99)) = wgpu_against_cpu("swirl", dir.path()) else {
        return;
    };
    // Lavapipe measured mean 0.052, p99 1.03, max 1.22 (a film read at the wrong place
    // or coverage ignored is several ΔE): above the paper's p99 (0.76) on this dark frame
    // that the film covers, within gpu_scene's 2.0; the cause is not analysed yet.
    assert!(mean <= 0.25, "mean ΔE2000 {mean} > 0.25");
    assert!(p99 <= 1.5, "99th percentile ΔE2000 {p99} > 1.5");
}

/// Mean and 99th-percentile ΔE2000 of `a` against `b` through `bubbles compare`.
fn compare(dir: &Path, a: &str, b: &str) -> (f64, f64) {
    let out = bubbles(&["compare", a, b, "--json"], dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let json = String::from_utf8_lossy(&out.stdout);
    eprintln!("{a} vs {b}: {json}");
    (json_field(&json, "mean"), json_field(&json, "p99"))
}

#[test]
fn white_furnace_through_wgpu_stays_within_one_code_value_of_the_background() {
    let dir = tempfile::tempdir().unwrap();
    if !render("white-furnace", "wgpu", "gpu.png", dir.path()) {
        return;
    }
    let img = image::open(dir.path().join("gpu.png")).unwrap().to_rgb8();
    // The background: a uniform white environment, clamp tone curve.
    let background = img.get_pixel(0, 0).0;
    assert_eq!(background, [255; 3], "background");
    let worst = img
        .enumerate_pixels()
        .flat_map(|(x, y, p)| (0..3).map(move |k| (x, y, background[k].abs_diff(p.0[k]))))
        .max_by_key(|d| d.2)
        .unwrap();
    assert!(
        worst.2 <= 1,
        "pixel ({}, {}) is {} code values off",
        worst.0,
        worst.1,
        worst.2
    );
}

#[test]
fn wgpu_without_an_adapter_is_an_input_error_naming_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no-such-icd.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args([
            "render",
            "--backend",
            "wgpu",
            "--width",
            "8",
            "--height",
            "8",
        ])
        .args(["--out", "x.png"])
        .current_dir(dir.path())
        .env("VK_DRIVER_FILES", &missing)
        .env("VK_ICD_FILENAMES", &missing)
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for needle in [
        "no wgpu adapter",
        "VK_DRIVER_FILES",
        "mesa-vulkan-drivers",
        "--backend cpu",
    ] {
        assert!(err.contains(needle), "missing {needle:?} in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.path().join("x.png").exists(), "no image on failure");
}

/// The wgpu backend has no water pass: `pond` must be refused by name, never drawn
/// without its water (found when water and wgpu landed in the same session).
#[test]
fn pond_through_wgpu_is_refused_naming_the_water() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "render",
        "pond",
        "--backend",
        "wgpu",
        "--width",
        "16",
        "--height",
        "12",
        "--out",
        "x.png",
    ];
    let Some((out, err)) = run_unless_no_adapter(&args, dir.path()) else {
        return;
    };
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("water") && err.contains("--backend cpu"),
        "{err}"
    );
    assert!(!dir.path().join("x.png").exists(), "no image on failure");
}

/// `--samples 9` has no MSAA count anywhere: the frame is rendered at the nearest count
/// the device offers, and stderr says so once, naming both counts.
#[test]
fn a_sample_count_the_device_lacks_is_replaced_by_the_nearest_and_said() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "render",
        "paper",
        "--backend",
        "wgpu",
        "--width",
        "32",
        "--height",
        "24",
        "--samples",
        "9",
        "--out",
        "x.png",
    ];
    let Some((out, err)) = run_unless_no_adapter(&args, dir.path()) else {
        return;
    };
    assert!(out.status.success(), "{err}");
    assert!(dir.path().join("x.png").exists());
    assert_eq!(
        err.matches("--samples 9 is rendered with").count(),
        1,
        "{err}"
    );
    assert!(
        err.contains("with 8 samples") || err.contains("with 4 samples"),
        "{err}"
    );
}

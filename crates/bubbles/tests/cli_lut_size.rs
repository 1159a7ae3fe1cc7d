//! The film tables' size (`--lut-thickness-samples`, `--lut-angle-samples`, `[render]
//! lut_thickness_samples` / `lut_angle_samples`): it reaches the bake, and sizes outside
//! the limits of `bubbles --help` are refused naming the flag or key.

use std::path::Path;
use std::process::Output;

mod common;
use common::{bubbles, stderr};

const SCENE: &str = "[camera]\neye_m = [0.0, 0.06, 0.2]\ntarget_m = [0.0, 0.06, 0.0]\n\
                     [[bubbles]]\ncenter_m = [0.0, 0.06, 0.0]\nradius_m = 0.05\n";

fn scene(extra: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), format!("{SCENE}{extra}")).unwrap();
    dir
}

/// Renders `s.toml` at 24 × 24, one sample, small cube maps, into `out`.
fn render(dir: &Path, out: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        "s.toml",
        "--out",
        out,
        "--width",
        "24",
        "--height",
        "24",
        "--samples",
        "1",
        "--cube-map-size",
        "8",
    ];
    args.extend(extra);
    bubbles(&args, dir)
}

fn refused(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    for needle in needles {
        assert!(err.contains(needle), "{needle:?} missing from: {err}");
    }
}

#[test]
fn table_size_reaches_the_bake() {
    let dir = scene("");
    for (out, extra) in [
        ("default.png", &[][..]),
        (
            "explicit.png",
            &[
                "--lut-thickness-samples",
                "4096",
                "--lut-angle-samples",
                "128",
            ][..],
        ),
        (
            "tiny.png",
            &["--lut-thickness-samples", "4", "--lut-angle-samples", "2"][..],
        ),
    ] {
        let o = render(dir.path(), out, extra);
        assert!(o.status.success(), "{out}: {}", stderr(&o));
    }
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert_eq!(
        read("default.png"),
        read("explicit.png"),
        "the default is 4096 x 128"
    );
    assert_ne!(
        read("default.png"),
        read("tiny.png"),
        "a 4 x 2 table renders the same image"
    );
    // The scene's keys do the same as the flags.
    let keyed = scene("[render]\nlut_thickness_samples = 4\nlut_angle_samples = 2\n");
    let o = render(keyed.path(), "tiny.png", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(keyed.path().join("tiny.png")).unwrap(),
        read("tiny.png")
    );
}

#[test]
fn table_sizes_outside_the_limits_are_refused_naming_flag_or_key() {
    let dir = scene("");
    refused(
        &render(dir.path(), "x.png", &["--lut-thickness-samples", "1"]),
        &["--lut-thickness-samples 1", "2..=16384"],
    );
    refused(
        &render(dir.path(), "x.png", &["--lut-angle-samples", "5000"]),
        &["--lut-angle-samples 5000", "2..=1024"],
    );
    let dir = scene("[render]\nlut_angle_samples = 1\n");
    refused(
        &render(dir.path(), "x.png", &[]),
        &["render.lut_angle_samples", "1 is outside"],
    );
    assert!(!dir.path().join("x.png").exists());
}

#[test]
fn tables_past_the_memory_limit_are_refused_before_baking() {
    let light = "[[lights]]\nposition_m = [0.0, 1.0, 0.0]\nradius_m = 0.1\n";
    let dir = scene(&light.repeat(16));
    // 17 tables of 16384 x 1024 RGB f32 are 3.19 GiB.
    refused(
        &render(
            dir.path(),
            "x.png",
            &[
                "--lut-thickness-samples",
                "16384",
                "--lut-angle-samples",
                "1024",
            ],
        ),
        &["17 film tables of 16384x1024", "GiB"],
    );
}

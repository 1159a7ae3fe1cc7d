//! `bubbles animate --start-s T --slow-motion K`: frames between solver steps show a
//! burst's hole growing; frame ranges and resume give the frames of one run byte for
//! byte; a directory of another start or time scale is refused; bad values exit 2
//! naming them, before anything is written.

mod common;

use common::hostile::refused;
use common::{bubbles, stderr};
use std::path::Path;

/// A 2 cm bubble whose 500 nm film (±2 %) is over its rupture thickness at its thinnest
/// cells: a hole opens there at the first film step (t = 1/60 s) and its rim crosses
/// the bubble at 10 m/s, in 6.3 ms.
const BURSTING: &str = "[camera]\neye_m = [0.0, 0.0, 0.07]\ntarget_m = [0.0, 0.0, 0.0]\n\
    [[bubbles]]\ncenter_m = [0.0, 0.0, 0.0]\nradius_m = 0.02\nmean_thickness_nm = 500.0\n\
    thickness_variation = 0.02\nrupture_thickness_nm = 499.0\nblack_threshold_nm = 0.0\n\
    film_grid = 16\n";

/// Ten frames 0.4 ms apart from just after the hole opens (10 fps, 250× slower), all
/// but the last within one 1/240 s solver step.
const SLOW: [(&str, &str); 4] = [
    ("--start-s", "0.0167"),
    ("--seconds", "0.004"),
    ("--fps", "10"),
    ("--slow-motion", "250"),
];

/// `bubbles animate` of the bursting scene into `out` with [`SLOW`]'s flags, those in
/// `changed` given other values, then `extra`.
fn slow_burst(
    out: &str,
    changed: &[(&str, &str)],
    extra: &[&str],
    dir: &Path,
) -> std::process::Output {
    let mut args = vec!["animate", "b.toml", "--out", out];
    for (flag, value) in SLOW {
        let value = changed
            .iter()
            .find(|(f, _)| *f == flag)
            .map_or(value, |c| c.1);
        args.extend([flag, value]);
    }
    args.extend([
        "--width",
        "48",
        "--height",
        "36",
        "--samples",
        "1",
        "--cube-map-size",
        "16",
    ]);
    args.extend(extra);
    bubbles(&args, dir)
}

fn scene_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("b.toml"), BURSTING).unwrap();
    dir
}

fn frame(dir: &Path, k: u64) -> Vec<u8> {
    std::fs::read(dir.join(format!("frame_{k:05}.png"))).unwrap()
}

#[test]
fn slow_motion_frames_between_solver_steps_show_the_hole_growing() {
    let tmp = scene_dir();
    let out = slow_burst("full", &[], &[], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let full = tmp.path().join("full");
    assert!(full.join("frame_00009.png").is_file());
    assert!(!full.join("frame_00010.png").exists());
    // Only the rim moves between solver steps: each frame differs from the one before.
    for k in 1..10 {
        assert!(
            frame(&full, k) != frame(&full, k - 1),
            "frames {} and {k} (0.4 ms apart) are the same",
            k - 1
        );
    }
    let manifest = std::fs::read_to_string(full.join("animation.txt")).unwrap();
    assert!(
        manifest.contains("start_s 0.0167\nslow_motion 250\n"),
        "{manifest}"
    );
}

#[test]
fn slow_motion_frame_ranges_and_resume_give_the_frames_of_one_run() {
    let tmp = scene_dir();
    let out = slow_burst("full", &[], &[], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let out = slow_burst("part", &[], &["--frames", "4..7"], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let (full, part) = (tmp.path().join("full"), tmp.path().join("part"));
    for k in 4..7 {
        assert!(
            frame(&part, k) == frame(&full, k),
            "frame {k} of 4..7 differs"
        );
    }
    assert!(!part.join("frame_00003.png").exists());
    // Resume the part: the missing frames come out as in the full run.
    std::fs::remove_file(part.join("frame_00005.png")).unwrap();
    let out = slow_burst("part", &[], &["--resume"], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    for k in 0..10 {
        assert!(
            frame(&part, k) == frame(&full, k),
            "resumed frame {k} differs"
        );
    }
}

#[test]
fn a_directory_of_another_start_or_time_scale_is_refused() {
    let tmp = scene_dir();
    let out = slow_burst("full", &[], &["--frames", "0..1"], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let before = std::fs::read_to_string(tmp.path().join("full/animation.txt")).unwrap();
    for other in [
        &[("--slow-motion", "200")][..],
        &[("--start-s", "0.02")],
        &[
            ("--start-s", "0"),
            ("--slow-motion", "1"),
            ("--seconds", "0.2"),
        ],
    ] {
        let out = slow_burst("full", other, &["--resume"], tmp.path());
        refused(&out, &["animation.txt", "--slow-motion"]);
    }
    let after = std::fs::read_to_string(tmp.path().join("full/animation.txt")).unwrap();
    assert_eq!(before, after, "a refused run changed the manifest");
}

#[test]
fn bad_start_and_slow_motion_exit_2_naming_the_value_before_writing() {
    let tmp = scene_dir();
    for (changed, needles) in [
        (
            &[("--slow-motion", "0")][..],
            &["--slow-motion 0", "> 0"][..],
        ),
        (&[("--slow-motion", "-2")], &["--slow-motion -2"]),
        (&[("--slow-motion", "NaN")], &["--slow-motion NaN"]),
        (&[("--slow-motion", "inf")], &["--slow-motion inf"]),
        (
            &[("--slow-motion", "20000")],
            &["--slow-motion 20000", "10000"],
        ),
        (&[("--start-s", "-1")], &["--start-s -1", ">= 0"]),
        (&[("--start-s", "NaN")], &["--start-s NaN"]),
        (&[("--start-s", "4000")], &["--start-s 4000", "3600"]),
        (
            &[("--start-s", "3599.999")],
            &["--start-s 3599.999", "ends after 3600"],
        ),
        (
            &[
                ("--slow-motion", "10000"),
                ("--fps", "240"),
                ("--seconds", "0.01"),
            ],
            &["makes 24000 frames", "10000"],
        ),
        (&[("--slow-motion", "1e-3")], &["makes no frame"]),
    ] {
        let out = slow_burst("d", changed, &[], tmp.path());
        refused(&out, needles);
        assert!(!tmp.path().join("d").exists(), "{changed:?} wrote output");
    }
}

//! Ctrl-C (SIGINT) and SIGTERM during `render` and `animate` (issue 28): the run stops at
//! its next safe point, leaves no temporary file (`.raster-*.tmp`, `.bubbles-*.tmp`) and
//! no partial output, and exits 130 or 143 with one line on stderr.
#![cfg(unix)]

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::files_in;

const SCENE: &str = "[camera]\neye_m = [0.0, 0.1, 0.4]\ntarget_m = [0.0, 0.05, 0.0]\n\
                     [[bubbles]]\ncenter_m = [0.0, 0.06, 0.0]\nradius_m = 0.05\n";

fn spawn(args: &[&str], dir: &Path) -> Child {
    std::fs::write(dir.join("s.toml"), SCENE).unwrap();
    Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("bubbles starts")
}

/// Waits (at most a minute) until `ready` holds, then sends `signal` to the child.
fn signal_when(child: &Child, signal: &str, ready: impl Fn() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < Duration::from_secs(60), "never got ready");
        std::thread::sleep(Duration::from_millis(20));
    }
    let sent = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
}

/// Waits for the child; asserts its exit code and a one-line message naming `signal`.
fn assert_stopped(child: Child, code: i32, signal: &str) {
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "stderr: {err}");
    let last = err
        .lines()
        .rev()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_default();
    assert!(
        last.contains(signal) && last.contains("temporary files removed"),
        "{err}"
    );
    assert_eq!(err.matches("error:").count(), 1, "{err}");
}

fn no_temporaries(dir: &Path) -> bool {
    files_in(dir).iter().all(|f| !f.ends_with(".tmp"))
}

#[test]
fn sigint_during_a_long_render_stops_it_with_130_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "render", "s.toml", "--out", "x.png", "--time-s", "3600", "--width", "8", "--height", "8",
    ];
    let child = spawn(&args, dir.path());
    signal_when(&child, "INT", || {
        std::thread::sleep(Duration::from_millis(1500));
        true
    });
    assert_stopped(child, 130, "SIGINT");
    assert_eq!(files_in(dir.path()), ["s.toml"]);
}

#[test]
fn sigterm_during_animate_frames_stops_with_143_and_leaves_whole_frames_only() {
    let dir = tempfile::tempdir().unwrap();
    let args = long_animation("f");
    let child = spawn(&args, dir.path());
    let frames = dir.path().join("f");
    signal_when(&child, "TERM", || frames.join("frame_00002.png").exists());
    assert_stopped(child, 143, "SIGTERM");
    assert!(no_temporaries(&frames), "{:?}", files_in(&frames));
    for name in files_in(&frames).iter().filter(|f| f.ends_with(".png")) {
        assert!(image::open(frames.join(name)).is_ok(), "{name} is whole");
    }
}

#[test]
fn sigint_during_an_apng_removes_its_temporary_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let args = long_animation("a.apng");
    let child = spawn(&args, dir.path());
    signal_when(&child, "INT", || !no_temporaries(dir.path()));
    assert_stopped(child, 130, "SIGINT");
    assert_eq!(files_in(dir.path()), ["s.toml"]);
}

/// `bubbles animate` of `s.toml` for 100 s at 10 fps into `out`, 8×8 with one sample: long
/// enough that a signal always lands while frames are being written.
fn long_animation(out: &str) -> [&str; 14] {
    [
        "animate",
        "s.toml",
        "--seconds",
        "100",
        "--fps",
        "10",
        "--out",
        out,
        "--width",
        "8",
        "--height",
        "8",
        "--samples",
        "1",
    ]
}

//! Helpers of the hostile-input tests: the refusal check, a base scene and tiny render
//! flags.

use super::stderr;
use std::process::Output;

/// Asserts exit code 2, a short message (under 600 bytes) and every needle in it;
/// returns stderr.
#[track_caller]
pub fn refused(out: &Output, needles: &[&str]) -> String {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    for needle in needles {
        assert!(err.contains(needle), "{needle:?} missing from: {err}");
    }
    assert!(
        err.len() < 600,
        "message too long ({} bytes): {err}",
        err.len()
    );
    err
}

pub const BASE: &str = "[camera]\neye_m = [0.0, 0.1, 0.4]\ntarget_m = [0.0, 0.05, 0.0]\n\
                    [[bubbles]]\ncenter_m = [0.0, 0.06, 0.0]\nradius_m = 0.05\n";

/// Writes `BASE` followed by `extra` as `s.toml` in a new directory.
pub fn scene(extra: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), format!("{BASE}{extra}")).unwrap();
    dir
}

pub const TINY: [&str; 8] = [
    "--width",
    "16",
    "--height",
    "12",
    "--samples",
    "1",
    "--cube-map-size",
    "4",
];

//! `bubbles bake` at the edges of its numbers and its memory (issue 28): every number
//! outside the range where the bake stays finite and physical is refused by flag and
//! value, in a few digits, with exit code 2 and no file written; a bake whose tables and
//! writers would pass the planned-memory limit is refused before any work.

mod common;

use common::{bake, files_in};
use std::path::Path;
use std::time::{Duration, Instant};

/// Bakes EXR tables of `resolution` into `out_dir` with the flags `extra`, and checks that
/// the bake succeeds and every texel it wrote is finite.
fn assert_bakes_finite_tables(out_dir: &Path, resolution: &str, extra: &[&str]) {
    let mut args = vec![
        "--out",
        out_dir.to_str().expect("utf-8"),
        "--resolution",
        resolution,
        "--format",
        "exr",
    ];
    args.extend_from_slice(extra);
    let output = bake(&args);
    assert!(
        output.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let set = lut::LutSet::load(out_dir).expect("loads back");
    for (name, table) in set.named_tables() {
        assert!(
            table.texels().iter().flatten().all(|v| v.is_finite()),
            "{extra:?}: {name} has a non-finite texel"
        );
    }
}

/// Runs a small bake with `extra` that must be refused; returns its stderr.
#[track_caller]
fn refused(dir: &Path, extra: &[&str]) -> String {
    let out_dir = dir.join("out");
    let mut args = vec!["--out", out_dir.to_str().expect("utf-8")];
    if !extra.contains(&"--resolution") {
        args.extend(["--resolution", "16x4"]);
    }
    args.extend_from_slice(extra);
    let output = bake(&args);
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(output.status.code(), Some(2), "{extra:?}: {stderr}");
    assert!(output.stdout.is_empty(), "stdout for {extra:?}");
    assert!(files_in(&out_dir).is_empty(), "files left for {extra:?}");
    // Never a 300-digit decimal, never "inf" or "NaN" standing for what was typed.
    let longest_digits = stderr
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest_digits <= 12, "{extra:?}: {stderr}");
    stderr
}

#[test]
fn a_thickness_range_that_overflows_f32_is_refused_by_its_value() {
    let dir = tempfile::tempdir().expect("temp dir");
    // 1e308 was narrowed to f32 and reported as "0..inf".
    for (value, shown) in [
        ("1e308", "1e308"),
        ("3.5e38", "3.5e38"),
        ("100001", "100001"),
        ("1e-300", "1e-300"),
        ("0.5", "0.5"),
        ("-1e308", "-1e308"),
        ("inf", "inf"),
        ("NaN", "NaN"),
    ] {
        let stderr = refused(dir.path(), &["--thickness-max-nm", value]);
        assert!(
            stderr.contains(&format!("--thickness-max-nm {shown} is out of range"))
                && stderr.contains("1..=100000 nm"),
            "{value}: {stderr}"
        );
        assert!(!stderr.contains("0..inf"), "{value}: {stderr}");
    }
}

#[test]
fn film_indices_and_steps_outside_their_physical_range_are_refused_by_value() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (args, needle) in [
        (
            &["--n-film", "1e-300"][..],
            "--n-film 1e-300 is out of range: it must be in 1..=4",
        ),
        (&["--n-film", "1e308"][..], "--n-film 1e308 is out of range"),
        (&["--n-film", "4.5"][..], "--n-film 4.5 is out of range"),
        (&["--n-film", "0.999"][..], "--n-film 0.999 is out of range"),
        (&["--n-film", "nan"][..], "--n-film NaN is out of range"),
        (
            &["--step-nm", "1e-300"][..],
            "--step-nm 1e-300 is out of range",
        ),
        (
            &["--step-nm", "1e308"][..],
            "--step-nm 1e308 is out of range",
        ),
        (&["--step-nm", "-5"][..], "--step-nm -5 is out of range"),
    ] {
        let stderr = refused(dir.path(), args);
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}

#[test]
fn the_ends_of_every_range_are_accepted_and_bake_finite_tables() {
    let dir = tempfile::tempdir().expect("temp dir");
    for extra in [
        &["--thickness-max-nm", "1", "--n-film", "1"][..],
        &["--thickness-max-nm", "100000", "--n-film", "4"][..],
    ] {
        assert_bakes_finite_tables(&dir.path().join("ends"), "64x8", extra);
    }
}

#[test]
fn a_bake_past_the_memory_limit_is_refused_before_any_work() {
    let dir = tempfile::tempdir().expect("temp dir");
    let start = Instant::now();
    // Seven light tables, reflectivity and transmittance of 16384 x 4096 RGB f32 are
    // 7.5 GB before any writer; this ran for a minute at 5 to 7 GB resident before.
    let stderr = refused(
        dir.path(),
        &[
            "--resolution",
            "16384x4096",
            "--illuminant",
            "d65",
            "d50",
            "a",
            "e",
            "f2",
            "f11",
            "sodium",
            "--format",
            "exr,png16,png8",
        ],
    );
    let took = start.elapsed();
    assert!(
        took < Duration::from_secs(10),
        "took {took:?}: work started?"
    );
    for needle in [
        "9 tables of 16384x4096",
        "plans",
        "GiB",
        "above the 3 GiB memory limit",
    ] {
        assert!(stderr.contains(needle), "{needle:?}: {stderr}");
    }
}

#[test]
fn spectra_at_the_edges_of_their_range_bake_finite_tables_or_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let csv = |name: &str, rows: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, format!("wavelength_nm,value\n{rows}")).expect("write");
        path.to_str().expect("utf-8").to_owned()
    };
    // Relative spectra: a light or white of 1e-300 everywhere is as good as one of 1, and
    // a spectrum given far outside the visible is read where the visible is.
    let tiny = csv("tiny.csv", "380,1e-300\n780,1e-300\n");
    let wide = csv("wide.csv", "1e-300,1\n1e300,1\n");
    for extra in [
        ["--illuminant", tiny.as_str()],
        ["--reference", tiny.as_str()],
        ["--illuminant", wide.as_str()],
    ] {
        assert_bakes_finite_tables(&dir.path().join("spectra"), "32x4", &extra);
    }
    let huge = csv("huge.csv", "380,1e300\n780,1e300\n");
    let stderr = refused(dir.path(), &["--illuminant", huge.as_str()]);
    assert!(stderr.contains("value 1e300 is outside"), "{stderr}");
}

//! `bubbles chart` end to end: the PNG's size, layout and colours, and its errors.

use std::path::Path;
use std::process::{Command, Output};

fn bubbles_chart(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .arg("chart")
        .args(args)
        .output()
        .expect("bubbles runs")
}

fn chart(dir: &Path, extra: &[&str]) -> image::RgbaImage {
    let out = dir.join("chart.png");
    let mut args = vec!["--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let result = bubbles_chart(&args);
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    image::open(&out).unwrap().to_rgba8()
}

/// Layout constants of the chart (see `commands/chart.rs`).
const LEFT_PX: u32 = 28;
const RIGHT_PX: u32 = 12;
const TOP_PX: u32 = 10;

#[test]
fn writes_a_png_of_the_requested_size_and_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let img = chart(dir.path(), &["--width", "640", "--height", "300"]);
    assert_eq!(img.dimensions(), (640, 300));
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["chart.png"]);
}

#[test]
fn rows_show_newtons_series_from_black_to_the_first_order_white() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (1200u32, 500u32);
    let img = chart(dir.path(), &[]);
    assert_eq!(img.dimensions(), (w, h));
    let plot_w = w - LEFT_PX - RIGHT_PX;
    let y = TOP_PX + 5;
    let column = |d_nm: f64| LEFT_PX + ((d_nm / 4000.0) * f64::from(plot_w)) as u32;
    // A film much thinner than λ/4 reflects almost nothing (destructive
    // interference of the two surface reflections, one with a phase flip).
    let thin = img.get_pixel(column(2.0), y);
    assert!(thin[0] < 40 && thin[1] < 40 && thin[2] < 40, "{thin:?}");
    // Around 100 nm (optical 133 nm, a quarter wave at 532 nm) the first-order
    // reflection is nearly neutral and bright.
    let white = img.get_pixel(column(100.0), y);
    let spread = white.0[..3].iter().max().unwrap() - white.0[..3].iter().min().unwrap();
    assert!(white[1] > 150 && spread < 60, "{white:?}");
    // Exposure: the brightest channel of the 0° row is exactly 255.
    let row0_max = (LEFT_PX..w - RIGHT_PX)
        .map(|x| *img.get_pixel(x, y).0[..3].iter().max().unwrap())
        .max()
        .unwrap();
    assert_eq!(row0_max, 255);
}

#[test]
fn each_row_is_uniform_vertically() {
    let dir = tempfile::tempdir().unwrap();
    let img = chart(dir.path(), &["--width", "400", "--height", "200"]);
    // Rows are (200 − 10 − 22 − 16) / 5 = 30 px tall.
    for x in [LEFT_PX + 50, LEFT_PX + 200] {
        assert_eq!(img.get_pixel(x, TOP_PX), img.get_pixel(x, TOP_PX + 29));
    }
}

#[test]
fn oblique_rows_are_at_least_as_bright_as_the_normal_row() {
    let dir = tempfile::tempdir().unwrap();
    let img = chart(dir.path(), &["--width", "400", "--height", "200"]);
    let luma = |x: u32, y: u32| {
        let p = img.get_pixel(x, y);
        u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])
    };
    let row_sum = |y: u32| (LEFT_PX..400 - RIGHT_PX).map(|x| luma(x, y)).sum::<u32>();
    let (top0, top4) = (TOP_PX + 5, TOP_PX + 4 * 34 + 5);
    assert!(row_sum(top4) > row_sum(top0));
}

#[test]
fn fixed_exposure_and_other_lights_work() {
    let dir = tempfile::tempdir().unwrap();
    let dim = chart(
        dir.path(),
        &["--width", "300", "--height", "150", "--exposure", "1"],
    );
    let max = dim
        .pixels()
        .map(|p| p[0].max(p[1]).max(p[2]))
        .max()
        .unwrap();
    // Unexposed, a soap film (R ≤ 0.08 at 0°, more at 75°) stays dim.
    assert!(max < 255, "{max}");
    for light in ["sodium", "a", "f11"] {
        chart(
            dir.path(),
            &["--width", "300", "--height", "150", "--illuminant", light],
        );
    }
    chart(
        dir.path(),
        &[
            "--width",
            "300",
            "--height",
            "150",
            "--observer",
            "1964",
            "--n-film",
            "1.5",
        ],
    );
}

/// Runs with bad arguments, asserting exit code 2 and that no file appeared.
fn rejected(dir: &Path, args: &[&str]) -> String {
    let out = bubbles_chart(args);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        std::fs::read_dir(dir).unwrap().next().is_none(),
        "{args:?} left a file"
    );
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn bad_arguments_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("chart.png");
    let out = out.to_str().unwrap();
    let missing_dir = dir.path().join("no_such_dir").join("chart.png");
    let err = rejected(dir.path(), &["--out", missing_dir.to_str().unwrap()]);
    assert!(err.contains("no_such_dir"), "{err}");
    let err = rejected(dir.path(), &["--out", dir.path().to_str().unwrap()]);
    assert!(err.contains("directory"), "{err}");
    let err = rejected(dir.path(), &["--out", out, "--width", "10"]);
    assert!(err.contains("--width 10"), "{err}");
    let err = rejected(dir.path(), &["--out", out, "--height", "100000"]);
    assert!(err.contains("--height 100000"), "{err}");
    let err = rejected(dir.path(), &["--out", out, "--illuminant", "d75"]);
    assert!(err.contains("d75"), "{err}");
    let err = rejected(dir.path(), &["--out", out, "--exposure", "-1"]);
    assert!(err.contains("--exposure -1"), "{err}");
    let err = rejected(dir.path(), &["--out", out, "--n-film", "nan"]);
    assert!(err.contains("NaN") || err.contains("nan"), "{err}");
}

//! `bubbles simulate --export-film`: the film-flow field as one EXR per frame and bubble,
//! read back; and the refusal when no bubble has a flow.

mod common;

use common::{bubbles, stderr};
use std::path::Path;

const SCENE: &str = r#"
[camera]
eye_m = [0.0, 0.0, 0.3]
target_m = [0.0, 0.0, 0.0]

[[bubbles]]
center_m = [0.0, 0.0, 0.0]
radius_m = 0.03
mean_thickness_nm = 400.0
film_grid = 16
thickness_variation = 0.1
drainage_viscosity_pa_s = 1e-6
"#;

/// Writes `scene` to `dir/film.toml` and simulates it for `seconds`, exporting the film
/// field at `fps` into `dir/film`; asserts it succeeded.
fn export_film(dir: &Path, scene: &str, seconds: &str, fps: &str) {
    std::fs::write(dir.join("film.toml"), scene).unwrap();
    let args = [
        "simulate",
        "film.toml",
        "--seconds",
        seconds,
        "--fps",
        fps,
        "--export-film",
        "film",
    ];
    let out = bubbles(&args, dir);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn export_film_writes_the_cube_map_field_of_each_frame() {
    let dir = tempfile::tempdir().unwrap();
    export_film(dir.path(), SCENE, "0.5", "4");
    let mut names: Vec<String> = std::fs::read_dir(dir.path().join("film"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = (0..=2).map(|k| format!("film_0_{k:05}.exr")).collect();
    assert_eq!(
        names, expected,
        "one EXR per output frame, no temporary files left"
    );
    for name in &names {
        let image = image::open(dir.path().join("film").join(name))
            .unwrap()
            .to_rgb32f();
        assert_eq!(image.dimensions(), (6 * 16, 16), "{name}: 6n × n");
        let (mut sum, mut count) = (0.0f64, 0usize);
        for p in image.pixels() {
            assert!(p[0].is_finite() && p[0] > 0.0, "{name}: thickness {}", p[0]);
            assert_eq!(p[1], 1.0, "{name}: no hole, full coverage");
            assert_eq!(p[2], 0.0, "{name}: an isothermal film's temperature");
            sum += f64::from(p[0]);
            count += 1;
        }
        // Cells of a gnomonic grid differ in area, so the plain mean of the cells is
        // only near the area-weighted 400 nm (the film holds its volume exactly).
        let mean = sum / count as f64;
        assert!(
            (mean - 400.0).abs() < 40.0,
            "{name}: mean cell thickness {mean} nm"
        );
    }
}

/// With `bottom_warming_k` the blue channel is the film's temperature above the ambient:
/// after 1 s (four relaxation times of the 400 nm film) the −Y face is near the air's
/// 4 K bottom and the +Y face near its cold top, every cell within [0, 4] K.
#[test]
fn export_film_carries_the_warmed_films_temperature_in_blue() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!("{SCENE}bottom_warming_k = 4.0\n");
    export_film(dir.path(), &scene, "1", "1");
    let image = image::open(dir.path().join("film/film_0_00001.exr"))
        .unwrap()
        .to_rgb32f();
    let face_mean = |face: u32| {
        let texels = (0..16).flat_map(|y| (0..16).map(move |x| (face * 16 + x, y)));
        texels
            .map(|(x, y)| f64::from(image.get_pixel(x, y)[2]))
            .sum::<f64>()
            / 256.0
    };
    let (top, bottom) = (face_mean(2), face_mean(3));
    eprintln!("film temperature: +Y face {top:.3} K, −Y face {bottom:.3} K");
    assert!(
        bottom > 3.0 && top < 1.0,
        "+Y face {top:.3} K, −Y face {bottom:.3} K"
    );
    assert!(image.pixels().all(|p| (0.0..=4.0).contains(&p[2])));
}

#[test]
fn export_film_without_a_film_flow_exits_2_naming_film_grid() {
    let dir = tempfile::tempdir().unwrap();
    // Scene bubbles flow by default; this one asks for the per-vertex film.
    std::fs::write(
        dir.path().join("still.toml"),
        SCENE.replace("film_grid = 16", "film_grid = 0"),
    )
    .unwrap();
    let out = bubbles(
        &[
            "simulate",
            "still.toml",
            "--seconds",
            "0.1",
            "--export-film",
            "film",
        ],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("film_grid"), "{}", stderr(&out));
}

#[test]
fn a_film_grid_that_does_not_halve_to_eight_exits_2_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = SCENE.replace("film_grid = 16", "film_grid = 63");
    std::fs::write(dir.path().join("film.toml"), scene).unwrap();
    let out = bubbles(&["simulate", "film.toml", "--seconds", "0.1"], dir.path());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("film_grid"), "{}", stderr(&out));
    assert!(stderr(&out).contains("63"), "{}", stderr(&out));
}

#[test]
fn film_grids_above_the_cell_limit_exit_2_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let one = SCENE
        .split("[[bubbles]]")
        .nth(1)
        .unwrap()
        .replace("film_grid = 16", "film_grid = 512");
    let scene = format!(
        "{}[[bubbles]]{one}[[bubbles]]{one}",
        SCENE.split("[[bubbles]]").next().unwrap()
    );
    std::fs::write(dir.path().join("film.toml"), scene).unwrap();
    let out = bubbles(&["simulate", "film.toml", "--seconds", "0.1"], dir.path());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("3145728 cells"), "{}", stderr(&out));
}

#[test]
fn a_bad_film_gradient_exits_2_naming_the_key_and_the_value() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!("{SCENE}film_gradient = \"diagonal\"\n");
    std::fs::write(dir.path().join("film.toml"), scene).unwrap();
    let out = bubbles(&["simulate", "film.toml", "--seconds", "0.1"], dir.path());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let msg = stderr(&out);
    assert!(msg.contains("film_gradient"), "{msg}");
    assert!(msg.contains("diagonal"), "{msg}");
    assert!(msg.contains("two-point") && msg.contains("normal"), "{msg}");
}

/// The normal gradient, chosen in the scene, steps the film (`--export-film` reads it).
#[test]
fn the_normal_film_gradient_simulates() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!("{SCENE}film_gradient = \"normal\"\n");
    export_film(dir.path(), &scene, "0.25", "4");
    assert!(dir.path().join("film").read_dir().unwrap().count() > 0);
}

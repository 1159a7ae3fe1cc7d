//! `[bubbles.meniscus]`: a bubble standing on a wet surface keeps no film below its
//! contact line (read back through `--export-film`) and stays where it stands; bad
//! values exit 2 naming the key; the built-in `dome` scene simulates.

mod common;

use common::{bubbles, stderr};

const SCENE: &str = r#"
[camera]
eye_m = [0.0, 0.05, 0.3]
target_m = [0.0, 0.0, 0.0]

[[bubbles]]
center_m = [0.0, 0.0, 0.0]
radius_m = 0.03
mean_thickness_nm = 400.0
film_grid = 16
thickness_variation = 0.1
drainage_viscosity_pa_s = 1e-6

[bubbles.meniscus]
contact_height = 0.25
"#;

/// Face `f`'s cube-map basis: major axis, s axis, t axis (OpenGL order).
const FACES: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
    ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]),
    ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]),
    ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
    ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]),
    ([0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]),
];

/// The height over the radius (y of the unit direction) of texel `(x, y)` of face `f`.
fn height(f: usize, x: u32, y: u32, n: u32) -> f64 {
    let (m, s_axis, t_axis) = FACES[f];
    let s = (f64::from(x) + 0.5) * 2.0 / f64::from(n) - 1.0;
    let t = (f64::from(y) + 0.5) * 2.0 / f64::from(n) - 1.0;
    let d: Vec<f64> = (0..3)
        .map(|k| m[k] + s * s_axis[k] + t * t_axis[k])
        .collect();
    d[1] / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

#[test]
fn no_film_lies_below_the_contact_line_of_a_standing_bubble() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("dome.toml"), SCENE).unwrap();
    let args = ["simulate", "dome.toml", "--seconds", "0.5", "--fps", "2"];
    let out = bubbles(
        &[&args[..], &["--export-film", "film"]].concat(),
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let last = dir.path().join("film").join("film_0_00001.exr");
    let image = image::open(&last).unwrap().to_rgb32f();
    let n = 16;
    let (mut below, mut above) = (0, 0);
    for (x, y, p) in image.enumerate_pixels() {
        let up = height((x / n) as usize, x % n, y, n);
        if up < 0.25 {
            assert!(
                p[0] == 0.0 && p[1] == 0.0,
                "below the line at {up:.3}: {p:?}"
            );
            below += 1;
        } else {
            assert!(p[0] > 100.0 && p[1] == 1.0, "film at {up:.3}: {p:?}");
            above += 1;
        }
    }
    assert!(
        below > 800 && above > 500,
        "{below} cells below, {above} above"
    );
}

#[test]
fn a_meniscus_value_out_of_range_exits_2_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    for (key, bad) in [
        ("contact_height", "1.0"),
        ("regenerated_fraction", "0.0"),
        ("patch_radius_m", "-0.004"),
    ] {
        let scene = format!("{SCENE}{key} = {bad}\n").replace("contact_height = 0.25\n", "");
        std::fs::write(dir.path().join("bad.toml"), scene).unwrap();
        let out = bubbles(&["simulate", "bad.toml", "--seconds", "0.1"], dir.path());
        assert_eq!(out.status.code(), Some(2), "{key}: {}", stderr(&out));
        assert!(stderr(&out).contains(key), "{key}: {}", stderr(&out));
    }
}

#[test]
fn a_meniscus_without_the_film_flow_exits_2_naming_film_grid() {
    let dir = tempfile::tempdir().unwrap();
    let scene = SCENE.replace("film_grid = 16\n", "film_grid = 0\n");
    std::fs::write(dir.path().join("bad.toml"), scene).unwrap();
    let out = bubbles(&["simulate", "bad.toml", "--seconds", "0.1"], dir.path());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let msg = stderr(&out);
    assert!(
        msg.contains("meniscus") && msg.contains("film_grid"),
        "{msg}"
    );
}

#[test]
fn the_dome_scene_stands_and_flows() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(&["simulate", "dome", "--seconds", "0.25"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
}

//! `bubbles render` end to end for render fidelity (issue 8): cameras looking straight up
//! or down, lights of every built-in spectrum, and sodium highlights with the exact
//! spectral colour of `bubbles color`.

use std::path::Path;
use std::process::Command;

mod common;
use common::{bubbles, stderr};

/// Renders `scene` (TOML text) at `size`² with one sample to EXR; returns the linear image.
fn render_exr(scene: &str, size: u32, dir: &Path) -> image::Rgb32FImage {
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let size = size.to_string();
    let out = bubbles(
        &[
            "render",
            "scene.toml",
            "--out",
            "out.exr",
            "--width",
            &size,
            "--height",
            &size,
            "--samples",
            "1",
        ],
        dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    image::open(dir.join("out.exr")).unwrap().to_rgb32f()
}

#[test]
fn camera_looking_straight_down_or_up_renders() {
    for (eye_y, target_y) in [(0.5, 0.0), (-0.5, 0.0)] {
        let dir = tempfile::tempdir().unwrap();
        let scene = format!(
            "[camera]\neye_m = [0.0, {eye_y}, 0.0]\ntarget_m = [0.0, {target_y}, 0.0]\n\
             [[bubbles]]\ncenter_m = [0.0, 0.0, 0.0]\nradius_m = 0.05\n"
        );
        let img = render_exr(&scene, 24, dir.path());
        assert!(img.pixels().all(|p| p.0.iter().all(|c| c.is_finite())));
    }
}

#[test]
fn paper_renders_with_every_built_in_light_spectrum() {
    let paper = include_str!("../scenes/paper.toml");
    assert!(paper.contains("spectrum = \"d65\""));
    for spectrum in ["d65", "d50", "a", "e", "f2", "f11", "sodium"] {
        let dir = tempfile::tempdir().unwrap();
        let scene = paper.replace("spectrum = \"d65\"", &format!("spectrum = \"{spectrum}\""));
        let img = render_exr(&scene, 32, dir.path());
        assert!(
            img.pixels().all(|p| p.0.iter().all(|c| c.is_finite())),
            "{spectrum}: a pixel is not finite"
        );
    }
}

/// `bubbles color --illuminant sodium` for one film: linear sRGB.
fn sodium_film_rgb(thickness_nm: f64, angle_deg: f64, dir: &Path) -> [f64; 3] {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args(["color", "--illuminant", "sodium"])
        .current_dir(dir)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("bubbles runs");
    use std::io::Write;
    write!(
        child.stdin.take().unwrap(),
        "thickness_nm,angle_deg\n{thickness_nm},{angle_deg}\n"
    )
    .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let row: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    [row[5], row[6], row[7]].map(|v| v.parse().unwrap())
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = v.iter().map(|c| c * c).sum::<f64>().sqrt();
    v.map(|c| c / n)
}

#[test]
fn sodium_highlight_has_the_exact_spectral_colour_of_bubbles_color() {
    // A uniform 500 nm bubble in the dark, lit by a sodium lamp 60° off the view axis
    // (out of frame, to the right): the brightest pixel of the right half is the front
    // face's highlight alone (the left half shows the back face's, seen through the film).
    let dir = tempfile::tempdir().unwrap();
    let a = 60f64.to_radians();
    let scene = format!(
        "[camera]\neye_m = [0.0, 0.0, 0.3]\ntarget_m = [0.0, 0.0, 0.0]\nvfov_deg = 30.0\n\
         [environment]\nkind = \"uniform\"\nrgb = [0.0, 0.0, 0.0]\n\
         [[lights]]\nposition_m = [{:.6}, 0.0, {:.6}]\nradius_m = 0.05\n\
         spectrum = \"sodium\"\nluminance = 100.0\n\
         [[bubbles]]\ncenter_m = [0.0, 0.0, 0.0]\nradius_m = 0.05\n\
         mean_thickness_nm = 500.0\nthickness_variation = 0.0\n\
         [dynamics]\ngravity_m_per_s2 = [0.0, 0.0, 0.0]\n",
        2.0 * a.sin(),
        2.0 * a.cos()
    );
    let img = render_exr(&scene, 96, dir.path());
    let brightest = img
        .enumerate_pixels()
        .filter(|(x, _, _)| *x > 48)
        .map(|(_, _, p)| p)
        .max_by(|p, q| p[0].total_cmp(&q[0]))
        .unwrap()
        .0
        .map(f64::from);
    assert!(brightest[0] > 0.1, "no highlight: {brightest:?}");
    // The highlight sits where the normal bisects view and light: about 30° incidence.
    let want = unit(sodium_film_rgb(500.0, 30.0, dir.path()));
    let got = unit(brightest);
    assert!(
        want[2] < 0.0,
        "sodium lies outside the sRGB gamut: {want:?}"
    );
    let off = (0..3).map(|k| (got[k] - want[k]).abs()).fold(0.0, f64::max);
    assert!(
        off < 1e-3,
        "highlight colour {got:?} vs bubbles color {want:?}: off by {off}"
    );
}

/// XYZ rows of `bubbles color` (D65) for the films in `rows` (`thickness_nm,angle_deg`).
fn film_xyz(rows: &str, dir: &Path) -> Vec<[f64; 3]> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .arg("color")
        .current_dir(dir)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("bubbles runs");
    let input = format!("thickness_nm,angle_deg\n{rows}");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        use std::io::Write;
        stdin.write_all(input.as_bytes()).unwrap();
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .skip(1)
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            [f[2], f[3], f[4]].map(|v| v.parse().unwrap())
        })
        .collect()
}

#[test]
fn film_colours_stop_changing_beyond_the_table_thickness_range() {
    // The renderer clamps thickness at the tables' last column: past it a film must look
    // like the thick-film (incoherent) limit, here the mean over 10–12 µm, even exposed
    // so that the reflection is white (CIELAB relative to that limit).
    let dir = tempfile::tempdir().unwrap();
    let d_max = f64::from(lut::config::DEFAULT_THICKNESS_MAX_NM);
    for angle in [0, 45, 75] {
        let films: String = (0..)
            .map(|k| d_max + 5.0 * f64::from(k))
            .take_while(|d| *d <= 12_000.0)
            .map(|d| format!("{d},{angle}\n"))
            .collect();
        let xyz = film_xyz(&films, dir.path());
        let tail = &xyz[xyz.len() - 401..];
        let limit = tail
            .iter()
            .fold([0.0; 3], |a, c| [a[0] + c[0], a[1] + c[1], a[2] + c[2]]);
        let limit = limit.map(|c| c / tail.len() as f64);
        let lab = |c: [f64; 3]| thinfilm::lab::lab_from_xyz(c, limit);
        let (worst, at) = xyz
            .iter()
            .enumerate()
            .map(|(k, c)| (thinfilm::lab::ciede2000(lab(*c), lab(limit)), k))
            .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        assert!(
            worst < 1.0,
            "{angle}°: ΔE00 {worst:.2} from the thick-film limit at {} nm",
            d_max + 5.0 * at as f64
        );
    }
}

//! `bubbles color` end to end: output against an independent Airy + CIE sum, and its errors.

use std::io::Write;
use std::process::{Command, Output, Stdio};

use thinfilm::cmf::Observer;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply};
use thinfilm::illuminant::Illuminant;

fn bubbles_color(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .arg("color")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("bubbles runs");
    // The command may reject its options and exit before reading stdin; the broken
    // pipe that then ends this write is expected, and the exit status tells the story.
    let _ = child.stdin.take().unwrap().write_all(stdin.as_bytes());
    child.wait_with_output().unwrap()
}

/// Parsed output rows: (thickness, angle, [x, y, z, r, g, b], hex).
fn rows(output: &Output) -> Vec<(f64, f64, Vec<f64>, String)> {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8(output.stdout.clone()).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("thickness_nm,angle_deg,x,y,z,r_lin,g_lin,b_lin,srgb_hex")
    );
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 9, "{line}");
            let n: Vec<f64> = f[..8].iter().map(|v| v.parse().unwrap()).collect();
            (n[0], n[1], n[2..].to_vec(), f[8].to_owned())
        })
        .collect()
}

/// Normal-incidence reflectance of a free-standing film (Airy, closed form):
/// R = 2ρ(1 − cos δ) / (1 + ρ² − 2ρ cos δ), ρ = ((n − 1)/(n + 1))², δ = 4πnd/λ.
fn film_r_normal(n: f64, d_nm: f64, wavelength_nm: f64) -> f64 {
    let rho = ((n - 1.0) / (n + 1.0)).powi(2);
    let cos_delta = (4.0 * std::f64::consts::PI * n * d_nm / wavelength_nm).cos();
    2.0 * rho * (1.0 - cos_delta) / (1.0 + rho * rho - 2.0 * rho * cos_delta)
}

/// XYZ by the CIE 1 nm sum, written out here independently of the integrator.
fn xyz_1nm(illuminant: Illuminant, r: impl Fn(f64) -> f64) -> [f64; 3] {
    let e = illuminant.spectrum();
    let (mut xyz, mut norm) = ([0.0; 3], 0.0);
    for nm in 360..=830 {
        let w = f64::from(nm);
        let (cmf, power) = (Observer::Cie1931.cmf(w), e.value_at(w));
        (0..3).for_each(|c| xyz[c] += r(w) * power * cmf[c]);
        norm += power * cmf[1];
    }
    xyz.map(|v| v / norm)
}

fn assert_close(actual: f64, expected: f64, tol: f64, what: &str) {
    let diff = (actual - expected).abs();
    assert!(
        diff <= tol,
        "{what}: got {actual}, expected {expected}, |diff| = {diff:e}"
    );
}

#[test]
fn normal_incidence_matches_closed_form_airy_and_1nm_cie_sum() {
    let input = "thickness_nm,angle_deg\n0,0\n120,0\n250,0\n400,0\n780,0\n1500,0\n";
    for (illuminant, n) in [("d65", 1.33), ("a", 1.45)] {
        let n_text = n.to_string();
        let out = bubbles_color(&["--illuminant", illuminant, "--n-film", &n_text], input);
        let light = Illuminant::from_name(illuminant).unwrap();
        for (d, angle, v, _) in rows(&out) {
            assert_eq!(angle, 0.0);
            let expected = xyz_1nm(light, |w| film_r_normal(n, d, w));
            for c in 0..3 {
                // 8 printed decimals and the 2 nm cubic quadrature.
                assert_close(
                    v[c],
                    expected[c],
                    2e-6,
                    &format!("{illuminant} d = {d} XYZ[{c}]"),
                );
            }
        }
    }
}

#[test]
fn zero_thickness_reflects_nothing() {
    let out = bubbles_color(&[], "thickness_nm,angle_deg\n0,0\n0,60\n");
    for (_, _, v, hex) in rows(&out) {
        assert!(v.iter().all(|&c| c.abs() < 1e-12), "{v:?}");
        assert_eq!(hex, "#000000");
    }
}

#[test]
fn linear_srgb_is_the_matrix_times_xyz_and_hex_its_encoding() {
    let out = bubbles_color(&[], "thickness_nm,angle_deg\n310,0\n550,30\n900,70\n");
    for (d, _, v, hex) in rows(&out) {
        let rgb = apply(&SRGB_FROM_XYZ, [v[0], v[1], v[2]]);
        for c in 0..3 {
            assert_close(v[3 + c], rgb[c], 5e-8, &format!("d = {d} rgb[{c}]"));
        }
        let expected = thinfilm::colorspace::hex(thinfilm::colorspace::srgb8_from_linear(rgb));
        assert_eq!(hex, expected);
    }
}

#[test]
fn oblique_light_reflects_more_than_normal() {
    // Fresnel: the film's single-surface reflectance grows with angle, so the
    // angle-averaged colour brightens (at a thickness averaging over fringes).
    let out = bubbles_color(&[], "thickness_nm,angle_deg\n5000,0\n5000,45\n5000,75\n");
    let y: Vec<f64> = rows(&out).iter().map(|r| r.2[1]).collect();
    assert!(y[0] < y[1] && y[1] < y[2], "{y:?}");
    // Far from the fringes' scale, R averages to 2ρ/(1 + ρ) (incoherent limit).
    let rho = (0.33f64 / 2.33).powi(2);
    assert_close(y[0], 2.0 * rho / (1.0 + rho), 2e-3, "incoherent limit");
}

#[test]
fn sodium_light_has_one_chromaticity_at_every_thickness() {
    let input = "thickness_nm,angle_deg\n100,0\n300,0\n450,20\n1200,50\n";
    let out = bubbles_color(&["--illuminant", "sodium"], input);
    let chroma: Vec<[f64; 2]> = rows(&out)
        .iter()
        .map(|r| {
            let s = r.2[0] + r.2[1] + r.2[2];
            [r.2[0] / s, r.2[1] / s]
        })
        .collect();
    let cmf = Observer::Cie1931.cmf(589.2);
    let s: f64 = cmf.iter().sum();
    for xy in chroma {
        assert_close(xy[0], cmf[0] / s, 2e-4, "sodium x");
        assert_close(xy[1], cmf[1] / s, 2e-4, "sodium y");
    }
}

#[test]
fn csv_illuminant_equal_to_d65_gives_the_same_colours() {
    let d65 = Illuminant::D65.spectrum();
    let mut csv = String::from("wavelength_nm,value\n");
    for (w, v) in d65.wavelengths_nm().iter().zip(d65.values()) {
        csv.push_str(&format!("{w},{v}\n"));
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("my_d65.csv");
    std::fs::write(&path, csv).unwrap();
    let input = "thickness_nm,angle_deg\n200,0\n640,35\n";
    let from_file = bubbles_color(&["--illuminant", path.to_str().unwrap()], input);
    let built_in = bubbles_color(&["--illuminant", "d65"], input);
    assert_eq!(from_file.stdout, built_in.stdout);
    assert!(from_file.status.success());
}

#[test]
fn observer_1964_differs_from_1931() {
    let input = "thickness_nm,angle_deg\n400,0\n";
    let a = bubbles_color(&["--observer", "1931"], input);
    let b = bubbles_color(&["--observer", "1964"], input);
    assert!(a.status.success() && b.status.success());
    assert_ne!(a.stdout, b.stdout);
}

#[test]
fn output_is_the_same_at_any_thread_count() {
    let mut input = String::from("thickness_nm,angle_deg\n");
    for i in 0..300 {
        input.push_str(&format!("{},{}\n", i * 7, (i % 89) as f64));
    }
    let run = |threads: &str| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_bubbles"))
            .arg("color")
            .env("RAYON_NUM_THREADS", threads)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(input.as_bytes())
            .unwrap();
        child.wait_with_output().unwrap().stdout
    };
    let one = run("1");
    assert_eq!(one, run("4"));
    assert_eq!(String::from_utf8(one).unwrap().lines().count(), 301);
}

/// Runs with bad input and returns stderr, asserting exit 2 and empty stdout.
fn rejected(args: &[&str], stdin: &str) -> String {
    let out = bubbles_color(args, stdin);
    assert_eq!(out.status.code(), Some(2), "{args:?} {stdin:?}");
    assert!(
        out.stdout.is_empty(),
        "stdout: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn bad_rows_are_rejected_naming_line_and_value() {
    let ok = "thickness_nm,angle_deg\n100,0\n";
    let cases = [
        (format!("{ok}200,abc\n"), ["line 3", "abc"]),
        (format!("{ok}-5,0\n"), ["line 3", "-5"]),
        (format!("{ok}100,90\n"), ["line 3", "90"]),
        (format!("{ok}100,-1\n"), ["line 3", "-1"]),
        (format!("{ok}100\n"), ["line 3", "1 fields"]),
        (format!("{ok}nan,0\n"), ["line 3", "nan"]),
        ("thickness_nm\n100\n".to_owned(), ["line 1", "angle_deg"]),
    ];
    for (input, needles) in cases {
        let err = rejected(&[], &input);
        for needle in needles {
            assert!(err.contains(needle), "{input:?}: {err}");
        }
    }
}

#[test]
fn bad_options_are_rejected_naming_the_value() {
    let input = "thickness_nm,angle_deg\n100,0\n";
    let err = rejected(&["--illuminant", "d75"], input);
    assert!(
        err.contains("d75") && err.contains("d65, d50, a, e, f2, f11, sodium"),
        "{err}"
    );
    let err = rejected(&["--observer", "1976"], input);
    assert!(err.contains("1976"), "{err}");
    let err = rejected(&["--n-film", "0"], input);
    assert!(err.contains("--n-film 0"), "{err}");
    // Finite but so large that n² overflows: once a NaN colour and exit 1.
    let err = rejected(&["--n-film", "1e155"], input);
    assert!(err.contains("--n-film 1e155"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.csv");
    std::fs::write(&path, "wavelength_nm,value\n400,1\n410,-2\n").unwrap();
    let err = rejected(&["--illuminant", path.to_str().unwrap()], input);
    assert!(err.contains("line 3") && err.contains("-2"), "{err}");
    let huge = dir.path().join("huge.csv");
    std::fs::write(&huge, "wavelength_nm,value\n400,1\n500,1e308\n600,1\n").unwrap();
    let err = rejected(&["--illuminant", huge.to_str().unwrap()], input);
    assert!(
        err.contains("huge.csv") && err.contains("line 3") && err.contains("1e308"),
        "{err}"
    );
    let missing = dir.path().join("missing.csv");
    let err = rejected(&["--illuminant", missing.to_str().unwrap()], input);
    assert!(err.contains("missing.csv"), "{err}");
}

#[test]
fn header_only_input_gives_header_only_output() {
    let out = bubbles_color(&[], "thickness_nm,angle_deg\n");
    assert!(rows(&out).is_empty());
}

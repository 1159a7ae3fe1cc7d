//! `bubbles fit --cauchy-a`: a film's thickness and Cauchy index fitted together from a
//! spectrum the exact model wrote, and bad ranges refused with exit 2 naming them.

mod common;

use std::process::Output;

use thinfilm::dispersion::RefractiveIndex;
use thinfilm::{Complex64, Incidence, Layer, Stack};

fn fit(args: &[&str], stdin: &str) -> Output {
    common::bubbles_piped(&[&["fit"], args].concat(), stdin)
}

/// `wavelength_nm,r` of `a + b/λ²` at `d` nm on silicon, at normal incidence.
fn oxide_spectrum(d: f64, a: f64, b_nm2: f64) -> String {
    let index = RefractiveIndex::cauchy_over(a, b_nm2, 0.0, [300.0, 900.0]).unwrap();
    let silicon = Complex64::new(3.88, 0.02);
    let stack = Stack::new(1.0, vec![Layer::new(index, d)], silicon).unwrap();
    let mut csv = String::from("wavelength_nm,r\n");
    for k in 0..=150 {
        let w = 420.0 + 2.5 * k as f64;
        let r = stack.try_response_at(w, Incidence::NORMAL).unwrap().r();
        csv.push_str(&format!("{w},{r}\n"));
    }
    csv
}

#[test]
fn fit_with_cauchy_a_recovers_thickness_and_index() {
    let csv = oxide_spectrum(1187.0, 1.47, 4200.0);
    let stack = "1.0 | 1.5 @ 0 | 3.88+0.02i";
    let output = fit(
        &[
            "--spectrum",
            "-",
            "--stack",
            stack,
            "--cauchy-a",
            "1.3,1.7",
            "--max-nm",
            "4000",
        ],
        &csv,
    );
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8(output.stdout).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let values: Vec<f64> = (lines.next().unwrap().split(','))
        .map(|f| f.parse().unwrap())
        .collect();
    let at = |name: &str| values[header.iter().position(|h| *h == name).unwrap()];
    assert!((at("thickness_nm") - 1187.0).abs() < 1e-3, "{text}");
    assert!((at("a") - 1.47).abs() < 1e-6, "{text}");
    assert!((at("b_nm2") - 4200.0).abs() < 1e-2, "{text}");
    assert!(at("rms_residual") < 1e-9, "{text}");
}

#[test]
fn fit_rejects_bad_cauchy_ranges_with_exit_2_naming_them() {
    let csv = oxide_spectrum(500.0, 1.46, 3500.0);
    for (args, needle) in [
        (vec!["--cauchy-a", "1.7,1.3"], "Cauchy a range [1.7, 1.3]"),
        (vec!["--cauchy-a", "1.3"], "--cauchy-a takes two numbers"),
        (
            vec!["--cauchy-a", "1.3,1.7", "--cauchy-b-nm2", "5,nan"],
            "Cauchy b range [5, NaN]",
        ),
        (vec!["--cauchy-b-nm2", "0,1"], "--cauchy-a"),
    ] {
        let output = fit(&[&["--spectrum", "-"], args.as_slice()].concat(), &csv);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(output.stdout.is_empty());
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
    }
}

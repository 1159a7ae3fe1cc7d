//! `bubbles reflectance` run as a process: values against the library, and every class of
//! bad input rejected with exit code 2 and nothing on stdout.

use std::process::Output;

use thinfilm::airy::ThinFilm;
use thinfilm::dispersion::RefractiveIndex;

mod common;

const HEADER: &str = "thickness_nm,angle_deg,wavelength_nm,n_film,r_s,r_p,r,t";

fn run(args: &[&str], stdin: &str) -> Output {
    common::bubbles_piped(&[&["reflectance"], args].concat(), stdin)
}

fn stdout(output: &Output) -> String {
    assert!(
        output.status.success(),
        "exit {:?}, stderr: {}",
        output.status.code(),
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout.clone()).unwrap()
}

/// Parses output rows into numbers, checking the header.
fn rows(text: &str) -> Vec<Vec<f64>> {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(HEADER));
    lines
        .map(|l| l.split(',').map(|f| f.parse::<f64>().unwrap()).collect())
        .collect()
}

fn expected(n_outside: f64, d: f64, angle: f64, l: f64, n: f64) -> [f64; 4] {
    let film = ThinFilm::symmetric(n_outside, RefractiveIndex::Constant(n), d);
    // The CLI takes the angle itself, not its cosine, so grazing rows stay exact.
    let incidence = thinfilm::Incidence::try_from_angle_deg(angle).unwrap();
    let resp = film.try_response_at(l, incidence).unwrap();
    [resp.r_s, resp.r_p, resp.r(), resp.t()]
}

#[test]
fn stdin_rows_match_the_library_exactly() {
    let input = "wavelength_nm,n_film,thickness_nm,angle_deg\n550,1.33,500,30\n400,1.45,0,0\n\n830,1.2,2500.5,89.9\n";
    let out = rows(&stdout(&run(&[], input)));
    let queries = [
        (500.0, 30.0, 550.0, 1.33),
        (0.0, 0.0, 400.0, 1.45),
        (2500.5, 89.9, 830.0, 1.2),
    ];
    assert_eq!(out.len(), queries.len());
    for (row, &(d, a, l, n)) in out.iter().zip(&queries) {
        assert_eq!(&row[..4], &[d, a, l, n]);
        // Shortest round-trip formatting: bit-for-bit the library's values.
        assert_eq!(&row[4..], &expected(1.0, d, a, l, n));
    }
    assert_eq!(out[1][6], 0.0, "a vanishing film reflects nothing");
}

#[test]
fn n_film_column_is_optional_and_n_outside_applies() {
    let out = rows(&stdout(&run(
        &["--n-outside", "1.1"],
        "thickness_nm,angle_deg,wavelength_nm\n300,45,600\n",
    )));
    assert_eq!(out[0][3], 1.33);
    assert_eq!(&out[0][4..], &expected(1.1, 300.0, 45.0, 600.0, 1.33));
    let out = rows(&stdout(&run(
        &["--n-film", "1.4"],
        "thickness_nm,angle_deg,wavelength_nm\n300,45,600\n",
    )));
    assert_eq!(out[0][3], 1.4);
    assert_eq!(&out[0][4..], &expected(1.0, 300.0, 45.0, 600.0, 1.4));
}

#[test]
fn transmittance_is_reported_and_conserves_energy() {
    let out = rows(&stdout(&run(
        &[],
        "thickness_nm,angle_deg,wavelength_nm\n123,10,450\n777,70,700\n",
    )));
    for row in out {
        assert!(
            (row[6] + row[7] - 1.0).abs() < 1e-12,
            "r + t = {}",
            row[6] + row[7]
        );
        assert_eq!(row[6], (row[4] + row[5]) / 2.0);
    }
}

#[test]
fn single_query_flags_print_header_and_one_row() {
    let text = stdout(&run(
        &[
            "--thickness-nm",
            "500",
            "--angle-deg",
            "30",
            "--wavelength-nm",
            "550",
        ],
        "",
    ));
    let out = rows(&text);
    assert_eq!(out.len(), 1);
    assert_eq!(&out[0][..4], &[500.0, 30.0, 550.0, 1.33]);
    assert_eq!(&out[0][4..], &expected(1.0, 500.0, 30.0, 550.0, 1.33));
    let text = stdout(&run(
        &[
            "--thickness-nm",
            "500",
            "--angle-deg",
            "30",
            "--wavelength-nm",
            "550",
            "--n-film",
            "1.5",
        ],
        "",
    ));
    assert_eq!(rows(&text)[0][3], 1.5);
}

#[test]
fn header_only_gives_header_only() {
    assert_eq!(
        stdout(&run(&[], "thickness_nm,angle_deg,wavelength_nm\n")),
        format!("{HEADER}\n")
    );
}

/// Runs with bad input and checks: exit code 2, empty stdout, stderr naming `needles`.
#[track_caller]
fn rejects(args: &[&str], stdin: &str, needles: &[&str]) {
    let output = run(args, stdin);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "stderr: {stderr}");
    assert!(
        output.stdout.is_empty(),
        "stdout: {}",
        String::from_utf8_lossy(&output.stdout)
    );
    for needle in needles {
        assert!(
            stderr.contains(needle),
            "stderr {stderr:?} lacks {needle:?}"
        );
    }
}

const GOOD: &str = "thickness_nm,angle_deg,wavelength_nm\n100,10,500\n";

#[test]
fn non_numeric_field_is_rejected_with_line_and_value() {
    rejects(
        &[],
        &format!("{GOOD}abc,10,500\n"),
        &["line 3", "thickness_nm", "'abc'"],
    );
    rejects(
        &[],
        &format!("{GOOD}100,NaN,500\n"),
        &["line 3", "angle_deg", "'NaN'"],
    );
}

#[test]
fn missing_or_unknown_columns_are_rejected() {
    rejects(
        &[],
        "thickness_nm,angle_deg\n1,2\n",
        &["line 1", "wavelength_nm"],
    );
    rejects(
        &[],
        "thickness_nm,angle_deg,wavelength_nm,colour\n1,2,500,red\n",
        &["unknown column 'colour'"],
    );
    rejects(&[], &format!("{GOOD}100,10\n"), &["line 3", "2 fields"]);
    rejects(&[], "", &["empty input"]);
}

#[test]
fn negative_thickness_is_rejected() {
    rejects(
        &[],
        &format!("{GOOD}-5,10,500\n"),
        &["line 3", "thickness_nm", "'-5'"],
    );
    rejects(
        &[
            "--thickness-nm",
            "-5",
            "--angle-deg",
            "0",
            "--wavelength-nm",
            "500",
        ],
        "",
        &["--thickness-nm -5"],
    );
}

#[test]
fn angle_outside_0_to_90_is_rejected() {
    rejects(
        &[],
        &format!("{GOOD}100,90,500\n"),
        &["line 3", "angle_deg", "'90'"],
    );
    rejects(&[], &format!("{GOOD}100,-1,500\n"), &["line 3", "'-1'"]);
    rejects(
        &[
            "--thickness-nm",
            "5",
            "--angle-deg",
            "95",
            "--wavelength-nm",
            "500",
        ],
        "",
        &["--angle-deg 95"],
    );
}

#[test]
fn wavelength_outside_the_constant_index_range_is_rejected() {
    rejects(
        &[],
        &format!("{GOOD}100,10,99.9\n"),
        &["line 3", "wavelength_nm", "'99.9'", "[100, 100000]"],
    );
    rejects(
        &[],
        &format!("{GOOD}100,10,100001\n"),
        &["line 3", "'100001'"],
    );
}

#[test]
fn infrared_and_ultraviolet_wavelengths_match_the_library() {
    let input = "thickness_nm,angle_deg,wavelength_nm\n300,20,1550\n300,20,350\n";
    let out = rows(&stdout(&run(&[], input)));
    for (row, l) in out.iter().zip([1550.0, 350.0]) {
        let want = expected(1.0, 300.0, 20.0, l, 1.33);
        assert_eq!(&row[4..], &want[..], "{l} nm");
    }
}

#[test]
fn bad_refractive_index_is_rejected() {
    let header = "thickness_nm,angle_deg,wavelength_nm,n_film\n";
    rejects(
        &[],
        &format!("{header}100,10,500,0\n"),
        &["line 2", "n_film", "'0'"],
    );
    rejects(
        &[],
        &format!("{header}100,10,500,-1.3\n"),
        &["line 2", "'-1.3'"],
    );
    rejects(
        &[],
        &format!("{header}100,10,500,inf\n"),
        &["line 2", "'inf'"],
    );
    // Finite, but n² overflows: once printed NaN and exited 0.
    rejects(
        &[],
        &format!("{header}0,0,500,1e155\n"),
        &["line 2", "'1e155'"],
    );
    rejects(&["--n-outside", "0"], GOOD, &["--n-outside 0"]);
    rejects(&["--n-film", "-2"], GOOD, &["--n-film -2"]);
}

#[test]
fn partial_single_query_flags_are_rejected() {
    rejects(&["--thickness-nm", "5"], "", &["--angle-deg"]);
}

#[test]
fn incoherent_slide_in_a_stack_is_the_closed_form_sum_of_intensities() {
    // A bare 1 mm slide: R = R1 + T1² R1 / (1 − R1²) for each polarisation, R1 from the
    // single interface; its thickness does not matter when it does not absorb.
    let text = stdout(&run(
        &["--stack", "1.0 | 1.52 @ 1e6 incoherent | 1.0"],
        "angle_deg,wavelength_nm\n0,550\n45,600\n",
    ));
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("angle_deg,wavelength_nm,r_s,r_p,r,t,a"));
    for (line, angle) in lines.zip([0.0, 45.0]) {
        let v: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        let cos = f64::to_radians(angle).cos();
        let one = thinfilm::Interface::new(1.0, thinfilm::Complex64::new(1.52, 0.0))
            .unwrap()
            .response(cos);
        for (r, r1) in [(v[2], one.r_s), (v[3], one.r_p)] {
            let t1 = 1.0 - r1;
            let closed = r1 + t1 * t1 * r1 / (1.0 - r1 * r1);
            assert!((r - closed).abs() < 1e-14, "angle {angle}: {r} vs {closed}");
        }
        assert!(
            v[6].abs() < 1e-14,
            "a lossless slide absorbs nothing: a = {}",
            v[6]
        );
    }
}

#[test]
fn misspelt_incoherent_marker_is_rejected_naming_it() {
    rejects(
        &[
            "--stack",
            "1.0 | 1.52 @ 1e6 incoherant | 1.0",
            "--angle-deg",
            "0",
            "--wavelength-nm",
            "550",
        ],
        "",
        &["medium 2", "1e6 incoherant"],
    );
}

// `bubbles fit` (here beside the reflectance it inverts): a spectrum written by
// `bubbles reflectance --stack` is fitted back.

fn fit(args: &[&str], stdin: &str) -> Output {
    common::bubbles_piped(&[&["fit"], args].concat(), stdin)
}

#[test]
fn fit_recovers_the_thickness_that_reflectance_wrote() {
    let mut query = String::from("angle_deg,wavelength_nm\n");
    for k in 0..=100 {
        query.push_str(&format!("10,{}\n", 420 + 4 * k));
    }
    let stack = "1.0 | 1.46 @ 812.5 | 3.88+0.02i";
    let spectrum = stdout(&common::bubbles_piped(
        &["reflectance", "--stack", stack],
        &query,
    ));
    // Keep wavelength_nm and the unpolarised r (columns 2 and 5).
    let mut csv = String::from("wavelength_nm,r\n");
    for line in spectrum.lines().skip(1) {
        let v: Vec<&str> = line.split(',').collect();
        csv.push_str(&format!("{},{}\n", v[1], v[4]));
    }
    let out = stdout(&fit(
        &[
            "--spectrum",
            "-",
            "--stack",
            stack,
            "--angle-deg",
            "10",
            "--max-nm",
            "3000",
        ],
        &csv,
    ));
    let mut lines = out.lines();
    assert_eq!(
        lines.next(),
        Some(
            "thickness_nm,low_nm,high_nm,sigma_nm,systematic_nm,offset,rms_residual,runner_up_nm,runner_up_rms"
        )
    );
    let v: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|f| f.parse().unwrap())
        .collect();
    assert!((v[0] - 812.5).abs() < 1e-3, "{v:?}");
    assert!(v[1] <= 812.5 + 1e-3 && 812.5 - 1e-3 <= v[2], "{v:?}");
}

#[test]
fn fit_rejects_bad_input_with_exit_2_naming_it() {
    let spectrum = "wavelength_nm,r\n400,0.1\n500,0.2\n600,0.3\n";
    for (args, stdin, needle) in [
        (
            vec!["--spectrum", "-"],
            "wavelength_nm,r\n400,0.1\n500,x\n",
            "x",
        ),
        (vec!["--spectrum", "-", "--angle-deg", "95"], spectrum, "95"),
        (
            vec!["--spectrum", "-", "--min-nm", "9", "--max-nm", "1"],
            spectrum,
            "[9, 1]",
        ),
        (
            vec![
                "--spectrum",
                "-",
                "--stack",
                "1 | 1.46 @ 0 | 3.9",
                "--vary-layer",
                "2",
            ],
            spectrum,
            "--vary-layer 2",
        ),
        (
            vec!["--spectrum", "/nonexistent/s.csv"],
            "",
            "/nonexistent/s.csv",
        ),
    ] {
        let output = fit(&args, stdin);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(output.stdout.is_empty());
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
    }
}

#[test]
fn graded_layer_in_a_stack_reports_its_error_bound_and_a_constant_one_is_homogeneous() {
    let query = "angle_deg,wavelength_nm\n0,550\n40,700\n";
    let graded = stdout(&run(
        &["--stack", "1.0 | linear(1.8, 1.8) @ 250 | 1.52"],
        query,
    ));
    let plain = stdout(&run(&["--stack", "1.0 | 1.8 @ 250 | 1.52"], query));
    let mut g = graded.lines();
    assert_eq!(
        g.next(),
        Some("angle_deg,wavelength_nm,r_s,r_p,r,t,a,error_bound")
    );
    for (g, p) in g.zip(plain.lines().skip(1)) {
        let g: Vec<f64> = g.split(',').map(|f| f.parse().unwrap()).collect();
        let p: Vec<f64> = p.split(',').map(|f| f.parse().unwrap()).collect();
        for k in 2..6 {
            assert!((g[k] - p[k]).abs() < 1e-12, "{g:?} vs {p:?}");
        }
        assert!(g[7] <= 1e-9, "error bound {}", g[7]);
    }
    // An air-to-glass ramp: far below bare glass's 4.3 %, within its stated bound.
    let ramp = stdout(&run(
        &[
            "--stack",
            "1.0 | linear(1.0, 1.52) @ 500 | 1.52",
            "--graded-tolerance",
            "1e-7",
        ],
        "angle_deg,wavelength_nm\n0,550\n",
    ));
    let v: Vec<f64> = ramp
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|f| f.parse().unwrap())
        .collect();
    assert!(v[4] < 0.005 && v[7] <= 1e-7, "{v:?}");
}

#[test]
fn bad_graded_layers_are_rejected_naming_them() {
    let flags = ["--angle-deg", "0", "--wavelength-nm", "550"];
    for (stack, needle) in [
        ("1.0 | linear(1.0 1.5) @ 100 | 1.5", "n_front, n_back"),
        ("1.0 | exponential(1.0, 1.5+1i) @ 100 | 1.5", "real"),
        (
            "1.0 | linear(1.0, 1.5) @ 100 | linear(1.0, 1.5) @ 100 | 1.5",
            "only one",
        ),
        (
            "1.0 | graded(/nonexistent/p.csv) | 1.5",
            "/nonexistent/p.csv",
        ),
        ("1.0 | linear(1.0, -1.5) @ 100 | 1.5", "-1.5"),
    ] {
        rejects(
            &[&["--stack", stack][..], &flags[..]].concat(),
            "",
            &[needle],
        );
    }
    rejects(
        &[
            &[
                "--stack",
                "1.0 | linear(1.0, 1.5) @ 100 | 1.5",
                "--graded-tolerance",
                "0",
            ][..],
            &flags[..],
        ]
        .concat(),
        "",
        &["--graded-tolerance 0"],
    );
}

//! `bubbles reflectance --stack` run as a process: multilayer and absorbing stacks against
//! the library's single film, closed forms and R + T + A = 1, and bad stacks rejected.

use std::process::Output;

use thinfilm::airy::ThinFilm;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::{Complex64, Incidence, Interface};

mod common;

fn run(args: &[&str], stdin: &str) -> Output {
    common::bubbles_piped(&[&["reflectance"], args].concat(), stdin)
}

/// The header and the numeric rows of a successful run.
fn table(args: &[&str], stdin: &str) -> (String, Vec<Vec<f64>>) {
    let out = run(args, stdin);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "exit {:?}: {stderr}",
        out.status.code()
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_owned();
    let rows = lines
        .map(|l| l.split(',').map(|f| f.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[track_caller]
fn assert_close(label: &str, actual: f64, expected: f64, tol: f64) {
    let diff = (actual - expected).abs();
    assert!(
        diff <= tol,
        "{label}: {actual} vs {expected}, |diff| = {diff:e} > {tol:e}"
    );
}

#[test]
fn one_layer_stack_is_the_airy_film() {
    let input = "angle_deg,wavelength_nm,thickness_nm\n0,550,0\n30,1064,250\n80,1550,1200\n";
    let (header, rows) = table(&["--stack", "1.0 | 1.33 @ 0 | 1.0"], input);
    assert_eq!(header, "thickness_nm,angle_deg,wavelength_nm,r_s,r_p,r,t,a");
    for row in rows {
        let (d, angle, l) = (row[0], row[1], row[2]);
        let film = ThinFilm::symmetric(1.0, RefractiveIndex::Constant(1.33), d);
        let want = film
            .try_response_at(l, Incidence::try_from_angle_deg(angle).unwrap())
            .unwrap();
        assert_close("r_s", row[3], want.r_s, 1e-14);
        assert_close("r_p", row[4], want.r_p, 1e-14);
        assert_close("t", row[6], want.t(), 1e-14);
        assert_close("a (lossless)", row[7], 0.0, 1e-14);
    }
}

#[test]
fn quarter_wave_antireflection_coating_matches_its_closed_form() {
    // λ/4 of MgF2 (1.38) on glass (1.52) at 550 nm: R = ((n0 ns − n1²)/(n0 ns + n1²))².
    let d = 550.0 / (4.0 * 1.38);
    let stack = format!("1.0 | 1.38 @ {d} | 1.52");
    let (header, rows) = table(
        &[
            "--stack",
            &stack,
            "--angle-deg",
            "0",
            "--wavelength-nm",
            "550",
        ],
        "",
    );
    assert_eq!(header, "angle_deg,wavelength_nm,r_s,r_p,r,t,a");
    let want = ((1.52 - 1.38f64 * 1.38) / (1.52 + 1.38 * 1.38)).powi(2);
    assert_close("R", rows[0][4], want, 1e-14);
}

#[test]
fn absorbing_stack_conserves_energy_and_thick_metal_is_bare_metal() {
    let input =
        "angle_deg,wavelength_nm,thickness_nm\n0,550,5\n45,700,20\n60,400,40\n0,550,20000\n";
    let (_, rows) = table(
        &[
            "--stack",
            "1.0 | 1.38 @ 100 | 0.18+3.4i @ 0 | 1.5",
            "--vary-layer",
            "2",
        ],
        input,
    );
    for row in &rows {
        let (r, t, a) = (row[5], row[6], row[7]);
        assert_close("r + t + a", r + t + a, 1.0, 1e-15);
        assert!(a > 0.0 && r > 0.0 && t >= 0.0, "{row:?}");
    }
    // 20 µm of metal: the glass behind is out of reach; compare with the metal as substrate.
    let (_, bare) = table(
        &[
            "--stack",
            "1.0 | 1.38 @ 100 | 0.18+3.4i",
            "--angle-deg",
            "0",
            "--wavelength-nm",
            "550",
        ],
        "",
    );
    let thick = rows.last().unwrap();
    assert_close("R", thick[5], bare[0][4], 1e-14);
    assert_eq!(thick[6], 0.0);
    // And the bare metal is one Fresnel interface.
    let (_, metal) = table(
        &[
            "--stack",
            "1.0 | 0.18+3.4i",
            "--angle-deg",
            "0",
            "--wavelength-nm",
            "550",
        ],
        "",
    );
    let surface = Interface::new(1.0, Complex64::new(0.18, 3.4)).unwrap();
    assert_close("R", metal[0][4], surface.response(1.0).r(), 1e-15);
}

#[test]
fn tabulated_substrate_is_read_from_csv() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gold.csv");
    std::fs::write(&path, "wavelength_nm,n,k\n500,0.97,1.87\n1550,0.52,10.7\n").unwrap();
    let table_stack = format!("1.0 | 1.38 @ 100 | {}", path.display());
    let args = ["--angle-deg", "20", "--wavelength-nm", "1550"];
    let (_, on_table) = table(&[&["--stack", &table_stack][..], &args].concat(), "");
    let (_, on_value) = table(
        &[&["--stack", "1.0 | 1.38 @ 100 | 0.52+10.7i"][..], &args].concat(),
        "",
    );
    assert_eq!(on_table, on_value);
    let out = run(
        &[
            "--stack",
            &table_stack,
            "--angle-deg",
            "0",
            "--wavelength-nm",
            "1600",
        ],
        "",
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("1600") && stderr.contains("1550"),
        "{stderr}"
    );
}

#[test]
fn bad_stacks_and_queries_exit_2_naming_the_value() {
    let one = ["--angle-deg", "0", "--wavelength-nm", "550"];
    for (stack, needle) in [
        ("1.0", "at least"),
        ("1.0 | 1.38 | 1.5", "`1.38` is not `index @ thickness_nm`"),
        ("1.0 | 1.38 @ -5 | 1.5", "`-5`"),
        ("1.0 | 1.38 @ 100 | 0.2-3i", "0.2-3i"),
        ("0.5+1i | 1.5", "incidence medium"),
        ("1.0 | glass @ 10 | 1.5", "`glass`"),
        ("1.0 | 1e155 @ 10 | 1.5", "1e155"),
        ("1.0 | missing.csv", "missing.csv"),
    ] {
        let out = run(&[&["--stack", stack][..], &one].concat(), "");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stack}: {stderr}");
        assert!(out.stdout.is_empty(), "{stack}");
        assert!(
            stderr.contains(needle),
            "{stack}: {stderr:?} lacks {needle:?}"
        );
    }
    for (input, needle) in [
        ("angle_deg,wavelength_nm\n0,50\n", "50 nm"),
        ("angle_deg,wavelength_nm\n90,500\n", "angle_deg 90"),
        ("angle_deg,wavelength_nm,thickness_nm\n0,500,-1\n", "'-1'"),
    ] {
        let out = run(&["--stack", "1.0 | 1.38 @ 100 | 1.5"], input);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{input}: {stderr}");
        assert!(
            stderr.contains(needle) && stderr.contains("line 2"),
            "{stderr}"
        );
    }
    let out = run(
        &["--stack", "1.0 | 1.5", "--vary-layer", "1"],
        "angle_deg,wavelength_nm,thickness_nm\n0,500,1\n",
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--vary-layer 1"));
}

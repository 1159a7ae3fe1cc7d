//! `bubbles bake` end to end: what it writes, and that bad input exits 2 with a clear
//! message, nothing on stdout and no file in the output directory.

mod common;

use common::{bake, files_in};
use std::path::Path;

/// Runs a bake that must be refused as bad input, returning its stderr.
fn refused(dir: &Path, extra: &[&str]) -> String {
    let out_dir = dir.to_str().expect("utf-8 path");
    let mut args = vec!["--out", out_dir];
    if !extra.contains(&"--resolution") {
        args.extend(["--resolution", "16x4"]);
    }
    args.extend_from_slice(extra);
    let output = bake(&args);
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(
        output.status.code(),
        Some(2),
        "args {extra:?}; stderr: {stderr}"
    );
    assert!(output.stdout.is_empty(), "stdout not empty for {extra:?}");
    assert_eq!(
        files_in(dir),
        Vec::<String>::new(),
        "files left for {extra:?}"
    );
    stderr
}

#[test]
fn writes_every_table_in_every_format_and_loads_back_bit_exactly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out_dir = dir.path().join("luts");
    let output = bake(&[
        "--out",
        out_dir.to_str().expect("utf-8"),
        "--resolution",
        "64x16",
        "--thickness-max-nm",
        "1500",
        "--illuminant",
        "sodium",
        "f11",
        "--format",
        "exr,png16,png8",
        "--water-dispersion",
        "--observer",
        "1964",
        "--step-nm",
        "10",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let names = files_in(&out_dir);
    for stem in ["reflectivity", "transmittance", "light_sodium", "light_f11"] {
        for suffix in [".exr", ".png", ".preview.png"] {
            assert!(
                names.contains(&format!("{stem}{suffix}")),
                "{stem}{suffix} in {names:?}"
            );
        }
    }
    assert!(names.contains(&"lut.json".to_owned()));
    assert_eq!(names.len(), 13, "{names:?}");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(stdout.lines().count(), 13, "{stdout}");

    let set = lut::LutSet::load(&out_dir).expect("loads");
    let config = lut::BakeConfig::builder()
        .resolution(64, 16)
        .thickness_max_nm(1500.0)
        .lights(
            [
                thinfilm::illuminant::Illuminant::Sodium,
                thinfilm::illuminant::Illuminant::F11,
            ]
            .map(lut::Light::illuminant)
            .to_vec(),
        )
        .film_index(thinfilm::dispersion::RefractiveIndex::Water)
        .observer(thinfilm::cmf::Observer::Cie1964)
        .step_nm(10.0)
        .build()
        .expect("valid");
    let direct = lut::bake(&config);
    assert_eq!(set.meta, direct.meta);
    for ((name, loaded), (_, baked)) in set.named_tables().into_iter().zip(direct.named_tables()) {
        let same_bits = loaded
            .texels()
            .iter()
            .zip(baked.texels())
            .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
        assert!(
            same_bits,
            "{name} differs from a library bake of the same settings"
        );
    }
}

#[test]
fn a_csv_light_gets_a_table_named_after_its_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let csv = dir.path().join("lamp.csv");
    std::fs::write(&csv, "wavelength_nm,value\n400,1\n550,3\n700,1\n").expect("write");
    let out_dir = dir.path().join("out");
    let output = bake(&[
        "--out",
        out_dir.to_str().expect("utf-8"),
        "--resolution",
        "8x4",
        "--illuminant",
        csv.to_str().expect("utf-8"),
        "--n-film",
        "1.4",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let set = lut::LutSet::load(&out_dir).expect("loads");
    assert!(set.light("lamp").is_some());
    assert!(
        set.meta.film_index.contains("1.4"),
        "{}",
        set.meta.film_index
    );
}

#[test]
fn refuses_zero_and_absurd_resolutions() {
    let dir = tempfile::tempdir().expect("temp dir");
    for resolution in ["0x16", "16x0", "1x4", "16385x4", "4x99999", "512", "axb"] {
        let stderr = refused(dir.path(), &["--resolution", resolution]);
        assert!(stderr.contains(resolution), "{resolution}: {stderr}");
    }
}

#[test]
fn refuses_negative_and_zero_thickness_ranges() {
    let dir = tempfile::tempdir().expect("temp dir");
    for thickness in ["-5", "0", "nan", "1e9"] {
        let stderr = refused(dir.path(), &["--thickness-max-nm", thickness]);
        assert!(stderr.contains("thickness"), "{thickness}: {stderr}");
    }
}

#[test]
fn refuses_an_unknown_illuminant_listing_the_valid_ones() {
    let dir = tempfile::tempdir().expect("temp dir");
    let stderr = refused(dir.path(), &["--illuminant", "d65", "candle"]);
    assert!(stderr.contains("candle"), "{stderr}");
    for name in ["d65", "a", "f11", "sodium"] {
        assert!(stderr.contains(name), "{name} not listed: {stderr}");
    }
    let stderr = refused(dir.path(), &["--reference", "moonlight"]);
    assert!(stderr.contains("moonlight"), "{stderr}");
}

#[test]
fn refuses_a_malformed_csv_spectrum_naming_the_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let csv = dir.path().join("broken.csv");
    std::fs::write(&csv, "wavelength_nm,value\n400,1\n450,-2\n").expect("write");
    let out_dir = dir.path().join("out");
    let stderr = refused(&out_dir, &["--illuminant", csv.to_str().expect("utf-8")]);
    assert!(
        stderr.contains("broken.csv") && stderr.contains("line 3"),
        "{stderr}"
    );
    let missing = dir.path().join("missing.csv");
    let stderr = refused(
        &out_dir,
        &["--illuminant", missing.to_str().expect("utf-8")],
    );
    assert!(stderr.contains("missing.csv"), "{stderr}");
}

#[test]
fn refuses_an_unwritable_directory() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("a-file");
    std::fs::write(&file, b"not a directory").expect("write");
    let out_dir = file.join("luts");
    let output = bake(&[
        "--out",
        out_dir.to_str().expect("utf-8"),
        "--resolution",
        "8x4",
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(output.stdout.is_empty());
    assert!(stderr.contains("a-file"), "{stderr}");
    assert_eq!(std::fs::read(&file).expect("read"), b"not a directory");
}

#[test]
fn refuses_other_bad_values() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (args, needle) in [
        (&["--format", "exr,tiff"][..], "tiff"),
        (&["--observer", "1950"][..], "1950"),
        (&["--step-nm", "0"][..], "step"),
        (&["--n-film", "-1.3"][..], "-1.3"),
        (
            &["--n-film", "1.3", "--water-dispersion"][..],
            "water-dispersion",
        ),
        (&["--reference", "sodium"][..], "sodium"),
    ] {
        let stderr = refused(dir.path(), args);
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}

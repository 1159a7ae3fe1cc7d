//! Hostile input end to end (issues 8 and 16): every case that once hung, ate memory,
//! panicked or printed a misleading message now exits 2 with a message naming the key
//! or flag and the value, or finishes within the limits of `bubbles --help`.

use std::path::Path;
use std::process::Output;

mod common;
use common::bubbles;
use common::hostile::{BASE, TINY, refused, scene};

fn render(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["render", "s.toml", "--out", "x.png"];
    args.extend(extra);
    bubbles(&args, dir)
}

#[test]
fn render_time_of_a_billion_seconds_is_refused() {
    let dir = scene("");
    refused(
        &render(dir.path(), &["--time-s", "1e9"]),
        &["--time-s", "1e9"],
    );
    let dir = tempfile::tempdir().unwrap();
    let text = BASE.replace(
        "[[bubbles]]\ncenter_m = [0.0, 0.06, 0.0]\nradius_m = 0.05\n",
        "",
    );
    std::fs::write(dir.path().join("s.toml"), format!("time_s = 1e9\n{text}")).unwrap();
    refused(&render(dir.path(), &[]), &["s.toml:1:", "time_s", "1e9"]);
}

#[test]
fn simulate_for_a_billion_seconds_is_refused_before_stepping() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(&["simulate", "paper", "--seconds", "1e9"], dir.path());
    refused(&out, &["--seconds 1e9", "1000000"]);
}

#[test]
fn tiny_and_huge_time_steps_are_refused_with_their_key() {
    for dt in ["1e-300", "1e300"] {
        let dir = scene(&format!("[dynamics]\ndt_s = {dt}\n"));
        let out = bubbles(&["simulate", "s.toml", "--seconds", "1"], dir.path());
        refused(&out, &["dynamics.dt_s", dt]);
    }
}

#[test]
fn obj_export_at_a_trillion_fps_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "simulate",
        "paper",
        "--seconds",
        "1",
        "--fps",
        "1e12",
        "--export-obj",
        "D",
    ];
    refused(
        &bubbles(&args, dir.path()),
        &["--fps 1e12", "OBJ files", "10000"],
    );
    let written = std::fs::read_dir(dir.path().join("D")).map_or(0, Iterator::count);
    assert_eq!(written, 0);
}

#[test]
fn bench_with_u32_max_frames_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(&["bench", "--frames", "4294967295"], dir.path());
    refused(&out, &["--frames 4294967295", "100000"]);
}

#[test]
fn bench_width_and_height_set_the_size() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "bench",
        "--frames",
        "1",
        "--width",
        "24",
        "--height",
        "16",
        "--cube-map-size",
        "4",
        "--samples",
        "1",
    ];
    let out = bubbles(&args, dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = String::from_utf8_lossy(&out.stdout);
    let sizes: Vec<&str> = report
        .lines()
        .skip(2)
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert_eq!(sizes, ["24x16"], "{report}");
}

#[test]
fn huge_cube_maps_are_refused_naming_flag_or_key() {
    let dir = scene("");
    refused(
        &render(dir.path(), &["--cube-map-size", "8192"]),
        &["--cube-map-size 8192", "1024"],
    );
    refused(
        &render(dir.path(), &["--cube-map-size", "0"]),
        &["--cube-map-size 0"],
    );
    let dir = scene("[render]\ncube_map_size = 0\n");
    let err = refused(
        &render(dir.path(), &[]),
        &["render.cube_map_size", "0 is outside"],
    );
    assert!(!err.contains("face_size"), "{err}");
}

#[test]
fn ten_thousand_bubbles_are_refused_before_allocating() {
    let mut extra = String::new();
    for i in 0..10_000 {
        let (x, z) = ((i % 100) as f64 * 0.2, (i / 100) as f64 * 0.2);
        extra.push_str(&format!(
            "[[bubbles]]\ncenter_m = [{x}, 1.0, {z}]\nradius_m = 0.05\n"
        ));
    }
    let dir = scene(&extra);
    refused(&render(dir.path(), &TINY), &["10001 bubbles", "1000"]);
}

#[test]
fn a_render_planning_more_than_the_memory_budget_is_refused() {
    let mut extra = String::new();
    for i in 0..900 {
        let (x, z) = ((i % 30) as f64 * 0.2, (i / 30) as f64 * 0.2);
        extra.push_str(&format!(
            "[[bubbles]]\ncenter_m = [{x}, 1.0, {z}]\nradius_m = 0.05\nsubdivisions = 0\n"
        ));
    }
    let dir = scene(&extra);
    let out = render(
        dir.path(),
        &["--cube-map-size", "256", "--width", "16", "--height", "16"],
    );
    refused(&out, &["cube_map_size = 256", "GiB", "limit"]);
}

#[test]
fn ten_thousand_spheres_are_refused() {
    let sphere = "[[objects]]\nkind = \"sphere\"\ncenter_m = [1.0, 0.0, 1.0]\nradius_m = 0.01\n\
                  material = { kind = \"solid\", albedo = [0.5, 0.5, 0.5] }\n";
    let dir = scene(&sphere.repeat(10_000));
    refused(&render(dir.path(), &TINY), &["10000 objects", "1000"]);
}

/// A PNG chunk: length, type, data, CRC-32.
fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let body = [&kind[..], data].concat();
    let mut crc = !0u32;
    for &b in &body {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend(body);
    out.extend((!crc).to_be_bytes());
    out
}

/// A 100-byte PNG whose header claims `side × side` pixels (a decompression bomb's
/// shape: the decoder would allocate the pixels before finding the data short).
fn png_header(side: u32) -> Vec<u8> {
    let mut ihdr = side.to_be_bytes().to_vec();
    ihdr.extend(side.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    // An empty zlib stream: one stored block of length 0, Adler-32 of nothing.
    let idat = [
        0x78, 0x01, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0x00, 0x00, 0x00, 0x01,
    ];
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &idat));
    png.extend(chunk(b"IEND", &[]));
    png
}

#[test]
fn decompression_bomb_environment_is_refused_from_its_header() {
    let dir = scene("[environment]\nkind = \"equirect\"\npath = \"bomb.png\"\n");
    std::fs::write(dir.path().join("bomb.png"), png_header(20000)).unwrap();
    refused(
        &render(dir.path(), &TINY),
        &["environment.path", "bomb.png", "20000x20000"],
    );
}

#[test]
fn endless_files_are_refused_not_read_forever() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(&["render", "/dev/zero", "--out", "x.png"], dir.path());
    refused(&out, &["/dev/zero", "64 MiB"]);
    let mesh = "[[objects]]\nkind = \"mesh\"\npath = \"/dev/zero\"\n\
                material = { kind = \"solid\", albedo = [1, 1, 1] }\n";
    let dir = scene(mesh);
    let err = refused(
        &render(dir.path(), &TINY),
        &["objects.path", "/dev/zero", "OBJ"],
    );
    assert!(!err.contains("image"), "{err}");
    let light = "[[lights]]\nposition_m = [0, 1, 0]\nradius_m = 0.1\nspectrum = \"z.csv\"\n";
    let dir = scene(light);
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("z.csv")).unwrap();
    refused(
        &render(dir.path(), &TINY),
        &["spectrum", "z.csv", "not a regular file"],
    );
}

#[test]
fn extreme_radius_and_thickness_name_key_line_and_value() {
    for (key, value, line) in [
        ("radius_m", "1e-300", "s.toml:6:"),
        ("radius_m", "1e300", "s.toml:6:"),
        ("mean_thickness_nm", "1e300", "s.toml:7:"),
    ] {
        let text = if key == "radius_m" {
            BASE.replace("radius_m = 0.05", &format!("radius_m = {value}"))
        } else {
            format!("{BASE}{key} = {value}\n")
        };
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("s.toml"), text).unwrap();
        for command in ["render", "simulate"] {
            let out = bubbles(
                &[command, "s.toml", "--out", "x.png"][..if command == "render" { 4 } else { 2 }],
                dir.path(),
            );
            let err = refused(&out, &[line, &format!("bubbles.{key}"), value]);
            assert!(
                !err.contains("inf") && !err.contains("18446744073709551615"),
                "{err}"
            );
        }
    }
}

#[test]
fn far_eye_is_refused_as_out_of_range_not_as_eye_equals_target() {
    let text = BASE.replace("eye_m = [0.0, 0.1, 0.4]", "eye_m = [0, 0, 1e30]");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), text).unwrap();
    let err = refused(&render(dir.path(), &TINY), &["camera.eye_m", "1e30"]);
    assert!(!err.contains("both"), "{err}");
}

#[test]
fn overflowing_light_spectrum_names_the_file_and_value() {
    let light = "[[lights]]\nposition_m = [0, 1, 0]\nradius_m = 0.1\nspectrum = \"big.csv\"\n";
    let dir = scene(light);
    std::fs::write(
        dir.path().join("big.csv"),
        "wavelength_nm,value\n400,1e308\n700,1e308\n",
    )
    .unwrap();
    refused(&render(dir.path(), &TINY), &["big.csv", "line 2", "1e308"]);
    let out = bubbles(
        &["bake", "--out", "o", "--illuminant", "big.csv"],
        dir.path(),
    );
    refused(&out, &["big.csv", "line 2", "1e308"]);
}

#[test]
fn equirect_intensity_and_film_index_of_1e39_are_refused_not_panics() {
    let dir = scene("[environment]\nkind = \"equirect\"\npath = \"e.png\"\nintensity = 1e39\n");
    image::RgbImage::from_pixel(4, 2, image::Rgb([100, 150, 200]))
        .save(dir.path().join("e.png"))
        .unwrap();
    refused(
        &render(dir.path(), &TINY),
        &["environment.intensity", "1e39"],
    );
    let dir = scene("[film]\nn_film = 1e39\n");
    refused(&render(dir.path(), &TINY), &["film.n_film", "1e39"]);
}

#[test]
fn tiny_checker_scale_names_its_key_and_value() {
    let dir = scene(
        "[ground]\nmaterial = { kind = \"checker\", a = [1, 1, 1], b = [0, 0, 0], scale_m = 1e-300 }\n",
    );
    refused(&render(dir.path(), &TINY), &["scale_m", "1e-300"]);
}

#[test]
fn solver_messages_use_the_scene_names() {
    let sphere = "[[objects]]\nkind = \"sphere\"\ncenter_m = [0.0, 0.06, 0.0]\nradius_m = 0.02\n\
                  material = { kind = \"solid\", albedo = [1, 1, 1] }\n";
    let dir = scene(sphere);
    let out = bubbles(&["simulate", "s.toml"], dir.path());
    let err = refused(
        &out,
        &[
            "[[bubbles]] #1",
            "[[objects]] #1 (sphere, center_m = [0, 0.06, 0], radius_m = 0.02)",
            "[0.0, 0.06, 0.0]",
        ],
    );
    assert!(
        !err.contains("colliders[") && !err.contains("DVec3"),
        "{err}"
    );
}

/// Found by cli_extreme_numbers: a ground raised above the bubble was refused with a
/// message that named only the bubble's centre, never the key that was wrong.
#[test]
fn a_ground_above_the_bubble_is_refused_naming_ground_height_m() {
    let dir = scene("[ground]\nheight_m = 100.0\n");
    refused(
        &bubbles(&["simulate", "s.toml"], dir.path()),
        &["ground.height_m = 100", "[[bubbles]] #1"],
    );
}

#[test]
fn samples_refusals_name_the_flag_or_the_key() {
    let dir = scene("[render]\nsamples = 3\n");
    refused(&render(dir.path(), &[]), &["render.samples", "3"]);
    refused(&render(dir.path(), &["--samples", "5"]), &["--samples 5"]);
}

#[test]
fn help_states_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["--help"][..],
        &["render", "--help"],
        &["simulate", "--help"],
        &["bench", "--help"],
    ] {
        let out = bubbles(args, dir.path());
        let help = String::from_utf8_lossy(&out.stdout);
        assert!(
            help.contains("Limits") && help.contains("1..=1024 texels"),
            "{args:?}: {help}"
        );
    }
}

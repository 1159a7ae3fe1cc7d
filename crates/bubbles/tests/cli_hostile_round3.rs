//! Issue 28, round three of hostile use: numbers that overflowed on the way through
//! (image texels, tiny indices, huge thicknesses), 300-digit numbers in messages,
//! fixed-length arrays with extra elements, unwritable outputs found only after the
//! work, `animate --resume` trusting damaged frames, and the reference tracer's
//! exponential work. Each case exits 2 with a message naming the value, or works.

use std::path::Path;
use std::process::Output;

mod common;
use common::hostile::{BASE, TINY, refused, scene};
use common::{bubbles, bubbles_piped, files_in, stderr};

fn render(dir: &Path, out: &str) -> Output {
    let mut args = vec!["render", "s.toml", "--out", out];
    args.extend(TINY);
    bubbles(&args, dir)
}

/// A 4 × 2 linear EXR, every texel 0.5 but texel (1, 0), which is `value` in green.
fn write_exr(path: &Path, value: f32) {
    let mut img = image::Rgb32FImage::from_pixel(4, 2, image::Rgb([0.5, 0.5, 0.5]));
    img.put_pixel(1, 0, image::Rgb([0.5, value, 0.5]));
    img.save(path).unwrap();
}

#[test]
fn environment_texel_1e34_times_intensity_1e6_is_refused_not_a_panic() {
    let dir = scene("[environment]\nkind = \"equirect\"\npath = \"e.exr\"\nintensity = 1e6\n");
    write_exr(&dir.path().join("e.exr"), 1e34);
    refused(
        &render(dir.path(), "x.png"),
        &[
            "e.exr",
            "texel (1, 0)",
            "1e34",
            "intensity 1000000",
            "0..=1000000",
        ],
    );
}

#[test]
fn environment_and_ground_texels_near_f32_max_are_refused_not_nan_pixels() {
    let dir = scene("[environment]\nkind = \"equirect\"\npath = \"e.exr\"\n");
    write_exr(&dir.path().join("e.exr"), 3.4e38);
    refused(
        &render(dir.path(), "x.exr"),
        &["e.exr", "texel (1, 0)", "3.4e38"],
    );
    assert!(!dir.path().join("x.exr").exists());

    let ground = "[ground]\nmaterial = { kind = \"image\", path = \"g.exr\", scale_m = 0.1 }\n";
    let dir = scene(ground);
    write_exr(&dir.path().join("g.exr"), 3.4e38);
    refused(
        &render(dir.path(), "x.exr"),
        &["g.exr", "texel (1, 0)", "3.4e38"],
    );

    let faces = ["px", "nx", "py", "ny", "pz", "nz"].map(|f| format!("\"{f}.exr\""));
    let dir = scene(&format!(
        "[environment]\nkind = \"cube\"\nfaces = [{}]\n",
        faces.join(", ")
    ));
    for (k, f) in ["px", "nx", "py", "ny", "pz", "nz"].iter().enumerate() {
        let img = image::Rgb32FImage::from_pixel(2, 2, image::Rgb([0.5; 3]));
        let mut img = img;
        if k == 3 {
            img.put_pixel(1, 1, image::Rgb([3.4e38, 0.0, 0.0]));
        }
        img.save(dir.path().join(format!("{f}.exr"))).unwrap();
    }
    refused(
        &render(dir.path(), "x.exr"),
        &["ny.exr", "texel (1, 1)", "3.4e38"],
    );
}

#[test]
fn environment_texels_at_the_radiance_limit_render_finite_pixels() {
    let dir = scene("[environment]\nkind = \"equirect\"\npath = \"e.exr\"\nintensity = 10\n");
    write_exr(&dir.path().join("e.exr"), 1e5);
    let out = render(dir.path(), "x.exr");
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.path().join("x.exr")).unwrap().to_rgb32f();
    assert!(img.pixels().flat_map(|p| p.0).all(f32::is_finite));
}

fn reflectance(args: &[&str]) -> Output {
    bubbles_piped(&[&["reflectance"], args].concat(), "")
}

const ONE_QUERY: [&str; 4] = ["--angle-deg", "30", "--wavelength-nm", "550"];

#[test]
fn reflectance_indices_below_the_floor_are_refused_not_nan() {
    for (stack, medium) in [
        ("1e-300 | 1.38 @ 100 | 1.0", "n_incident"),
        ("1.0 | 1e-300 @ 100 | 1.0", "medium 2"),
        ("1e6 | 1.38 @ 100 | 1e-300", "medium 3"),
        ("1.0 | 1.38 @ 100 | 0.0009+1i", "medium 3"),
    ] {
        let out = reflectance(&[&["--stack", stack], &ONE_QUERY[..]].concat());
        let err = refused(&out, &[medium, "[0.001, "]);
        assert!(!err.contains("NaN") && out.stdout.is_empty(), "{err}");
    }
    for flag in ["--n-outside", "--n-film"] {
        let out =
            reflectance(&[&["--thickness-nm", "100", flag, "1e-300"], &ONE_QUERY[..]].concat());
        refused(&out, &[flag, "1e-300", "[0.001, 1e6]"]);
    }
    let csv = "thickness_nm,angle_deg,wavelength_nm,n_film\n100,30,550,1e-300\n";
    let out = bubbles_piped(&["reflectance"], csv);
    refused(&out, &["line 2", "n_film", "1e-300"]);
}

#[test]
fn reflectance_thickness_of_1e308_is_refused_not_unphysical() {
    let out = reflectance(&[&["--stack", "1.0 | 1.38 @ 1e308 | 1.0"], &ONE_QUERY[..]].concat());
    refused(&out, &["medium 2", "1e308", "[0, 1e9] nm"]);
    let out = reflectance(&[&["--thickness-nm", "1e308"], &ONE_QUERY[..]].concat());
    refused(&out, &["--thickness-nm 1e308", "[0, 1e9] nm"]);
    let stack = ["--stack", "1.0 | 1.38 @ 100 | 1.0"];
    let out = bubbles_piped(
        &[&["reflectance"], &stack[..]].concat(),
        "angle_deg,wavelength_nm,thickness_nm\n30,550,1e308\n",
    );
    refused(&out, &["line 2", "thickness_nm", "1e308"]);
}

#[test]
fn color_thickness_of_1e30_is_refused_as_input_not_an_optics_failure() {
    let out = bubbles_piped(&["color"], "thickness_nm,angle_deg\n1e30,10\n");
    refused(&out, &["line 2", "thickness_nm", "1e30", "[0, 1e9] nm"]);
}

#[test]
fn fit_over_a_thickness_range_of_1e308_is_refused_not_a_panic_or_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let spectrum = "wavelength_nm,r\n400,0.05\n500,0.08\n600,0.03\n700,0.06\n";
    std::fs::write(dir.path().join("r.csv"), spectrum).unwrap();
    // 1e308 overflowed a capacity (exit 101), 1e12 asked for 851 GB (abort).
    for max in ["1e308", "1e12"] {
        let out = bubbles(&["fit", "--spectrum", "r.csv", "--max-nm", max], dir.path());
        refused(&out, &[max, "more than 1e8: narrow the range"]);
    }
    let out = bubbles(
        &["fit", "--spectrum", "r.csv", "--max-nm", "2000"],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn reflectance_at_the_edges_of_the_ranges_stays_physical() {
    for stack in [
        "1.0 | 1.38 @ 1e9 | 1.0",
        "1.0 | 0.18+3.4i @ 1e9 | 1.0",
        "1e-3 | 1e6 @ 1e9 | 1e6+1e6i",
        "1e6 | 1e-3 @ 100 | 1e-3",
    ] {
        let out = reflectance(&[&["--stack", stack], &ONE_QUERY[..]].concat());
        assert!(out.status.success(), "{stack}: {}", stderr(&out));
        let text = String::from_utf8(out.stdout).unwrap();
        let row: Vec<f64> = text
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        let (r, t, a) = (row[4], row[5], row[6]);
        for v in [r, t] {
            assert!((0.0..=1.0).contains(&v), "{stack}: {text}");
        }
        assert!(
            a.abs() <= 1.0 && (r + t + a - 1.0).abs() < 1e-9,
            "{stack}: {text}"
        );
    }
}

#[test]
fn numbers_in_messages_are_short_not_300_digits() {
    let fps = bubbles(
        &[
            "animate",
            "demo",
            "--seconds",
            "1",
            "--fps",
            "1e-300",
            "--out",
            "f",
        ],
        Path::new("."),
    );
    let err = refused(&fps, &["--fps 1e-300", "at least 1/7200"]);
    assert!(!err.contains("1 / fps"), "{err}");
    let complex = reflectance(
        &[
            &["--stack", "1.0 | 0.18+1e308i @ 100 | 1.0"],
            &ONE_QUERY[..],
        ]
        .concat(),
    );
    refused(&complex, &["0.18+1e308i"]);
    let out = bubbles_piped(&["color", "--n-film", "1e-300"], "");
    refused(&out, &["1e-300"]);
}

#[test]
fn fixed_length_arrays_with_extra_elements_are_refused_with_line_and_column() {
    for (water, place) in [
        (
            "min_m = [-1.0, -1.0]\nmax_m = [1.0, 1.0]\nslices = [4, 4, 4]\n",
            "s.toml:10:10: water.slices: an array of 3 elements where 2",
        ),
        (
            "min_m = [-1.0, -1.0]\nmax_m = [1.0, 1.0]\nslices = [4, 4, \"x\"]\n",
            "s.toml:10:17: water.slices: invalid type: string \"x\"",
        ),
        (
            "min_m = [-1.0, -1.0, 0.0]\nmax_m = [1.0, 1.0]\n",
            "s.toml:8:9: water.min_m: an array of 3 elements where 2",
        ),
    ] {
        let dir = scene(&format!("[water]\n{water}"));
        refused(&render(dir.path(), "x.png"), &[place]);
    }
    let dir = tempfile::tempdir().unwrap();
    let eye = BASE.replace("eye_m = [0.0, 0.1, 0.4]", "eye_m = [0.0, 0.1, 0.4, 9.0]");
    std::fs::write(dir.path().join("s.toml"), eye).unwrap();
    refused(
        &render(dir.path(), "x.png"),
        &["s.toml:2:9: camera.eye_m: an array of 4 elements where 3"],
    );
}

#[test]
fn an_unwritable_output_is_refused_before_the_work_and_named_once() {
    let dir = scene("");
    let err = refused(
        &render(dir.path(), "/proc/x.png"),
        &["--out /proc/x.png", "cannot create a file in /proc"],
    );
    assert_eq!(err.matches("cannot").count(), 1, "{err}");
    assert!(
        !err.contains(".tmp"),
        "the probe's temporary name is noise: {err}"
    );
    let chart = bubbles(&["chart", "--out", "/proc/c.png"], dir.path());
    refused(&chart, &["--out /proc/c.png"]);
    let animate = bubbles(
        &[
            "animate",
            "s.toml",
            "--seconds",
            "0.1",
            "--out",
            "/proc/a.apng",
        ],
        dir.path(),
    );
    refused(&animate, &["--out /proc/a.apng"]);
    let frames = bubbles(
        &[
            "animate",
            "s.toml",
            "--seconds",
            "0.1",
            "--out",
            "/proc/frames",
        ],
        dir.path(),
    );
    refused(&frames, &["--out /proc/frames"]);
}

#[test]
fn animate_to_an_apng_path_that_is_a_directory_is_refused() {
    let dir = scene("");
    std::fs::create_dir(dir.path().join("x.apng")).unwrap();
    let out = bubbles(
        &["animate", "s.toml", "--seconds", "0.1", "--out", "x.apng"],
        dir.path(),
    );
    refused(&out, &["x.apng", "is a directory"]);
    assert!(files_in(&dir.path().join("x.apng")).is_empty());
}

fn animate(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "animate",
        "s.toml",
        "--seconds",
        "0.2",
        "--fps",
        "10",
        "--out",
        "f",
    ];
    args.extend(TINY);
    args.extend(extra);
    bubbles(&args, dir)
}

#[test]
fn resume_renders_truncated_and_empty_frames_again_and_removes_temporaries() {
    let dir = scene("");
    let out = animate(dir.path(), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let frames = dir.path().join("f");
    let whole = std::fs::read(frames.join("frame_00001.png")).unwrap();
    std::fs::write(frames.join("frame_00000.png"), b"").unwrap();
    std::fs::write(frames.join("frame_00001.png"), &whole[..whole.len() / 2]).unwrap();
    std::fs::write(frames.join(".bubbles-AbC123.tmp"), b"partial").unwrap();
    let out = animate(dir.path(), &["--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("frame_00000.png") && err.contains("frame_00001.png"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(frames.join("frame_00001.png")).unwrap(),
        whole
    );
    assert!(image::open(frames.join("frame_00000.png")).is_ok());
    assert_eq!(
        files_in(&frames),
        ["animation.txt", "frame_00000.png", "frame_00001.png"]
    );
}

#[test]
fn resume_renders_swapped_frames_again_by_their_recorded_checksums() {
    let dir = scene("");
    assert!(animate(dir.path(), &[]).status.success());
    let frames = dir.path().join("f");
    let manifest = std::fs::read_to_string(frames.join("animation.txt")).unwrap();
    assert_eq!(manifest.matches("fnv1a64").count(), 2, "{manifest}");
    let (a, b) = (
        frames.join("frame_00000.png"),
        frames.join("frame_00001.png"),
    );
    let (first, second) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_ne!(first, second);
    // Both decode at the right size: only the checksums tell them apart.
    std::fs::write(&a, &second).unwrap();
    std::fs::write(&b, &first).unwrap();
    let out = animate(dir.path(), &["--resume"]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert_eq!(
        err.matches("does not match its checksum").count(),
        2,
        "{err}"
    );
    assert_eq!(std::fs::read(&a).unwrap(), first);
    assert_eq!(std::fs::read(&b).unwrap(), second);
}

#[test]
fn resume_into_frames_without_their_settings_file_is_refused() {
    let dir = scene("");
    assert!(animate(dir.path(), &[]).status.success());
    std::fs::remove_file(dir.path().join("f/animation.txt")).unwrap();
    let out = animate(dir.path(), &["--resume"]);
    refused(&out, &["--out f", "frames but no animation.txt"]);
}

#[test]
fn resume_where_a_frame_path_is_a_directory_names_the_frame() {
    let dir = scene("");
    assert!(animate(dir.path(), &[]).status.success());
    let frame = dir.path().join("f/frame_00001.png");
    std::fs::remove_file(&frame).unwrap();
    std::fs::create_dir(&frame).unwrap();
    let out = animate(dir.path(), &["--resume"]);
    refused(&out, &["frame 1", "frame_00001.png", "is a directory"]);
}

#[test]
fn reference_depth_64_on_sixteen_bubbles_is_refused_before_tracing() {
    let bubbles_line: String = (0..16)
        .map(|k| {
            format!(
                "[[bubbles]]\ncenter_m = [{}, 0.06, 0.0]\nradius_m = 0.02\n",
                -0.4 + 0.05 * f64::from(k)
            )
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let text =
        format!("[camera]\neye_m = [0.0, 0.1, 0.4]\ntarget_m = [0.0, 0.05, 0.0]\n{bubbles_line}");
    std::fs::write(dir.path().join("s.toml"), text).unwrap();
    let start = std::time::Instant::now();
    let out = bubbles(
        &[
            "render",
            "s.toml",
            "--out",
            "x.png",
            "--width",
            "4",
            "--height",
            "4",
            "--backend",
            "reference",
            "--ref-depth",
            "64",
            "--ref-min-weight",
            "0",
        ],
        dir.path(),
    );
    refused(
        &out,
        &[
            "--ref-depth 64",
            "film hits",
            "over the limit of 4.398046511104e12",
        ],
    );
    assert!(!dir.path().join("x.png").exists());
    eprintln!("refused in {:.2} s", start.elapsed().as_secs_f64());
}

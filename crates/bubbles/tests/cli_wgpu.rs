//! `--backend wgpu` end to end against the CPU backend (the specification), issue 12.
//!
//! Runs with `cargo test -p bubbles --features wgpu --test cli_wgpu`. Without an adapter
//! the image tests skip with a message, except under `CI=true`, where they fail.
#![cfg(feature = "wgpu")]

use std::path::Path;

mod common;
use common::{bubbles, json_field, stderr};

/// Renders built-in `scene` at 400×400 to `out` with `backend`; `false` (skip) outside CI
/// when the wgpu backend finds no adapter.
fn render(scene: &str, backend: &str, out: &str, dir: &Path) -> bool {
    render_with(scene, backend, out, dir, &[])
}

/// [`render`] with extra flags.
fn render_with(scene: &str, backend: &str, out: &str, dir: &Path, extra: &[&str]) -> bool {
    let mut args = vec![
        "render",
        scene,
        "--backend",
        backend,
        "--width",
        "400",
        "--height",
        "400",
        "--out",
        out,
    ];
    args.extend(extra);
    let Some((run, err)) = run_unless_no_adapter(&args, dir) else {
        return false;
    };
    assert!(run.status.success(), "{backend}: {err}");
    true
}

/// Runs `bubbles args` in `dir`: its output and stderr, or `None` (said on stderr) when
/// no wgpu adapter is found outside CI, where the wgpu tests are skipped.
fn run_unless_no_adapter(args: &[&str], dir: &Path) -> Option<(std::process::Output, String)> {
    let run = bubbles(args, dir);
    let err = stderr(&run);
    if !run.status.success() && err.contains("no wgpu adapter") && std::env::var_os("CI").is_none()
    {
        eprintln!("skipped: {err}");
        return None;
    }
    Some((run, err))
}

/// Renders `scene` through wgpu and through the CPU with per-triangle partial shading
/// (like for like: the GPU shades a partly covered pixel once per triangle) into `dir`;
/// returns their mean and 99th-percentile ΔE2000, or `None` when no adapter was found.
fn wgpu_against_cpu(scene: &str, dir: &Path) -> Option<(f64, f64)> {
    if !render(scene, "wgpu", "gpu.png", dir) {
        return None;
    }
    let per_triangle = ["--partial-shading", "per-triangle"];
    assert!(render_with(scene, "cpu", "cpu.png", dir, &per_triangle));
    Some(compare(dir, "cpu.png", "gpu.png"))
}

#[test]
fn paper_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    let Some(measured) = wgpu_against_cpu("paper", dir.path()) else {
        return;
    };
    // With the cube footprint filter ported the rims agree too: lavapipe measured mean
    // 0.042, p99 0.74; the GPU's taps all at level 0 gave p99 0.94, one level-0 tap 1.95.
    assert_within("paper", measured, (0.25, 0.9));
    // The CPU's default shares a partly covered pixel's shading across its layer: the
    // backends then differ at bubble edges (lavapipe: mean 0.076, p99 1.09).
    assert!(render("paper", "cpu", "cpu-shared.png", dir.path()));
    let measured = compare(dir.path(), "cpu-shared.png", "gpu.png");
    assert_within("per-surface CPU", measured, (0.25, 1.6));
}

/// `swirl`: one bubble whose film flow reaches the renderers as a film field (thickness
/// and coverage per pixel, black spots included), drawn by the GPU as by the CPU.
#[test]
fn swirl_film_field_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    let Some(measured) = wgpu_against_cpu("swirl", dir.path()) else {
        return;
    };
    // Lavapipe measured mean 0.052, p99 1.03, max 1.22 (a film read at the wrong place
    // or coverage ignored is several ΔE): above the paper's p99 (0.76) on this dark frame
    // that the film covers, within gpu_scene's 2.0; the cause is not analysed yet.
    assert_within("swirl", measured, (0.25, 1.5));
}

/// `dome`: a film standing on a wet surface, its lower half without film (coverage 0
/// below the contact line) and its plumes of regenerated film, drawn by the GPU as by
/// the CPU.
#[test]
fn dome_film_with_no_film_below_its_contact_line_through_wgpu_matches_the_cpu_backend() {
    let dir = tempfile::tempdir().unwrap();
    let Some(measured) = wgpu_against_cpu("dome", dir.path()) else {
        return;
    };
    // Lavapipe measured mean 0.021, p99 0.64, max 4.97.
    assert_within("dome", measured, (0.25, 1.5));
}

/// Mean and 99th-percentile ΔE2000 of `a` against `b` through `bubbles compare`.
fn compare(dir: &Path, a: &str, b: &str) -> (f64, f64) {
    let out = bubbles(&["compare", a, b, "--json"], dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let json = String::from_utf8_lossy(&out.stdout);
    eprintln!("{a} vs {b}: {json}");
    (json_field(&json, "mean"), json_field(&json, "p99"))
}

/// Asserts that ΔE2000 `(mean, p99)` of `what` lies within `(max_mean, max_p99)`.
fn assert_within(what: &str, (mean, p99): (f64, f64), (max_mean, max_p99): (f64, f64)) {
    assert!(mean <= max_mean, "{what}: mean ΔE2000 {mean} > {max_mean}");
    assert!(
        p99 <= max_p99,
        "{what}: 99th percentile ΔE2000 {p99} > {max_p99}"
    );
}

/// [`scene_file_against_cpu`] for `file` at 128×128 with dynamic cube maps and with the
/// static environment in reflections: each mode's `(mean, p99)`, or `None` without an
/// adapter.
fn dynamic_and_static_against_cpu(
    file: &str,
    dir: &Path,
) -> Option<Vec<(&'static str, (f64, f64))>> {
    let mut measured = Vec::new();
    for reflection in ["dynamic", "static"] {
        let flags = ["--reflection", reflection];
        measured.push((reflection, scene_file_against_cpu(file, dir, 128, &flags)?));
    }
    Some(measured)
}

#[test]
fn white_furnace_through_wgpu_stays_within_one_code_value_of_the_background() {
    let dir = tempfile::tempdir().unwrap();
    if !render("white-furnace", "wgpu", "gpu.png", dir.path()) {
        return;
    }
    let img = image::open(dir.path().join("gpu.png")).unwrap().to_rgb8();
    // The background: a uniform white environment, clamp tone curve.
    let background = img.get_pixel(0, 0).0;
    assert_eq!(background, [255; 3], "background");
    let worst = img
        .enumerate_pixels()
        .flat_map(|(x, y, p)| (0..3).map(move |k| (x, y, background[k].abs_diff(p.0[k]))))
        .max_by_key(|d| d.2)
        .unwrap();
    assert!(
        worst.2 <= 1,
        "pixel ({}, {}) is {} code values off",
        worst.0,
        worst.1,
        worst.2
    );
}

#[test]
fn wgpu_without_an_adapter_is_an_input_error_naming_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no-such-icd.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args([
            "render",
            "--backend",
            "wgpu",
            "--width",
            "8",
            "--height",
            "8",
        ])
        .args(["--out", "x.png"])
        .current_dir(dir.path())
        .env("VK_DRIVER_FILES", &missing)
        .env("VK_ICD_FILENAMES", &missing)
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for needle in [
        "no wgpu adapter",
        "VK_DRIVER_FILES",
        "mesa-vulkan-drivers",
        "--backend cpu",
    ] {
        assert!(err.contains(needle), "missing {needle:?} in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.path().join("x.png").exists(), "no image on failure");
}

/// `pond` (issue 24) as its file renders it: the water's floor refracted with
/// Beer–Lambert absorption, the exact Fresnel blend, and reflections from the cube map
/// seen from the mirrored eye with the bubbles in it; the bubbles over the water.
#[test]
fn pond_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    let Some(measured) = wgpu_against_cpu("pond", dir.path()) else {
        return;
    };
    // Lavapipe measured mean 0.056, p99 0.79 (the Fresnel blend flipped or Beer–Lambert
    // dropped is several ΔE).
    assert_within("pond", measured, (0.15, 1.0));
}

/// `pond`'s water in each reflection mode at 128×128: the mirrored cube map, the
/// environment alone, and the sphere map read through seed 002's view space.
#[test]
fn pond_in_every_reflection_mode_through_wgpu_matches_the_cpu_backend() {
    let dir = tempfile::tempdir().unwrap();
    let Some(mut measured) = dynamic_and_static_against_cpu("pond", dir.path()) else {
        return;
    };
    let sphere = ["--reflection", "sphere-map"];
    let Some(d) = scene_file_against_cpu("pond", dir.path(), 128, &sphere) else {
        return;
    };
    measured.push(("sphere-map", d));
    // Lavapipe measured mean 0.061–0.074, p99 0.79–0.81.
    for (reflection, d) in measured {
        assert_within(reflection, d, (0.15, 1.0));
    }
}

/// `--samples 9` has no MSAA count anywhere: the frame is rendered at the nearest count
/// the device offers, and stderr says so once, naming both counts.
#[test]
fn a_sample_count_the_device_lacks_is_replaced_by_the_nearest_and_said() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "render",
        "paper",
        "--backend",
        "wgpu",
        "--width",
        "32",
        "--height",
        "24",
        "--samples",
        "9",
        "--out",
        "x.png",
    ];
    let Some((out, err)) = run_unless_no_adapter(&args, dir.path()) else {
        return;
    };
    assert!(out.status.success(), "{err}");
    assert!(dir.path().join("x.png").exists());
    assert_eq!(
        err.matches("--samples 9 is rendered with").count(),
        1,
        "{err}"
    );
    assert!(
        err.contains("with 8 samples") || err.contains("with 4 samples"),
        "{err}"
    );
}

/// Renders scene file `scene` (in `dir`) at `size`×`size` through wgpu and through the
/// CPU with per-triangle partial shading, both with `extra` flags; returns their mean and
/// 99th-percentile ΔE2000, or `None` when no adapter was found.
fn scene_file_against_cpu(
    scene: &str,
    dir: &Path,
    size: u32,
    extra: &[&str],
) -> Option<(f64, f64)> {
    let size = size.to_string();
    let render = |backend: &str, out: &str, more: &[&str]| {
        let mut args = vec![
            "render",
            scene,
            "--backend",
            backend,
            "--width",
            &size,
            "--height",
            &size,
            "--out",
            out,
        ];
        args.extend(extra);
        args.extend(more);
        run_unless_no_adapter(&args, dir).map(|(run, err)| {
            assert!(run.status.success(), "{backend} {extra:?}: {err}");
        })
    };
    render("wgpu", "gpu.png", &[])?;
    render("cpu", "cpu.png", &["--partial-shading", "per-triangle"])?;
    eprint!("{scene} {extra:?}: ");
    Some(compare(dir, "cpu.png", "gpu.png"))
}

/// A scene over `environment` (a TOML `[environment]` table): a checker ground the
/// environment lights, a bubble that reflects it, the camera looking along −Z and up, so
/// that most of the frame is the environment itself.
fn environment_scene(environment: &str) -> String {
    format!(
        r#"[camera]
eye_m = [0.0, 0.05, 0.3]
target_m = [0.0, 0.1, 0.0]
vfov_deg = 70.0

{environment}

[ground]
height_m = 0.0
material = {{ kind = "checker", a = [0.8, 0.8, 0.78], b = [0.1, 0.12, 0.2], scale_m = 0.04 }}

[[bubbles]]
center_m = [0.01, 0.09, 0.06]
radius_m = 0.08
mean_thickness_nm = 500.0
subdivisions = 3
seed = 1

[film]
n_film = 1.33
illuminant = "d65"
"#
    )
}

/// Writes an sRGB PNG of `w`×`h` whose texel `(x, y)` is `rgb(x, y)`.
fn write_png(path: &Path, (w, h): (u32, u32), rgb: impl Fn(u32, u32) -> [u8; 3]) {
    image::RgbImage::from_fn(w, h, |x, y| image::Rgb(rgb(x, y)))
        .save(path)
        .unwrap();
}

/// An equirect environment (issue 24): the sky behind every pixel, the dynamic cube maps'
/// sky and the static reflection all read the latitude-longitude image as the CPU does.
/// The image varies along both axes and is asymmetric about every meridian, so a flipped
/// or shifted mapping shows.
#[test]
fn equirect_environment_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    write_equirect_scene(dir.path());
    let Some(measured) = dynamic_and_static_against_cpu("equirect.toml", dir.path()) else {
        return;
    };
    for (reflection, d) in measured {
        assert_within(reflection, d, (0.25, 1.2));
    }
}

/// Writes `equirect.toml`, [`environment_scene`] under a generated 48×24 equirect
/// `env.png` that varies along both axes and is asymmetric about every meridian.
fn write_equirect_scene(dir: &Path) {
    write_png(&dir.join("env.png"), (48, 24), |x, y| {
        let stripe = if (x / 6 + y / 4) % 2 == 0 { 40 } else { 0 };
        [
            (40 + 4 * x) as u8,
            (30 + 8 * y) as u8,
            (200 - 3 * x + stripe) as u8,
        ]
    });
    let scene = environment_scene("[environment]\nkind = \"equirect\"\npath = \"env.png\"");
    std::fs::write(dir.join("equirect.toml"), scene).unwrap();
}

/// Sphere-map reflections (issue 24): the bubble reads the mirror-ball image the CLI
/// makes from the environment (`SphereMap::from_environment`) as `SphereMap::sample`
/// does; the equirect environment makes every direction's colour its own, so a flipped
/// axis of the map shows on the bubble.
#[test]
fn sphere_map_reflection_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    write_equirect_scene(dir.path());
    let flags = ["--reflection", "sphere-map"];
    let Some(measured) = scene_file_against_cpu("equirect.toml", dir.path(), 128, &flags) else {
        return;
    };
    assert_within("sphere map", measured, (0.25, 1.2));
}

/// Cube-face environment (issue 24): the sky reads level 0 as `CubeMap::sample`, the
/// static reflection the faces' mip chain through the footprint filter. Each face has its
/// own colour and a gradient along both of its axes, so a swapped face or flipped axis
/// shows.
#[test]
fn cube_face_environment_through_wgpu_matches_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    let base: [[u32; 3]; 6] = [
        [200, 60, 40],
        [40, 160, 60],
        [60, 90, 220],
        [90, 70, 40],
        [200, 180, 60],
        [150, 60, 190],
    ];
    let names = ["px", "nx", "py", "ny", "pz", "nz"];
    for (name, b) in names.iter().zip(base) {
        write_png(&dir.path().join(format!("{name}.png")), (16, 16), |x, y| {
            [
                b[0] * (8 + x) / 24,
                b[1] * (24 - y / 2) / 24,
                b[2] * (10 + x + y) / 40,
            ]
            .map(|c| c as u8)
        });
    }
    let faces = names.map(|n| format!("\"{n}.png\"")).join(", ");
    let scene = environment_scene(&format!(
        "[environment]\nkind = \"cube\"\nfaces = [{faces}]"
    ));
    std::fs::write(dir.path().join("cube.toml"), scene).unwrap();
    let Some(measured) = dynamic_and_static_against_cpu("cube.toml", dir.path()) else {
        return;
    };
    for (reflection, d) in measured {
        assert_within(reflection, d, (0.25, 1.2));
    }
}

/// A scene of a ground (`ground` adds to its section), one object (`object`, its
/// placement) wearing `tex.png`, and a 500 nm bubble beside it whose cube map shows both.
fn beside_a_bubble(ground: &str, object: &str) -> String {
    format!(
        r#"[camera]
eye_m = [0.0, 0.12, 0.3]
target_m = [0.0, 0.05, 0.0]
vfov_deg = 60.0

[ground]
height_m = 0.0
{ground}

[[objects]]
{object}
material = {{ kind = "image", path = "tex.png", scale_m = 1.0 }}

[[bubbles]]
center_m = [0.06, 0.06, 0.02]
radius_m = 0.05
mean_thickness_nm = 500.0
subdivisions = 3
seed = 1

[film]
n_film = 1.33
illuminant = "d65"
"#
    )
}

/// Textured materials (issue 24): the ground repeats an image every `scale_m` along x and
/// z, a sphere wears it by its mesh UVs, as `ground_albedo` and `object_albedo` read it;
/// the bubble's dynamic cube map shows both. The image varies along both axes, so a
/// flipped axis shows.
#[test]
fn textured_materials_through_wgpu_match_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("tex.png"), (16, 16), |x, y| {
        let spot = if x < 5 && y < 3 { 120 } else { 0 };
        [
            (30 + 14 * x) as u8,
            (20 + 12 * y + spot) as u8,
            (220 - 6 * x - 5 * y) as u8,
        ]
    });
    let scene = beside_a_bubble(
        r#"material = { kind = "image", path = "tex.png", scale_m = 0.07 }"#,
        r#"kind = "sphere"
center_m = [-0.06, 0.05, -0.05]
radius_m = 0.05"#,
    );
    std::fs::write(dir.path().join("textured.toml"), scene).unwrap();
    let Some(measured) = scene_file_against_cpu("textured.toml", dir.path(), 128, &[]) else {
        return;
    };
    assert_within("textured", measured, (0.25, 1.2));
}

/// An OBJ object (issue 24): an octahedron with per-vertex UVs, read, offset and scaled
/// as the CPU reads it, wearing a texture, beside a bubble whose cube map shows it. Its
/// faces are flat and its vertices shared, so a winding or normal lost on the way shows.
#[test]
fn obj_mesh_objects_through_wgpu_match_the_cpu_backend_in_ciede2000() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("tex.png"), (8, 8), |x, y| {
        [
            (40 + 25 * x) as u8,
            (200 - 20 * y) as u8,
            (60 + 10 * (x ^ y)) as u8,
        ]
    });
    let obj = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
               vt 0 0\nvt 1 0\nvt 0.5 1\nvt 0.5 0\nvt 1 1\nvt 0 1\n\
               f 1/1 3/3 5/5\nf 3/3 2/2 5/5\nf 2/2 4/4 5/5\nf 4/4 1/1 5/5\n\
               f 3/3 1/1 6/6\nf 2/2 3/3 6/6\nf 4/4 2/2 6/6\nf 1/1 4/4 6/6\n";
    std::fs::write(dir.path().join("octa.obj"), obj).unwrap();
    let scene = beside_a_bubble(
        "",
        r#"kind = "mesh"
path = "octa.obj"
offset_m = [-0.06, 0.05, -0.04]
scale = 0.05"#,
    );
    std::fs::write(dir.path().join("obj.toml"), scene).unwrap();
    let Some(measured) = scene_file_against_cpu("obj.toml", dir.path(), 128, &[]) else {
        return;
    };
    assert_within("obj mesh", measured, (0.25, 1.2));
}

/// `bubbles animate` with `args` plus a 96×96 `paper` of three frames (0.2 s at 15 fps)
/// in `dir`, or `None` when no adapter was found outside CI.
fn animate(dir: &Path, args: &[&str]) -> Option<String> {
    let mut all = vec![
        "animate",
        "paper",
        "--seconds",
        "0.2",
        "--fps",
        "15",
        "--width",
        "96",
        "--height",
        "96",
    ];
    all.extend(args);
    let (run, err) = run_unless_no_adapter(&all, dir)?;
    assert!(run.status.success(), "{all:?}: {err}");
    Some(err)
}

#[test]
fn animate_through_wgpu_writes_frames_apng_and_gif_as_the_cpu_path_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let gpu = ["--backend", "wgpu"];
    // Frames 0..2, then --resume renders the one missing.
    let first = [&gpu[..], &["--out", "gpu", "--frames", "0..2"]].concat();
    if animate(d, &first).is_none() {
        return;
    }
    assert!(
        !d.join("gpu/frame_00002.png").exists(),
        "--frames 0..2 wrote frame 2"
    );
    animate(d, &[&gpu[..], &["--out", "gpu", "--resume"]].concat()).unwrap();
    // The CPU's frames, shaded like for like (once per triangle, as the GPU shades).
    animate(d, &["--out", "cpu", "--partial-shading", "per-triangle"]).unwrap();
    for k in 0..3 {
        let name = format!("frame_{k:05}.png");
        let measured = compare(d, &format!("cpu/{name}"), &format!("gpu/{name}"));
        assert_within(&name, measured, (0.25, 1.5));
        // No two backends round alike everywhere: identical bytes would mean the CPU drew it.
        assert!(measured.0 > 0.0, "frame {k} is the CPU's, byte for byte");
    }
    // A resumed GPU directory is refused to the CPU: the manifest names the backend.
    let mixed = bubbles(
        &[
            "animate",
            "paper",
            "--seconds",
            "0.2",
            "--fps",
            "15",
            "--width",
            "96",
            "--height",
            "96",
            "--out",
            "gpu",
            "--resume",
        ],
        d,
    );
    assert_eq!(mixed.status.code(), Some(2), "{}", stderr(&mixed));
    // One APNG: its first frame is the directory's first frame, byte for byte.
    animate(d, &[&gpu[..], &["--out", "gpu.apng"]].concat()).unwrap();
    let apng = image::open(d.join("gpu.apng")).unwrap().to_rgb8();
    let frame0 = image::open(d.join("gpu/frame_00000.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(apng.as_raw(), frame0.as_raw(), "the APNG's first frame");
    // The GIF preview, with its ΔE against the exact frames said.
    let err = animate(d, &[&gpu[..], &["--out", "gpu.gif"]].concat()).unwrap();
    assert!(
        d.join("gpu.gif").exists() && err.contains("CIEDE2000"),
        "{err}"
    );
}

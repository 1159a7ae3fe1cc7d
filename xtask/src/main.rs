//! `cargo xtask`: figures, benches and checks.

use std::process::{Command, ExitCode};

mod docs_check;
mod reference_figures;
mod speed_ratio;

const USAGE: &str = "usage: cargo xtask <figures|bench|ci|docs-check>
  figures     regenerate the PNG figures under docs/figures/
              (--reference: instead, the slow measured table of docs/reference.md)
  bench       run every crate's criterion benches, then `bubbles bench` (frame breakdown)
              (--ratio [--rounds N] [--baseline BIN]: instead, the reference-to-frame speed
              ratio of docs/reference.md, interleaved in N rounds, default 3)
  ci          run what .ci/run runs (fmt, clippy, tests, docs-check)
  docs-check  check that every figure block in docs/ names the command that reproduces it";

fn main() -> ExitCode {
    let task = std::env::args().nth(1);
    let ok = match task.as_deref() {
        Some("figures") if std::env::args().any(|a| a == "--reference") => {
            let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
            cargo(&["build", "--release", "-p", "bubbles"])
                && reference_figures::run(&root, &reference_figures::bubbles_binary(&root))
        }
        Some("figures") => figures(),
        Some("bench") if std::env::args().any(|a| a == "--ratio") => ratio(),
        Some("bench") => bench(),
        Some("ci") => ci(),
        Some("docs-check") => docs_check::run(),
        _ => {
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// Runs cargo with `args` from the workspace root, returning whether it succeeded.
fn cargo(args: &[&str]) -> bool {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    eprintln!("$ cargo {}", args.join(" "));
    Command::new(cargo)
        .args(args)
        .current_dir(root)
        .status()
        .is_ok_and(|s| s.success())
}

/// `bench --ratio`: builds the release binary and times the reference against the frame.
fn ratio() -> bool {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
    };
    for flag in ["--rounds", "--baseline"] {
        if args.iter().any(|a| a == flag) && value(flag).is_none() {
            eprintln!("{flag} needs a value");
            return false;
        }
    }
    let rounds = match value("--rounds").map(|r| (r, r.parse::<usize>())) {
        None => 3,
        Some((_, Ok(n))) if (1..=100).contains(&n) => n,
        Some((r, _)) => {
            eprintln!("--rounds {r}: takes a count from 1 to 100");
            return false;
        }
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let baseline = value("--baseline").map(std::path::PathBuf::from);
    if let Some(b) = baseline.as_deref().filter(|b| !b.is_file()) {
        eprintln!("--baseline {}: no such file", b.display());
        return false;
    }
    cargo(&["build", "--release", "-p", "bubbles"])
        && speed_ratio::run(
            &root,
            &reference_figures::bubbles_binary(&root),
            baseline.as_deref(),
            rounds,
        )
}

/// Criterion benches of the library crates, then the whole-frame breakdown of the CLI.
fn bench() -> bool {
    let criterion = cargo(&[
        "bench",
        "-p",
        "thinfilm",
        "-p",
        "lut",
        "-p",
        "bubble-dynamics",
        "-p",
        "raster",
        "--",
        "--warm-up-time",
        "1",
        "--measurement-time",
        "3",
    ]);
    let frame = cargo(&["run", "--release", "-p", "bubbles", "--", "bench"]);
    criterion && frame
}

fn ci() -> bool {
    cargo(&["fmt", "--all", "--check"])
        && cargo(&[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ])
        && cargo(&["test", "--workspace"])
        && docs_check::run()
}

fn figures() -> bool {
    /// Seed 000, Fig. 2: (a) the sodium light-source texture and (b) the RGB reflectivity
    /// texture, as 8-bit sRGB previews of a 512 × 512 bake (thickness 0–2000 nm left to
    /// right, cos θ 0–1 top to bottom: the texture's own layout, the paper's upside down).
    fn seed000_fig2(root: &std::path::Path) -> bool {
        let bake_dir = root.join("target").join("fig2-bake");
        let Some(bake_arg) = bake_dir.to_str() else {
            return false;
        };
        let baked = cargo(&[
            "run",
            "--release",
            "-p",
            "bubbles",
            "--",
            "bake",
            "--out",
            bake_arg,
            "--resolution",
            "512x512",
            "--illuminant",
            "sodium",
            "--format",
            "png8",
        ]);
        let copied = baked
            && [
                ("light_sodium.preview.png", "fig2a_sodium_light_texture.png"),
                ("reflectivity.preview.png", "fig2b_reflectivity_texture.png"),
            ]
            .iter()
            .all(|(from, to)| {
                std::fs::copy(bake_dir.join(from), root.join("docs/figures").join(to)).is_ok()
            });
        let _ = std::fs::remove_dir_all(&bake_dir);
        copied
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    if std::fs::create_dir_all(root.join("docs/figures")).is_err() {
        return false;
    }
    // Both run even if one fails, so one broken figure does not hide the others.
    let fig2 = seed000_fig2(&root);
    let chart = cargo(&[
        "run",
        "--release",
        "-p",
        "bubbles",
        "--",
        "chart",
        "--out",
        "docs/figures/chart.png",
    ]);
    let render = |scene: &str, out: &str, size: [&str; 2]| {
        cargo(&[
            "run",
            "--release",
            "-p",
            "bubbles",
            "--",
            "render",
            scene,
            "--out",
            out,
            "--width",
            size[0],
            "--height",
            size[1],
        ])
    };
    // The README's main job (seed 000 Fig. 4 at its 400 × 400) and the furnace invariant.
    let paper = render("paper", "docs/figures/paper.png", ["400", "400"]);
    let furnace = render(
        "white-furnace",
        "docs/figures/white-furnace.png",
        ["200", "200"],
    );
    // A sodium lamp (docs/rendering.md): light outside the sRGB gamut.
    let sodium = render(
        "docs/scenes/sodium.toml",
        "docs/figures/sodium.png",
        ["400", "400"],
    );
    let gallery = gallery();
    fig2 && chart && paper && furnace && sodium && gallery
}

/// `scene`'s burst as `dir/<scene>_burst.apng`: 7 ms from `start_s`, 200× slower than
/// real time, 30 fps at 320 × 240.
fn burst_movie(dir: &str, scene: &str, start_s: &str, bubbles: &dyn Fn(&[&str]) -> bool) -> bool {
    let movie = format!("{dir}/{scene}_burst.apng");
    bubbles(&[
        "animate",
        scene,
        "--start-s",
        start_s,
        "--seconds",
        "0.007",
        "--fps",
        "30",
        "--slow-motion",
        "200",
        "--out",
        &movie,
        "--width",
        "320",
        "--height",
        "240",
    ])
}

/// The swirl scene's burst in slow motion (docs/gallery.md): an animated PNG 200× slower
/// than real time from just before the hole opens (t = 11.4667 s) until the bubble is
/// gone, and two larger stills 1 ms apart taken as the frames of a second animation.
fn swirl_burst(dir: &str, bubbles: &dyn Fn(&[&str]) -> bool) -> bool {
    let mut ok = burst_movie(dir, "swirl", "11.466", bubbles);
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let frames = std::env::temp_dir().join("bubbles-swirl-burst-stills");
    let _ = std::fs::remove_dir_all(&frames);
    let frames_arg = frames.to_string_lossy().into_owned();
    ok &= bubbles(&[
        "animate",
        "swirl",
        "--start-s",
        "11.468",
        "--seconds",
        "0.002",
        "--fps",
        "10",
        "--slow-motion",
        "100",
        "--out",
        &frames_arg,
        "--width",
        "640",
        "--height",
        "480",
    ]);
    for (k, time_s) in [(0, "11.468"), (1, "11.469")] {
        let from = frames.join(format!("frame_{k:05}.png"));
        let to = root.join(format!("{dir}/swirl_burst_t{time_s}.png"));
        ok &= std::fs::copy(from, to).is_ok();
    }
    let _ = std::fs::remove_dir_all(&frames);
    ok
}

/// The gallery scenes of docs/gallery.md (seed 000 Figs. 5–7, the demo, seed 002's pond
/// and the living film's swirl): a still and a short animated PNG of each, a GIF preview
/// of the wind scene, the swirl at four ages, and the pond at two times for
/// docs/water.md.
fn gallery() -> bool {
    const GALLERY: [(&str, &str, &str, &str); 7] = [
        // scene, still time (s), animation length (s), fps
        ("wind", "0.2", "1.2", "15"),
        ("plane-collision", "0.15", "1.2", "15"),
        ("bubble-collision", "0.12", "1", "20"),
        ("demo", "0.5", "2", "10"),
        ("pond", "1", "2", "10"),
        ("swirl", "5", "11.5", "8"),
        ("dome", "8", "12", "8"),
    ];
    let dir = "docs/figures/gallery";
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    if std::fs::create_dir_all(root.join(dir)).is_err() {
        return false;
    }
    let bubbles = |args: &[&str]| {
        let mut all = vec!["run", "--release", "-p", "bubbles", "--"];
        all.extend_from_slice(args);
        cargo(&all)
    };
    let mut ok = true;
    for (scene, still_s, seconds, fps) in GALLERY {
        let still = format!("{dir}/{scene}.png");
        let movie = format!("{dir}/{scene}.apng");
        ok &= bubbles(&[
            "render", scene, "--out", &still, "--time-s", still_s, "--width", "400", "--height",
            "300",
        ]);
        ok &= bubbles(&[
            "animate",
            scene,
            "--seconds",
            seconds,
            "--fps",
            fps,
            "--out",
            &movie,
            "--width",
            "200",
            "--height",
            "150",
        ]);
    }
    // The swirl scene's film at four ages, full size (docs/gallery.md).
    for time_s in ["0.5", "5", "8", "10.5"] {
        let still = format!("{dir}/swirl_t{time_s}.png");
        ok &= bubbles(&["render", "swirl", "--out", &still, "--time-s", time_s]);
    }
    // The dome's film at four ages, full size (docs/gallery.md).
    for time_s in ["1", "4", "8", "11"] {
        let still = format!("{dir}/dome_t{time_s}.png");
        ok &= bubbles(&["render", "dome", "--out", &still, "--time-s", time_s]);
    }
    for time_s in ["0.5", "2"] {
        let still = format!("{dir}/pond_t{time_s}s.png");
        ok &= bubbles(&[
            "render", "pond", "--out", &still, "--time-s", time_s, "--width", "400", "--height",
            "300",
        ]);
    }
    ok &= swirl_burst(dir, &bubbles);
    // The dome's burst: its hole opens on the left at about 11.987 s, the rim crosses in 5 ms.
    ok &= burst_movie(dir, "dome", "11.986", &bubbles);
    let gif = format!("{dir}/wind.gif");
    ok &= bubbles(&[
        "animate",
        "wind",
        "--seconds",
        "1.2",
        "--fps",
        "15",
        "--out",
        &gif,
        "--width",
        "200",
        "--height",
        "150",
    ]);
    ok
}

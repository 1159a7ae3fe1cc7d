//! `cargo xtask figures --reference`: the measured table of docs/reference.md. Renders
//! `paper` at 400 × 400 with the CPU backend and the spectral reference, then one
//! approximation at a time, compares each with `bubbles compare`, and writes the images,
//! the heat map and `docs/figures/reference/measured.md` (slow: minutes per reference).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const DIR: &str = "docs/figures/reference";
const SIZE: [&str; 4] = ["--width", "400", "--height", "400"];

/// One render: a name, the extra `bubbles render` flags, and what it isolates.
struct Variant {
    name: &'static str,
    flags: &'static [&'static str],
    what: &'static str,
}

/// Pairs compared besides "every variant against the reference": (image, against).
const PAIRS: [(&str, &str); 1] = [("ref-centre", "ref-no-films")];

const VARIANTS: [Variant; 16] = [
    Variant {
        name: "reference",
        flags: &["--backend", "reference"],
        what: "the reference: depth 8, polarised, spectral, 16 to 1024 rays per pixel to a standard error of ΔE 0.15",
    },
    Variant {
        name: "cpu",
        flags: &[],
        what: "the CPU backend as shipped (4 samples, dynamic 128² cube maps read where reflected rays meet the ground)",
    },
    Variant {
        name: "ref-depth2",
        flags: &["--backend", "reference", "--ref-depth", "2"],
        what: "reference, 2 films per path (front and back: what the CPU pass composites)",
    },
    Variant {
        name: "ref-depth1",
        flags: &["--backend", "reference", "--ref-depth", "1"],
        what: "reference, 1 film per path",
    },
    Variant {
        name: "ref-unpolarised",
        flags: &["--backend", "reference", "--ref-unpolarised"],
        what: "reference, s and p averaged at every film",
    },
    Variant {
        name: "ref-rgb",
        flags: &["--backend", "reference", "--ref-rgb"],
        what: "reference, RGB transport with films projected as the LUT bakes them",
    },
    Variant {
        name: "cpu-1spp",
        flags: &["--samples", "1"],
        what: "CPU backend, 1 sample per pixel",
    },
    Variant {
        name: "cpu-16spp",
        flags: &["--samples", "16"],
        what: "CPU backend, 16 samples per pixel",
    },
    Variant {
        name: "cpu-lut256x64",
        flags: &[
            "--lut-thickness-samples",
            "256",
            "--lut-angle-samples",
            "64",
        ],
        what: "CPU backend, film tables of 256 x 64 instead of 4096 x 128",
    },
    Variant {
        name: "cpu-lut1024x32",
        flags: &[
            "--lut-thickness-samples",
            "1024",
            "--lut-angle-samples",
            "32",
        ],
        what: "CPU backend, film tables of 1024 x 32",
    },
    Variant {
        name: "cpu-static",
        flags: &["--reflection", "static"],
        what: "CPU backend, environment only in reflections (no cube map)",
    },
    Variant {
        name: "cpu-centre",
        flags: &["--reflection-origin", "centre"],
        what: "CPU backend, cube maps read from the bubble's centre (seed 000), not where reflected rays meet the ground",
    },
    Variant {
        name: "ref-seed1",
        flags: &["--backend", "reference", "--ref-seed", "1"],
        what: "reference with another sampling seed: its noise",
    },
    Variant {
        name: "ref-16-point",
        flags: &[
            "--backend",
            "reference",
            "--ref-max-samples",
            "16",
            "--ref-point-textures",
        ],
        what: "reference as it was: 16 rays per pixel, point-sampled checkers, no refinement",
    },
    Variant {
        name: "ref-no-films",
        flags: &["--backend", "reference", "--ref-reflections", "no-films"],
        what: "reference, reflected rays pass through all films",
    },
    Variant {
        name: "ref-centre",
        flags: &["--backend", "reference", "--ref-reflections", "centre"],
        what: "reference, reflected rays from the bubble's centre through all films (a perfect cube map)",
    },
];

/// Runs every variant, compares each with the reference, writes the table.
pub fn run(root: &Path, bubbles: &Path) -> bool {
    if std::fs::create_dir_all(root.join(DIR)).is_err() {
        return false;
    }
    let mut rows = Vec::new();
    for v in &VARIANTS {
        let out = format!("{DIR}/{}.png", v.name);
        let mut args = vec!["render", "paper", "--out", out.as_str()];
        args.extend(SIZE);
        args.extend(v.flags);
        let start = Instant::now();
        let (ok, _, log) = run_bubbles(root, bubbles, &args);
        if !ok {
            return false;
        }
        let secs = format!(
            "{:.1}{}",
            start.elapsed().as_secs_f64(),
            rays_per_pixel(&log)
        );
        let heat = (v.name == "cpu").then(|| format!("{DIR}/heatmap-cpu.png"));
        let reference = format!("{DIR}/reference.png");
        let mut cmp = vec!["compare", "--json", reference.as_str(), out.as_str()];
        if let Some(h) = &heat {
            cmp.extend(["--heatmap", h.as_str()]);
        }
        let (ok, json, _) = run_bubbles(root, bubbles, &cmp);
        if !ok {
            return false;
        }
        rows.push(format!(
            "| {} | {} | {} | {} |",
            v.name,
            v.what,
            secs,
            summary(&json)
        ));
    }
    for (image, against) in PAIRS {
        let (a, b) = (format!("{DIR}/{against}.png"), format!("{DIR}/{image}.png"));
        let (ok, json, _) = run_bubbles(root, bubbles, &["compare", "--json", &a, &b]);
        if !ok {
            return false;
        }
        rows.push(format!(
            "| {image} | against {against} | | {} |",
            summary(&json)
        ));
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let table = format!(
        "<!-- written by `cargo xtask figures --reference`; load average before the last render: {} -->\n\
         | image | what | wall s (incl. simulation and bake) | ΔE2000 vs reference: mean / p95 / max |\n|---|---|---|---|\n{}\n",
        load.trim(),
        rows.join("\n")
    );
    std::fs::write(root.join(DIR).join("measured.md"), table).is_ok()
}

/// `" (N rays/px)"` from the reference's closing line on stderr, or nothing.
fn rays_per_pixel(log: &str) -> String {
    log.split(" rays per pixel on average")
        .next()
        .filter(|head| head.len() < log.len())
        .and_then(|head| head.rsplit(' ').next())
        .map_or(String::new(), |n| format!(" ({n} rays/px)"))
}

/// `mean / p95 / max` from compare's JSON.
fn summary(json: &str) -> String {
    let field = |k: &str| -> String {
        json.split(&format!("\"{k}\": "))
            .nth(1)
            .and_then(|r| r.split([',', '}']).next())
            .and_then(|v| v.trim().parse::<f64>().ok())
            .map_or("?".into(), |v| format!("{v:.2}"))
    };
    format!("{} / {} / {}", field("mean"), field("p95"), field("max"))
}

/// Runs `bubbles args`: success, stdout and stderr (also echoed).
fn run_bubbles(root: &Path, bubbles: &Path, args: &[&str]) -> (bool, String, String) {
    eprintln!("$ bubbles {}", args.join(" "));
    match Command::new(bubbles).args(args).current_dir(root).output() {
        Ok(out) => {
            let log = String::from_utf8_lossy(&out.stderr).into_owned();
            eprint!("{log}");
            let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
            (out.status.success(), stdout, log)
        }
        Err(e) => {
            eprintln!("cannot run {}: {e}", bubbles.display());
            (false, String::new(), String::new())
        }
    }
}

/// The release `bubbles` binary under the target directory.
pub fn bubbles_binary(root: &Path) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or(root.join("target"), PathBuf::from);
    target.join("release").join("bubbles")
}

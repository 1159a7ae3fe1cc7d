//! `cargo xtask bench --ratio`: seed 000's Fig. 4 speed ratio on this machine. Times the
//! spectral reference's `paper` at 400 × 400 and the CPU backend's frame, interleaved in
//! rounds so that both see the same machine state, and prints a markdown table and the
//! median ratio. With `--baseline`, the two binaries' frames alternate in order by round.
//!
//! CPU time comes from the kernel's account of reaped children (`/proc/self/stat`), so a
//! frame's CPU time is that of a 210-frame bench minus a 10-frame one, over 200 frames:
//! start-up (table bake, simulation to t) cancels.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

const SIZE: &str = "400x400";

/// Runs `rounds` rounds with `bubbles` (and `baseline`, another binary, when given).
pub fn run(root: &Path, bubbles: &Path, baseline: Option<&Path>, rounds: usize) -> bool {
    println!(
        "| round | reference CPU-s (wall s) | CPU frame CPU-ms (wall ms, sim ms) | ratio, CPU time |{}",
        if baseline.is_some() {
            " baseline frame CPU-ms | baseline ratio |"
        } else {
            ""
        }
    );
    println!(
        "|---|---|---|---|{}",
        if baseline.is_some() { "---|---|" } else { "" }
    );
    let (mut ratios, mut base_ratios) = (Vec::new(), Vec::new());
    for round in 1..=rounds {
        let Some((ref_cpu_s, ref_wall_s)) = timed(root, bubbles, &reference_args()) else {
            return false;
        };
        // Odd rounds time the binary first, even rounds the baseline: whichever runs
        // right after the reference would otherwise always meet the same machine state.
        let order: Vec<&Path> = match baseline {
            Some(base) if round % 2 == 0 => vec![base, bubbles],
            Some(base) => vec![bubbles, base],
            None => vec![bubbles],
        };
        let mut frames = Vec::new();
        for bin in order {
            let Some(f) = frame_cost(root, bin) else {
                return false;
            };
            frames.push((bin, f));
        }
        let frame = &frames.iter().find(|(b, _)| *b == bubbles).expect("timed").1;
        ratios.push(ref_cpu_s * 1e3 / frame.cpu_ms);
        let mut row = format!(
            "| {round} | {ref_cpu_s:.2} ({ref_wall_s:.2}) | {:.2} ({:.2}, {:.2}) | {:.0}× |",
            frame.cpu_ms,
            frame.wall_ms,
            frame.sim_ms,
            ref_cpu_s * 1e3 / frame.cpu_ms
        );
        if let Some(base) = baseline {
            let b = &frames.iter().find(|(b, _)| *b == base).expect("timed").1;
            base_ratios.push(ref_cpu_s * 1e3 / b.cpu_ms);
            row += &format!(" {:.2} | {:.0}× |", b.cpu_ms, ref_cpu_s * 1e3 / b.cpu_ms);
        }
        println!("{row}");
    }
    println!(
        "\nmedian ratio over {rounds} rounds: {:.0}×",
        median(&mut ratios)
    );
    if baseline.is_some() {
        println!("baseline median ratio: {:.0}×", median(&mut base_ratios));
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("\nload average after the last round: {}", load.trim());
    true
}

/// The middle value (the mean of the two middle ones for an even count).
fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => values[n / 2],
        _ => (values[n / 2 - 1] + values[n / 2]) / 2.0,
    }
}

fn reference_args() -> Vec<String> {
    let out = std::env::temp_dir().join("xtask-ratio-reference.png");
    [
        "render",
        "paper",
        "--backend",
        "reference",
        "--width",
        "400",
        "--height",
        "400",
    ]
    .map(String::from)
    .into_iter()
    .chain(["--out".into(), out.to_string_lossy().into_owned()])
    .collect()
}

/// One CPU frame's cost: CPU time, and the bench's own wall-time columns.
struct Frame {
    cpu_ms: f64,
    wall_ms: f64,
    sim_ms: f64,
}

fn frame_cost(root: &Path, bubbles: &Path) -> Option<Frame> {
    let bench =
        |frames: &str| ["bench", "paper", "--size", SIZE, "--frames", frames].map(String::from);
    let (long_s, _) = timed(root, bubbles, &bench("210"))?;
    let (short_s, _) = timed(root, bubbles, &bench("10"))?;
    // The bench's table, read by its header's names (`size sim_ms … frame_ms fps`):
    // builds before the film column had one column fewer.
    let out = Command::new(bubbles)
        .args(bench("100"))
        .current_dir(root)
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let header: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with("size"))?
        .split_whitespace()
        .collect();
    let row: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with(SIZE))?
        .split_whitespace()
        .collect();
    let column = |name: &str| -> Option<f64> {
        let at = header.iter().position(|h| *h == name)?;
        row.get(at)?.parse().ok()
    };
    Some(Frame {
        cpu_ms: (long_s - short_s) / 200.0 * 1e3,
        wall_ms: column("frame_ms")?,
        sim_ms: column("sim_ms")?,
    })
}

/// Runs `bubbles args`, returning its CPU time (user + system, children reaped) and wall
/// time in seconds.
fn timed(root: &Path, bubbles: &Path, args: &[String]) -> Option<(f64, f64)> {
    eprintln!("$ bubbles {}", args.join(" "));
    let before = children_cpu_s()?;
    let start = Instant::now();
    let status = match Command::new(bubbles)
        .args(args)
        .current_dir(root)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
    {
        Ok(status) => status,
        Err(e) => {
            eprintln!("cannot run {}: {e}", bubbles.display());
            return None;
        }
    };
    let wall = start.elapsed().as_secs_f64();
    if !status.success() {
        eprintln!("bubbles {} failed: {status}", args.join(" "));
        return None;
    }
    Some((children_cpu_s()? - before, wall))
}

/// User + system time of this process's reaped children (`cutime + cstime`, fields 16 and
/// 17 of `/proc/self/stat`), in seconds; Linux's clock tick is 1/100 s.
fn children_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name, which may hold spaces.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // `rest` starts at field 3 (state), so field k is at index k − 3.
    let ticks = |k: usize| fields.get(k - 3)?.parse::<f64>().ok();
    Some((ticks(16)? + ticks(17)?) / 100.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_is_the_middle_value_or_the_mean_of_the_two_middle_ones() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }
}

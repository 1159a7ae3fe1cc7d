//! Best of 2000 fills of the 5-layer stack of `bench/vs_colour_multilayer.py` over λ
//! 360–830 nm by 1 and angles 0–75° by 7.5 (5 181 points) on one core, unpolarised:
//! `cargo run --release -p thinfilm --example stack_timing`. A best-of loop reads a noisy
//! shared machine better than criterion's mean.

use std::time::Instant;
use thinfilm::grid::Polarisation;
use thinfilm::stack_grid::StackGrid;
use thinfilm::tmm::{Layer, Stack};

/// Times building the grid and filling it, best of 2000.
fn main() {
    let layers = [
        (1.38, 100.0),
        (2.1, 60.0),
        (1.46, 90.0),
        (2.1, 60.0),
        (1.38, 100.0),
    ]
    .map(|(n, d)| Layer::lossless(n, d))
    .to_vec();
    let stack = Stack::new(1.0, layers, 1.52).unwrap();
    let wl: Vec<f64> = (360..=830).map(f64::from).collect();
    let angles: Vec<f64> = (0..=10).map(|k| 7.5 * f64::from(k)).collect();
    let (mut r, mut t) = (
        vec![0.0; wl.len() * angles.len()],
        vec![0.0; wl.len() * angles.len()],
    );
    let mut best = f64::MAX;
    for _ in 0..2000 {
        let s = Instant::now();
        let grid = StackGrid::try_new(&stack, &angles, &wl).unwrap();
        grid.try_fill(Polarisation::Unpolarised, &mut r, &mut t)
            .unwrap();
        best = best.min(s.elapsed().as_secs_f64());
    }
    println!(
        "best {:.1} µs for {} points, R[0] {:.6}",
        best * 1e6,
        r.len(),
        r[0]
    );
}

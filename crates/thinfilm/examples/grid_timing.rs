//! Best of 100 fills of colour-science's film grid (d 0–2000 nm by 10, angles 0–75° by
//! 7.5, λ 360–830 nm by 1: 1 041 381 points, soap in air) on one core, outputs reused:
//! `cargo run --release -p thinfilm --example grid_timing [fast]` (`fast`: the f32 fill).
//! A best-of loop reads a noisy shared machine better than criterion's mean.

use std::time::Instant;
use thinfilm::grid::{FilmGrid, Polarisation};
/// Times the exact fill, or the fast one with the argument `fast`.
fn main() {
    let fast = std::env::args().nth(1).as_deref() == Some("fast");
    let angles: Vec<f64> = (0..=10).map(|k| 7.5 * k as f64).collect();
    let wl: Vec<f64> = (360..=830).map(f64::from).collect();
    let d: Vec<f64> = (0..=200).map(|k| 10.0 * k as f64).collect();
    let grid = FilmGrid::try_new(1.0, 1.33, &angles, &wl).unwrap();
    let n = grid.len();
    let mut r = vec![0.0; n * d.len()];
    let mut t = vec![0.0; n * d.len()];
    let mut best = f64::MAX;
    for _ in 0..100 {
        let s = Instant::now();
        for (k, (r, t)) in r.chunks_mut(n).zip(t.chunks_mut(n)).enumerate() {
            if fast {
                grid.try_fill_cells_fast(d[k], 0, Polarisation::Unpolarised, r, t)
                    .unwrap();
            } else {
                grid.try_fill(d[k], Polarisation::Unpolarised, r, t)
                    .unwrap();
            }
        }
        best = best.min(s.elapsed().as_secs_f64());
    }
    println!(
        "fast {fast}: best {:.3} ms, r sum {}",
        best * 1e3,
        r.iter().sum::<f64>()
    );
}

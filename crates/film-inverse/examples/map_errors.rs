//! Compares a `bubbles thickness` map with a true thickness map (R channels of two EXRs
//! of one size): RMS error over fitted pixels, the share off by more than 100 nm (half
//! an order), and where the worst are.
//! `cargo run --release -p film-inverse --example map_errors -- MAP.exr TRUTH.exr`

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [map, truth] = [&args[0], &args[1]].map(|p| image::open(p).expect("an EXR").to_rgba32f());
    assert_eq!(map.dimensions(), truth.dimensions(), "maps of one size");
    let (mut sum2, mut ok, mut wrong, mut fitted) = (0.0f64, 0usize, 0usize, 0usize);
    let mut worst = Vec::new();
    for (i, (m, t)) in map.pixels().zip(truth.pixels()).enumerate() {
        if m[3] != 1.0 {
            continue;
        }
        fitted += 1;
        let e = f64::from(m[0] - t[0]);
        if e.abs() > 100.0 {
            wrong += 1;
            worst.push((
                e.abs(),
                i as u32 % map.width(),
                i as u32 / map.width(),
                m[0],
                t[0],
            ));
        } else {
            sum2 += e * e;
            ok += 1;
        }
    }
    worst.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!(
        "fitted {fitted} of {}: RMS {:.2} nm, {wrong} pixels ({:.3} %) off by more than 100 nm",
        map.width() * map.height(),
        (sum2 / ok.max(1) as f64).sqrt(),
        100.0 * wrong as f64 / fitted.max(1) as f64
    );
    for (e, x, y, m, t) in worst.iter().take(5) {
        println!("  ({x}, {y}): {m:.1} nm, truth {t:.1} nm ({e:.0} nm off)");
    }
}

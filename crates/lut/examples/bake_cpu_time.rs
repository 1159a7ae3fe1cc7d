//! CPU time per bake, which (unlike the wall time criterion reports) does not grow when
//! other processes share the cores: `cargo run --release -p lut --example bake_cpu_time
//! [WIDTHxHEIGHT] [REPEATS]`. Linux only (reads `/proc/self/stat`); 512x512 and 20 by default.
//!
//! Prints CPU ms per bake and CPU ns per spectral sample, for one thread and for rayon's
//! default pool, for the bake with cell means and the point-sampled bake before them; on an idle machine the default pool's wall time is about the CPU time
//! divided by the core count.

use std::time::Instant;

use lut::BakeConfig;

/// User + system CPU time of this process so far, in seconds, from `/proc/self/stat`.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are the 12th and 13th.
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    // USER_HZ is 100 on every Linux the workspace targets.
    Some(ticks / 100.0)
}

/// One way of baking a configuration.
type Bake = fn(&BakeConfig) -> lut::LutSet;

fn main() {
    let mut args = std::env::args().skip(1);
    let (width, height) = args
        .next()
        .and_then(|s| {
            let (w, h) = s.split_once('x')?;
            Some((w.parse().ok()?, h.parse().ok()?))
        })
        .unwrap_or((512, 512));
    let repeats: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(20);
    let config = BakeConfig::builder()
        .resolution(width, height)
        .lights(Vec::new())
        .build()
        .expect("valid resolution");
    let samples = lut::spectral_samples(&config) as f64;
    let bakes: [(&str, Bake); 2] = [
        ("point-sampled (before cell means)", lut::bake_point_sampled),
        ("with cell means", lut::bake),
    ];
    for threads in [1, rayon::current_num_threads()] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        for (name, bake) in bakes {
            pool.install(|| bake(&config));
            let (cpu0, wall0) = (cpu_seconds(), Instant::now());
            for _ in 0..repeats {
                pool.install(|| std::hint::black_box(bake(&config)));
            }
            let wall = wall0.elapsed().as_secs_f64() / repeats as f64;
            let cpu = cpu_seconds()
                .zip(cpu0)
                .map(|(b, a)| (b - a) / repeats as f64);
            let cpu_text = cpu.map_or("n/a".into(), |c| {
                format!(
                    "{:.1} ms CPU, {:.2} ns CPU per point sample",
                    c * 1e3,
                    c * 1e9 / samples
                )
            });
            println!(
                "{width}x{height}, reflectivity + transmittance, {name}, {threads} thread(s): {samples:.0} point samples, {:.1} ms wall, {cpu_text}",
                wall * 1e3
            );
        }
    }
}

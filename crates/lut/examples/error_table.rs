//! Prints the accuracy tables of docs/lut.md: the worst CIEDE2000 between a bilinear
//! lookup ([`lut::Lut::sample`]) and direct f64 evaluation of the film, against table
//! resolution and the smallest cos θ covered, for the default bake settings.
//!
//! `cargo run --release -p lut --example error_table [POINTS_PER_BAND]` (default 20000)
//!
//! Each cos θ band is probed with uniform random points, as many again packed into the
//! first two thickness columns (where reflectance rises as d² from a black film and
//! CIELAB is steepest), and the centre of every table cell in the band.

use lut::BakeConfig;
use lut::accuracy::{Table, cell_centre_points, delta_e_report, random_points};

const RESOLUTIONS: [(usize, usize); 8] = [
    (256, 64),
    (512, 64),
    (512, 128),
    (1024, 64),
    (1024, 128),
    (1024, 256),
    (2048, 128),
    (2048, 256),
];

/// cos θ bands, from grazing up; a domain `cos θ ≥ c` is the union of the bands above c.
const BANDS: [(f32, f32); 5] = [
    (0.0, 0.05),
    (0.05, 0.1),
    (0.1, 0.15),
    (0.15, 0.3),
    (0.3, 1.0),
];

fn band_points(config: &BakeConfig, (lo, hi): (f32, f32), count: usize) -> Vec<(f32, f32)> {
    let d_max = config.thickness_max_nm();
    let two_columns = 2.0 * d_max / (config.width() - 1) as f32;
    let in_band = |c: f32| lo + (hi - lo) * c;
    let seed = (lo * 1000.0) as u64;
    let mut points: Vec<_> = random_points(count, d_max, seed)
        .into_iter()
        .map(|(d, c)| (d, in_band(c)))
        .collect();
    points.extend(
        random_points(count, d_max, seed + 1)
            .into_iter()
            .map(|(d, c)| (d / d_max * two_columns, in_band(c))),
    );
    points.extend(
        cell_centre_points(config.width(), config.height(), d_max)
            .into_iter()
            .filter(|&(_, c)| c >= lo && (c < hi || hi == 1.0)),
    );
    points
}

/// Worst ΔE00 of `table` per band, grazing band first.
fn band_maxima(config: &BakeConfig, set: &lut::LutSet, table: Table, count: usize) -> Vec<f64> {
    BANDS
        .iter()
        .map(|&band| {
            delta_e_report(config, set, table, &band_points(config, band, count)).max_delta_e
        })
        .collect()
}

/// Running maxima from the top band down: entry k is the worst over `cos θ ≥ BANDS[k].0`.
fn domain_maxima(bands: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = bands
        .iter()
        .rev()
        .scan(0.0f64, |acc, &e| {
            *acc = acc.max(e);
            Some(*acc)
        })
        .collect();
    out.reverse();
    out
}

fn main() {
    let count: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    println!("Reflectivity, worst ΔE00 over d ∈ [0, 2000] nm and cos θ ≥ c:\n");
    println!("| resolution | c = 0.3 | c = 0.15 | c = 0.1 | c = 0.05 | c = 0 |");
    println!("|---|---|---|---|---|---|");
    for (width, height) in RESOLUTIONS {
        let config = BakeConfig::builder()
            .resolution(width, height)
            .build()
            .expect("valid resolution");
        let set = lut::bake(&config);
        let worst = domain_maxima(&band_maxima(&config, &set, Table::Reflectivity, count));
        let marker = if (width, height)
            == (
                BakeConfig::default().width(),
                BakeConfig::default().height(),
            ) {
            " (default)"
        } else {
            ""
        };
        println!(
            "| {width}×{height}{marker} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} |",
            worst[4], worst[3], worst[2], worst[1], worst[0]
        );
    }
    let config = BakeConfig::default();
    let set = lut::bake(&config);
    println!(
        "\nEvery table at the default {}×{}, same domains:\n",
        config.width(),
        config.height()
    );
    println!("| table | c = 0.3 | c = 0.15 | c = 0.1 | c = 0.05 | c = 0 |");
    println!("|---|---|---|---|---|---|");
    for (name, table) in [
        ("reflectivity", Table::Reflectivity),
        ("transmittance", Table::Transmittance),
        ("light_sodium", Table::Light(0)),
    ] {
        let worst = domain_maxima(&band_maxima(&config, &set, table, count));
        println!(
            "| {name} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} |",
            worst[4], worst[3], worst[2], worst[1], worst[0]
        );
    }
}

//! Prints the table of docs/lut.md: worst CIEDE2000 between a bilinear lookup and direct
//! f64 evaluation, against table resolution, for the default bake settings.
//!
//! `cargo run --release -p lut --example error_table [RANDOM_POINTS]`

use lut::BakeConfig;
use lut::accuracy::{Table, cell_centre_points, delta_e_report, random_points};

const RESOLUTIONS: [(usize, usize); 10] = [
    (128, 32),
    (256, 32),
    (256, 64),
    (512, 32),
    (512, 64),
    (512, 128),
    (512, 256),
    (1024, 64),
    (1024, 128),
    (1024, 256),
];

fn main() {
    let random_count: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000);
    println!(
        "| resolution | reflectivity max ΔE00 | mean | worst at (d nm, cos θ) | transmittance max ΔE00 | sodium light max ΔE00 |"
    );
    println!("|---|---|---|---|---|---|");
    for (width, height) in RESOLUTIONS {
        let config = BakeConfig::builder()
            .resolution(width, height)
            .build()
            .expect("valid resolution");
        let set = lut::bake(&config);
        let mut points = random_points(random_count, config.thickness_max_nm(), 2004);
        points.extend(cell_centre_points(width, height, config.thickness_max_nm()));
        let r = delta_e_report(&config, &set, Table::Reflectivity, &points);
        let t = delta_e_report(&config, &set, Table::Transmittance, &points);
        let s = delta_e_report(&config, &set, Table::Light(0), &points);
        println!(
            "| {width}×{height} | {:.3} | {:.4} | ({:.1}, {:.3}) | {:.3} | {:.3} |",
            r.max_delta_e,
            r.mean_delta_e,
            r.worst_thickness_nm,
            r.worst_cos_theta,
            t.max_delta_e,
            s.max_delta_e
        );
    }
}

//! The published accuracy of the default table (docs/lut.md): a bilinear lookup of the
//! reflectivity stays within CIEDE2000 0.5 of direct f64 evaluation for
//! d ∈ [0, 2000] nm and cos θ ∈ [0.1, 1].
//!
//! The full table of error against resolution comes from
//! `cargo run --release -p lut --example error_table`.

use lut::BakeConfig;
use lut::accuracy::{
    BOUND_COS_THETA_MIN as BOUND_COS_MIN, BOUND_DELTA_E, Table, cell_centre_points, delta_e_report,
    random_points,
};

/// Random points over the bounded domain, plus points packed into the first two columns,
/// where the d² onset of reflectance meets CIELAB's steep dark end, plus cell centres.
fn probe_points(config: &BakeConfig, random: usize, every_nth_centre: usize) -> Vec<(f32, f32)> {
    let d_max = config.thickness_max_nm();
    let to_domain = |c: f32| BOUND_COS_MIN + (1.0 - BOUND_COS_MIN) * c;
    let two_columns = 2.0 * d_max / (config.width() - 1) as f32;
    let mut points: Vec<_> = random_points(random, d_max, 11)
        .into_iter()
        .map(|(d, c)| (d, to_domain(c)))
        .collect();
    points.extend(
        random_points(random / 4, d_max, 12)
            .into_iter()
            .map(|(d, c)| (d / d_max * two_columns, to_domain(c))),
    );
    points.extend(
        cell_centre_points(config.width(), config.height(), d_max)
            .into_iter()
            .filter(|&(_, c)| c >= BOUND_COS_MIN)
            .step_by(every_nth_centre),
    );
    points
}

#[test]
fn default_reflectivity_table_meets_the_published_delta_e_bound() {
    let config = BakeConfig::default();
    let set = lut::bake(&config);
    let report = delta_e_report(
        &config,
        &set,
        Table::Reflectivity,
        &probe_points(&config, 3000, 97),
    );
    assert!(
        report.max_delta_e <= BOUND_DELTA_E,
        "max ΔE00 {:.3} at d = {} nm, cos θ = {} exceeds {BOUND_DELTA_E} (excess {:.3})",
        report.max_delta_e,
        report.worst_thickness_nm,
        report.worst_cos_theta,
        report.max_delta_e - BOUND_DELTA_E
    );
}

#[test]
fn a_coarse_table_breaks_the_bound_so_the_probe_can_fail() {
    let config = BakeConfig::builder()
        .resolution(128, 32)
        .build()
        .expect("valid config");
    let set = lut::bake(&config);
    let report = delta_e_report(
        &config,
        &set,
        Table::Reflectivity,
        &probe_points(&config, 1000, 7),
    );
    assert!(
        report.max_delta_e > BOUND_DELTA_E,
        "128x32 should miss the bound, max ΔE00 only {:.3}",
        report.max_delta_e
    );
}

#[test]
fn lookups_at_texel_centres_match_direct_evaluation() {
    let config = BakeConfig::builder()
        .resolution(64, 16)
        .build()
        .expect("valid config");
    let set = lut::bake(&config);
    let centres: Vec<_> = (0..16)
        .flat_map(|j| (0..64).map(move |i| (i, j)))
        .map(|(i, j)| {
            (
                set.reflectivity.thickness_nm_at(i),
                set.reflectivity.cos_theta_at(j),
            )
        })
        .collect();
    for table in [Table::Reflectivity, Table::Transmittance, Table::Light(0)] {
        let report = delta_e_report(&config, &set, table, &centres);
        assert!(
            report.max_delta_e < 0.01,
            "{table:?}: ΔE00 {:.4} at a texel centre (d = {}, cos θ = {})",
            report.max_delta_e,
            report.worst_thickness_nm,
            report.worst_cos_theta
        );
    }
}

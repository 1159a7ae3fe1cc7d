//! [`bake`]: every table of a [`BakeConfig`], in parallel rows on the fused f32 kernel.

use rayon::prelude::*;
use thinfilm::batch::{CellSpectrum, try_weighted_cell_row, weighted_reflectance_row};
use thinfilm::cells::cell_threshold_nm;
use thinfilm::cmf::Observer;

use crate::config::N_OUTSIDE;
use crate::meta::COLOR_SPACE;
use crate::table::axis_value;
use crate::weights::{CellPass, Pass, light_pass, reflectivity_pass};
use crate::{BakeConfig, Lut, LutMeta, LutSet};

/// Bakes the reflectivity, transmittance and light-source tables of `config`.
///
/// Rows are baked in parallel; each row is computed the same way on any thread, so the
/// result is bit-identical at any thread count.
pub fn bake(config: &BakeConfig) -> LutSet {
    bake_with_progress(config, &|| {})
}

/// Number of kernel rows [`bake_with_progress`] reports: one per row for the
/// reflectivity pass (transmittance is derived from it) and one per row per light.
pub fn progress_rows(config: &BakeConfig) -> usize {
    config.height * (1 + config.lights.len())
}

/// Number of (texel, wavelength) reflectance evaluations a bake of `config` makes:
/// texels × wavelengths of the reflectivity pass (transmittance is `1 − R`) plus
/// texels × wavelengths of each light (a line light costs only its lines).
pub fn spectral_samples(config: &BakeConfig) -> u64 {
    let texels = (config.width * config.height) as u64;
    let wavelengths: usize = reflectivity_pass(config).wavelength_nm.len()
        + (0..config.lights.len())
            .map(|k| light_pass(config, k).wavelength_nm.len())
            .sum::<usize>();
    texels * wavelengths as u64
}

/// Like [`bake`], calling `on_row` (from any thread) after each of the
/// [`progress_rows`] kernel rows.
pub fn bake_with_progress(config: &BakeConfig, on_row: &(dyn Fn() + Sync)) -> LutSet {
    bake_passes(config, on_row, true)
}

/// [`bake`] with every texel point-sampled, as before cell means: off by up to about 7
/// ΔE2000 near grazing incidence. Kept to measure what the cell means cost and fix
/// (docs/physics.md), not for use.
pub fn bake_point_sampled(config: &BakeConfig) -> LutSet {
    bake_passes(config, &|| {}, false)
}

fn bake_passes(config: &BakeConfig, on_row: &(dyn Fn() + Sync), use_cells: bool) -> LutSet {
    let cells = |mut pass: Pass| {
        if !use_cells {
            pass.cells = None;
        }
        pass
    };
    let thickness_nm: Vec<f32> = (0..config.width)
        .map(|i| axis_value(i, config.width, config.thickness_max_nm))
        .collect();
    let reflectivity_pass = cells(reflectivity_pass(config));
    let reflectivity = bake_pass(config, &reflectivity_pass, &thickness_nm, on_row);
    // The film is lossless (real index, the same real medium on both sides), so
    // T(λ) = 1 − R(λ) exactly, and the weights sum to 1 per channel, so
    // Σ W_k (1 − R_k) = 1 − Σ W_k R_k: one subtraction instead of a second spectral sum,
    // which would nearly double the bake. tests/bake_physics.rs checks this table against
    // the f64 path's own transmittance formula.
    let transmittance = reflectivity
        .par_iter()
        .map(|rgb| rgb.map(|c| 1.0 - c))
        .collect();
    let mut passes = vec![reflectivity_pass];
    let mut lights = Vec::with_capacity(config.lights.len());
    for (k, light) in config.lights.iter().enumerate() {
        let pass = cells(light_pass(config, k));
        let texels = bake_pass(config, &pass, &thickness_nm, on_row);
        lights.push((light.name().to_owned(), table(config, texels)));
        passes.push(pass);
    }
    LutSet {
        reflectivity: table(config, reflectivity),
        transmittance: table(config, transmittance),
        lights,
        meta: meta(config, &passes),
    }
}

/// Runs the fused reflectance kernel on every row of one table: point samples for the
/// thinner films, cell means (`thinfilm::cells`) from the thickness where the film's
/// spectral lines become too narrow to sample.
fn bake_pass(
    config: &BakeConfig,
    pass: &Pass,
    thickness_nm: &[f32],
    on_row: &(dyn Fn() + Sync),
) -> Vec<[f32; 3]> {
    let mut texels = vec![[0.0f32; 3]; config.width * config.height];
    texels
        .par_chunks_mut(config.width)
        .enumerate()
        .for_each(|(j, row)| {
            let cos_theta = axis_value(j, config.height, 1.0);
            let split = pass.cells.as_ref().map_or(row.len(), |cells| {
                cell_threshold_nm(
                    &cells.cells,
                    N_OUTSIDE,
                    &config.film_index,
                    f64::from(cos_theta),
                )
                .map_or(row.len(), |t| {
                    thickness_nm.partition_point(|&d| f64::from(d) < t)
                })
            });
            point_row(pass, cos_theta, &thickness_nm[..split], &mut row[..split]);
            if let Some(cells) = &pass.cells {
                cell_row(cells, cos_theta, &thickness_nm[split..], &mut row[split..]);
            }
            on_row();
        });
    texels
}

fn point_row(pass: &Pass, cos_theta: f32, thickness_nm: &[f32], out: &mut [[f32; 3]]) {
    weighted_reflectance_row(
        N_OUTSIDE as f32,
        cos_theta,
        &pass.wavelength_nm,
        &pass.n_film,
        &pass.weights,
        thickness_nm,
        out,
    );
}

/// Cell means of the continuous spectrum plus the lines, sampled.
fn cell_row(cells: &CellPass, cos_theta: f32, thickness_nm: &[f32], out: &mut [[f32; 3]]) {
    if thickness_nm.is_empty() {
        return;
    }
    let spectrum = CellSpectrum {
        edge_nm: &cells.cells.edges_nm,
        n_film_edge: &cells.n_film_edge,
        n_film_cell: &cells.n_film_cell,
        weights: &cells.weights,
    };
    try_weighted_cell_row(N_OUTSIDE as f32, cos_theta, &spectrum, thickness_nm, out)
        .expect("a validated BakeConfig gives valid cells wherever their threshold is finite");
    if cells.lines.wavelength_nm.is_empty() {
        return;
    }
    let mut lines = vec![[0.0f32; 3]; thickness_nm.len()];
    point_row(&cells.lines, cos_theta, thickness_nm, &mut lines);
    for (px, line) in out.iter_mut().zip(lines) {
        *px = std::array::from_fn(|c| px[c] + line[c]);
    }
}

fn table(config: &BakeConfig, texels: Vec<[f32; 3]>) -> Lut {
    Lut::try_new(config.width, config.height, config.thickness_max_nm, texels)
        .expect("a validated BakeConfig bakes finite texels of the right count")
}

fn meta(config: &BakeConfig, passes: &[Pass]) -> LutMeta {
    let mut wavelengths: Vec<f64> = passes
        .iter()
        .flat_map(|p| p.wavelength_nm_f64.iter().copied())
        .collect();
    wavelengths.sort_by(f64::total_cmp);
    wavelengths.dedup();
    LutMeta {
        thickness_max_nm: config.thickness_max_nm,
        n_outside: N_OUTSIDE,
        film_index: format!("{:?}", config.film_index),
        film_index_samples: wavelengths
            .into_iter()
            .map(|w| [w, config.film_index.n_at(w)])
            .collect(),
        observer: observer_name(config.observer).into(),
        step_nm: config.step_nm,
        reference_illuminant: config.reference.name().into(),
        color_space: COLOR_SPACE.into(),
    }
}

fn observer_name(observer: Observer) -> &'static str {
    match observer {
        Observer::Cie1931 => "CIE 1931 2-degree",
        Observer::Cie1964 => "CIE 1964 10-degree",
    }
}

//! Capillary smoothing of the film's thickness: the liquid's pressure under a curved
//! interface, `p = −(σ/2)∇²h` (each of the two interfaces sits at ±h/2 and bends by
//! half the thickness's curvature), drives a Poiseuille flux relative to the surfaces with
//! the drainage's own mobility, `q = −h³/(3μ_d) ∇p`, so
//! `∂h/∂t = −(σ/(6μ_d)) ∇·(h³ ∇∇²h)`: a thickness bump of degree l on a sphere of radius R
//! decays at `σh³(l(l+1))²/(6μ_d R⁴)`.
//!
//! Explicit, in sub-steps under a Gershgorin bound of the discrete operator, at most
//! [`MAX_SUBSTEPS`] of them. The rate grows as h³: a film pooled to tens of µm at a
//! bubble's bottom would need thousands of sub-steps, so there each edge's mobility is
//! capped at what the sub-steps resolve. Such a film is smoothed within a step anyway;
//! the cap only slows how fast, and films under a few µm (every film the optics colour)
//! keep the exact law. Fluxes that sum to zero keep liquid conserved to rounding, each
//! donor limited to half its content keeps h ≥ 0.

use super::compare::{largest, pick, smaller};
use super::face_geometry::FaceGeometry;
use super::fluxes::{FromArray, GatherScratch, apply_limited, net_inflow};
use super::grid::CubeSphere;
use super::sides::{CellSides, EdgeBlock, SeamEnds};
use crate::avx2::with_avx2;

/// Most explicit sub-steps a film step spends on capillary smoothing.
pub(crate) const MAX_SUBSTEPS: u32 = 64;

/// Largest `sub_dt·bound` a sub-step takes. The operator is similar to a symmetric
/// positive semi-definite one (a weighted Laplacian times a Laplacian), so its eigenvalues
/// λ are real and ≥ 0, forward Euler is stable for `sub_dt·λ ≤ 2`, and the bound (the
/// product of the two Laplacians' ∞-norms) is ≥ every λ; 1.8 keeps the finest mode
/// damped.
const STABLE_RATE_DT: f64 = 1.8;

/// What the smoothing reads: the film's surface tension and the drainage's viscosity.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Capillary {
    /// One interface's surface tension σ, N/m.
    pub sigma_n_per_m: f64,
    /// The drainage's effective viscosity μ_d, Pa·s (finite and positive).
    pub drainage_viscosity_pa_s: f64,
    /// Radius of the sphere, m.
    pub radius_m: f64,
}

/// Buffers reused across steps.
#[derive(Clone, Debug, Default)]
pub(crate) struct CapillaryScratch {
    /// The grid's Laplacian ∞-norm on the unit sphere and the cell count it is for (it
    /// depends on the grid alone).
    laplacian_norm: Option<(usize, f64)>,
    laplacian: Vec<f64>,
    flux: Vec<f64>,
    /// The gathers' buffers.
    gather: GatherScratch,
    /// The seam edges' end values.
    seam_ends: SeamEnds,
}

/// Moves liquid by the capillary pressure over `dt_s`; `h_m` per cell.
pub(crate) fn smooth_thickness(
    grid: &CubeSphere,
    sides: &CellSides,
    c: Capillary,
    dt_s: f64,
    h_m: &mut [f64],
    s: &mut CapillaryScratch,
) {
    // h³/(3μ_d) times σ/2 (the pressure's factor), per m³ of h³.
    let per_cubed = 0.5 * c.sigma_n_per_m / (3.0 * c.drainage_viscosity_pa_s);
    // Gershgorin: |∇·(M∇)| ≤ max M · |∇²| and |∇²| ≤ 2 max Σ l/(d A R²).
    let norm = match s.laplacian_norm {
        Some((cells, norm)) if cells == grid.cells() => norm,
        _ => {
            let norm = laplacian_norm(grid);
            s.laplacian_norm = Some((grid.cells(), norm));
            norm
        }
    };
    let thickest = largest(h_m);
    let max_mobility = per_cubed * thickest * thickest * thickest;
    let rate = max_mobility * (norm / (c.radius_m * c.radius_m)).powi(2);
    if rate * dt_s < 1e-3 {
        return; // a smoothing the step cannot see (every film of the optics' range)
    }
    let substeps = (rate * dt_s / STABLE_RATE_DT)
        .ceil()
        .min(f64::from(MAX_SUBSTEPS));
    let sub_dt = dt_s / substeps;
    // Cap the mobility where the sub-steps cannot resolve the rate.
    let cap = max_mobility * (STABLE_RATE_DT / (rate * sub_dt)).min(1.0);
    let mobility = Mobility { per_cubed, cap };
    for _ in 0..substeps as u32 {
        substep((grid, sides), c.radius_m, mobility, sub_dt, h_m, s);
    }
}

/// The ∞-norm of the grid's Laplacian on the unit sphere, `2 max_c Σ l/(d A)`.
fn laplacian_norm(grid: &CubeSphere) -> f64 {
    let ea = grid.edge_arrays();
    let mut sums = vec![0.0; grid.cells()];
    for (([a, b], l), d) in ea.cells.iter().zip(&ea.length).zip(&ea.dual_length) {
        sums[*a as usize] += l / d;
        sums[*b as usize] += l / d;
    }
    let areas = grid.areas_sr();
    2.0 * sums
        .iter()
        .zip(areas)
        .map(|(s, a)| s / a)
        .fold(0.0, f64::max)
}

/// An edge's mobility `M = per_cubed·h³` at its donor's thickness, at most `cap`.
#[derive(Clone, Copy, Debug)]
struct Mobility {
    per_cubed: f64,
    cap: f64,
}

/// One forward-Euler sub-step of `∂h/∂t = −∇·(M ∇(−∇²h))`: two passes over the edges
/// (the thickness's differences, then the volumes), each followed by the cells' gathers.
fn substep(
    (grid, sides): (&CubeSphere, &CellSides),
    radius_m: f64,
    mobility: Mobility,
    dt_s: f64,
    h_m: &mut [f64],
    s: &mut CapillaryScratch,
) {
    let fg = grid.face_geometry();
    s.flux.resize(grid.edges().len(), 0.0);
    // ∇²h as the net inflow of the differences `(h_b − h_a) l/d` (their sum out of a
    // cell, with the sign of an inflow: a cell below its neighbours gains).
    sides.for_each_edge_run(
        #[inline(always)]
        |run| {
            let (ha, hb) = run.ends(h_m);
            differences_block(run, [ha, hb], fg, &mut s.flux);
        },
    );
    let seams = sides.seams();
    let ends = s.seam_ends.gather(seams, h_m);
    with_avx2(
        #[inline(always)]
        || differences_block(seams, ends, fg, &mut s.flux),
    );
    net_inflow(
        sides,
        (&mut FromArray(&s.flux), h_m),
        &mut s.laplacian,
        &mut s.gather,
        |_, _, _| {},
    );
    let per_r2 = 1.0 / (radius_m * radius_m);
    // A face at a time, each with face 0's inverse areas (the same on every face).
    let per_area = &fg.inverse_area_per_sr;
    for face in s.laplacian.chunks_exact_mut(per_area.len()) {
        for (lap, per_area) in face.iter_mut().zip(per_area) {
            *lap *= per_area * per_r2;
        }
    }
    // Volume from a to b over the sub-step, per R² (m·sr): the flux runs down the
    // pressure −(σ/2)∇²h, i.e. up the gradient of ∇²h (the ½σ is in the mobility), so
    // out of a bump, whose top has the lowest ∇²h.
    //
    // The mobility is the donor's h³ (the cell the liquid leaves), not the edge's mean:
    // the fourth-order flow has no maximum principle, and beside a pool tens of µm thick
    // a mean-thickness mobility drew liquid out of the thin film one cell further at the
    // pool's rate, emptying it in a step (bubbles resting on the ground burst within a
    // second). At the donor's, a thin cell gives at its own slow rate.
    let laplacian = &s.laplacian[..];
    let per_length = dt_s / (radius_m * radius_m);
    let volumes = Volumes {
        fg,
        mobility,
        per_length,
    };
    sides.for_each_edge_run(
        #[inline(always)]
        |run| {
            let ((ha, hb), (la, lb)) = (run.ends(h_m), run.ends(laplacian));
            volumes.block(run, [ha, hb, la, lb], &mut s.flux);
        },
    );
    let seams = sides.seams();
    let [[ha, hb], [la, lb]] = s.seam_ends.gather_many(seams, [h_m, laplacian]);
    with_avx2(
        #[inline(always)]
        || volumes.block(seams, [ha, hb, la, lb], &mut s.flux),
    );
    // Each donor gives at most half its content: h stays ≥ 0.
    apply_limited(
        sides,
        grid,
        &mut FromArray(&s.flux),
        1.0,
        h_m,
        &mut s.gather,
    );
}

/// `(h_a − h_b) l/d` over a block of edges with thicknesses `[ha, hb]` at their ends,
/// into `out` (the Laplacian's differences, [`substep`]).
#[inline(always)]
fn differences_block(
    run: impl EdgeBlock,
    [ha, hb]: [&[f64]; 2],
    fg: &FaceGeometry,
    out: &mut [f64],
) {
    let len = run.count();
    let (l, per_d) = (
        run.constant(&fg.length),
        run.constant(&fg.inverse_dual_length),
    );
    let (ha, hb, out) = (&ha[..len], &hb[..len], run.values_mut(out));
    for i in 0..len {
        out[i] = (ha[i] - hb[i]) * l[i] * per_d[i];
    }
}

/// The sub-step's volumes across the edges ([`substep`]).
struct Volumes<'a> {
    /// The grid's constants.
    fg: &'a FaceGeometry,
    /// Each edge's mobility from its donor's thickness.
    mobility: Mobility,
    /// The sub-step over `R²`.
    per_length: f64,
}

impl Volumes<'_> {
    /// The volumes over a block of edges with thicknesses and Laplacians `[ha, hb, la,
    /// lb]` at their ends, into `out`.
    #[inline(always)]
    fn block(&self, run: impl EdgeBlock, [ha, hb, la, lb]: [&[f64]; 4], out: &mut [f64]) {
        let len = run.count();
        let (fg, Mobility { per_cubed, cap }) = (self.fg, self.mobility);
        let (l, per_d) = (
            run.constant(&fg.length),
            run.constant(&fg.inverse_dual_length),
        );
        let (ha, hb, la, lb) = (&ha[..len], &hb[..len], &la[..len], &lb[..len]);
        let out = run.values_mut(out);
        for i in 0..len {
            let rise = lb[i] - la[i];
            let donor = pick(rise >= 0.0, ha[i], hb[i]);
            let m = smaller(per_cubed * donor * donor * donor, cap);
            out[i] = m * rise * per_d[i] * l[i] * self.per_length;
        }
    }
}

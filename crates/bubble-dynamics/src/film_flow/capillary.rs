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
//!
//! Where the step takes one sub-step of the smoothing and one of the thickness
//! transport, the smoothing's volumes join the transport's ([`Term`]: the splitting and
//! its stability there); else the smoothing runs after the transport.

use std::ops::Range;

use super::compare::{largest, pick, smaller};
use super::face_geometry::FaceGeometry;
use super::fluxes::{
    EdgeValues, GatherScratch, Thinned, apply_limited, apply_limited_to, net_inflow,
};
use super::grid::CubeSphere;
use super::sides::{CellSides, EdgeBlock, EdgeRun, SeamEnds, Seams};

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
}

/// Buffers the smoothing shares with the step's other passes: the gathers', the seams'
/// ends and a spent cell field's.
///
/// Why shared: the thickness transport, which runs just before, leaves them in cache,
/// where buffers of the smoothing's own were written cold every step
/// (the window, the rows carried between bands, the seams' values and the rim's, about
/// 0.2 MB at n = 64: 0.11 M of the smoothing's 0.27 M LL write misses over
/// `film_profile 64 0 9.81`'s 40 steps).
pub(crate) struct Shared<'a> {
    /// The gathers' buffers.
    pub(crate) gather: &'a mut GatherScratch,
    /// The seam edges' end values.
    pub(crate) seam_ends: &'a mut SeamEnds,
    /// A cell field's buffer whose values are spent, for the thickness's Laplacian per
    /// cell, per m: the one the thickness transport has just read its thickness from
    /// (`Scratch::cell`), partly in cache, where a buffer of the smoothing's own was
    /// written cold every step (the step's LL misses over `film_profile 64 0 9.81`'s 40
    /// steps went from 11.06 M to 11.00 M, the smoothing's write misses from 0.160 M to
    /// 0.144 M).
    pub(crate) laplacian: &'a mut Vec<f64>,
}

/// Moves liquid by the capillary pressure over `dt_s`; `h_m` per cell. Where `thin`
/// and a sub-step is taken, the last one's apply also thins every cell by it, kept ≥ 0
/// ([`Thinned`]: the evaporation): returns whether it did.
pub(crate) fn smooth_thickness(
    grid: &CubeSphere,
    sides: &CellSides,
    c: Capillary,
    (dt_s, thin): (f64, Option<f64>),
    h_m: &mut [f64],
    (s, shared): (&mut CapillaryScratch, Shared),
) -> bool {
    let Some(((substeps, mobility, sub_dt), _)) = plan(grid, c, dt_s, h_m, s) else {
        return false; // a smoothing the step cannot see (every film of the optics' range)
    };
    for k in 0..substeps {
        let thin = thin.filter(|_| k + 1 == substeps);
        let shared = Shared {
            gather: &mut *shared.gather,
            seam_ends: &mut *shared.seam_ends,
            laplacian: &mut *shared.laplacian,
        };
        substep(
            (grid, sides),
            c.radius_m,
            mobility,
            (sub_dt, thin),
            h_m,
            shared,
        );
    }
    thin.is_some()
}

/// The sub-steps a smoothing of `h_m` over `dt_s` takes, their mobility and their
/// length, and the share of one sub-step's stability bound the whole step would take
/// (`rate·dt/`[`STABLE_RATE_DT`]); `None` where the step cannot see it (a rate under
/// 1e-3 a step).
fn plan(
    grid: &CubeSphere,
    c: Capillary,
    dt_s: f64,
    h_m: &[f64],
    s: &mut CapillaryScratch,
) -> Option<((u32, Mobility, f64), f64)> {
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
        return None;
    }
    let substeps = (rate * dt_s / STABLE_RATE_DT)
        .ceil()
        .min(f64::from(MAX_SUBSTEPS));
    let sub_dt = dt_s / substeps;
    // Cap the mobility where the sub-steps cannot resolve the rate.
    let cap = max_mobility * (STABLE_RATE_DT / (rate * sub_dt)).min(1.0);
    let plan = (substeps as u32, Mobility { per_cubed, cap }, sub_dt);
    Some((plan, rate * dt_s / STABLE_RATE_DT))
}

/// The smoothing as one more term of the thickness transport's volumes over the step
/// ([`super::upwind::Volumes`]), where one sub-step takes it: each edge's capillary
/// volume from the Laplacian of the thickness the transport starts from, added to the
/// edge's transport volume before the one limited apply.
///
/// Why: the smoothing's own limited apply, a second pass over the thickness after the
/// transport's, cost about 30 M instructions over `film_profile 64 0 9.81`'s 40 steps;
/// joined, the term costs the transport about 10 M, and the step went from 581.8 M to
/// 564.5 M instructions (its LL misses from 11.00 M to 11.13 M: the Laplacian, a pass of
/// its own before the transport, is read back by the transport partly from beyond L2),
/// 562.0 M with the uniform evaporation joined too (`fluxes::Thinned`, out of place).
/// The splitting: the transport and the smoothing both take their rates from the
/// thickness at the step's start (an unsplit forward Euler step of their sum) where the
/// smoothing took the transported thickness (Lie splitting); both are first order in
/// time. Stability: a forward Euler step of a sum `A + B` over `dt` is the convex
/// combination `θ·(1 + (dt/θ)A) + (1 − θ)·(1 + (dt/(1 − θ))B)`, so it is stable where
/// each part's forward Euler step is over its stretched step, that is where the two
/// parts' shares of their own bounds sum to at most 1 (the strong-stability-preserving
/// argument): the smoothing's share `rate·dt/`[`STABLE_RATE_DT`] plus the transport's
/// `2·courant` (its one sub-step's condition is `2·courant ≤ 1`). Each part alone under
/// its bound does not make the sum stable, so the transport joins the term only there
/// (`transport::joins`), and the shared outflow limit keeps every cell ≥ 0 whatever
/// they sum to. Elsewhere, or where either needs more sub-steps, the two run apart as
/// before.
#[derive(Clone, Copy)]
pub(crate) struct Term<'a> {
    /// The thickness's Laplacian per cell, per m.
    pub(crate) laplacian: &'a [f64],
    /// Each edge's mobility.
    mobility: Mobility,
    /// The step over `R²`.
    per_length: f64,
}

/// The smoothing's one sub-step over `dt_s` as a [`Term`]'s mobility and step over R²,
/// with the share of its stability bound it takes ([`plan`]), its Laplacian into
/// `shared.laplacian`; `None` where the step cannot see it or it takes more than one
/// sub-step.
pub(crate) fn one_substep(
    (grid, sides): (&CubeSphere, &CellSides),
    c: Capillary,
    dt_s: f64,
    h_m: &[f64],
    (s, mut shared): (&mut CapillaryScratch, Shared),
) -> Option<((Mobility, f64), f64)> {
    let ((substeps, mobility, sub_dt), share) = plan(grid, c, dt_s, h_m, s)?;
    if substeps != 1 {
        return None;
    }
    laplacian(grid, sides, c.radius_m, h_m, &mut shared);
    Some(((mobility, sub_dt / (c.radius_m * c.radius_m)), share))
}

impl<'a> Term<'a> {
    /// The term of [`one_substep`]'s `(mobility, per_length)` and the Laplacian.
    pub(crate) fn new(laplacian: &'a [f64], (mobility, per_length): (Mobility, f64)) -> Self {
        Self {
            laplacian,
            mobility,
            per_length,
        }
    }

    /// The capillary volume across an edge of length `l` and inverse dual length
    /// `per_d`, thicknesses `[ha, hb]` and Laplacians `[la, lb]` at its ends ([`volume`]).
    #[inline(always)]
    pub(crate) fn volume(&self, h: [f64; 2], lap: [f64; 2], [l, per_d]: [f64; 2]) -> f64 {
        volume((self.mobility, self.per_length), h, lap, [l, per_d])
    }

    /// The volumes over a block of edges with thicknesses and Laplacians `[ha, hb, la,
    /// lb]` at their ends: into `out` (the smoothing's own pass), or added to the
    /// transport's volumes there (`ADD`: the joined sub-step).
    #[inline(always)]
    pub(crate) fn block<const ADD: bool>(
        &self,
        fg: &FaceGeometry,
        run: impl EdgeBlock,
        [ha, hb, la, lb]: [&[f64]; 4],
        out: &mut [f64],
    ) {
        let len = run.count();
        let (l, per_d) = (
            run.constant(&fg.length),
            run.constant(&fg.inverse_dual_length),
        );
        let (ha, hb, la, lb) = (&ha[..len], &hb[..len], &la[..len], &lb[..len]);
        let (l, per_d, out) = (&l[..len], &per_d[..len], &mut out[..len]);
        for i in 0..len {
            let v = self.volume([ha[i], hb[i]], [la[i], lb[i]], [l[i], per_d[i]]);
            if ADD {
                out[i] += v;
            } else {
                out[i] = v;
            }
        }
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
pub(crate) struct Mobility {
    per_cubed: f64,
    cap: f64,
}

/// One forward-Euler sub-step of `∂h/∂t = −∇·(M ∇(−∇²h))`: two gathers by bands
/// ([`super::fluxes`]), of the thickness's differences into the Laplacian, then of the
/// volumes into the thickness, each cell then thinned by `thin` where given.
fn substep(
    (grid, sides): (&CubeSphere, &CellSides),
    radius_m: f64,
    mobility: Mobility,
    (dt_s, thin): (f64, Option<f64>),
    h_m: &mut [f64],
    mut shared: Shared,
) {
    let fg = grid.face_geometry();
    laplacian(grid, sides, radius_m, h_m, &mut shared);
    substep_apply(
        (grid, fg, sides),
        radius_m,
        mobility,
        (dt_s, thin),
        h_m,
        shared,
    );
}

/// The thickness's Laplacian per cell, per m, into `shared.laplacian`.
fn laplacian(
    grid: &CubeSphere,
    sides: &CellSides,
    radius_m: f64,
    h_m: &[f64],
    shared: &mut Shared,
) {
    let fg = grid.face_geometry();
    // ∇²h as the net inflow of the differences `(h_b − h_a) l/d` (their sum out of a
    // cell, with the sign of an inflow: a cell below its neighbours gains), over the
    // cells' areas and R²: face 0's inverse areas (the same on every face).
    let (per_r2, n) = (1.0 / (radius_m * radius_m), sides.n());
    let per_area = &fg.inverse_area_per_sr;
    let mut differences = Differences {
        fg,
        seam_ends: &mut *shared.seam_ends,
    };
    let pass = (&mut differences, h_m);
    // Every entry is written below: the buffer needs its length, not a fill.
    let laplacian = &mut *shared.laplacian;
    laplacian.resize(h_m.len(), 0.0);
    net_inflow(sides, pass, &mut *shared.gather, |_, face, rows, inflow| {
        let cells = rows.start * n..rows.end * n;
        let (per_area, first) = (&per_area[cells.clone()], face * n * n + cells.start);
        let lap = &mut laplacian[first..first + cells.len()];
        for ((lap, inflow), per_area) in lap.iter_mut().zip(inflow).zip(per_area) {
            *lap = inflow * (per_area * per_r2);
        }
    });
}

/// The sub-step's limited apply of the volumes from the Laplacian in `laplacian`
/// ([`substep`]).
fn substep_apply(
    (grid, fg, sides): (&CubeSphere, &FaceGeometry, &CellSides),
    radius_m: f64,
    mobility: Mobility,
    (dt_s, thin): (f64, Option<f64>),
    h_m: &mut [f64],
    shared: Shared,
) {
    let Shared {
        gather,
        seam_ends,
        laplacian,
    } = shared;
    // Volume from a to b over the sub-step, per R² (m·sr): the flux runs down the
    // pressure −(σ/2)∇²h, i.e. up the gradient of ∇²h (the ½σ is in the mobility), so
    // out of a bump, whose top has the lowest ∇²h.
    //
    // The mobility is the donor's h³ (the cell the liquid leaves), not the edge's mean:
    // the fourth-order flow has no maximum principle, and beside a pool tens of µm thick
    // a mean-thickness mobility drew liquid out of the thin film one cell further at the
    // pool's rate, emptying it in a step (bubbles resting on the ground burst within a
    // second). At the donor's, a thin cell gives at its own slow rate.
    let mut volumes = Volumes {
        fg,
        term: Term::new(&laplacian[..], (mobility, dt_s / (radius_m * radius_m))),
        seam_ends,
    };
    // Each donor gives at most half its content: h stays ≥ 0.
    match thin {
        None => apply_limited(sides, grid, &mut volumes, 1.0, h_m, gather),
        Some(by) => {
            let h = &mut Thinned { values: h_m, by };
            apply_limited_to(sides, grid, &mut volumes, 1.0, h, gather);
        }
    }
}

/// The Laplacian's differences across every edge, from the thickness ([`EdgeValues`]).
struct Differences<'a> {
    /// The grid's constants.
    fg: &'a FaceGeometry,
    /// The seams' ends.
    seam_ends: &'a mut SeamEnds,
}

impl EdgeValues for Differences<'_> {
    #[inline(always)]
    fn seams(&mut self, seams: Seams, h: &[f64], out: &mut [f64]) {
        let ends = self.seam_ends.gather(seams, h);
        differences_block(seams, ends, self.fg, out);
    }

    #[inline(always)]
    fn run(&mut self, run: EdgeRun, _rows: Range<usize>, h: &[f64], out: &mut [f64]) {
        let run = run.padded(out.len(), h.len());
        let (ha, hb) = run.ends(h);
        differences_block(run, [ha, hb], self.fg, out);
    }
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
    let (ha, hb, out) = (&ha[..len], &hb[..len], &mut out[..len]);
    for i in 0..len {
        out[i] = (ha[i] - hb[i]) * l[i] * per_d[i];
    }
}

/// The sub-step's volumes across the edges ([`substep`]), from the thickness
/// ([`EdgeValues`]).
struct Volumes<'a> {
    /// The grid's constants.
    fg: &'a FaceGeometry,
    /// The mobility, the sub-step over `R²` and the thickness's Laplacian.
    term: Term<'a>,
    /// The seams' ends.
    seam_ends: &'a mut SeamEnds,
}

impl EdgeValues for Volumes<'_> {
    #[inline(always)]
    fn seams(&mut self, seams: Seams, h: &[f64], out: &mut [f64]) {
        let lap = self.term.laplacian;
        let [[ha, hb], [la, lb]] = self.seam_ends.gather_many(seams, [h, lap]);
        self.term
            .block::<false>(self.fg, seams, [ha, hb, la, lb], out);
    }

    #[inline(always)]
    fn run(&mut self, run: EdgeRun, _rows: Range<usize>, h: &[f64], out: &mut [f64]) {
        let run = run.padded(out.len(), h.len());
        let ((ha, hb), (la, lb)) = (run.ends(h), run.ends(self.term.laplacian));
        self.term
            .block::<false>(self.fg, run, [ha, hb, la, lb], out);
    }
}

/// The volume across an edge ([`Term::block`]), from its ends' thicknesses and
/// Laplacians, its length and inverse dual length.
#[inline(always)]
fn volume(
    (mobility, per_length): (Mobility, f64),
    [ha, hb]: [f64; 2],
    [la, lb]: [f64; 2],
    [l, per_d]: [f64; 2],
) -> f64 {
    let Mobility { per_cubed, cap } = mobility;
    let rise = lb - la;
    let donor = pick(rise >= 0.0, ha, hb);
    let m = smaller(per_cubed * donor * donor * donor, cap);
    m * rise * per_d * l * per_length
}

//! The implicit Marangoni step's linear system, `(diag(α) + L_w) x = b` with `L_w` a
//! weighted graph Laplacian over the cube-sphere's cells: conjugate gradients
//! preconditioned by one symmetric multigrid V-cycle over the grid's halvings.
//!
//! The conjugate gradients run in `f64`, the V-cycle in `f32` (see [`Work`]: a
//! preconditioner need only be a fixed map near `M⁻¹`, and the V-cycle's `f32` rounding
//! is far below its own error as an inverse).
//!
//! Coarse levels are re-discretised, not Galerkin: the mass term `α` sums over the four
//! children, and a coarse edge's weight is half the sum of the two fine edges along it
//! (the weight `l/d` of a Laplacian is scale-free in 2D, while piecewise-constant
//! Galerkin coarsening would double it and halve the coarse correction).

use super::grid::{CubeSphere, parent_cell};
use crate::avx2::with_avx2;

/// Sides of every cell: each level is itself a cube-sphere, whose cells all have four
/// neighbours, so the stencils have four sides everywhere (no per-cell loop bounds).
const SIDES: usize = 4;

/// Per side `k`: each cell's weight of the edge to its `k`-th neighbour (one array a side,
/// so a run of cells reads each side's weights contiguously and the loop vectorises).
type Stencil<T> = [Vec<T>; SIDES];

/// The two precisions the solve computes in: `f64` for the conjugate gradients, `f32`
/// for the V-cycle that preconditions them (see [`Work`]). The loops are written once,
/// generic over it, each an IEEE operation in a fixed order in either.
trait Real:
    Copy
    + PartialEq
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::AddAssign
{
    const ZERO: Self;
}

impl Real for f64 {
    const ZERO: Self = 0.0;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
}

/// Shortest run of cells with a shared neighbour pattern taken as a [`Segment::Run`].
const MIN_RUN: usize = 4;

/// A stretch of consecutive cells, in the level's numbering, that a sweep visits in turn.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Segment {
    /// Cells `start..end`, each read through its own neighbour list.
    Cells { start: usize, end: usize },
    /// Cells `start..end` whose `k`-th neighbours are the cells `from[k]..` in the same
    /// order, all outside the run (on the other colour): the face interiors' rows in the
    /// chequered numbering. Their updates do not read one another, so a run is relaxed
    /// as slices, with no neighbour indices to load or bounds to check, and the same
    /// results.
    Run {
        start: usize,
        end: usize,
        from: [usize; SIDES],
    },
}

/// A level's cells and edges (`a`, `b` cell indices), with per-cell neighbour lists.
#[derive(Clone, Debug)]
struct Level {
    cells: usize,
    edges: Vec<(u32, u32)>,
    /// The four neighbours of each cell in increasing order, and the edges to them, in
    /// matching order (increasing, so a face interior's cells share one pattern).
    neighbours: Vec<[u32; SIDES]>,
    neighbour_edges: Vec<[u32; SIDES]>,
    /// The cells as runs and stretches of single cells, in order.
    segments: Vec<Segment>,
    /// The cells a backward sweep reads before it updates them (those with a neighbour
    /// after them), as ranges: the only ones whose coarse correction is ever read. The
    /// rest (about half: a face interior's second colour) it overwrites unread, since a
    /// cell's update does not read its own value, so the V-cycle does not correct them.
    read_before_update: Vec<std::ops::Range<usize>>,
    /// Fine cell → this level's cell, for the level below (finer) this one.
    parent_of_fine: Vec<u32>,
    /// This level's cells as stretches whose children lie every other fine cell: the
    /// restrictions sum each cell's four children in increasing order, the order a
    /// scatter over the fine cells added them (so the same bits), with no zeroed sums
    /// to start from and no child indices to load.
    child_runs: Vec<ChildRun>,
    /// The finer level's [`Level::read_before_update`] cells as stretches whose parents
    /// (on this level) step by one every other cell: the coarse correction's reads.
    parent_runs: Vec<ParentRun>,
    /// This level's edge → the two fine edges along it, in increasing order.
    fine_edges: Vec<[u32; 2]>,
    /// Fine edge → coarse edge it lies along (`u32::MAX` inside a coarse cell), for the
    /// level above (coarser) this one: what [`Level::fine_edges`] is built from.
    coarse_edge_of_fine: Vec<u32>,
}

/// The face size a grid of `n` coarsens to: halved while even and above
/// [`COARSEST_FACE`].
fn coarsest_face(mut n: usize) -> usize {
    while n % 2 == 0 && n > COARSEST_FACE {
        n /= 2;
    }
    n
}

/// Largest number of cells solved directly on the coarsest level.
const DENSE_CELLS: usize = 6 * 8 * 8;
/// Face size the hierarchy coarsens down to when it can (a dense Cholesky of 6·4² cells
/// costs 0.3 M flops a step; of 6·8², 19 M).
const COARSEST_FACE: usize = 4;

/// The multigrid hierarchy of a cube-sphere, built once per grid size.
#[derive(Clone, Debug)]
pub struct Hierarchy {
    levels: Vec<Level>,
    /// The grid's cell at each position of the finest level's numbering.
    fine_order: Vec<u32>,
}

/// The numbers of one system: per level, the mass term and the edge weights.
///
/// Mixed precision: the conjugate gradients (their residual, dot products and updates,
/// and the operator `M` they apply) run in `f64`, so a solve still reaches an `f64`
/// tolerance; the V-cycle that preconditions them runs in `f32` (its stencils, inverse
/// diagonals, residuals and corrections, rounded once a system in
/// `Hierarchy::prepare`), where an AVX2 instruction takes eight cells, not four, and a
/// sweep streams half the bytes. Why that is safe: conjugate gradients need of their
/// preconditioner only a fixed symmetric positive definite map `r ↦ z`, and they take as
/// few iterations as that map is close to `M⁻¹`. The `f32` V-cycle does the same
/// operations in the same order on every call (a fixed map, symmetric as the `f64` one
/// was, up to rounding), and its rounding, about 1e-7 of each value, is far below its
/// own error as an inverse (5–7 iterations to 1e-6 put that near a tenth a cycle), so
/// the iterations do not rise (`film_profile` prints the same counts as the `f64`
/// V-cycle did). `x` and the residual the tolerance is judged on are updated in `f64`
/// from the same `f64` direction and its `f64` product with `M`, so the answer's
/// accuracy does not depend on the preconditioner's. `f32`'s narrower range is kept
/// away from: the system enters the V-cycle scaled by a power of two that brings the
/// finest level's largest diagonal entry to `[1, 2)`, and each right-hand side by one
/// that brings its norm there (a power of two changes the exponent, not the bits of the
/// rest), so no system or residual underflows or overflows in it.
#[derive(Clone, Debug, Default)]
pub struct Work {
    alpha: Vec<Vec<f64>>,
    weight: Vec<Vec<f64>>,
    /// The coarsest level's Cholesky factor, of the system as scaled for the V-cycle
    /// ([`Work::scale`]), in `f64` (the level is solved in `f64`: its right-hand side
    /// and answer converted, [`Work::coarse_rhs`] and [`Work::coarse_x`]).
    coarse_factor: Vec<f64>,
    coarse_rhs: Vec<f64>,
    coarse_x: Vec<f64>,
    /// Per level but the coarsest (the finest level where it is the coarsest), each cell's
    /// four edge weights in neighbour order in `f64`: the finest level's is the conjugate
    /// gradients' operator, the others what the V-cycle's are rounded from.
    stencil: Vec<Stencil<f64>>,
    /// The power of two the V-cycle's system is scaled by (1 where there is one level).
    scale: f64,
    /// Per level, in `f32` and scaled by [`Work::scale`]: each cell's mass term, inverse
    /// diagonal, and four edge weights in neighbour order (the smoother and the operator
    /// then read one cell's numbers contiguously).
    mass: Vec<Vec<f32>>,
    inv_diag: Vec<Vec<f32>>,
    stencil32: Vec<Stencil<f32>>,
    /// Per level, the V-cycle's right-hand side (on the finest level the conjugate
    /// gradients' residual, scaled and rounded) and its answer.
    residual: Vec<Vec<f32>>,
    /// A level's residual `r − M z` before it is restricted (the finest level's length).
    operator: Vec<f32>,
    correction: Vec<Vec<f32>>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    /// `b`, `x` and the guess in the finest level's numbering.
    b: Vec<f64>,
    x: Vec<f64>,
    guess: Vec<f64>,
}

/// When a solve stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveLimits {
    /// Residual relative to the starting guess's at which it stops.
    pub tolerance: f64,
    /// Most conjugate-gradient iterations.
    pub max_iterations: u32,
}

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveReport {
    /// Conjugate-gradient iterations taken.
    pub iterations: u32,
    /// Final residual norm relative to the starting guess's.
    pub relative_residual: f64,
    /// The residual norm the tolerance is relative to: the starting `x`'s (not the
    /// guess's, where one was taken).
    pub start_residual: f64,
}

impl Hierarchy {
    /// Halves the grid while its face size stays even and above [`COARSEST_FACE`].
    pub fn new(grid: &CubeSphere) -> Self {
        let fine_edges: Vec<(u32, u32)> = grid.edges().iter().map(|e| (e.a, e.b)).collect();
        let mut n = grid.face_size();
        let mut levels = vec![Level::new(grid.cells(), fine_edges)];
        let mut orders = vec![chequered_order(n)];
        while n > coarsest_face(n) {
            let fine = levels.last().expect("one level");
            let parent: Vec<u32> = (0..fine.cells).map(|c| parent_cell(n, c) as u32).collect();
            let (coarse, coarse_edge_of_fine) = coarsen(fine, &parent, 6 * (n / 2) * (n / 2));
            levels.last_mut().expect("one level").coarse_edge_of_fine = coarse_edge_of_fine;
            let mut coarse = coarse;
            coarse.parent_of_fine = parent;
            levels.push(coarse);
            orders.push(chequered_order(n / 2));
            n /= 2;
        }
        let mut levels = renumber(&levels, &orders);
        for k in 1..levels.len() {
            let (fine, coarse) = levels.split_at_mut(k);
            coarse[0].link_to_fine(&fine[k - 1]);
        }
        let fine_order = orders.swap_remove(0);
        Self { levels, fine_order }
    }

    /// Whether a face size coarsens down to a directly solvable level.
    pub fn supports(face_size: usize) -> bool {
        let n = coarsest_face(face_size);
        n >= 1 && 6 * n * n <= DENSE_CELLS
    }

    /// Solves `(diag(alpha) + L_weight) x = b` into `x`, starting from `x`'s values, until
    /// `limits` say stop.
    ///
    /// # Panics
    /// If a slice's length does not match the finest level.
    pub fn solve(
        &self,
        work: &mut Work,
        alpha: &[f64],
        weight: &[f64],
        b: &[f64],
        x: &mut [f64],
        limits: SolveLimits,
    ) -> SolveReport {
        self.solve_with_guess(work, alpha, weight, b, x, None, limits)
    }

    /// As [`Hierarchy::solve`], the tolerance still relative to the residual of `x`'s
    /// values, but starting from `guess` instead where its residual is smaller: a guess
    /// that anticipates the answer saves iterations without changing when the solve
    /// counts as done.
    ///
    /// # Panics
    /// If a slice's length does not match the finest level.
    #[allow(clippy::too_many_arguments)] // the system's four arrays, its start and limits
    pub fn solve_with_guess(
        &self,
        work: &mut Work,
        alpha: &[f64],
        weight: &[f64],
        b: &[f64],
        x: &mut [f64],
        guess: Option<&[f64]>,
        limits: SolveLimits,
    ) -> SolveReport {
        self.prepare(work, alpha, weight);
        self.solve_prepared(work, b, x, guess, limits)
    }

    /// As [`Hierarchy::solve_with_guess`] for the system the last solve prepared (same
    /// `alpha` and weights), with a new right-hand side `b`: the restriction to the
    /// coarse levels and the coarsest level's factorisation are not redone.
    ///
    /// # Panics
    /// If a slice's length does not match the finest level, or no solve came before.
    pub fn solve_prepared(
        &self,
        work: &mut Work,
        b: &[f64],
        x: &mut [f64],
        guess: Option<&[f64]>,
        limits: SolveLimits,
    ) -> SolveReport {
        let nc = self.levels[0].cells;
        assert!(b.len() == nc && x.len() == nc, "system size mismatch");
        assert!(!work.stencil.is_empty(), "no system prepared");
        let order = &self.fine_order;
        let (mut bo, mut xo, mut go) = (
            std::mem::take(&mut work.b),
            std::mem::take(&mut work.x),
            std::mem::take(&mut work.guess),
        );
        gather(order, b, &mut bo);
        gather(order, x, &mut xo);
        let guess = guess.filter(|g| g.len() == nc).map(|g| {
            gather(order, g, &mut go);
            go.as_slice()
        });
        let report = self.solve_ordered(work, &bo, &mut xo, guess, limits);
        for (&cell, v) in order.iter().zip(&xo) {
            x[cell as usize] = *v;
        }
        (work.b, work.x, work.guess) = (bo, xo, go);
        report
    }

    /// The solve in the levels' own (chequered) numbering, compiled for AVX2 where the
    /// processor has it ([`with_avx2`]).
    fn solve_ordered(
        &self,
        work: &mut Work,
        b: &[f64],
        x: &mut [f64],
        guess: Option<&[f64]>,
        limits: SolveLimits,
    ) -> SolveReport {
        with_avx2(
            #[inline(always)]
            || {
                let SolveLimits {
                    tolerance,
                    max_iterations,
                } = limits;
                let fine = &self.levels[0];
                let nc = fine.cells;
                work.r.resize(nc, 0.0);
                work.z.resize(nc, 0.0);
                work.p.resize(nc, 0.0);
                work.q.resize(nc, 0.0);
                let mut r = std::mem::take(&mut work.r);
                let mut z = std::mem::take(&mut work.z);
                let mut p = std::mem::take(&mut work.p);
                let mut q = std::mem::take(&mut work.q);
                residual(fine, &work.alpha[0], &work.stencil[0], x, b, &mut r);
                // Relative to the warm start's residual: the step's change, not the whole field.
                let mut start_norm = dot(&r, &r).sqrt();
                let b_norm = if start_norm > 0.0 { start_norm } else { 1.0 };
                if let Some(guess) = guess.filter(|_| start_norm > 0.0) {
                    residual(fine, &work.alpha[0], &work.stencil[0], guess, b, &mut z);
                    let guess_norm = dot(&z, &z).sqrt();
                    if guess_norm < start_norm {
                        x.copy_from_slice(guess);
                        r.copy_from_slice(&z);
                        start_norm = guess_norm;
                    }
                }
                let mut report = SolveReport {
                    iterations: 0,
                    relative_residual: start_norm / b_norm,
                    start_residual: b_norm,
                };
                if report.relative_residual > tolerance {
                    self.precondition(work, &r, start_norm, &mut z);
                    p.copy_from_slice(&z);
                    let mut rz = dot(&r, &z);
                    while report.iterations < max_iterations {
                        apply(fine, &work.alpha[0], &work.stencil[0], &p, &mut q);
                        let pq = dot(&p, &q);
                        if pq <= 0.0 || !pq.is_finite() {
                            break;
                        }
                        let step = rz / pq;
                        let rr = update_and_norm2(step, &p, &q, x, &mut r);
                        report.iterations += 1;
                        report.relative_residual = rr.sqrt() / b_norm;
                        if report.relative_residual <= tolerance {
                            break;
                        }
                        self.precondition(work, &r, rr.sqrt(), &mut z);
                        let rz_next = dot(&r, &z);
                        let beta = rz_next / rz;
                        rz = rz_next;
                        for i in 0..nc {
                            p[i] = z[i] + beta * p[i];
                        }
                    }
                }
                (work.r, work.z, work.p, work.q) = (r, z, p, q);
                report
            },
        )
    }

    /// Restricts the system's numbers to every level, and rounds them to `f32` for the
    /// V-cycle (see [`Work`]).
    fn prepare(&self, work: &mut Work, alpha: &[f64], weight: &[f64]) {
        with_avx2(
            #[inline(always)]
            || self.prepare_here(work, alpha, weight),
        );
    }

    /// [`Hierarchy::prepare`]'s work, inlined into the AVX2 build where there is one.
    #[inline(always)]
    fn prepare_here(&self, work: &mut Work, alpha: &[f64], weight: &[f64]) {
        let count = self.levels.len();
        work.alpha.resize(count, Vec::new());
        // `work.weight[0]` stays unused: the finest level's weights are `weight` itself
        // (a copy of them was a 0.4 MB memcpy a step at n = 64).
        work.weight.resize(count, Vec::new());
        work.residual.resize(count, Vec::new());
        work.correction.resize(count, Vec::new());
        gather(&self.fine_order, alpha, &mut work.alpha[0]);
        for k in 1..count {
            let coarse = &self.levels[k];
            let (done, rest) = work.alpha.split_at_mut(k);
            restrict(&coarse.child_runs, &done[k - 1], &mut rest[0]);
            let (done, rest) = work.weight.split_at_mut(k);
            let fine_weight = if k == 1 { weight } else { &done[k - 1] };
            restrict_weights(&coarse.fine_edges, fine_weight, &mut rest[0]);
        }
        // Each level's stencil in `f64` (the finest level's is the conjugate gradients'
        // operator), then the V-cycle's numbers rounded from it, array by array.
        let smoothed = count.saturating_sub(1).max(1);
        work.stencil.resize(smoothed, Stencil::default());
        for (k, level) in self.levels[..smoothed].iter().enumerate() {
            let weight = if k == 0 { weight } else { &work.weight[k] };
            let [w0, w1, w2, w3] = &mut work.stencil[k];
            for w in [&mut *w0, &mut *w1, &mut *w2, &mut *w3] {
                w.resize(level.cells, 0.0);
            }
            let sides = (w0.iter_mut().zip(w1.iter_mut())).zip(w2.iter_mut().zip(w3.iter_mut()));
            for (((w0, w1), (w2, w3)), es) in sides.zip(&level.neighbour_edges) {
                (*w0, *w1) = (weight[es[0] as usize], weight[es[1] as usize]);
                (*w2, *w3) = (weight[es[2] as usize], weight[es[3] as usize]);
            }
        }
        // One level: the dense solve is the whole preconditioner, in `f64`, unscaled.
        work.scale = if count == 1 {
            1.0
        } else {
            power_of_two_below(largest_diagonal(&work.alpha[0], &work.stencil[0])).recip()
        };
        let scale = work.scale;
        work.mass.resize(count - 1, Vec::new());
        work.inv_diag.resize(count - 1, Vec::new());
        work.stencil32.resize(count - 1, Stencil::default());
        for k in 0..count - 1 {
            let (alpha, stencil) = (&work.alpha[k], &work.stencil[k]);
            for (w32, w) in work.stencil32[k].iter_mut().zip(stencil) {
                rounded(scale, w, w32);
            }
            rounded(scale, alpha, &mut work.mass[k]);
            // The diagonal summed in `f64` from the unrounded numbers, then rounded once.
            let inv_diag = &mut work.inv_diag[k];
            inv_diag.resize(alpha.len(), 0.0);
            let [w0, w1, w2, w3] = stencil;
            let sides = w0.iter().zip(w1).zip(w2.iter().zip(w3));
            for (d, (((w0, w1), (w2, w3)), a)) in inv_diag.iter_mut().zip(sides.zip(alpha)) {
                *d = (1.0 / (scale * (a + w0 + w1 + w2 + w3))) as f32;
            }
        }
        let last = count - 1;
        let weight = if last == 0 {
            weight
        } else {
            &work.weight[last]
        };
        let (level, alpha) = (&self.levels[last], &work.alpha[last]);
        dense_cholesky(level, alpha, weight, scale, &mut work.coarse_factor);
    }

    /// `z` = the preconditioner applied to the conjugate gradients' residual `r`, whose
    /// norm is `norm`: one V-cycle in `f32` (see [`Work`]), or the dense solve where the
    /// finest level is the coarsest.
    #[inline(always)]
    fn precondition(&self, work: &mut Work, r: &[f64], norm: f64, z: &mut [f64]) {
        let cells = self.levels[0].cells;
        if self.levels.len() == 1 {
            dense_solve(&work.coarse_factor, cells, r, z);
            return;
        }
        // `M' = scale·M` is the system the V-cycle holds and `r' = to·r` its right-hand
        // side, so `M⁻¹ r = (scale / to)·M'⁻¹ r'`; each factor a power of two, exact.
        let to = power_of_two_below(norm).recip();
        let back = work.scale / to;
        let mut r32 = std::mem::take(&mut work.residual[0]);
        rounded(to, r, &mut r32);
        let mut z32 = std::mem::take(&mut work.correction[0]);
        z32.resize(cells, 0.0);
        self.v_cycle(work, 0, &r32, &mut z32);
        for (zi, v) in z.iter_mut().zip(&z32) {
            *zi = back * f64::from(*v);
        }
        work.residual[0] = r32;
        work.correction[0] = z32;
    }

    /// One symmetric V-cycle on level `k` for residual `r`, result in `z`, in `f32`.
    fn v_cycle(&self, work: &mut Work, k: usize, r: &[f32], z: &mut [f32]) {
        with_avx2(
            #[inline(always)]
            || {
                // `z` is not zeroed: the dense solve writes every cell before it reads it,
                // and the first sweep reads only the cells it has updated (as from zero).
                let level = &self.levels[k];
                if k + 1 == self.levels.len() {
                    let (mut rc, mut zc) = (
                        std::mem::take(&mut work.coarse_rhs),
                        std::mem::take(&mut work.coarse_x),
                    );
                    rc.resize(level.cells, 0.0);
                    for (v, &ri) in rc.iter_mut().zip(r) {
                        *v = f64::from(ri);
                    }
                    zc.resize(level.cells, 0.0);
                    dense_solve(&work.coarse_factor, level.cells, &rc, &mut zc);
                    for (zi, v) in z.iter_mut().zip(&zc) {
                        *zi = *v as f32;
                    }
                    (work.coarse_rhs, work.coarse_x) = (rc, zc);
                    return;
                }
                let (inv_diag, stencil) = (&work.inv_diag[k], &work.stencil32[k]);
                relax_from_zero(level, inv_diag, stencil, r, z);
                gauss_seidel(level, inv_diag, stencil, r, z, false);
                let coarse = &self.levels[k + 1];
                let mut rc = std::mem::take(&mut work.residual[k + 1]);
                rc.resize(coarse.cells, 0.0);
                let mut mz = std::mem::take(&mut work.operator);
                // Kept at the finest level's length and sliced: resized to each level's in
                // turn, it was zeroed again (0.15 MB at n = 64) every V-cycle.
                if mz.len() < level.cells {
                    mz.resize(level.cells, 0.0);
                }
                let d = &mut mz[..level.cells];
                residual(level, &work.mass[k], stencil, z, r, d);
                restrict(&coarse.child_runs, &mz, &mut rc);
                work.operator = mz;
                let mut zc = std::mem::take(&mut work.correction[k + 1]);
                zc.resize(coarse.cells, 0.0);
                self.v_cycle(work, k + 1, &rc, &mut zc);
                correct(&coarse.parent_runs, &zc, z);
                work.residual[k + 1] = rc;
                work.correction[k + 1] = zc;
                let (inv_diag, stencil) = (&work.inv_diag[k], &work.stencil32[k]);
                gauss_seidel(level, inv_diag, stencil, r, z, true);
                gauss_seidel(level, inv_diag, stencil, r, z, true);
            },
        )
    }
}

/// `out = scale·values` rounded to `f32`.
#[inline(always)]
fn rounded(scale: f64, values: &[f64], out: &mut Vec<f32>) {
    out.resize(values.len(), 0.0);
    for (o, v) in out.iter_mut().zip(values) {
        *o = (scale * v) as f32;
    }
}

/// The largest diagonal entry `αᵢ + Σ wᵢⱼ` of a level's matrix (in lanes, each a running
/// maximum, as [`dot`] sums), 0 where there is none above 0.
#[inline(always)]
fn largest_diagonal(alpha: &[f64], [w0, w1, w2, w3]: &Stencil<f64>) -> f64 {
    let mut lanes = [0.0; LANES];
    let n = alpha.len();
    let (w0, w1, w2, w3) = (&w0[..n], &w1[..n], &w2[..n], &w3[..n]);
    for i in (0..n).step_by(LANES) {
        for k in 0..LANES.min(n - i) {
            let d = alpha[i + k] + w0[i + k] + w1[i + k] + w2[i + k] + w3[i + k];
            lanes[k] = if d > lanes[k] { d } else { lanes[k] };
        }
    }
    lanes
        .into_iter()
        .fold(0.0, |m, d| if d > m { d } else { m })
}

/// `2^⌊log₂ x⌋`, `x`'s exponent alone (kept within 2^±1000, so that its reciprocal is a
/// normal number too), or 1 where `x` is not positive and finite: the factors [`Work`]
/// scales the V-cycle's numbers by. From the bits, so that `x·2^k` gives exactly `2^k`
/// times the factor.
fn power_of_two_below(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    f64::from_bits((x.to_bits() >> 52).clamp(1023 - 1000, 1023 + 1000) << 52)
}

impl Level {
    /// # Panics
    /// If a cell does not have exactly [`SIDES`] edges (the level is not a cube-sphere).
    fn new(cells: usize, edges: Vec<(u32, u32)>) -> Self {
        let mut count = vec![0usize; cells];
        let mut neighbours = vec![[0u32; SIDES]; cells];
        let mut neighbour_edges = vec![[0u32; SIDES]; cells];
        for (e, &(a, b)) in edges.iter().enumerate() {
            for (cell, other) in [(a, b), (b, a)] {
                let (cell, k) = (cell as usize, &mut count[cell as usize]);
                assert!(*k < SIDES, "cell {cell} has more than {SIDES} sides");
                neighbours[cell][*k] = other;
                neighbour_edges[cell][*k] = e as u32;
                *k += 1;
            }
        }
        assert!(
            count.iter().all(|&k| k == SIDES),
            "a cell has under {SIDES} sides"
        );
        for (nb, es) in neighbours.iter_mut().zip(&mut neighbour_edges) {
            let mut pairs = [0; SIDES].map(|_| (0u32, 0u32));
            for k in 0..SIDES {
                pairs[k] = (nb[k], es[k]);
            }
            pairs.sort_unstable();
            *nb = pairs.map(|(n, _)| n);
            *es = pairs.map(|(_, e)| e);
        }
        Self {
            cells,
            edges,
            segments: segments(&neighbours),
            read_before_update: read_before_update(&neighbours),
            neighbours,
            neighbour_edges,
            parent_of_fine: Vec::new(),
            child_runs: Vec::new(),
            parent_runs: Vec::new(),
            fine_edges: Vec::new(),
            coarse_edge_of_fine: Vec::new(),
        }
    }

    /// Fills [`Level::child_runs`], [`Level::parent_runs`] and [`Level::fine_edges`] of
    /// this (coarse) level from its `parent_of_fine` and the finer level's
    /// `read_before_update` and `coarse_edge_of_fine`.
    ///
    /// # Panics
    /// If a cell does not have four children or an edge two fine edges (not a halving).
    fn link_to_fine(&mut self, fine: &Level) {
        let mut children = vec![Vec::with_capacity(4); self.cells];
        for (c, &parent) in self.parent_of_fine.iter().enumerate() {
            children[parent as usize].push(c as u32);
        }
        let mut fine_edges = vec![Vec::with_capacity(2); self.edges.len()];
        for (e, &coarse) in fine.coarse_edge_of_fine.iter().enumerate() {
            if coarse != u32::MAX {
                fine_edges[coarse as usize].push(e as u32);
            }
        }
        let children: Vec<[u32; 4]> = children
            .into_iter()
            .map(|c| c.try_into().expect("4 children"))
            .collect();
        self.child_runs = child_runs(&children);
        self.parent_runs = parent_runs(&self.parent_of_fine, &fine.read_before_update);
        self.fine_edges = fine_edges
            .into_iter()
            .map(|e| e.try_into().expect("2 fine edges"))
            .collect();
    }
}

/// The cells of a grid of face size `n`, those with `x + y` even on their face first, then
/// the odd ones: the levels' numbering, and so the order Gauss–Seidel visits them in.
/// Within a face an even cell's neighbours are all odd, so a sweep's consecutive updates
/// do not wait on one another (the core overlaps them, where the lexicographic order
/// chained every cell on the one before); only the cells along the cube's seams see a
/// same-coloured neighbour, which Gauss–Seidel in any fixed order allows.
fn chequered_order(n: usize) -> Vec<u32> {
    let cells = (0..6 * n * n).map(|c| c as u32);
    let colour = |&c: &u32| (c as usize % n + (c as usize / n) % n) % 2;
    let even = cells.clone().filter(|c| colour(c) == 0);
    even.chain(cells.filter(|c| colour(c) == 1)).collect()
}

fn coarsen(fine: &Level, parent: &[u32], coarse_cells: usize) -> (Level, Vec<u32>) {
    let mut index = std::collections::HashMap::new();
    let mut edges = Vec::new();
    let map = fine
        .edges
        .iter()
        .map(|&(a, b)| {
            let (pa, pb) = (parent[a as usize], parent[b as usize]);
            if pa == pb {
                return u32::MAX;
            }
            *index.entry((pa.min(pb), pa.max(pb))).or_insert_with(|| {
                edges.push((pa.min(pb), pa.max(pb)));
                (edges.len() - 1) as u32
            })
        })
        .collect();
    (Level::new(coarse_cells, edges), map)
}

/// `out = (diag(alpha) + L_w) x`, as `αᵢxᵢ + Σ w (xᵢ − xⱼ)`: the differences keep the
/// result accurate where the weights dwarf `α` and `x` is nearly uniform (a stiff step's
/// surfactant), which `diag·xᵢ − Σ w xⱼ` would lose to cancellation.
#[inline(always)]
fn apply<T: Real>(level: &Level, alpha: &[T], stencil: &Stencil<T>, x: &[T], out: &mut [T]) {
    operator::<T, false>(Cut::new(level, alpha, stencil, x), x, out);
}

/// `out = r − (diag(alpha) + L_w) x`: [`apply`]'s sums, each taken from `r` in the same
/// pass (apply and then a subtraction read `M x` back from memory).
#[inline(always)]
fn residual<T: Real>(
    level: &Level,
    alpha: &[T],
    stencil: &Stencil<T>,
    x: &[T],
    r: &[T],
    out: &mut [T],
) {
    operator::<T, true>(Cut::new(level, alpha, stencil, r), x, out);
}

/// A level's numbers as a sweep or the operator reads them, each array cut to the
/// level's length once: a run's slices of them then share one bounds check, and a
/// single cell's reads need none past its segment's (read through the level's `Vec`s,
/// every run re-read their lengths from memory and checked each slice apart: about 80
/// instructions a run).
#[derive(Clone, Copy)]
struct Cut<'a, T> {
    level: &'a Level,
    /// The inverse diagonal (a sweep) or the mass term (the operator).
    diag: &'a [T],
    w: [&'a [T]; SIDES],
    /// The right-hand side (unread by [`apply`]).
    r: &'a [T],
    neighbours: &'a [[u32; SIDES]],
}

impl<'a, T: Real> Cut<'a, T> {
    #[inline(always)]
    fn new(level: &'a Level, diag: &'a [T], stencil: &'a Stencil<T>, r: &'a [T]) -> Self {
        let n = level.cells;
        Self {
            level,
            diag: &diag[..n],
            w: [
                &stencil[0][..n],
                &stencil[1][..n],
                &stencil[2][..n],
                &stencil[3][..n],
            ],
            r: &r[..n],
            neighbours: &level.neighbours[..n],
        }
    }

    /// The cells of `run` of each side's weights.
    #[inline(always)]
    fn weights(&self, run: std::ops::Range<usize>) -> [&'a [T]; SIDES] {
        [
            &self.w[0][run.clone()],
            &self.w[1][run.clone()],
            &self.w[2][run.clone()],
            &self.w[3][run],
        ]
    }
}

/// [`apply`] (`RESIDUAL` false: `r` unread) or [`residual`] (true).
#[inline(always)]
fn operator<T: Real, const RESIDUAL: bool>(s: Cut<'_, T>, x: &[T], out: &mut [T]) {
    let n = s.level.cells;
    let (x, out) = (&x[..n], &mut out[..n]);
    for segment in &s.level.segments {
        match *segment {
            Segment::Cells { start, end } => {
                assert!(start <= end && end <= n, "segment past the level");
                for i in start..end {
                    let (xi, nb) = (x[i], &s.neighbours[i]);
                    let mut sum = s.diag[i] * xi;
                    for k in 0..SIDES {
                        sum += s.w[k][i] * (xi - x[nb[k] as usize]);
                    }
                    out[i] = if RESIDUAL { s.r[i] - sum } else { sum };
                }
            }
            Segment::Run { start, end, from } => {
                let (run, len) = (start..end, end - start);
                let mut chunk = OperatorRun::<T, RESIDUAL> {
                    near: [
                        &x[from[0]..][..len],
                        &x[from[1]..][..len],
                        &x[from[2]..][..len],
                        &x[from[3]..][..len],
                    ],
                    w: s.weights(run.clone()),
                    alpha: &s.diag[run.clone()],
                    x: &x[run.clone()],
                    r: &s.r[run.clone()],
                    out: &mut out[run],
                };
                in_chunks(len, &mut chunk);
            }
        }
    }
}

/// [`operator`] on a [`Segment::Run`], the same sums read as slices: the neighbours'
/// values a side, the weights a side, the run's own mass terms, values and right-hand
/// side (unread unless `RESIDUAL`), and where the sums go.
struct OperatorRun<'a, T, const RESIDUAL: bool> {
    near: [&'a [T]; SIDES],
    w: [&'a [T]; SIDES],
    alpha: &'a [T],
    x: &'a [T],
    r: &'a [T],
    out: &'a mut [T],
}

impl<T: Real, const RESIDUAL: bool> Chunked for OperatorRun<'_, T, RESIDUAL> {
    #[inline(always)]
    fn lanes<const N: usize>(&mut self, i: usize) {
        let (near, w) = (sides::<T, N>(&self.near, i), sides::<T, N>(&self.w, i));
        let (a, xs) = (lanes::<T, N>(self.alpha, i), lanes::<T, N>(self.x, i));
        // Into an array first, then stored: every load before any store (the compiler
        // cannot tell `out` from the inputs, and left lanes stored one by one unvectorised).
        let mut sums = [T::ZERO; N];
        for j in 0..N {
            let xi = xs[j];
            let mut sum = a[j] * xi;
            sum += w[0][j] * (xi - near[0][j]);
            sum += w[1][j] * (xi - near[1][j]);
            sum += w[2][j] * (xi - near[2][j]);
            sum += w[3][j] * (xi - near[3][j]);
            sums[j] = sum;
        }
        if RESIDUAL {
            let r = lanes::<T, N>(self.r, i);
            for j in 0..N {
                sums[j] = r[j] - sums[j];
            }
        }
        self.out[i..][..N].copy_from_slice(&sums);
    }
}

/// A computation over a run's cells `0..len`, each cell's result from numbers that the
/// computation does not write ([`Segment::Run`]'s cells do not read one another): cells
/// `i..i + N` at once in [`Chunked::lanes`].
trait Chunked {
    fn lanes<const N: usize>(&mut self, i: usize);
}

/// Lanes a run's chunk takes: two AVX2 instructions of `f64`, one of `f32`.
const CHUNK: usize = 8;

/// Runs `c` over cells `0..len` in chunks of [`CHUNK`] lanes (of 4 for a run shorter
/// than that), the last chunk ending at `len` and overlapping the one before where `len`
/// is not a multiple: those cells computed twice from the same numbers, so the same
/// bits, and no cell left to a one-lane loop after the vector one (the runs are 31, 15
/// and 7 cells long at n = 64: with the compiler's own vector loop, an `f32` run's
/// leftover cells, one lane at a time, cost more than its vector part).
#[inline(always)]
fn in_chunks(len: usize, c: &mut impl Chunked) {
    #[inline(always)]
    fn by<const N: usize>(len: usize, c: &mut impl Chunked) {
        let mut i = 0;
        while i + N <= len {
            c.lanes::<N>(i);
            i += N;
        }
        if i < len {
            c.lanes::<N>(len - N);
        }
    }
    if len >= CHUNK {
        by::<CHUNK>(len, c);
    } else if len >= 4 {
        by::<4>(len, c);
    } else {
        by::<1>(len, c);
    }
}

/// [`lanes`] of each side's slice (written out: `map` with a closure was kept out of
/// line, unvectorised and not compiled for AVX2).
#[inline(always)]
fn sides<'a, T: Real, const N: usize>(s: &[&'a [T]; SIDES], i: usize) -> [&'a [T; N]; SIDES] {
    [
        lanes(s[0], i),
        lanes(s[1], i),
        lanes(s[2], i),
        lanes(s[3], i),
    ]
}

/// `s[i..i + N]` as an array (its lanes indexed without bounds checks).
#[inline(always)]
fn lanes<T: Real, const N: usize>(s: &[T], i: usize) -> &[T; N] {
    s[i..][..N].try_into().expect("N lanes")
}

/// One Gauss–Seidel sweep of `M z = r`, forwards or backwards through the level's
/// (chequered) numbering.
#[inline(always)]
fn gauss_seidel<T: Real>(
    level: &Level,
    inv_diag: &[T],
    stencil: &Stencil<T>,
    r: &[T],
    z: &mut [T],
    back: bool,
) {
    // Plain loops, no closures: what is inlined here is compiled for AVX2 in a solve
    // that runs so (`with_avx2`); a closure the compiler keeps out of line is not.
    let s = Cut::new(level, inv_diag, stencil, r);
    let z = &mut z[..level.cells];
    if back {
        for segment in level.segments.iter().rev() {
            relax_segment(s, segment, z, back);
        }
    } else {
        for segment in &level.segments {
            relax_segment(s, segment, z, back);
        }
    }
}

/// The first forward Gauss–Seidel sweep of a V-cycle, as [`gauss_seidel`] from `z = 0`
/// but with whatever `z` holds left unread: each cell reads the neighbours the sweep has
/// updated (those before it) and takes zero for the rest, so the V-cycle need not zero
/// `z` first. A zero neighbour still multiplies its weight: the same operations, so the
/// same bits, as the sweep over a zeroed `z`.
#[inline(always)]
fn relax_from_zero<T: Real>(
    level: &Level,
    inv_diag: &[T],
    stencil: &Stencil<T>,
    r: &[T],
    z: &mut [T],
) {
    let s = Cut::new(level, inv_diag, stencil, r);
    let n = level.cells;
    let z = &mut z[..n];
    for segment in &level.segments {
        match *segment {
            Segment::Cells { start, end } => {
                assert!(start <= end && end <= n, "segment past the level");
                for i in start..end {
                    let nb = &s.neighbours[i];
                    let (z0, z1) = (swept(z, nb[0], i), swept(z, nb[1], i));
                    let (z2, z3) = (swept(z, nb[2], i), swept(z, nb[3], i));
                    let near = s.w[0][i] * z0 + s.w[1][i] * z1;
                    let far = s.w[2][i] * z2 + s.w[3][i] * z3;
                    z[i] = (s.r[i] + near + far) * s.diag[i];
                }
            }
            // A run whose neighbours all come after it: all zero, so none is read.
            Segment::Run { start, end, from } if from[0] > start => {
                let run = start..end;
                let mut chunk = RelaxRun {
                    near: None,
                    w: s.weights(run.clone()),
                    inv_diag: &s.diag[run.clone()],
                    r: &s.r[run.clone()],
                    cells: &mut z[run],
                };
                in_chunks(end - start, &mut chunk);
            }
            Segment::Run { start, end, from } => relax_run(s, start..end, from, z),
        }
    }
}

/// Cell `j`'s value in a sweep from zero that has reached cell `i`: updated if before it.
#[inline(always)]
fn swept<T: Real>(z: &[T], j: u32, i: usize) -> T {
    let j = j as usize;
    if j < i { z[j] } else { T::ZERO }
}

/// Gauss–Seidel's update of one segment, its single cells in the sweep's direction.
#[inline(always)]
fn relax_segment<T: Real>(s: Cut<'_, T>, segment: &Segment, z: &mut [T], back: bool) {
    match *segment {
        Segment::Cells { start, end } => {
            assert!(start <= end && end <= z.len(), "segment past the level");
            if back {
                for i in (start..end).rev() {
                    relax_cell(s, i, z);
                }
            } else {
                for i in start..end {
                    relax_cell(s, i, z);
                }
            }
        }
        Segment::Run { start, end, from } => relax_run(s, start..end, from, z),
    }
}

/// Gauss–Seidel's update of cell `i` alone.
#[inline(always)]
fn relax_cell<T: Real>(s: Cut<'_, T>, i: usize, z: &mut [T]) {
    let nb = &s.neighbours[i];
    let near = s.w[0][i] * z[nb[0] as usize] + s.w[1][i] * z[nb[1] as usize];
    let far = s.w[2][i] * z[nb[2] as usize] + s.w[3][i] * z[nb[3] as usize];
    z[i] = (s.r[i] + near + far) * s.diag[i];
}

/// Gauss–Seidel's update of a [`Segment::Run`]: no cell of it reads another, so the
/// order within it does not matter (either sweep direction gives the same numbers) and
/// it is computed as slices, in chunks of lanes ([`in_chunks`]). Its neighbours all lie
/// after it or all before it ([`segments`] takes no other), so `z` splits into the run
/// and the cells it reads.
#[inline(always)]
fn relax_run<T: Real>(
    s: Cut<'_, T>,
    run: std::ops::Range<usize>,
    from: [usize; SIDES],
    z: &mut [T],
) {
    let len = run.len();
    let (cells, others, base) = if from[0] > run.start {
        let (lo, hi) = z.split_at_mut(run.end);
        (&mut lo[run.start..], &*hi, run.end)
    } else {
        let (lo, hi) = z.split_at_mut(run.start);
        (hi, &*lo, 0)
    };
    let mut chunk = RelaxRun {
        near: Some([
            &others[from[0] - base..][..len],
            &others[from[1] - base..][..len],
            &others[from[2] - base..][..len],
            &others[from[3] - base..][..len],
        ]),
        w: s.weights(run.clone()),
        inv_diag: &s.diag[run.clone()],
        r: &s.r[run],
        cells: &mut cells[..len],
    };
    in_chunks(len, &mut chunk);
}

/// [`relax_run`]'s numbers: the neighbours' values a side (`None`: all zero, as in the
/// first sweep from zero), the weights a side, the run's inverse diagonal and
/// right-hand side, and its cells.
struct RelaxRun<'a, T> {
    near: Option<[&'a [T]; SIDES]>,
    w: [&'a [T]; SIDES],
    inv_diag: &'a [T],
    r: &'a [T],
    cells: &'a mut [T],
}

impl<T: Real> Chunked for RelaxRun<'_, T> {
    #[inline(always)]
    fn lanes<const N: usize>(&mut self, i: usize) {
        let w = sides::<T, N>(&self.w, i);
        let (inv_diag, r) = (lanes::<T, N>(self.inv_diag, i), lanes::<T, N>(self.r, i));
        // Into an array first, then stored (as in `OperatorRun`).
        let mut out = [T::ZERO; N];
        if let Some(near) = self.near {
            let z = sides::<T, N>(&near, i);
            for j in 0..N {
                let near = w[0][j] * z[0][j] + w[1][j] * z[1][j];
                let far = w[2][j] * z[2][j] + w[3][j] * z[3][j];
                out[j] = (r[j] + near + far) * inv_diag[j];
            }
        } else {
            // A zero neighbour still multiplies its weight: the same operations as from a
            // zeroed `z` (see `relax_from_zero`).
            for j in 0..N {
                let near = w[0][j] * T::ZERO + w[1][j] * T::ZERO;
                let far = w[2][j] * T::ZERO + w[3][j] * T::ZERO;
                out[j] = (r[j] + near + far) * inv_diag[j];
            }
        }
        self.cells[i..][..N].copy_from_slice(&out);
    }
}

/// A level's cells as [`Segment`]s: maximal runs of at least [`MIN_RUN`] consecutive
/// cells whose neighbours lie at the same offsets, all after the run or all before it,
/// and the single cells between them.
fn segments(neighbours: &[[u32; SIDES]]) -> Vec<Segment> {
    let offsets = |i: usize| neighbours[i].map(|n| n as isize - i as isize);
    let (cells, mut out, mut loose) = (neighbours.len(), Vec::new(), 0);
    let mut i = 0;
    while i < cells {
        let d = offsets(i);
        let one_side = d.iter().all(|&o| o > 0) || d.iter().all(|&o| o < 0);
        let mut end = i + 1;
        // Grown while every offset reaches past the run, so no cell of it reads another.
        while one_side
            && end < cells
            && offsets(end) == d
            && d.iter().all(|o| o.unsigned_abs() > end - i)
        {
            end += 1;
        }
        if end - i >= MIN_RUN {
            if loose < i {
                out.push(Segment::Cells {
                    start: loose,
                    end: i,
                });
            }
            let from = neighbours[i].map(|n| n as usize);
            out.push(Segment::Run {
                start: i,
                end,
                from,
            });
            loose = end;
        }
        i = end;
    }
    if loose < cells {
        out.push(Segment::Cells {
            start: loose,
            end: cells,
        });
    }
    out
}

/// [`Level::read_before_update`]: maximal ranges of the cells with a neighbour after them.
fn read_before_update(neighbours: &[[u32; SIDES]]) -> Vec<std::ops::Range<usize>> {
    let mut out: Vec<std::ops::Range<usize>> = Vec::new();
    for (i, nb) in neighbours.iter().enumerate() {
        if !nb.iter().any(|&j| j as usize > i) {
            continue;
        }
        match out.last_mut() {
            Some(cells) if cells.end == i => cells.end = i + 1,
            _ => out.push(i..i + 1),
        }
    }
    out
}

/// `out[i] = values[order[i]]`.
#[inline(always)]
fn gather(order: &[u32], values: &[f64], out: &mut Vec<f64>) {
    // Plain loops here and in the restrictions: `extend` with a closure was kept out of
    // line, so not compiled for AVX2 with the rest of the solve.
    out.resize(order.len(), 0.0);
    for (o, &c) in out.iter_mut().zip(order) {
        *o = values[c as usize];
    }
}

/// The levels in the numbering `orders` gives each (`orders[k][new] = old`): cells,
/// edges' ends and the fine-to-coarse parents renumbered, edges kept in their order.
fn renumber(levels: &[Level], orders: &[Vec<u32>]) -> Vec<Level> {
    let inverse = |order: &[u32]| {
        let mut inv = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            inv[old as usize] = new as u32;
        }
        inv
    };
    let inverses: Vec<Vec<u32>> = orders.iter().map(|o| inverse(o)).collect();
    let mut out: Vec<Level> = Vec::with_capacity(levels.len());
    for (k, level) in levels.iter().enumerate() {
        let inv = &inverses[k];
        let edges = level
            .edges
            .iter()
            .map(|&(a, b)| (inv[a as usize], inv[b as usize]));
        let mut renumbered = Level::new(level.cells, edges.collect());
        renumbered.coarse_edge_of_fine = level.coarse_edge_of_fine.clone();
        if k > 0 {
            let fine_inv = &inverses[k - 1];
            renumbered.parent_of_fine = vec![0; level.parent_of_fine.len()];
            for (fine, &parent) in level.parent_of_fine.iter().enumerate() {
                renumbered.parent_of_fine[fine_inv[fine] as usize] = inv[parent as usize];
            }
        }
        out.push(renumbered);
    }
    out
}

/// Lanes of the dot products' partial sums: independent adds the core can overlap (one
/// running sum waits on every add before it), in a fixed order, so results stay the same.
const LANES: usize = 4;

#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; LANES];
    let (a_main, b_main) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail: f64 = a_main
        .remainder()
        .iter()
        .zip(b_main.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in a_main.zip(b_main) {
        for k in 0..LANES {
            lanes[k] += x[k] * y[k];
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// `x += step·p`, `r −= step·q`, and returns `r·r`, summed as [`dot`] sums: each lane's
/// `r` squared as it is made (one pass over `r`, where the dot read it back), `x` in a
/// pass of its own (with both updated in one loop the compiler could not tell them
/// apart and kept it scalar).
#[inline(always)]
fn update_and_norm2(step: f64, p: &[f64], q: &[f64], x: &mut [f64], r: &mut [f64]) -> f64 {
    for (xi, pi) in x.iter_mut().zip(p) {
        *xi += step * pi;
    }
    let main = r.len() - r.len() % LANES;
    let (r, r_tail) = r.split_at_mut(main);
    let (q, q_tail) = q.split_at(main);
    let mut lanes = [0.0; LANES];
    for (rs, qs) in r.chunks_exact_mut(LANES).zip(q.chunks_exact(LANES)) {
        let next: [f64; LANES] = std::array::from_fn(|k| rs[k] - step * qs[k]);
        rs.copy_from_slice(&next);
        for k in 0..LANES {
            lanes[k] += next[k] * next[k];
        }
    }
    for (ri, qi) in r_tail.iter_mut().zip(q_tail) {
        *ri -= step * qi;
    }
    let tail: f64 = r_tail.iter().zip(r_tail.iter()).map(|(x, y)| x * y).sum();
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// A stretch of coarse cells `start..end` whose `q`-th children are the fine cells
/// `from[q]`, `from[q] + 2`, … (a coarse row's cells, one colour, have every other fine
/// cell of a row of each colour as children).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ChildRun {
    start: usize,
    end: usize,
    from: [usize; 4],
}

/// [`Level::child_runs`] from each coarse cell's children: maximal stretches of stride 2.
fn child_runs(children: &[[u32; 4]]) -> Vec<ChildRun> {
    let mut out = Vec::new();
    let mut c = 0;
    while c < children.len() {
        let from = children[c].map(|f| f as usize);
        let at = |end: usize| from.map(|f| (f + 2 * (end - c)) as u32);
        let mut end = c + 1;
        while end < children.len() && children[end] == at(end) {
            end += 1;
        }
        out.push(ChildRun {
            start: c,
            end,
            from,
        });
        c = end;
    }
    out
}

/// `coarse` = the fine values summed over each coarse cell's children, from zero and in
/// increasing order, as a scatter over the fine cells summed them: the restriction of
/// a level's residual `r − M z` (the equations are area-integrated) and of its mass term.
#[inline(always)]
fn restrict<T: Real>(runs: &[ChildRun], fine: &[T], coarse: &mut Vec<T>) {
    coarse.resize(runs.last().map_or(0, |r| r.end), T::ZERO);
    for run in runs {
        let len = run.end - run.start;
        let (a, b) = (
            every_other(fine, run.from[0], len),
            every_other(fine, run.from[1], len),
        );
        let (c, d) = (
            every_other(fine, run.from[2], len),
            every_other(fine, run.from[3], len),
        );
        let children = a.zip(b).zip(c.zip(d));
        for (v, ((a, b), (c, d))) in coarse[run.start..run.end].iter_mut().zip(children) {
            *v = T::ZERO + *a + *b + *c + *d;
        }
    }
}

/// `values[from]`, `values[from + 2]`, … , `len` of them.
#[inline(always)]
fn every_other<T>(
    values: &[T],
    from: usize,
    len: usize,
) -> std::iter::StepBy<std::slice::Iter<'_, T>> {
    values[from..][..2 * len - 1].iter().step_by(2)
}

/// A stretch of fine cells `start..end` whose parents are the coarse cells `from[0]`,
/// `from[1]`, `from[0] + 1`, `from[1] + 1`, … in turn (a fine row's cells of one colour
/// alternate between the coarse colours, each in order).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ParentRun {
    start: usize,
    end: usize,
    from: [usize; 2],
}

/// [`Level::parent_runs`]: the fine cells `cells` cut into maximal [`ParentRun`]s.
fn parent_runs(parent: &[u32], cells: &[std::ops::Range<usize>]) -> Vec<ParentRun> {
    let mut out = Vec::new();
    for range in cells.iter().cloned() {
        let mut i = range.start;
        while i < range.end {
            let from = [
                parent[i] as usize,
                parent[(i + 1).min(range.end - 1)] as usize,
            ];
            let mut end = i + 1;
            while end < range.end && parent[end] as usize == from[(end - i) % 2] + (end - i) / 2 {
                end += 1;
            }
            out.push(ParentRun {
                start: i,
                end,
                from,
            });
            i = end;
        }
    }
    out
}

/// `z += zc` at each [`ParentRun`]'s cells from their parents: the V-cycle's coarse
/// correction, where a backward sweep reads it.
#[inline(always)]
fn correct(runs: &[ParentRun], zc: &[f32], z: &mut [f32]) {
    for run in runs {
        let n = (run.end - run.start) / 2;
        let (even, odd) = (&zc[run.from[0]..][..n], &zc[run.from[1]..][..n]);
        let mut pairs = z[run.start..run.end].chunks_exact_mut(2);
        for (pair, (a, b)) in (&mut pairs).zip(even.iter().zip(odd)) {
            let pair: &mut [f32; 2] = pair.try_into().expect("a pair");
            *pair = [pair[0] + *a, pair[1] + *b];
        }
        if let Some(zi) = pairs.into_remainder().first_mut() {
            *zi += zc[run.from[0] + n];
        }
    }
}

/// The edge weights of a coarse level: half the sum of the two fine edges' along each
/// (see the module's documentation), summed from zero in increasing order.
#[inline(always)]
fn restrict_weights(fine_edges: &[[u32; 2]], fine: &[f64], coarse: &mut Vec<f64>) {
    coarse.resize(fine_edges.len(), 0.0);
    for (v, &[e, f]) in coarse.iter_mut().zip(fine_edges) {
        *v = 0.0 + 0.5 * fine[e as usize] + 0.5 * fine[f as usize];
    }
}

/// The lower Cholesky factor of the coarsest level's matrix, column-major (`m[k·n + i]`
/// = `L[i][k]`), into `m` (a buffer kept from step to step: a fresh 74 kB one each step
/// was a malloc and free).
///
/// Column by column, each earlier column's part taken off all the rows at once: every
/// entry is the same sum in the same order as row by row, but where row by row each
/// entry was one chain of dependent subtractions (the core waiting on each), a column's
/// rows are independent lanes the compiler vectorises.
#[inline(always)]
fn dense_cholesky(level: &Level, alpha: &[f64], weight: &[f64], scale: f64, m: &mut Vec<f64>) {
    let n = level.cells;
    m.clear();
    m.resize(n * n, 0.0);
    // The matrix is symmetric: column-major is the same as row-major.
    for i in 0..n {
        m[i * n + i] = scale * alpha[i];
    }
    for (&(a, b), w) in level.edges.iter().zip(weight) {
        let (a, b, w) = (a as usize, b as usize, scale * w);
        m[a * n + a] += w;
        m[b * n + b] += w;
        m[a * n + b] -= w;
        m[b * n + a] -= w;
    }
    for j in 0..n {
        let (done, rest) = m.split_at_mut(j * n);
        let column = &mut rest[j..n];
        for k in 0..j {
            let earlier = &done[k * n + j..][..n - j];
            let c = earlier[0];
            for (s, l) in column.iter_mut().zip(earlier) {
                *s -= l * c;
            }
        }
        let d = column[0].max(f64::MIN_POSITIVE).sqrt();
        column[0] = d;
        for s in &mut column[1..] {
            *s /= d;
        }
    }
}

/// Solves `L Lᵀ x = b` with [`dense_cholesky`]'s column-major factor `l`: forwards a
/// column at a time (each `x[i]` the same sum in the same order as row by row, the rows
/// independent lanes), backwards a row of `Lᵀ` (a column of `L`, contiguous) at a time.
#[inline(always)]
fn dense_solve(l: &[f64], n: usize, b: &[f64], x: &mut [f64]) {
    let (l, x) = (&l[..n * n], &mut x[..n]);
    x.copy_from_slice(&b[..n]);
    for k in 0..n {
        let column = &l[k * n + k..][..n - k];
        let (solved, rest) = x.split_at_mut(k + 1);
        let xk = solved[k] / column[0];
        solved[k] = xk;
        for (s, lik) in rest.iter_mut().zip(&column[1..]) {
            *s -= lik * xk;
        }
    }
    for i in (0..n).rev() {
        let column = &l[i * n + i..][..n - i];
        let (head, solved) = x.split_at_mut(i + 1);
        let mut s = head[i];
        for (lki, xk) in column[1..].iter().zip(solved.iter()) {
            s -= lki * xk;
        }
        head[i] = s / column[0];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(diag(alpha) + L_w) x` in the grid's own numbering, straight from its edges.
    fn grid_apply(grid: &CubeSphere, alpha: &[f64], weight: &[f64], x: &[f64]) -> Vec<f64> {
        let mut out: Vec<f64> = alpha.iter().zip(x).map(|(a, v)| a * v).collect();
        for (e, w) in grid.edges().iter().zip(weight) {
            let (a, b) = (e.a as usize, e.b as usize);
            out[a] += w * (x[a] - x[b]);
            out[b] -= w * (x[a] - x[b]);
        }
        out
    }

    /// Edge weights 10⁴× the mass term on `grid` of `n` cells a side, as a frame's
    /// Marangoni step gives.
    fn stiff_weights(grid: &CubeSphere, n: usize) -> Vec<f64> {
        grid.edges()
            .iter()
            .map(|e| 1e4 * e.length / e.dual_length / (n * n) as f64)
            .collect()
    }

    /// The stiff test system at `n` cells a face: the grid, its hierarchy, the mass
    /// term, the weights (10⁴× the mass term, as a frame's Marangoni step gives) and the
    /// right-hand side `rhs(centre) · area`.
    fn stiff_system(
        n: usize,
        rhs: impl Fn(glam::DVec3) -> f64,
    ) -> (CubeSphere, Hierarchy, Vec<f64>, Vec<f64>, Vec<f64>) {
        let grid = CubeSphere::new(n);
        let h = Hierarchy::new(&grid);
        let alpha = grid.areas_sr().to_vec();
        let weight = stiff_weights(&grid, n);
        let b = grid
            .centres()
            .iter()
            .zip(&alpha)
            .map(|(c, a)| a * rhs(*c))
            .collect();
        (grid, h, alpha, weight, b)
    }

    /// A stiff system solved on this thread with or without AVX2 (`portable`), to a
    /// loose tolerance so that it iterates.
    fn solve_on_this_thread(n: usize, portable: bool) -> (Vec<f64>, SolveReport) {
        crate::avx2::set_portable_only(portable);
        let (grid, h, alpha, weight, b) = stiff_system(n, |c| (2.0 * c.x - c.y * c.z).sin());
        let mut x = vec![0.0; grid.cells()];
        let limits = SolveLimits {
            tolerance: 1e-9,
            max_iterations: 50,
        };
        let report = h.solve(&mut Work::default(), &alpha, &weight, &b, &mut x, limits);
        crate::avx2::set_portable_only(false);
        (x, report)
    }

    /// The `f32` V-cycle and the `f64` conjugate gradients alike: at n = 8 (single cells
    /// only), 32 and 64 (runs of 15 and 7 cells, and of 31).
    #[test]
    fn the_avx2_solve_gives_the_portable_solves_bits() {
        for n in [8, 32, 64] {
            let (fast, fast_report) = solve_on_this_thread(n, false);
            let (plain, plain_report) = solve_on_this_thread(n, true);
            assert_eq!(fast_report, plain_report, "n {n}");
            let differ = fast
                .iter()
                .zip(&plain)
                .filter(|(a, b)| a.to_bits() != b.to_bits());
            assert_eq!(differ.count(), 0, "n {n}: cells differ");
            assert!(fast_report.iterations >= 2, "n {n}: {fast_report:?}");
        }
    }

    /// A stiff system (weights 10⁴× the mass term, as a frame's Marangoni step gives)
    /// converges to 1e-12 from zero in at most 20 iterations at n = 16 and 64 alike (the
    /// multigrid preconditioner keeps the count from growing with the grid), and the
    /// answer satisfies the system: the `f32` V-cycle does not keep the `f64` iterations
    /// from a tolerance far below `f32`'s rounding. n = 4 is one level, solved densely.
    #[test]
    fn stiff_system_converges_in_few_iterations() {
        for n in [4, 16, 64] {
            let (grid, h, alpha, weight, b) = stiff_system(n, |c| (3.0 * c.x * c.y + c.z).exp());
            let mut x = vec![0.0; grid.cells()];
            let mut work = Work::default();
            let limits = SolveLimits {
                tolerance: 1e-12,
                max_iterations: 50,
            };
            let report = h.solve(&mut work, &alpha, &weight, &b, &mut x, limits);
            assert!(report.iterations <= 20, "n {n}: {report:?}");
            let ax = grid_apply(&grid, &alpha, &weight, &x);
            let err = ax
                .iter()
                .zip(&b)
                .map(|(p, q)| (p - q).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(err <= 1e-9 * dot(&b, &b).sqrt(), "n {n}: residual {err}");
        }
    }

    /// The V-cycle's `f32` never meets the system's own scale: a system scaled by 2⁻²⁰⁰ with
    /// a right-hand side scaled by 2¹⁰⁰, and one by 2¹⁵⁰ with 2⁻¹⁵⁰ (each far outside
    /// `f32`'s range, which would underflow or overflow every number), solve in the same
    /// iterations to the same bits, scaled, as the system itself.
    #[test]
    fn systems_far_outside_f32s_range_solve_alike() {
        let n = 16;
        let (grid, h, alpha, weight, b) = stiff_system(n, |c| (2.0 * c.x - c.y * c.z).sin());
        let limits = SolveLimits {
            tolerance: 1e-9,
            max_iterations: 50,
        };
        let solve = |system: f64, rhs: f64| {
            let alpha: Vec<f64> = alpha.iter().map(|a| system * a).collect();
            let weight: Vec<f64> = weight.iter().map(|w| system * w).collect();
            let b: Vec<f64> = b.iter().map(|v| rhs * v).collect();
            let mut x = vec![0.0; grid.cells()];
            let report = h.solve(&mut Work::default(), &alpha, &weight, &b, &mut x, limits);
            (x, report)
        };
        let (x, report) = solve(1.0, 1.0);
        assert!(report.iterations >= 2, "{report:?}");
        for (system, rhs) in [(-200, 100), (150, -150)] {
            let (system, rhs) = (2f64.powi(system), 2f64.powi(rhs));
            let (scaled, scaled_report) = solve(system, rhs);
            assert_eq!(scaled_report.iterations, report.iterations);
            assert_eq!(scaled_report.relative_residual, report.relative_residual);
            let back: Vec<f64> = scaled.iter().map(|v| v * system / rhs).collect();
            assert_eq!(back, x, "system scaled by {system:e}, b by {rhs:e}");
        }
    }

    /// A guess near the answer saves iterations and meets the same residual target as
    /// the plain solve from `x`; a guess worse than `x` is not taken.
    #[test]
    fn a_good_guess_saves_iterations_and_a_bad_one_is_ignored() {
        let n = 16;
        let grid = CubeSphere::new(n);
        let h = Hierarchy::new(&grid);
        let alpha = grid.areas_sr().to_vec();
        let weight = stiff_weights(&grid, n);
        let answer: Vec<f64> = grid
            .centres()
            .iter()
            .map(|c| 1.0 + 0.01 * c.x * c.y)
            .collect();
        let b = grid_apply(&grid, &alpha, &weight, &answer);
        let mut work = Work::default();
        let limits = SolveLimits {
            tolerance: 1e-6,
            max_iterations: 50,
        };
        let start = vec![1.0; grid.cells()];
        let near: Vec<f64> = answer.iter().map(|a| a + 1e-6 * (a - 1.0)).collect();
        let far: Vec<f64> = answer.iter().map(|a| 3.0 * a).collect();
        let solve = |guess: Option<&[f64]>, work: &mut Work| {
            let mut x = start.clone();
            let report = h.solve_with_guess(work, &alpha, &weight, &b, &mut x, guess, limits);
            (report, x)
        };
        let (plain, _) = solve(None, &mut work);
        let (guessed, x) = solve(Some(&near), &mut work);
        let (ignored, _) = solve(Some(&far), &mut work);
        assert!(
            guessed.iterations < plain.iterations,
            "{guessed:?} vs {plain:?}"
        );
        assert!(guessed.relative_residual <= 1e-6, "{guessed:?}");
        assert_eq!(ignored, plain);
        let worst = x
            .iter()
            .zip(&answer)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-8, "error {worst}");
    }

    /// [`runs_relax_and_apply_exactly_as_single_cells_do`] in one precision (`T`, values
    /// made by `real`) on every level but the coarsest of n = 64, whose runs of 31, 15
    /// and 7 cells are several chunks of lanes and a part, one and a part, and two
    /// chunks of 4 overlapping.
    fn relax_and_apply_through_runs<T: Real + std::fmt::Debug>(real: fn(f64) -> T) {
        let h = Hierarchy::new(&CubeSphere::new(64));
        for level in &h.levels[..h.levels.len() - 1] {
            let n = level.cells;
            let value = |i: usize, k: usize| real(1.0 + ((i * 7 + k * 13) % 17) as f64 / 3.0);
            let stencil: Stencil<T> =
                std::array::from_fn(|k| (0..n).map(|i| value(i, k)).collect());
            let inv_diag: Vec<T> = (0..n)
                .map(|i| real(1.0 / (10.0 + 1.0 + ((i * 7 + 65) % 17) as f64 / 3.0)))
                .collect();
            let r: Vec<T> = (0..n).map(|i| value(i, 6) - real(2.0)).collect();
            let mut single = level.clone();
            single.segments = vec![Segment::Cells { start: 0, end: n }];
            let zero = real(0.0);
            let (mut z_runs, mut z_cells) = (vec![zero; n], vec![zero; n]);
            for back in [false, false, true, true] {
                gauss_seidel(level, &inv_diag, &stencil, &r, &mut z_runs, back);
                gauss_seidel(&single, &inv_diag, &stencil, &r, &mut z_cells, back);
                assert_eq!(z_runs, z_cells);
            }
            // The first sweep leaves what `z` held unread: from garbage as from zero.
            let mut from_zero = vec![zero; n];
            gauss_seidel(level, &inv_diag, &stencil, &r, &mut from_zero, false);
            let mut from_garbage = vec![real(f64::NAN); n];
            relax_from_zero(level, &inv_diag, &stencil, &r, &mut from_garbage);
            assert_eq!(from_garbage, from_zero);
            // A backward sweep reads only `read_before_update`'s cells before it updates
            // them: the others' values (the correction skips them) may be anything.
            let mut full = z_runs.clone();
            gauss_seidel(level, &inv_diag, &stencil, &r, &mut full, true);
            let mut skipped = vec![real(f64::NAN); n];
            for cells in level.read_before_update.iter().cloned() {
                skipped[cells.clone()].copy_from_slice(&z_runs[cells]);
            }
            gauss_seidel(level, &inv_diag, &stencil, &r, &mut skipped, true);
            assert_eq!(skipped, full);
            let (mut by_runs, mut by_cells) = (vec![zero; n], vec![zero; n]);
            apply(level, &inv_diag, &stencil, &z_runs, &mut by_runs);
            apply(&single, &inv_diag, &stencil, &z_runs, &mut by_cells);
            assert_eq!(by_runs, by_cells);
            let (mut by_runs, mut by_cells) = (vec![zero; n], vec![zero; n]);
            residual(level, &inv_diag, &stencil, &z_runs, &r, &mut by_runs);
            residual(&single, &inv_diag, &stencil, &z_runs, &r, &mut by_cells);
            assert_eq!(by_runs, by_cells);
        }
    }

    /// Gauss–Seidel sweeps (both ways) and the operator give bit for bit the same numbers
    /// through the runs as cell by cell, the first sweep of a V-cycle the same as a sweep
    /// from zero, a backward sweep the same whatever the cells it does not read first
    /// hold, and the runs cover most of the fine level.
    #[test]
    fn runs_relax_and_apply_exactly_as_single_cells_do() {
        relax_and_apply_through_runs(|v| v);
        relax_and_apply_through_runs(|v| v as f32);
        let h = Hierarchy::new(&CubeSphere::new(16));
        let in_runs: usize = h.levels[0]
            .segments
            .iter()
            .map(|s| match *s {
                Segment::Run { start, end, .. } => end - start,
                Segment::Cells { .. } => 0,
            })
            .sum();
        assert!(
            in_runs * 4 > h.levels[0].cells * 3,
            "{in_runs} cells in runs"
        );
    }

    /// The restriction's and the correction's stretches name every coarse cell's four
    /// children in increasing order, and each read-before-update fine cell's parent.
    #[test]
    fn child_and_parent_runs_match_the_parents() {
        for n in [6, 16, 64] {
            let h = Hierarchy::new(&CubeSphere::new(n));
            for k in 1..h.levels.len() {
                let (fine, coarse) = (&h.levels[k - 1], &h.levels[k]);
                let mut children = vec![Vec::new(); coarse.cells];
                for (c, &p) in coarse.parent_of_fine.iter().enumerate() {
                    children[p as usize].push(c);
                }
                for run in &coarse.child_runs {
                    let cells = children[run.start..run.end].iter().enumerate();
                    for (j, children) in cells {
                        let at = run.from.map(|f| f + 2 * j);
                        assert_eq!(*children, at, "n = {n}, level {k}, cell {}", run.start + j);
                    }
                }
                assert_eq!(coarse.child_runs.last().map(|r| r.end), Some(coarse.cells));
                let mut read = Vec::new();
                for run in &coarse.parent_runs {
                    for i in run.start..run.end {
                        let j = i - run.start;
                        let parent = run.from[j % 2] + j / 2;
                        assert_eq!(coarse.parent_of_fine[i] as usize, parent, "cell {i}");
                        read.push(i);
                    }
                }
                let expected: Vec<usize> =
                    fine.read_before_update.iter().cloned().flatten().collect();
                assert_eq!(read, expected);
            }
        }
    }

    #[test]
    fn supported_face_sizes_coarsen_to_a_small_level() {
        for n in [1, 2, 4, 5, 8, 16, 24, 64, 128, 256, 512] {
            assert!(Hierarchy::supports(n), "{n}");
        }
        for n in [9, 63, 99] {
            assert!(!Hierarchy::supports(n), "{n}");
        }
    }
}

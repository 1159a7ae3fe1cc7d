//! The implicit Marangoni step's linear system, `(diag(α) + L_w) x = b` with `L_w` a
//! weighted graph Laplacian over the cube-sphere's cells: conjugate gradients
//! preconditioned by one symmetric multigrid V-cycle over the grid's halvings.
//!
//! The conjugate gradients run in `f64`, the V-cycle in `f32` (see [`Work`]: a
//! preconditioner need only be a fixed map near `M⁻¹`, and the V-cycle's `f32` rounding
//! is far below its own error as an inverse). Where the weights are given as `f32`
//! values (`Weights::F32`, as the Marangoni step rounds them where it makes them), the
//! V-cycle's finest copy, scaled by a power of two, holds them exactly: the conjugate
//! gradients' `f64` passes read it widened (no `f64` copy of the weights is made), and
//! their last iterations, once the residual is within `F32_FROM_TOLERANCES` tolerances
//! of the goal, run in `f32` but for `x` (`Hierarchy::iterate_in_f32`).
//!
//! Every level is held in a padded, colour-split layout (`layout`): each face ringed by
//! halo copies of its neighbours' cells, and the cells split by parity into two arrays,
//! so that every loop is one pass over contiguous slices. Its edge weights are held once
//! an edge, each cell's RIGHT and TOP ones (a cell reads its LEFT and BOTTOM ones from
//! its neighbours' entries, the halo's holding the seams'), and the passes that are not
//! a half-sweep take both colours a block at a time, so that an entry is streamed in
//! once for both of its cells. Where the system's faces are alike to the bit (the
//! Marangoni step's mass term is the cells' areas, the same on every face), the finest
//! level's mass term is held for face 0 alone and read by every face (`LevelField`).
//!
//! The solve is bound by memory traffic (at n = 64 a field of the finest level is
//! 220 kB in `f64`, the L2 1 MB), so each pass is counted: an iteration of the conjugate
//! gradients streams the weights once (the operator's product `q`; in `f32`, the
//! V-cycle's copy, where they are given as `f32` values, as the Marangoni step gives
//! them: `Weights::F32`), `x`, `r` and `p` once each, and writes `q` and
//! the V-cycle's right-hand side (an `f32` iteration streams `x` in `f64` and the rest in
//! `f32`, its residual the V-cycle's right-hand side itself). The preconditioned
//! residual `z` is never held in `f64` (`r·z` is summed from the V-cycle's own numbers,
//! `p = z + β·p` formed from them as it is read), and both starts' residuals come from
//! one pass over the system.
//!
//! The smoother is red–black Gauss–Seidel in that layout: each half-sweep updates one colour from the other's
//! values. Where a seam joins two cells of one colour (the faces' chequerboards do not
//! all agree across the cube's edges), the half-sweep reads its neighbour's value from
//! before it (a Jacobi step inside the colour): each half-sweep is still a symmetric
//! block relaxation `z += E D⁻¹ Eᵀ (r − M z)`, convergent since `2D − M_cc` is
//! diagonally dominant, and the V-cycle runs them in one order before the coarse
//! correction and in the reverse order after it, so the preconditioner stays symmetric.
//!
//! Coarse levels are re-discretised, not Galerkin: the mass term `α` sums over the four
//! children, and a coarse edge's weight is half the sum of the two fine edges along it
//! (the weight `l/d` of a Laplacian is scale-free in 2D, while piecewise-constant
//! Galerkin coarsening would double it and halve the coarse correction).

#[cfg(test)]
mod dense;
mod kernels;
mod layout;
mod sparse;

use super::grid::CubeSphere;
use super::sides::{BOTTOM, CellSides, LEFT, RIGHT, TOP};
use crate::avx2::with_avx2;
use kernels::{
    LevelField, NOT_A_CELL, Stencil, Weighted, add_widened, correct, direction_from_f64, dot,
    dot_f32, gather_row, operator, refresh, refresh_all, refresh_from_other, relax,
    relax_from_zero, residuals_in_place, restrict, restrict_field, rounded_level, scatter_row,
    scatter_run, subtract_scaled, update_and_norm2, update_direction, update_direction_f32,
    widened_dot,
};
use layout::Layout;
use sparse::{Factor, Pattern};

/// The two precisions the solve computes in: `f64` for the conjugate gradients, `f32`
/// for the V-cycle that preconditions them (see [`Work`]). The loops are written once,
/// generic over it, each an IEEE operation in a fixed order in either.
trait Real:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::AddAssign
{
    const ZERO: Self;
    /// The value in `f64` (exact).
    fn widen(self) -> f64;
    /// `x` rounded to this precision.
    fn narrow(x: f64) -> Self;
    /// `even[k] = values[2k]` and `odd[k] = values[2k + 1]` over a leading run of the
    /// values, where this precision has a vectorised copy for it
    /// ([`deinterleave_f64`](crate::avx2::deinterleave_f64),
    /// [`deinterleave_f32`](crate::avx2::deinterleave_f32)); returns how many values
    /// that was (none by default: the caller's own loop takes them all).
    #[inline(always)]
    fn deinterleave(_values: &[Self], _even: &mut [Self], _odd: &mut [Self]) -> usize {
        0
    }
    /// [`Real::deinterleave`]'s inverse, `out[2k] = even[k]` and `out[2k + 1] = odd[k]`
    /// ([`interleave_f64`](crate::avx2::interleave_f64)).
    #[inline(always)]
    fn interleave(_even: &[Self], _odd: &[Self], _out: &mut [Self]) -> usize {
        0
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    fn widen(self) -> f64 {
        self
    }
    fn narrow(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn deinterleave(values: &[Self], even: &mut [Self], odd: &mut [Self]) -> usize {
        crate::avx2::deinterleave_f64(values, even, odd)
    }
    #[inline(always)]
    fn interleave(even: &[Self], odd: &[Self], out: &mut [Self]) -> usize {
        crate::avx2::interleave_f64(even, odd, out)
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    fn widen(self) -> f64 {
        f64::from(self)
    }
    fn narrow(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn deinterleave(values: &[Self], even: &mut [Self], odd: &mut [Self]) -> usize {
        crate::avx2::deinterleave_f32(values, even, odd)
    }
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
const DIRECT_CELLS: usize = 6 * 8 * 8;
/// Face size the hierarchy coarsens down to when it can, solved by a sparse Cholesky
/// factor (`sparse`). Down to 6·4² cells took as many instructions over `film_profile n
/// 0 9.81`'s 40 steps (642.4 M at n = 64, 183.2 M at 32; 125 and 158 PCG iterations,
/// against 126 and 164 here) but more time: its triangular solves are chains of
/// dependent multiply-adds, about 20 k instructions a V-cycle at a fraction of the
/// sweeps' rate, and criterion's n = 32 step took 311 µs against 280–290 µs down to
/// 6·2² (n = 64 alike, 1.21–1.24 ms). Down to 6·8² cells took 130 iterations but
/// 726.9 M instructions at n = 64: its factor, 48 k multiply-adds a step, cost 36 M.
const COARSEST_FACE: usize = 2;

/// How many tolerances above the goal the conjugate gradients' residual may be when they
/// go on in `f32` ([`Hierarchy::iterate_in_f32`], where the weights are given as `f32`
/// values). Each `f32` iteration's product `α M p` is rounded, the operator's sums of
/// differences to about `c·ε` of the residual it removes (`ε` = 6e-8; `c` measured about
/// 3 over `film_profile 64 0 9.81`'s steps, but 12 for the first iteration from a start,
/// which therefore stays in `f64`: its product in `f32` would have left the tracked
/// residual 7e-7 of the start's from the true one), so the residual the iterations
/// track falls from the true one by about `c·ε·2¹⁶ ≈ 0.01` tolerances at most. Measured
/// against the true residual formed afresh in `f64` over `film_profile`'s 20 first
/// steps: at most 2.8e-9 of the start's residual (3 thousandths of the 1e-6 tolerance)
/// at n = 64, 4.3e-10 at 128, 1.3e-8 at 32 (measured while the system was the `f64`
/// weights' and the `f32` iterations applied their roundings, which only added to the
/// gap: now both read the same `f32` values); driven through the normal gradient, 5e-4
/// of each solve's tolerance (its defect corrections' included). Over the 40 steps, at
/// the same 126 PCG iterations (164 at 32): 640.2 → 625.5 M instructions and 14.16 →
/// 13.08 M LL misses at n = 64, 183.4 → 178.5 M and 1.95 → 1.82 M misses at 32 (with
/// [`dot_f32`]; its products widened to `f64` as [`widened_dot`] sums them, 630.4 M and
/// 180.4 M; with the product in a field of its own, not the V-cycle's scratch
/// [`Work::operator`], 13.48 M and 2.00 M misses).
const F32_FROM_TOLERANCES: f64 = 65536.0;

/// Gauss–Seidel sweeps a side of the V-cycle's coarse correction on a level of face size
/// `m` in a hierarchy whose finest level's is `finest`. Where the finest level's fields
/// outgrow the L2 (`finest` 64 and up), a PCG iteration saved saves their streaming from
/// memory, and more sweeps pay where a sweep is cheap (the small levels, and a level
/// whose fields stay in L2); below, the whole solve stays in L2 and three everywhere took
/// the fewest instructions. Over `film_profile n 0 9.81`'s 40 steps, at n = 64 (5, 4 and
/// 8 on the levels of 64, 32 and ≤ 16) 132 PCG iterations (3 a step from step 30 on),
/// 751.1 M instructions and 17.3 M LL misses, against three everywhere's 176 (3.9 a
/// step), 747.2 M and 18.8 M; at n = 128 (3 on the finest) 2.97 G and 204 M against
/// 2.93 G and 212 M, where 5 on it too took 2.98 G and 220 M; at n = 32 these counts
/// took 235 M instructions against 223 M, the same misses. (Three everywhere: one took
/// 531 iterations at n = 64, two 230, four 155.) On the levels of 8 and 4, 6
/// took as few iterations as 8 where the level of 4 was solved directly (125 at n = 64,
/// 163 at 128; 4 took 128 at 64) and 2.6 M fewer instructions at n = 64; with the level
/// of 4 swept too, 126 at n = 64 ([`COARSEST_FACE`]). Four on the level of 64 took 128
/// iterations and 2 % fewer instructions, but its answers, each within the tolerance,
/// drifted from the tightly solved film's (tolerance 1e-9): after `film_state_hash 64
/// 40`'s 40 steps the isothermal film's velocity by 0.46 of its largest and its thickness
/// by 0.11, where with 5 they stay within 1.7e-2 and 5.7e-3 of it.
fn sweeps(m: usize, finest: usize) -> usize {
    match m {
        _ if finest < 64 => 3,
        0..=8 => 6,
        9..=16 => 8,
        17..=32 => 4,
        33..=64 => 5,
        _ => 3,
    }
}

/// The multigrid hierarchy of a cube-sphere, built once per grid size.
#[derive(Clone, Debug)]
pub struct Hierarchy {
    /// Each level's layout, finest first.
    levels: Vec<Layout>,
    /// Per weight field ([`RIGHT_W`](layout::RIGHT_W), [`TOP_W`](layout::TOP_W)), the finest level's entries that hold a
    /// seam edge's weight, as `(position, edge)` in increasing position: the rim cells'
    /// RIGHT or TOP entries and the halo's (the rest of a face row's weights are a slice
    /// of the grid's edges).
    seam_weights: [Vec<[u32; 2]>; 2],
    /// The first cell's four sides' edges (LEFT, RIGHT, BOTTOM, TOP), whose weights set
    /// the V-cycle's scale ([`Work::scale`]) before the weights are put in the layout.
    first_edges: [u32; 4],
    /// The coarsest level's elimination order and factor pattern (its direct solve).
    coarsest: Pattern,
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
/// own error as an inverse. `x` and the residual the tolerance is judged on are updated
/// in `f64` from the same `f64` direction and its `f64` product with `M`, so the
/// answer's accuracy does not depend on the preconditioner's; `r·z`, which only weighs
/// the directions, is summed in `f64` from the V-cycle's `f32` right-hand side and
/// answer (`Hierarchy::precondition`). (The last iterations, where the weights are
/// given as `f32` values, run in `f32` but for `x`: `Hierarchy::iterate_in_f32`
/// says why the residual they track stays the true one to a few hundredths of the
/// tolerance.) `f32`'s narrower range is
/// kept away from: the system enters the V-cycle scaled by a power of two that brings
/// the first cell's diagonal entry to `[1, 2)`, and each right-hand side by one that
/// brings its norm there (a power of two changes the exponent, not the bits of the rest,
/// so which cell sets it changes no result), so no system or residual underflows or
/// overflows in it: `f32` spans 2^±126, and a film's diagonal entries lie within a few
/// powers of ten of one another (the cells' areas within 5.2×, their thickness floor
/// (the flow's `H_FLOOR_M`) keeping the weights finite). So weights given
/// as `f32` values stay exact, scaled, in the V-cycle's copy (a power of two moves an
/// `f32` exactly while it stays within 2^±126).
///
/// Every field here is in its level's split layout (`layout`); a field's cells outside
/// the faces stay zero where the conjugate gradients' dot products would see them.
#[derive(Clone, Debug, Default)]
pub struct Work {
    /// Per level, the mass term ([`NOT_A_CELL`] outside the cells) and the edge weights
    /// ([`Stencil`]) in `f64`: the finest level's the conjugate gradients' operator, the
    /// others what the V-cycle's are rounded from. Where the weights are given as `f32`
    /// values ([`Work::weights_f32`]) the finest level has no `f64` weights: its
    /// V-cycle copy holds them exactly, and is read in their stead.
    mass: Vec<Vec<f64>>,
    stencil: Vec<Stencil<f64>>,
    /// Whether the weights were given as [`Weights::F32`] (and there is a V-cycle to
    /// hold them): the finest level's weights are then [`Work::stencil32`]'s alone.
    weights_f32: bool,
    /// [`Weights::F32`]'s weights widened, where the finest level is the coarsest (its
    /// direct solve reads `f64` weights, and there is no V-cycle copy to read).
    widened: Vec<f64>,
    /// Whether the finest level's mass term (in `f64` and `f32`) is held per face
    /// ([`LevelField`]): the system's faces are alike to the bit, as the grid's cell
    /// areas are.
    mass_per_face: bool,
    /// The coarsest level's sparse Cholesky factor, of the system as scaled for the
    /// V-cycle ([`Work::scale`]), in `f64` (the level is solved in `f64`: its right-hand
    /// side and answer converted in [`Work::coarse_x`], in the elimination order).
    coarse_factor: Factor,
    coarse_x: Vec<f64>,
    /// The power of two the V-cycle's system is scaled by (1 where there is one level).
    scale: f64,
    /// Per level but the coarsest, in `f32` and scaled by [`Work::scale`]: the mass
    /// term, the inverse diagonal (zero outside the cells) and the edge weights (the
    /// finest level's exact where they were given as `f32` values: [`Work::weights_f32`]).
    mass32: Vec<Vec<f32>>,
    inv_diag: Vec<Vec<f32>>,
    stencil32: Vec<Stencil<f32>>,
    /// Per level, the V-cycle's right-hand side (on the finest level the conjugate
    /// gradients' residual, scaled and rounded) and its answer.
    residual: Vec<Vec<f32>>,
    correction: Vec<Vec<f32>>,
    /// A level's residual `r − M z` before it is restricted (the finest level's length).
    operator: Vec<f32>,
    /// One coarse row of the restriction.
    row: Vec<f32>,
    /// One face row of the finest level's numbers.
    row64: Vec<f64>,
    /// The conjugate gradients' residual (before the start, `b`), direction and the
    /// operator's product with it (at the start, the guess's residual).
    r: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    /// The preconditioned residual where the finest level is solved directly (in `f64`).
    z: Vec<f64>,
    /// The direction in the `f32` iterations ([`Hierarchy::iterate_in_f32`]; its
    /// product with `M` is held in [`Work::operator`], which the V-cycle only uses
    /// within itself: one field fewer to keep in cache).
    p32: Vec<f32>,
    /// `x` and the guess in the finest level's layout (`b` is put in [`Work::r`]).
    x: Vec<f64>,
    guess: Vec<f64>,
}

impl Work {
    /// Level `k`'s mass term in `f64`, as the kernels read it ([`LevelField`]).
    fn mass_term(&self, k: usize) -> LevelField<'_, f64> {
        LevelField {
            values: &self.mass[k],
            per_face: k == 0 && self.mass_per_face,
        }
    }

    /// The finest level's weights as the conjugate gradients read them: in `f64`, or the
    /// V-cycle's `f32` copy, scaled by [`Work::scale`] ([`Work::weights_f32`]).
    fn fine_weights(&self) -> FineWeights<'_> {
        if self.weights_f32 {
            FineWeights::F32((&self.stencil32[0], self.scale))
        } else {
            FineWeights::F64((&self.stencil[0], 1.0))
        }
    }
}

/// The finest level's weights as the conjugate gradients' `f64` passes read them
/// ([`Work::fine_weights`]).
#[derive(Clone, Copy)]
enum FineWeights<'a> {
    /// The `f64` weights.
    F64(Weighted<'a, f64, f64>),
    /// The V-cycle's `f32` copy, scaled (exact: the weights were given as `f32` values).
    F32(Weighted<'a, f32, f64>),
}

/// A system's mass term `α` as [`Hierarchy::solve_from_start_and_change`] is given it.
#[derive(Clone, Copy, Debug)]
pub(crate) enum MassTerm<'a> {
    /// Per cell, in the grid's numbering.
    Cells(&'a [f64]),
    /// Face 0's cells' values alone, every face's the same to the bit (as the grid's
    /// cell areas are): the solve need not read the other faces to find that out.
    EveryFace(&'a [f64]),
}

/// A system's edge weights as [`Hierarchy::solve_from_start_and_change`] is given them.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Weights<'a> {
    /// Any `f64` values.
    F64(&'a [f64]),
    /// `f32` values: the system solved is theirs, exactly. The V-cycle's copy, scaled by
    /// a power of two, holds them exactly, so the conjugate gradients' `f64` passes (the
    /// starts' residuals, the first iterations) read it widened and no `f64` copy is
    /// made ([`Work::weights_f32`]), and their last iterations run in `f32`
    /// ([`Hierarchy::iterate_in_f32`]) on the same numbers.
    F32(&'a [f32]),
}

/// Where [`Hierarchy::solve_prepared_from`] starts.
#[derive(Clone, Copy)]
enum Start<'a> {
    /// From the answer's own values, and the guess where one is given.
    Values(Option<&'a [f64]>),
    /// From the start given, and its sum with the change where one is given as the guess.
    Changed(&'a [f64], Option<&'a [f64]>),
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
    /// Whether the iterations started from the guess (its residual was the smaller).
    pub from_guess: bool,
}

impl Hierarchy {
    /// Halves the grid while its face size stays even and above the coarsest level's
    /// (`COARSEST_FACE`, 2).
    pub fn new(grid: &CubeSphere) -> Self {
        let sides = CellSides::new(grid);
        let mut levels = vec![Layout::of_grid(&sides)];
        let mut n = grid.face_size();
        while n > coarsest_face(n) {
            let coarse = levels.last().expect("one level").coarser();
            levels.push(coarse);
            n /= 2;
        }
        let seam_weights = seam_weights(&levels[0], &sides);
        let coarsest = Pattern::new(levels.last().expect("a level"));
        Self {
            levels,
            seam_weights,
            first_edges: sides.edge[0],
            coarsest,
        }
    }

    /// Whether a face size coarsens down to a directly solvable level.
    pub fn supports(face_size: usize) -> bool {
        let n = coarsest_face(face_size);
        n >= 1 && 6 * n * n <= DIRECT_CELLS
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
        assert_eq!(
            alpha.len(),
            self.levels[0].position.len(),
            "system size mismatch"
        );
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
        let nc = self.levels[0].position.len();
        assert!(x.len() == nc, "system size mismatch");
        let guess = guess.filter(|g| g.len() == nc);
        self.solve_prepared_from(work, b, Start::Values(guess), x, limits)
    }

    /// As [`Hierarchy::solve_with_guess`] from `start`, with the guess `start + change`
    /// where `change` is given (and of the system's size), the answer written to `x`
    /// (its values not read): the start and the guess go straight into the solve's
    /// layout, in one pass, where a caller's own pass would write both out in the grid's
    /// numbering first and the solve read them back.
    ///
    /// # Panics
    /// If a slice's length does not match the finest level.
    pub(crate) fn solve_from_start_and_change(
        &self,
        work: &mut Work,
        (alpha, weight, b): (MassTerm, Weights, &[f64]),
        (start, change): (&[f64], Option<&[f64]>),
        x: &mut [f64],
        limits: SolveLimits,
    ) -> SolveReport {
        let nc = self.levels[0].position.len();
        assert!(start.len() == nc, "system size mismatch");
        assert_eq!(x.len(), nc, "system size mismatch");
        self.prepare_mass(work, alpha, weight);
        let change = change.filter(|c| c.len() == nc);
        self.solve_prepared_from(work, b, Start::Changed(start, change), x, limits)
    }

    /// [`Hierarchy::solve_prepared`] from `start` ([`Start`]), the answer into `x`: the
    /// right-hand side, the start and the guess put in the split layout, solved there, and
    /// the answer put back.
    fn solve_prepared_from(
        &self,
        work: &mut Work,
        b: &[f64],
        start: Start,
        x: &mut [f64],
        limits: SolveLimits,
    ) -> SolveReport {
        let fine = &self.levels[0];
        let nc = fine.position.len();
        assert!(b.len() == nc && x.len() == nc, "system size mismatch");
        assert!(!work.stencil.is_empty(), "no system prepared");
        // `b` goes into the residual's field: the residual is taken from it in place.
        let (mut bs, mut xs, mut gs) = (
            std::mem::take(&mut work.r),
            std::mem::take(&mut work.x),
            std::mem::take(&mut work.guess),
        );
        let mut row = std::mem::take(&mut work.row64);
        let guessed = with_avx2(
            #[inline(always)]
            || {
                to_split(fine, b, &mut bs);
                match start {
                    Start::Values(guess) => {
                        to_split(fine, x, &mut xs);
                        if let Some(g) = guess {
                            to_split(fine, g, &mut gs);
                        }
                        guess.is_some()
                    }
                    Start::Changed(start, None) => {
                        to_split(fine, start, &mut xs);
                        false
                    }
                    Start::Changed(start, Some(change)) => {
                        start_and_guess_split(fine, (start, change), (&mut xs, &mut gs), &mut row);
                        true
                    }
                }
            },
        );
        work.row64 = row;
        let guess = guessed.then_some(&mut gs);
        work.r = bs;
        let report = self.solve_split(work, &mut xs, guess, limits);
        with_avx2(
            #[inline(always)]
            || from_split(fine, &mut xs, x),
        );
        (work.x, work.guess) = (xs, gs);
        report
    }

    /// The conjugate gradients in the finest level's split layout, compiled for AVX2
    /// where the processor has it ([`with_avx2`]), from `b` in [`Work::r`]. Where the
    /// guess is taken, it and `x` trade places (a swap, not a copy of the field).
    fn solve_split(
        &self,
        work: &mut Work,
        x: &mut Vec<f64>,
        guess: Option<&mut Vec<f64>>,
        limits: SolveLimits,
    ) -> SolveReport {
        with_avx2(
            #[inline(always)]
            || {
                let fine = &self.levels[0];
                let len = fine.len();
                let mut r = std::mem::take(&mut work.r);
                let mut own_p = std::mem::take(&mut work.p);
                let mut q = std::mem::take(&mut work.q);
                for v in [&mut r, &mut q] {
                    v.resize(len, 0.0);
                }
                refresh_all(fine, x);
                let mut guess = guess;
                if let Some(g) = guess.as_mut() {
                    refresh_all(fine, g);
                }
                // Both starts' residuals in one pass over the system: `x`'s into `r`, the
                // guess's into `q`, from the `b` that `r` holds.
                let starts = [Some(&x[..]), guess.as_deref().map(|g| &g[..])];
                self.start_residuals(work, starts, [&mut r, &mut q]);
                // Relative to the start's residual: the step's change, not the whole field.
                let mut start_norm = dot(&r, &r).sqrt();
                let b_norm = if start_norm > 0.0 { start_norm } else { 1.0 };
                let mut from_guess = false;
                if let Some(guess) = guess.as_mut().filter(|_| start_norm > 0.0) {
                    let guess_norm = dot(&q, &q).sqrt();
                    if guess_norm < start_norm {
                        std::mem::swap(x, guess);
                        std::mem::swap(&mut r, &mut q);
                        start_norm = guess_norm;
                        from_guess = true;
                    }
                }
                // The start not taken is not read again: its field holds the direction
                // (one field fewer to keep in cache), else `Work::p`.
                let p = match guess {
                    Some(spare) => spare,
                    None => {
                        own_p.resize(len, 0.0);
                        &mut own_p
                    }
                };
                let mut report = SolveReport {
                    iterations: 0,
                    relative_residual: start_norm / b_norm,
                    start_residual: b_norm,
                    from_guess,
                };
                if report.relative_residual > limits.tolerance {
                    let (mut rz, back) = self.precondition(work, &r, start_norm);
                    self.next_direction(work, back, None, p);
                    while report.iterations < limits.max_iterations {
                        refresh_all(fine, p);
                        self.apply(work, p, &mut q);
                        let pq = dot(p, &q);
                        if pq <= 0.0 || !pq.is_finite() {
                            break;
                        }
                        let step = rz / pq;
                        let rr = update_and_norm2(step, p, &q, x, &mut r);
                        report.iterations += 1;
                        report.relative_residual = rr.sqrt() / b_norm;
                        let done = report.relative_residual <= limits.tolerance;
                        if done || report.iterations == limits.max_iterations {
                            break;
                        }
                        let (rz_next, back) = self.precondition(work, &r, rr.sqrt());
                        let beta = rz_next / rz;
                        rz = rz_next;
                        if self.continues_in_f32(work, report.relative_residual, limits) {
                            let state = (rz, back, beta);
                            self.iterate_in_f32(work, state, (p, x), limits, &mut report);
                            break;
                        }
                        self.next_direction(work, back, Some(beta), p);
                    }
                }
                (work.r, work.p, work.q) = (r, own_p, q);
                report
            },
        )
    }

    /// Whether the conjugate gradients, at a residual `relative` to the start's, go on
    /// in `f32` ([`Hierarchy::iterate_in_f32`]): where the weights were given as `f32`
    /// values ([`Work::weights_f32`]; there is then a V-cycle) and the residual is within
    /// [`F32_FROM_TOLERANCES`] tolerances of the goal.
    #[inline(always)]
    fn continues_in_f32(&self, work: &Work, relative: f64, limits: SolveLimits) -> bool {
        work.weights_f32
            && self.levels.len() > 1
            && relative <= F32_FROM_TOLERANCES * limits.tolerance
    }

    /// The conjugate gradients' iterations from the one whose preconditioned residual
    /// the V-cycle just made, in `f32` but for `x` (see [`F32_FROM_TOLERANCES`]): the
    /// residual `r' = t·r` is the V-cycle's own right-hand side ([`Work::residual`]),
    /// `t` the power of two [`Hierarchy::precondition`] scaled it by, and the direction
    /// is held as `p' = p/back` ([`Work::p32`]; `back = scale/t` is `z`'s factor, fixed
    /// from here, so `p' = z' + β·p'`), its product `q' = scale·M p'` by the V-cycle's
    /// `f32` operator (in [`Work::operator`]); `x` is updated in `f64` by `α·back·p'`, each
    /// `p'` widened exactly, so `x − x₀` is the sum of the `f32` directions and `r'`
    /// falls from the true residual only by each iteration's `f32` rounding of `α M p`.
    /// The dot products are summed in `f32` lanes ([`dot_f32`]: they weigh the steps and
    /// measure the residual to a few millionths, where `x` and `r'` take each step
    /// alike). Given `(rz, back, beta)` of the last preconditioning and `p`, the last
    /// `f64` direction.
    #[inline(always)]
    fn iterate_in_f32(
        &self,
        work: &mut Work,
        (mut rz, back, beta): (f64, f64, f64),
        (p, x): (&[f64], &mut [f64]),
        limits: SolveLimits,
        report: &mut SolveReport,
    ) {
        let fine = &self.levels[0];
        let (scale, t) = (work.scale, work.scale / back);
        let b_norm = report.start_residual;
        let r32 = std::mem::take(&mut work.residual[0]);
        let mut p32 = std::mem::take(&mut work.p32);
        p32.resize(fine.len(), 0.0);
        // `p' = (back·z' + β·p)/back`.
        direction_from_f64(&work.correction[0], beta / back, p, &mut p32);
        let mut r32 = r32;
        while report.iterations < limits.max_iterations {
            refresh_all(fine, &mut p32);
            // `q'` in the V-cycle's scratch field, free until the V-cycle runs (kept at the
            // finest level's length; the operator writes all of it).
            let mut q32 = std::mem::take(&mut work.operator);
            q32.resize(fine.len(), 0.0);
            let mass = LevelField {
                values: &work.mass32[0],
                per_face: work.mass_per_face,
            };
            let w = (&work.stencil32[0], 1.0);
            operator::<f32, f32, false>(fine, mass, w, &[], &p32, &mut q32);
            // `p·M p = back²/scale · p'·q'`.
            let pq = dot_f32(&p32, &q32) * back * (back / scale);
            let usable = pq > 0.0 && pq.is_finite();
            if usable {
                let step = rz / pq;
                add_widened(step * back, &p32, x);
                // `r' −= t·step·M p = (t·step·back/scale)·q'`.
                subtract_scaled(((t * step) * (back / scale)) as f32, &q32, &mut r32);
            }
            work.operator = q32;
            if !usable {
                break;
            }
            let rr = dot_f32(&r32, &r32) / (t * t);
            report.iterations += 1;
            report.relative_residual = rr.sqrt() / b_norm;
            let done = report.relative_residual <= limits.tolerance;
            if done || report.iterations == limits.max_iterations {
                break;
            }
            let mut z32 = std::mem::take(&mut work.correction[0]);
            self.v_cycle(work, 0, &r32, &mut z32);
            // `r·z = (r'/t)·(back·z')`.
            let rz_next = dot_f32(&r32, &z32) * (back / t);
            let beta = rz_next / rz;
            rz = rz_next;
            update_direction_f32(beta as f32, &z32, &mut p32);
            work.correction[0] = z32;
        }
        work.residual[0] = r32;
        work.p32 = p32;
    }

    /// `q = M p` on the finest level, with the system's own weights (as
    /// [`Hierarchy::start_residuals`]: [`Work::fine_weights`]).
    #[inline(always)]
    fn apply(&self, work: &Work, p: &[f64], q: &mut [f64]) {
        let (fine, mass) = (&self.levels[0], work.mass_term(0));
        match work.fine_weights() {
            FineWeights::F64(w) => operator::<f64, f64, false>(fine, mass, w, &[], p, q),
            FineWeights::F32(w) => operator::<f64, f32, false>(fine, mass, w, &[], p, q),
        }
    }

    /// The starts' residuals in place ([`residuals_in_place`]) on the finest level, in
    /// `f64`, with the system's own weights: the `f64` ones, or, where the weights were
    /// given as `f32` values, the V-cycle's copy, which holds them exactly
    /// ([`Work::fine_weights`]). Either way the system solved is the one given, the one
    /// the caller's velocity correction applies.
    ///
    /// Why that matters: a start's residual is `b − M x₀` for the whole surfactant `x₀`,
    /// and where it was taken with the `f32` roundings of `f64` weights (as the solve did
    /// from 64 cells a face, to stream half the bytes), `M x₀` was off by about 6e-8 of
    /// `L x₀`, which in a stiff step dwarfs the residual, the step's change. The system
    /// solved was then the rounded weights', while the velocity correction moved Γ with
    /// the `f64` ones: each step's answer carried a grid-scale error some 9× the step's
    /// own change, alternating from step to step (on `film_profile 64 0 9.81`'s film,
    /// each step's change −0.37 correlated with the last's, its roughness
    /// `Σ_edges (Δc)²/(2Σc²)` 2.4 against 0.06), the tolerance was judged against a
    /// start's residual swollen by it, and the guess never paid. The Marangoni step now
    /// rounds its weights to `f32` where it makes them ([`Weights::F32`]), so the solve
    /// and the correction read the same numbers.
    #[inline(always)]
    fn start_residuals(&self, work: &Work, starts: [Option<&[f64]>; 2], out: [&mut [f64]; 2]) {
        let (fine, mass) = (&self.levels[0], work.mass_term(0));
        match work.fine_weights() {
            FineWeights::F64(w) => residuals_in_place(fine, (mass, w), starts, out),
            FineWeights::F32(w) => residuals_in_place(fine, (mass, w), starts, out),
        }
    }

    /// [`Hierarchy::prepare_mass`] of a mass term given per cell.
    fn prepare(&self, work: &mut Work, alpha: &[f64], weight: &[f64]) {
        self.prepare_mass(work, MassTerm::Cells(alpha), Weights::F64(weight));
    }

    /// Restricts the system's numbers to every level, and rounds them to `f32` for the
    /// V-cycle (see [`Work`]); notes whether the weights were given as `f32` values
    /// ([`Work::weights_f32`]: then put straight into the V-cycle's finest copy, scaled,
    /// with no `f64` copy, and the conjugate gradients may iterate in `f32`).
    ///
    /// # Panics
    /// If the mass term's length does not match the finest level (its cells, or a face's).
    fn prepare_mass(&self, work: &mut Work, alpha: MassTerm, weight: Weights) {
        let m = self.levels[0].m;
        let len = match alpha {
            MassTerm::Cells(a) => a.len() / 6,
            MassTerm::EveryFace(a) => a.len(),
        };
        assert_eq!(len, m * m, "system size mismatch");
        let one_level = self.levels.len() == 1;
        work.weights_f32 = matches!(weight, Weights::F32(_)) && !one_level;
        let mut widened = std::mem::take(&mut work.widened);
        let weight = match weight {
            Weights::F32(w) if one_level => {
                widened.clear();
                widened.extend(w.iter().map(|&v| f64::from(v)));
                Weights::F64(&widened)
            }
            given => given,
        };
        with_avx2(
            #[inline(always)]
            || self.prepare_here(work, alpha, weight),
        );
        work.widened = widened;
    }

    /// [`Hierarchy::prepare_mass`]'s work, inlined into the AVX2 build where there is one
    /// (`f32` weights only where there is a V-cycle to hold them).
    #[inline(always)]
    fn prepare_here(&self, work: &mut Work, alpha: MassTerm, weight: Weights) {
        let count = self.levels.len();
        work.mass.resize(count, Vec::new());
        work.stencil.resize(count, Stencil::default());
        work.residual.resize(count, Vec::new());
        work.correction.resize(count, Vec::new());
        for (k, level) in self.levels.iter().enumerate() {
            sized(&mut work.mass[k], level.len(), NOT_A_CELL);
            if k > 0 || !work.weights_f32 {
                for w in &mut work.stencil[k] {
                    sized(w, level.len(), 0.0);
                }
            }
            work.residual[k].resize(level.len(), 0.0);
            work.correction[k].resize(level.len(), 0.0);
        }
        self.size_the_v_cycles_fields(work);
        work.scale = self.scale_of(alpha, weight);
        self.fine_mass(work, alpha);
        match weight {
            Weights::F64(w) => {
                let (out, row) = (&mut work.stencil[0], &mut work.row64);
                self.fine_weights(w, out, row, |v| v);
            }
            Weights::F32(w) => {
                let (out, row) = (&mut work.stencil32[0], &mut work.row);
                // A power of two (in `f32`'s range: see `Work`): each product exact.
                let scale = work.scale as f32;
                self.fine_weights(w, out, row, |v| scale * v);
            }
        }
        // Each level rounded as soon as it is made, while its numbers are in cache.
        self.round_for_the_v_cycle(work, 0);
        for k in 1..count {
            let (fine, coarse) = (&self.levels[k - 1], &self.levels[k]);
            let per_face = k == 1 && work.mass_per_face;
            let (done, rest) = work.mass.split_at_mut(k);
            let fine_mass = LevelField {
                values: &done[k - 1],
                per_face,
            };
            restrict_field(fine, fine_mass, coarse, &mut rest[0], &mut work.row64);
            let (done, rest) = work.stencil.split_at_mut(k);
            let row = &mut work.row64;
            if k == 1 && work.weights_f32 {
                let w = (&work.stencil32[0], work.scale);
                kernels::restrict_weights(fine, w, coarse, &mut rest[0], row);
            } else {
                kernels::restrict_weights(fine, (&done[k - 1], 1.0), coarse, &mut rest[0], row);
            }
            self.round_for_the_v_cycle(work, k);
        }
        let last = count - 1;
        let system = (&work.mass[last][..], &work.stencil[last]);
        let level = &self.levels[last];
        let factor = &mut work.coarse_factor;
        self.coarsest.factor(level, system, work.scale, factor);
    }

    /// The power of two the V-cycle's system is scaled by ([`Work::scale`]): the one
    /// that brings the first cell's diagonal entry, its mass term plus its four side
    /// weights, to `[1, 2)`; 1 where there is one level (the direct solve is the whole
    /// preconditioner, in `f64`, unscaled).
    fn scale_of(&self, alpha: MassTerm, weight: Weights) -> f64 {
        if self.levels.len() == 1 {
            return 1.0;
        }
        let first = match alpha {
            MassTerm::Cells(a) | MassTerm::EveryFace(a) => a[0],
        };
        let side = |k: usize| {
            let e = self.first_edges[k] as usize;
            match weight {
                Weights::F64(w) => w[e],
                Weights::F32(w) => f64::from(w[e]),
            }
        };
        let diagonal = first + side(0) + side(1) + side(2) + side(3);
        power_of_two_below(diagonal).recip()
    }

    /// The finest level's mass term from the grid's cells, a face row at a time (face
    /// 0's alone where the system's faces are alike: [`Work::mass_per_face`]).
    #[inline(always)]
    fn fine_mass(&self, work: &mut Work, alpha: MassTerm) {
        let fine = &self.levels[0];
        let n = fine.m;
        // Checked where the caller does not say so: a pass over every face's values.
        let alike = match alpha {
            MassTerm::Cells(a) => faces_alike(a),
            MassTerm::EveryFace(_) => true,
        };
        work.mass_per_face = self.levels.len() > 1 && fine.faces_alike() && alike;
        let mass_faces = if work.mass_per_face { 1 } else { 6 };
        for face in 0..mass_faces {
            for y in 0..n {
                let alpha_row = match alpha {
                    MassTerm::Cells(a) => &a[(face * n + y) * n..][..n],
                    MassTerm::EveryFace(a) => &a[y * n..][..n],
                };
                scatter_row(fine, face, y, alpha_row, &mut work.mass[0]);
            }
        }
    }

    /// The finest level's weights from the grid's edges into `out`, each as `put` gives
    /// it, a face row at a time: a row's RIGHT weights but the last and its TOP weights
    /// (but the top row's) are a slice of the grid's edges ([`inside_a_face`]), put into
    /// `row` and scattered from there; then the entries that hold seam edges
    /// ([`Hierarchy::seam_weights`]), over whatever the runs left there. The entries no
    /// cell reads are left as they are (zero: no pass writes them).
    #[inline(always)]
    fn fine_weights<W: Copy, T: Real>(
        &self,
        weight: &[W],
        out: &mut Stencil<T>,
        row: &mut Vec<T>,
        put: impl Fn(W) -> T,
    ) {
        let fine = &self.levels[0];
        let n = fine.m;
        row.resize(n, T::ZERO);
        let [right, top] = out;
        for face in 0..6 {
            for y in 0..n {
                // The last cell's RIGHT entry is a seam's, written below: the run takes
                // the next edge there (the grid's edges run on past a row's last
                // x-edge), so it is whole chunks long, with no remainder a pair at a time.
                let (xs, first) = inside_a_face(n, face, y, RIGHT);
                if !xs.is_empty() {
                    let at = fine.padded_at(face, y + 1, 1 + xs.start);
                    put_run(fine, at, (&weight[first..][..n], &put), row, right);
                }
                let (xs, first) = inside_a_face(n, face, y, TOP);
                if !xs.is_empty() {
                    let at = fine.padded_at(face, y + 1, 1);
                    put_run(fine, at, (&weight[first..][..n], &put), row, top);
                }
            }
        }
        for (field, seams) in [right, top].into_iter().zip(&self.seam_weights) {
            for &[p, e] in seams {
                field[p as usize] = put(weight[e as usize]);
            }
        }
    }

    /// The V-cycle's fields of every level but the coarsest at their lengths (a level's
    /// weights set to zero where its length changes: the entries no cell reads stay so).
    fn size_the_v_cycles_fields(&self, work: &mut Work) {
        let smoothed = self.levels.len() - 1;
        work.mass32.resize(smoothed, Vec::new());
        work.inv_diag.resize(smoothed, Vec::new());
        work.stencil32.resize(smoothed, Stencil::default());
        for (k, level) in self.levels[..smoothed].iter().enumerate() {
            let n = level.len();
            work.mass32[k].resize(n, 0.0);
            work.inv_diag[k].resize(n, 0.0);
            for w in &mut work.stencil32[k] {
                sized(w, n, 0.0);
            }
        }
    }

    /// Level `k`'s numbers scaled by [`Work::scale`] and rounded to `f32`, the inverse
    /// diagonal summed in `f64` from the unrounded numbers and rounded once (zero outside
    /// the cells: [`rounded_level`]); nothing for the coarsest level, solved directly.
    /// The finest level's weights, where they were given as `f32` values, are in the
    /// V-cycle's copy already ([`Work::weights_f32`]): its diagonal is summed from it.
    #[inline(always)]
    fn round_for_the_v_cycle(&self, work: &mut Work, k: usize) {
        let (scale, smoothed) = (work.scale, self.levels.len() - 1);
        if k >= smoothed {
            return;
        }
        let level = &self.levels[k];
        let mass = LevelField {
            values: &work.mass[k],
            per_face: k == 0 && work.mass_per_face,
        };
        let (mass32, inv_diag) = (&mut work.mass32[k], &mut work.inv_diag[k]);
        if k == 0 && work.weights_f32 {
            let w = &work.stencil32[0];
            rounded_level(level, scale, (mass, w), (mass32, None), inv_diag);
        } else {
            let (w, w32) = (&work.stencil[k], Some(&mut work.stencil32[k]));
            rounded_level(level, scale, (mass, w), (mass32, w32), inv_diag);
        }
    }

    /// `z` = the preconditioner applied to the conjugate gradients' residual `r`, whose
    /// norm is `norm`: one V-cycle in `f32` (see [`Work`]), or the direct solve where the
    /// finest level is the coarsest. Returns `r·z` and the factor `back` that `z` is
    /// held scaled by: `z = back·z'`, `z'` the V-cycle's answer (in
    /// [`Work::correction`]) or the direct solve's (in [`Work::z`], `back` 1). `z` is not
    /// stored in `f64`: [`Hierarchy::next_direction`] forms it again as it reads it.
    #[inline(always)]
    fn precondition(&self, work: &mut Work, r: &[f64], norm: f64) -> (f64, f64) {
        if self.levels.len() == 1 {
            let mut z = std::mem::take(&mut work.z);
            z.resize(r.len(), 0.0);
            self.coarsest(work, r, &mut z);
            // `r·(1·z)`, as `widened_dot` would form it: the same bits.
            let rz = dot(r, &z);
            work.z = z;
            return (rz, 1.0);
        }
        // `M' = scale·M` is the system the V-cycle holds and `r' = to·r` its right-hand
        // side, so `M⁻¹ r = (scale / to)·M'⁻¹ r'`; each factor a power of two, exact.
        let to = power_of_two_below(norm).recip();
        let back = work.scale / to;
        let mut r32 = std::mem::take(&mut work.residual[0]);
        rounded(to, r, &mut r32);
        let mut z32 = std::mem::take(&mut work.correction[0]);
        self.v_cycle(work, 0, &r32, &mut z32);
        // `r·z` from the V-cycle's own numbers, still in cache where `r` is not: `r'`
        // is `to·r` rounded to `f32`, so `(r'·z')·back/to` is `r·z` but for that
        // rounding (about 1e-7 of each term, below the preconditioner's own error; `r`
        // itself, the tolerance's, stays exact in `f64`). `back/to` is a power of two.
        let rz = widened_dot(&r32, &z32) * (back / to);
        work.residual[0] = r32;
        work.correction[0] = z32;
        (rz, back)
    }

    /// The next search direction from the last preconditioned residual `z` (held as
    /// [`Hierarchy::precondition`] left it, scaled by `back`): `p = z + β·p`, or `p = z`
    /// for the first (`beta` `None`).
    #[inline(always)]
    fn next_direction(&self, work: &Work, back: f64, beta: Option<f64>, p: &mut [f64]) {
        if self.levels.len() == 1 {
            update_direction(back, &work.z, beta, p);
        } else {
            update_direction(back, &work.correction[0], beta, p);
        }
    }

    /// One symmetric V-cycle on level `k` for residual `r`, result in `z`, in `f32`:
    /// [`sweeps`] forward sweeps (colour 0 then 1, the first from zero), the coarse
    /// correction, as many backward sweeps (colour 1 then 0). Before each half-sweep the
    /// halo cells it reads are refreshed, and before the residual the stale ones of both
    /// colours.
    fn v_cycle(&self, work: &mut Work, k: usize, r: &[f32], z: &mut [f32]) {
        with_avx2(
            #[inline(always)]
            || {
                let level = &self.levels[k];
                if k + 1 == self.levels.len() {
                    self.coarsest(work, r, z);
                    return;
                }
                let (inv_diag, w) = (&work.inv_diag[k], &work.stencil32[k]);
                relax_from_zero(level, inv_diag, r, z);
                relax(level, 1, inv_diag, w, r, z);
                for _ in 1..sweeps(level.m, self.levels[0].m) {
                    for c in [0, 1] {
                        refresh(level, 1 - c, z);
                        relax(level, c, inv_diag, w, r, z);
                    }
                }
                // The operator reads both colours' halos: colour 0's was refreshed before
                // the last half-sweep (of colour 1), so only its cells copied from colour 1
                // are stale.
                refresh(level, 1, z);
                refresh_from_other(level, 0, z);
                let coarse = &self.levels[k + 1];
                let mut d = std::mem::take(&mut work.operator);
                // Kept at the finest level's length and sliced: resized to each level's in
                // turn, it would be zeroed again every V-cycle.
                d.resize(d.len().max(level.len()), 0.0);
                let mass = LevelField {
                    values: &work.mass32[k],
                    per_face: k == 0 && work.mass_per_face,
                };
                operator::<f32, f32, true>(level, mass, (w, 1.0), r, z, &mut d);
                let mut rc = std::mem::take(&mut work.residual[k + 1]);
                restrict(level, &d, coarse, &mut rc, &mut work.row);
                work.operator = d;
                let mut zc = std::mem::take(&mut work.correction[k + 1]);
                self.v_cycle(work, k + 1, &rc, &mut zc);
                correct(level, coarse, &zc, z);
                (work.residual[k + 1], work.correction[k + 1]) = (rc, zc);
                let (inv_diag, w) = (&work.inv_diag[k], &work.stencil32[k]);
                for _ in 0..sweeps(level.m, self.levels[0].m) {
                    for c in [1, 0] {
                        refresh(level, 1 - c, z);
                        relax(level, c, inv_diag, w, r, z);
                    }
                }
            },
        )
    }

    /// The coarsest level's direct solve (`sparse`), in `f64` (in either precision's fields: the
    /// V-cycle's last level, or the whole preconditioner where there is one level).
    #[inline(always)]
    fn coarsest<T: Real>(&self, work: &mut Work, r: &[T], z: &mut [T]) {
        let pattern = &self.coarsest;
        let x = &mut work.coarse_x;
        x.resize(pattern.cells(), 0.0);
        for (v, &p) in x.iter_mut().zip(pattern.positions()) {
            *v = r[p as usize].widen();
        }
        pattern.solve(&work.coarse_factor, x);
        for (v, &p) in x.iter().zip(pattern.positions()) {
            z[p as usize] = T::narrow(*v);
        }
    }
}

/// Of face `face`, row `y`, the cells whose side `k` lies inside the face (not on a
/// seam) and the first of their edges on it: the row's x-edges and y-edges are
/// consecutive ([`FaceLayout`](super::grid::FaceLayout)).
fn inside_a_face(n: usize, face: usize, y: usize, k: usize) -> (std::ops::Range<usize>, usize) {
    let x_edges = face * n * (n - 1) + y * (n - 1);
    let y_edges = |y: usize| 6 * n * (n - 1) + face * n * (n - 1) + (y - 1) * n;
    match k {
        LEFT if n > 1 => (1..n, x_edges),
        RIGHT if n > 1 => (0..n - 1, x_edges),
        BOTTOM if y > 0 => (0..n, y_edges(y)),
        TOP if y + 1 < n => (0..n, y_edges(y + 1)),
        _ => (0..0, 0),
    }
}

/// [`Hierarchy::seam_weights`] of the finest level `fine`: each rim cell's sides on a
/// seam, at the entries [`Layout::side_weights`] names.
fn seam_weights(fine: &Layout, sides: &CellSides) -> [Vec<[u32; 2]>; 2] {
    let n = sides.n();
    let mut seams = [Vec::new(), Vec::new()];
    for (c, edges) in sides.edge.iter().enumerate() {
        let (x, y, face) = (c % n, (c / n) % n, c / (n * n));
        for (k, (field, p)) in fine.side_weights(c).into_iter().enumerate() {
            if !inside_a_face(n, face, y, k).0.contains(&x) {
                seams[field].push([p as u32, edges[k]]);
            }
        }
    }
    for s in &mut seams {
        s.sort_unstable();
    }
    seams
}

/// `values`, each as `put` gives it (put in `row` first), at padded indices from `first`
/// on ([`scatter_run`]).
#[inline(always)]
fn put_run<W: Copy, T: Real>(
    layout: &Layout,
    first: usize,
    (values, put): (&[W], &impl Fn(W) -> T),
    row: &mut [T],
    out: &mut [T],
) {
    let row = &mut row[..values.len()];
    for (r, v) in row.iter_mut().zip(values) {
        *r = put(*v);
    }
    scatter_run(layout, first, row, out);
}

/// Whether every face's values (a sixth of `values` each) are face 0's, to the bit
/// (without a branch a value, so that the comparison vectorises).
fn faces_alike(values: &[f64]) -> bool {
    let (first, rest) = values.split_at(values.len() / 6);
    rest.chunks_exact(first.len()).all(|face| {
        let differ = face.iter().zip(first);
        differ.fold(0, |any, (a, b)| any | (a.to_bits() ^ b.to_bits())) == 0
    })
}

/// `v` at `len` entries, set to `fill` throughout where its length changes (a field of
/// another level's size holds nothing this one can keep).
fn sized<T: Copy>(v: &mut Vec<T>, len: usize, fill: T) {
    if v.len() != len {
        v.clear();
        v.resize(len, fill);
    }
}

/// `out` = the grid-numbered `values` in `layout`'s split arrays (the halo untouched).
#[inline(always)]
fn to_split(layout: &Layout, values: &[f64], out: &mut Vec<f64>) {
    out.resize(layout.len(), 0.0);
    let m = layout.m;
    for face in 0..6 {
        for y in 0..m {
            let row = &values[(face * m + y) * m..][..m];
            scatter_row(layout, face, y, row, out);
        }
    }
}

/// `xs` = `start` and `gs` = `start + change` (grid-numbered) in `layout`'s split arrays,
/// a face row at a time (the sum formed in `row`), the halo untouched.
#[inline(always)]
fn start_and_guess_split(
    layout: &Layout,
    (start, change): (&[f64], &[f64]),
    (xs, gs): (&mut Vec<f64>, &mut Vec<f64>),
    row: &mut Vec<f64>,
) {
    xs.resize(layout.len(), 0.0);
    gs.resize(layout.len(), 0.0);
    let m = layout.m;
    row.resize(m, 0.0);
    for face in 0..6 {
        for y in 0..m {
            let cells = (face * m + y) * m..(face * m + y + 1) * m;
            let (start, change) = (&start[cells.clone()], &change[cells]);
            scatter_row(layout, face, y, start, xs);
            for ((g, s), c) in row.iter_mut().zip(start).zip(change) {
                *g = s + c;
            }
            scatter_row(layout, face, y, row, gs);
        }
    }
}

/// `out` = `layout`'s split field in the grid's numbering.
#[inline(always)]
fn from_split(layout: &Layout, field: &mut [f64], out: &mut [f64]) {
    let m = layout.m;
    for face in 0..6 {
        for y in 0..m {
            gather_row(layout, face, y, field, &mut out[(face * m + y) * m..][..m]);
        }
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

#[cfg(test)]
mod tests {
    use super::layout::{RIGHT_W, TOP_W};
    use super::*;
    use crate::bits::differing_bits;
    use crate::film_flow::grid::parent_cell;

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

    /// The `f32` V-cycle and the `f64` conjugate gradients alike: at n = 8 (two levels,
    /// rows of 4 and 8 cells), 32 and 64 (four and five levels).
    #[test]
    fn the_avx2_solve_gives_the_portable_solves_bits() {
        for n in [8, 32, 64] {
            let (fast, fast_report) = solve_on_this_thread(n, false);
            let (plain, plain_report) = solve_on_this_thread(n, true);
            assert_eq!(fast_report, plain_report, "n {n}");
            let differ = differing_bits(&fast, &plain);
            assert_eq!(differ, 0, "n {n}: cells differ");
            assert!(fast_report.iterations >= 2, "n {n}: {fast_report:?}");
        }
    }

    /// A stiff system (weights 10⁴× the mass term, as a frame's Marangoni step gives)
    /// converges to 1e-12 from zero in at most 20 iterations at n = 16 and 64 alike (the
    /// multigrid preconditioner keeps the count from growing with the grid), and the
    /// answer satisfies the system: the `f32` V-cycle does not keep the `f64` iterations
    /// from a tolerance far below `f32`'s rounding. n = 1, 3 and 5 are one level, solved
    /// directly; 6 and 12 coarsen to an odd face (3).
    #[test]
    fn stiff_system_converges_in_few_iterations() {
        for n in [1, 2, 3, 5, 6, 12, 16, 64] {
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
    /// the plain solve from `x`, whether it is already within it or still iterates from
    /// there (from the guess's residual); a guess worse than `x` is not taken.
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
        let rough: Vec<f64> = answer.iter().map(|a| a + 1e-3 * (a - 1.0)).collect();
        let worst = |x: &[f64]| {
            x.iter()
                .zip(&answer)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max)
        };
        let (plain, _) = solve(None, &mut work);
        let (ignored, _) = solve(Some(&far), &mut work);
        assert_eq!(ignored, plain);
        for (guess, iterating) in [(&near, false), (&rough, true)] {
            let (guessed, x) = solve(Some(guess), &mut work);
            assert!(
                guessed.iterations < plain.iterations,
                "{guessed:?} vs {plain:?}"
            );
            assert_eq!(guessed.iterations > 0, iterating, "{guessed:?}");
            assert!(guessed.relative_residual <= 1e-6, "{guessed:?}");
            assert!(worst(&x) < 1e-8, "error {}", worst(&x));
        }
    }

    /// [`Hierarchy::solve_from_start_and_change`] is [`Hierarchy::solve_with_guess`] from
    /// the start with the guess `start + change` (summed in the grid's numbering), to the
    /// bit: with a change that is taken, one that is not (worse than the start) and none;
    /// the mass term given per cell or as face 0's (every face's the same); the weights
    /// (`f32` values) given as any `f64`s or as `f32` values (the conjugate gradients then
    /// ending in `f32`: [`Hierarchy::iterate_in_f32`]); at n = 64 and
    /// 16 (the mass term then held per face) and 3 (one level, where it cannot be).
    #[test]
    fn a_start_and_change_solve_as_the_start_and_its_guess() {
        for n in [64, 16, 3] {
            start_and_change_solve_alike(n);
        }
    }

    /// [`a_start_and_change_solve_as_the_start_and_its_guess`] at `n` cells a face.
    fn start_and_change_solve_alike(n: usize) {
        let (grid, h, alpha, weight, b) = stiff_system(n, |c| (2.0 * c.x - c.y * c.z).sin());
        // `f32` values, so that they can be given as such too.
        let weight32: Vec<f32> = weight.iter().map(|&w| w as f32).collect();
        let weight: Vec<f64> = weight32.iter().map(|&w| f64::from(w)).collect();
        let limits = SolveLimits {
            tolerance: 1e-9,
            max_iterations: 50,
        };
        let start: Vec<f64> = grid.centres().iter().map(|c| c.x * c.y).collect();
        let mut answer = start.clone();
        h.solve(
            &mut Work::default(),
            &alpha,
            &weight,
            &b,
            &mut answer,
            limits,
        );
        // Near the answer (the guess taken), and far from it (not taken).
        let near: Vec<f64> = answer
            .iter()
            .zip(&start)
            .map(|(a, s)| 0.9 * (a - s))
            .collect();
        let far: Vec<f64> = near.iter().map(|v| 1e3 * v).collect();
        let face = MassTerm::EveryFace(&alpha[..n * n]);
        let changes = [Some(&near), Some(&far), None];
        let weights = [Weights::F64(&weight), Weights::F32(&weight32)];
        for ((mass, change), weights) in [MassTerm::Cells(&alpha), face]
            .into_iter()
            .flat_map(|m| changes.map(|c| (m, c)))
            .flat_map(|mc| weights.map(|w| (mc, w)))
        {
            let mut work = Work::default();
            let guess: Option<Vec<f64>> =
                change.map(|c| start.iter().zip(c).map(|(s, c)| s + c).collect());
            let mut plain = start.clone();
            let system = (mass, weights, &b[..]);
            // The weights given alike: given as `f32` values, the conjugate gradients end
            // in `f32` ([`Hierarchy::iterate_in_f32`]).
            h.prepare_mass(&mut work, MassTerm::Cells(&alpha), weights);
            let expected = h.solve_prepared(&mut work, &b, &mut plain, guess.as_deref(), limits);
            let mut x = vec![f64::NAN; grid.cells()];
            let change = change.map(|c| &c[..]);
            let report = h.solve_from_start_and_change(
                &mut Work::default(),
                system,
                (&start, change),
                &mut x,
                limits,
            );
            let face = matches!(mass, MassTerm::EveryFace(_));
            let f32s = matches!(weights, Weights::F32(_));
            assert_eq!(
                report, expected,
                "n {n}, face 0's mass term: {face}, f32: {f32s}"
            );
            assert!(report.iterations >= 1, "{report:?}");
            let differ = differing_bits(&x, &plain);
            let change = change.map(|c| c[0]);
            assert_eq!(differ, 0, "change {change:?}, f32: {f32s}");
        }
    }

    /// Level `k`'s mass term at cell `c`, read as the kernels read it ([`LevelField`]).
    fn mass_at(h: &Hierarchy, work: &Work, k: usize, c: usize) -> f64 {
        let level = &h.levels[k];
        let field = if k == 0 {
            work.mass_term(0)
        } else {
            LevelField {
                values: &work.mass[k],
                per_face: false,
            }
        };
        let p = level.position[c] as usize;
        let face = c / (level.m * level.m);
        let shift = if field.per_face {
            level.face_start(face)
        } else {
            0
        };
        field.values[p - shift]
    }

    /// Edge weights of 10 to 22 in a pattern that repeats every 13 edges.
    fn test_weights(grid: &CubeSphere) -> Vec<f64> {
        (0..grid.edges().len())
            .map(|e| 10.0 + (e % 13) as f64)
            .collect()
    }

    /// A mass term whose faces differ (`1 + c mod 7`), and one whose faces are alike
    /// (`1 + (c mod n²) mod 7`), on `n` cells a face.
    fn mass_terms(n: usize) -> [(Vec<f64>, bool); 2] {
        let cells = 6 * n * n;
        let differ = (0..cells).map(|c| 1.0 + (c % 7) as f64).collect();
        let alike = (0..cells).map(|c| 1.0 + (c % (n * n) % 7) as f64).collect();
        [(differ, false), (alike, true)]
    }

    /// Every level's numbers as the grid's cells and edges give them, each side's weight
    /// read where [`Layout::side_weights`] names and the mass term as the kernels read
    /// it (held per face where the faces are alike and there is more than one level): the
    /// finest level's mass term and side weights at each cell's position, and each
    /// coarser level's mass the sum of its four children's, its side weights half the
    /// two fine weights along the side, and the same number seen from both cells of an
    /// edge (the matrix symmetric to the bit); outside the cells, the mass term
    /// [`NOT_A_CELL`] and every weight entry no cell reads zero.
    #[test]
    fn each_level_holds_the_grids_numbers_at_its_cells() {
        for n in [3, 6, 16] {
            let grid = CubeSphere::new(n);
            let h = Hierarchy::new(&grid);
            let weight = test_weights(&grid);
            let mut work = Work::default();
            for (alpha, alike) in mass_terms(n) {
                h.prepare(&mut work, &alpha, &weight);
                assert_eq!(work.mass_per_face, alike && n > 3, "n {n}");
                holds_the_grids_numbers(&h, &work, &alpha, &weight);
            }
        }
    }

    /// Weights given as `f32` values ([`Weights::F32`]) make the system their values
    /// given as `f64`s make, to the bit, though the finest level's weights are then held
    /// only in the V-cycle's scaled `f32` copy: the scale, every level's V-cycle numbers
    /// (mass term, inverse diagonal, weights), the coarse levels' `f64` numbers, the
    /// coarsest level's factor, and the conjugate gradients' product and starts'
    /// residuals on the finest level (read from the copy: [`Work::fine_weights`]); at
    /// n = 64 and 16 (the mass term held per face), 6 (the faces' mass terms differ, held
    /// whole) and 3 (one level: the weights widened), with AVX2 and without.
    #[test]
    fn weights_given_as_f32_values_make_their_f64_values_system() {
        let bits32 = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (n, portable) in [64, 16, 6, 3]
            .into_iter()
            .flat_map(|n| [(n, false), (n, true)])
        {
            crate::avx2::set_portable_only(portable);
            let (grid, h, alpha, weight, b) = stiff_system(n, |c| (2.0 * c.x - c.y * c.z).sin());
            let alpha: Vec<f64> = if n == 6 {
                let bump = |c: usize| 1.0 + 0.1 * (c % 5) as f64;
                alpha.iter().enumerate().map(|(c, a)| a * bump(c)).collect()
            } else {
                alpha
            };
            let weight32: Vec<f32> = weight.iter().map(|&w| w as f32).collect();
            let weight: Vec<f64> = weight32.iter().map(|&w| f64::from(w)).collect();
            let (mut wide, mut narrow) = (Work::default(), Work::default());
            h.prepare_mass(&mut wide, MassTerm::Cells(&alpha), Weights::F64(&weight));
            h.prepare_mass(
                &mut narrow,
                MassTerm::Cells(&alpha),
                Weights::F32(&weight32),
            );
            let levels = h.levels.len();
            assert_eq!(narrow.weights_f32, levels > 1, "n {n}");
            assert_eq!(narrow.mass_per_face, n == 64 || n == 16, "n {n}");
            assert_eq!(wide.scale.to_bits(), narrow.scale.to_bits(), "n {n}");
            for k in 0..levels - 1 {
                let (a, b) = (&wide, &narrow);
                assert_eq!(
                    bits32(&a.mass32[k]),
                    bits32(&b.mass32[k]),
                    "n {n} level {k}"
                );
                assert_eq!(
                    bits32(&a.inv_diag[k]),
                    bits32(&b.inv_diag[k]),
                    "n {n} level {k}"
                );
                for f in [RIGHT_W, TOP_W] {
                    let (a, b) = (&a.stencil32[k][f], &b.stencil32[k][f]);
                    assert_eq!(bits32(a), bits32(b), "n {n} level {k} field {f}");
                }
            }
            for k in usize::from(levels > 1)..levels {
                assert_eq!(
                    bits(&wide.mass[k]),
                    bits(&narrow.mass[k]),
                    "n {n} level {k}"
                );
                for f in [RIGHT_W, TOP_W] {
                    let (a, b) = (&wide.stencil[k][f], &narrow.stencil[k][f]);
                    assert_eq!(bits(a), bits(b), "n {n} level {k} field {f}");
                }
            }
            let factor = |w: &Work| format!("{:?}", w.coarse_factor);
            assert_eq!(factor(&wide), factor(&narrow), "n {n}");
            let fine = &h.levels[0];
            let field = |k: usize| -> Vec<f64> {
                let values: Vec<f64> = (0..grid.cells())
                    .map(|c| ((c * k) % 11) as f64 / 3.0 + alpha[c])
                    .collect();
                let mut split = Vec::new();
                to_split(fine, &values, &mut split);
                refresh_all(fine, &mut split);
                split
            };
            let (x, guess) = (field(37), field(53));
            let operated = |work: &Work| {
                let mut q = vec![f64::NAN; fine.len()];
                with_avx2(|| h.apply(work, &x, &mut q));
                let (mut r, mut s) = (Vec::new(), vec![f64::NAN; fine.len()]);
                to_split(fine, &b, &mut r);
                let starts = [Some(&x[..]), Some(&guess[..])];
                with_avx2(|| h.start_residuals(work, starts, [&mut r, &mut s]));
                [q, r, s].map(|v| bits(&v))
            };
            assert_eq!(operated(&wide), operated(&narrow), "n {n}");
            crate::avx2::set_portable_only(false);
        }
    }

    /// [`each_level_holds_the_grids_numbers_at_its_cells`] for one system.
    fn holds_the_grids_numbers(h: &Hierarchy, work: &Work, alpha: &[f64], weight: &[f64]) {
        let fine = &h.levels[0];
        let n = fine.m;
        let sides = CellSides::new(&CubeSphere::new(n));
        for c in 0..fine.position.len() {
            assert_eq!(mass_at(h, work, 0, c), alpha[c], "n {n} cell {c}");
            for (k, (field, q)) in fine.side_weights(c).into_iter().enumerate() {
                let expected = weight[sides.edge[c][k] as usize];
                assert_eq!(work.stencil[0][field][q], expected, "n {n} {c} side {k}");
            }
        }
        for (k, level) in h.levels.iter().enumerate() {
            outside_the_cells_nothing_is_read(level, &work.mass[k], &work.stencil[k]);
        }
        for k in 1..h.levels.len() {
            let (fine, coarse) = (&h.levels[k - 1], &h.levels[k]);
            let side = |level: &Layout, w: &Stencil<f64>, c: usize, s: usize| {
                let (field, q) = level.side_weights(c)[s];
                w[field][q]
            };
            let mut children = vec![0.0; coarse.position.len()];
            let mut child_side = vec![[0.0; 4]; coarse.position.len()];
            let m = fine.m;
            for c in 0..fine.position.len() {
                let parent = parent_cell(m, c);
                children[parent] += mass_at(h, work, k - 1, c);
                let (x, y) = (c % m, (c / m) % m);
                let on = [x % 2 == 0, x % 2 == 1, y % 2 == 0, y % 2 == 1];
                for s in 0..4 {
                    if on[s] {
                        child_side[parent][s] += 0.5 * side(fine, &work.stencil[k - 1], c, s);
                    }
                }
            }
            let w = &work.stencil[k];
            for c in 0..coarse.position.len() {
                let rel = (mass_at(h, work, k, c) - children[c]).abs() / children[c];
                assert!(rel < 1e-15, "n {n} level {k} cell {c}: {rel:e}");
                for (s, expected) in child_side[c].into_iter().enumerate() {
                    let got = side(coarse, w, c, s);
                    let rel = (got - expected).abs() / expected;
                    assert!(rel < 1e-15, "n {n} level {k} cell {c} side {s}: {rel:e}");
                    let j = coarse.neighbour[c][s] as usize;
                    let back = (0..4).find(|&b| coarse.neighbour[j][b] as usize == c);
                    let back = back.expect("the neighbour's side back");
                    let there = side(coarse, w, j, back);
                    assert_eq!(got.to_bits(), there.to_bits(), "n {n} {c}-{j}");
                }
            }
        }
    }

    /// The grid's cell areas, the Marangoni step's mass term, are alike on every face to
    /// the bit, so that its systems' mass terms are held per face.
    #[test]
    fn every_faces_areas_are_face_zeros() {
        for n in [2, 5, 16, 64] {
            assert!(faces_alike(CubeSphere::new(n).areas_sr()), "n {n}");
        }
        let mut areas = CubeSphere::new(16).areas_sr().to_vec();
        areas[5 * 256 + 17] *= 1.0 + f64::EPSILON;
        assert!(!faces_alike(&areas));
    }

    /// A start a small change away from the answer of the system `(alpha, weight, b)`
    /// (solved tightly): its residual is a small part of the weights' product with it,
    /// as a stiff step's is.
    fn near_the_answer(
        grid: &CubeSphere,
        h: &Hierarchy,
        (alpha, weight, b): (&[f64], &[f64], &[f64]),
    ) -> Vec<f64> {
        let mut x = vec![0.0; grid.cells()];
        let tight = SolveLimits {
            tolerance: 1e-13,
            max_iterations: 200,
        };
        h.solve(&mut Work::default(), alpha, weight, b, &mut x, tight);
        let largest = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let centres = grid.centres().iter();
        let bump = |c: &glam::DVec3| 1e-5 * largest * (3.0 * c.x).sin();
        x.iter().zip(centres).map(|(x, c)| x + bump(c)).collect()
    }

    /// The conjugate gradients' `f32` iterations ([`Hierarchy::iterate_in_f32`], for
    /// weights given as [`Weights::F32`]) end where the true residual of the given
    /// weights' system, formed afresh in `f64` from the answer straight from the grid's
    /// edges, meets the tolerance: it differs from the residual the iterations tracked
    /// (and report) by a twentieth of the tolerance at most; at n = 64 and 32, from a
    /// start that reaches the `f32` iterations after one iteration, from one that
    /// reaches them later, and from one near the answer (where a start's residual is a
    /// small part of `M x₀`: a start's residual taken with any other numbers than the
    /// system's, as when it was taken with the `f32` roundings of `f64` weights, answers
    /// another system, and this test's true residuals then missed the tracked ones by
    /// 0.4 of the tolerance); and with AVX2 as without, to the bit.
    #[test]
    fn the_f32_iterations_meet_the_tolerance_on_the_true_residual() {
        for n in [64, 32] {
            let (grid, h, alpha, weight, b) = stiff_system(n, |c| (2.0 * c.x - c.y * c.z).sin());
            let weight32: Vec<f32> = weight.iter().map(|&w| w as f32).collect();
            let weight: Vec<f64> = weight32.iter().map(|&w| f64::from(w)).collect();
            let limits = SolveLimits {
                tolerance: 1e-6,
                max_iterations: 50,
            };
            for start in [
                vec![0.0; grid.cells()],
                grid.centres().iter().map(|c| 1e3 * c.y).collect(),
                near_the_answer(&grid, &h, (&alpha, &weight, &b)),
            ] {
                let mut answers = Vec::new();
                for portable in [false, true] {
                    crate::avx2::set_portable_only(portable);
                    let mut work = Work::default();
                    let mut x = vec![f64::NAN; grid.cells()];
                    let system = (MassTerm::Cells(&alpha), Weights::F32(&weight32), &b[..]);
                    let report = h.solve_from_start_and_change(
                        &mut work,
                        system,
                        (&start, None),
                        &mut x,
                        limits,
                    );
                    crate::avx2::set_portable_only(false);
                    assert!(!work.p32.is_empty(), "n {n}: no f32 iterations, {report:?}");
                    let mx = grid_apply(&grid, &alpha, &weight, &x);
                    let left: f64 = b.iter().zip(&mx).map(|(b, m)| (b - m) * (b - m)).sum();
                    let relative = left.sqrt() / report.start_residual;
                    let tolerance = limits.tolerance;
                    assert!(
                        relative <= 1.05 * tolerance,
                        "n {n}: {relative:e}, {report:?}"
                    );
                    let apart = (relative - report.relative_residual).abs();
                    assert!(apart <= 0.05 * tolerance, "n {n}: {relative:e}, {report:?}");
                    answers.push((x, report));
                }
                let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(answers[0].1, answers[1].1, "n {n}");
                assert!(
                    bits(&answers[0].0) == bits(&answers[1].0),
                    "n {n}: AVX2 differs"
                );
            }
        }
    }

    /// [`dot_f32`] sums lane `k` over the `i ≡ k (mod 32)` in order in `f32`, then the
    /// lanes and the tail's widened products in order in `f64`: to the bit, with AVX2 and
    /// without, at lengths with and without a tail and shorter than a lane chunk.
    #[test]
    fn the_f32_dot_sums_its_lanes_in_order() {
        for len in [0, 5, 32, 100, 1000, 26136] {
            let a: Vec<f32> = (0..len)
                .map(|i| ((i * 37) % 101) as f32 * 0.37 - 9.0)
                .collect();
            let b: Vec<f32> = (0..len)
                .map(|i| ((i * 11) % 13) as f32 * 1.3 + 0.1)
                .collect();
            let main = len - len % 32;
            let mut lanes = [0.0f32; 32];
            for i in 0..main {
                lanes[i % 32] += a[i] * b[i];
            }
            let mut expected = 0.0;
            for lane in lanes {
                expected += f64::from(lane);
            }
            for i in main..len {
                expected += f64::from(a[i]) * f64::from(b[i]);
            }
            for portable in [false, true] {
                crate::avx2::set_portable_only(portable);
                let got = with_avx2(|| dot_f32(&a, &b));
                crate::avx2::set_portable_only(false);
                assert_eq!(
                    got.to_bits(),
                    expected.to_bits(),
                    "len {len}, portable {portable}"
                );
            }
        }
    }

    /// The split layout's scatters and gathers (their `f64` chunks, and the scatters'
    /// `f32` ones, copied by AVX2 shuffles where the processor has it,
    /// [`Real::deinterleave`]) put each value at its padded index's position and read it
    /// back, with and without AVX2: runs of every length from 0 to 40 from both colours'
    /// first cells, in `f64` and `f32`, and whole fields at face sizes with odd and even
    /// rows.
    #[test]
    fn scatters_and_gathers_put_each_value_at_its_position() {
        for portable in [false, true] {
            crate::avx2::set_portable_only(portable);
            for n in [3, 8, 13, 64] {
                let layout = &Hierarchy::new(&CubeSphere::new(n)).levels[0];
                for first in [layout.padded_at(1, 2, 0), layout.padded_at(1, 2, 1)] {
                    for len in 0..=40.min(layout.stride() - 1) {
                        let values: Vec<f64> = (0..len).map(|j| j as f64 + 0.5).collect();
                        let mut out = vec![-1.0; layout.len()];
                        scatter_run(layout, first, &values, &mut out);
                        let mut expected = vec![-1.0; layout.len()];
                        for (j, v) in values.iter().enumerate() {
                            expected[layout.index(first + j)] = *v;
                        }
                        assert_eq!(out, expected, "n {n} first {first} len {len}");
                        let narrow: Vec<f32> = values.iter().map(|&v| v as f32).collect();
                        let mut out32 = vec![-1.0f32; layout.len()];
                        scatter_run(layout, first, &narrow, &mut out32);
                        let expected32: Vec<f32> = expected.iter().map(|&v| v as f32).collect();
                        assert_eq!(out32, expected32, "f32: n {n} first {first} len {len}");
                    }
                }
                let cells = 6 * n * n;
                let values: Vec<f64> = (0..cells).map(|c| c as f64 * 0.25 - 7.0).collect();
                let mut field = vec![-1.0; layout.len()];
                to_split(layout, &values, &mut field);
                for (c, &p) in layout.position.iter().enumerate() {
                    assert_eq!(field[p as usize], values[c], "n {n} cell {c}");
                }
                let mut back = vec![0.0; cells];
                from_split(layout, &mut field, &mut back);
                assert_eq!(back, values, "n {n}");
            }
            crate::avx2::set_portable_only(false);
        }
    }

    /// The operator applies the grid's system at every cell, through the halo, the
    /// weights held once an edge and the mass term held whole or per face, and gives zero
    /// at every other position (there the weight entries hold seam weights, the values
    /// halo copies).
    #[test]
    fn the_operator_applies_the_grids_system_and_gives_zero_outside_the_cells() {
        for (n, (alpha, _)) in [1, 3, 6, 16]
            .into_iter()
            .flat_map(|n| mass_terms(n).map(|m| (n, m)))
        {
            let grid = CubeSphere::new(n);
            let h = Hierarchy::new(&grid);
            let cells = grid.cells();
            let weight = test_weights(&grid);
            let x: Vec<f64> = (0..cells).map(|c| ((c * 37) % 11) as f64 - 5.0).collect();
            let mut work = Work::default();
            h.prepare(&mut work, &alpha, &weight);
            let fine = &h.levels[0];
            let mut xs = Vec::new();
            to_split(fine, &x, &mut xs);
            refresh_all(fine, &mut xs);
            let none = vec![0.0; fine.len()];
            let mut out = vec![f64::NAN; fine.len()];
            let (mass, w) = (work.mass_term(0), &work.stencil[0]);
            operator::<f64, f64, false>(fine, mass, (w, 1.0), &none, &xs, &mut out);
            let expected = grid_apply(&grid, &alpha, &weight, &x);
            for (c, &p) in fine.position.iter().enumerate() {
                let err = (out[p as usize] - expected[c]).abs();
                assert!(err <= 1e-12 * expected[c].abs().max(1.0), "n {n} cell {c}");
            }
            for (p, v) in out.iter().enumerate() {
                assert!(fine.is_cell(p) || *v == 0.0, "n {n} position {p}: {v}");
            }
        }
    }

    /// Both starts' residuals taken in place from the `b` the first output holds are the
    /// operator's residuals from `b` apart, to the bit, and zero outside the cells: with
    /// both starts, and with the first alone (the second output then only zeroed there).
    #[test]
    fn residuals_in_place_are_the_operators_residuals() {
        for n in [3, 16] {
            let grid = CubeSphere::new(n);
            let h = Hierarchy::new(&grid);
            let cells = grid.cells();
            let weight = test_weights(&grid);
            let alpha: Vec<f64> = (0..cells).map(|c| 1.0 + (c % 5) as f64).collect();
            let field = |k: usize| -> Vec<f64> {
                (0..cells)
                    .map(|c| (((c * k) % 11) as f64 - 5.0) / 3.0)
                    .collect()
            };
            let mut work = Work::default();
            h.prepare(&mut work, &alpha, &weight);
            let fine = &h.levels[0];
            let [mut b, mut x, mut g] = [Vec::new(), Vec::new(), Vec::new()];
            for (values, split) in [(field(7), &mut b), (field(37), &mut x), (field(53), &mut g)] {
                to_split(fine, &values, split);
                refresh_all(fine, split);
            }
            let (mass, w) = (work.mass_term(0), &work.stencil[0]);
            let plain = |start: &[f64]| {
                let mut out = vec![f64::NAN; fine.len()];
                operator::<f64, f64, true>(fine, mass, (w, 1.0), &b, start, &mut out);
                out
            };
            let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            for guess in [Some(&g[..]), None] {
                let (mut r, mut q) = (b.clone(), vec![f64::NAN; fine.len()]);
                let system = (mass, (w, 1.0));
                residuals_in_place(fine, system, [Some(&x[..]), guess], [&mut r, &mut q]);
                assert_eq!(bits(&r), bits(&plain(&x)), "n {n}");
                if let Some(g) = guess {
                    assert_eq!(bits(&q), bits(&plain(g)), "n {n}");
                }
                for p in (0..fine.len()).filter(|&p| !fine.is_cell(p)) {
                    assert_eq!(r[p], 0.0, "n {n} position {p}");
                }
            }
        }
    }

    /// A level's mass term is [`NOT_A_CELL`] at every position outside its cells, and
    /// its weight fields zero at every entry that no cell's side reads.
    fn outside_the_cells_nothing_is_read(level: &Layout, mass: &[f64], w: &Stencil<f64>) {
        let mut read = [vec![false; level.len()], vec![false; level.len()]];
        for c in 0..level.position.len() {
            for (field, q) in level.side_weights(c) {
                read[field][q] = true;
            }
        }
        for p in 0..level.len() {
            if !level.is_cell(p) {
                assert_eq!(mass[p], NOT_A_CELL, "m {} position {p}", level.m);
            }
            for field in [RIGHT_W, TOP_W] {
                if !read[field][p] {
                    assert_eq!(w[field][p], 0.0, "m {} field {field} at {p}", level.m);
                }
            }
        }
    }

    /// A field in level `level`'s split layout, `f32`, zero outside the cells and at
    /// each cell a number in `[-1, 1)` from `seed` (a fixed hash, not a generator).
    fn cell_field(level: &Layout, seed: usize) -> Vec<f32> {
        let mut field = vec![0.0; level.len()];
        for (c, &p) in level.position.iter().enumerate() {
            let hash = (c * 2_654_435_761 + seed * 40_503) % 1_000_003;
            field[p as usize] = hash as f32 / 500_001.5 - 1.0;
        }
        field
    }

    /// `a·b` over a level's cells, in `f64`.
    fn cell_dot(level: &Layout, a: &[f32], b: &[f32]) -> f64 {
        let at = |v: &[f32], p: u32| f64::from(v[p as usize]);
        level.position.iter().map(|&p| at(a, p) * at(b, p)).sum()
    }

    /// The V-cycle is a symmetric map, as the conjugate gradients need of their
    /// preconditioner: `⟨V(a), b⟩ = ⟨a, V(b)⟩` up to its `f32` rounding, for fields `a`
    /// and `b` of the stiff system at n = 8 (two levels), 32 (four) and 64 (five, more
    /// sweeps on each: [`sweeps`]), each level's sweeps run forward before the coarse
    /// correction and backward after it.
    #[test]
    fn the_v_cycle_is_symmetric() {
        for n in [8, 32, 64] {
            let (_, h, alpha, weight, _) = stiff_system(n, |c| c.x);
            let mut work = Work::default();
            h.prepare(&mut work, &alpha, &weight);
            let fine = &h.levels[0];
            let (a, b) = (cell_field(fine, 1), cell_field(fine, 2));
            let (mut va, mut vb) = (vec![0.0; fine.len()], vec![0.0; fine.len()]);
            h.v_cycle(&mut work, 0, &a, &mut va);
            h.v_cycle(&mut work, 0, &b, &mut vb);
            let (ab, ba) = (cell_dot(fine, &va, &b), cell_dot(fine, &a, &vb));
            let scale = cell_dot(fine, &va, &va).sqrt() * cell_dot(fine, &b, &b).sqrt();
            let asymmetry = (ab - ba).abs() / scale;
            assert!(asymmetry < 1e-7, "n {n}: {ab} vs {ba}, {asymmetry:e}");
        }
    }

    /// The V-cycle's restriction is its coarse correction's transpose, to the bit: each
    /// fine cell takes its parent's value (and no other) and gives its residual to its
    /// parent (and no other), at coarse faces of 1, 2 and 4 cells.
    #[test]
    fn the_restriction_is_the_corrections_transpose() {
        for n in [2, 4, 8] {
            let fine = Layout::of_grid(&CellSides::new(&CubeSphere::new(n)));
            let coarse = fine.coarser();
            let (nf, nc) = (fine.position.len(), coarse.position.len());
            let mut row = Vec::new();
            let mut prolong = vec![vec![0.0; nc]; nf];
            for c in 0..nc {
                let mut zc = vec![0.0; coarse.len()];
                zc[coarse.position[c] as usize] = 1.0;
                let mut z = vec![0.0; fine.len()];
                correct(&fine, &coarse, &zc, &mut z);
                for (f, p) in fine.position.iter().enumerate() {
                    prolong[f][c] = z[*p as usize];
                }
            }
            for f in 0..nf {
                let mut d = vec![0.0f32; fine.len()];
                d[fine.position[f] as usize] = 1.0;
                let mut out = vec![0.0; coarse.len()];
                restrict(&fine, &d, &coarse, &mut out, &mut row);
                for c in 0..nc {
                    let given = out[coarse.position[c] as usize];
                    let parent = if parent_cell(n, f) == c { 1.0 } else { 0.0 };
                    assert_eq!(prolong[f][c], parent, "n {n} fine {f} coarse {c}");
                    assert_eq!(given.to_bits(), prolong[f][c].to_bits(), "n {n} {f} {c}");
                }
            }
        }
    }

    /// The coarse correction a face at a time gives the bits of its plain form: each
    /// coarse row gathered ([`gather_row`]) and added to its four fine child runs in
    /// turn; at coarse faces of odd sizes, of sizes below and above a chunk, and of 32.
    #[test]
    fn the_correction_by_faces_is_the_correction_by_rows() {
        for n in [2, 6, 8, 10, 24, 64] {
            let fine = Layout::of_grid(&CellSides::new(&CubeSphere::new(n)));
            let coarse = fine.coarser();
            let noise = |len: usize, seed: usize| -> Vec<f32> {
                (0..len)
                    .map(|i| (((i * 7919 + seed * 104_729) % 1000) as f32 - 500.0) / 37.0)
                    .collect()
            };
            let (mut zc, z) = (noise(coarse.len(), 1), noise(fine.len(), 2));
            let mut by_faces = z.clone();
            correct(&fine, &coarse, &zc, &mut by_faces);
            let (mut by_rows, mut row) = (z, vec![0.0; coarse.m]);
            for face in 0..6 {
                for y in 0..coarse.m {
                    gather_row(&coarse, face, y, &mut zc, &mut row);
                    for j in 0..2 {
                        for start in fine.children_of_row(face, y, j) {
                            for (zi, v) in by_rows[start..][..coarse.m].iter_mut().zip(&row) {
                                *zi += *v;
                            }
                        }
                    }
                }
            }
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&by_faces), bits(&by_rows), "n {n}");
        }
    }

    /// The restriction a face at a time gives the bits of its plain form: each coarse
    /// row's sums formed from its fine child runs ([`Layout::children_of_row`]) and
    /// scattered ([`scatter_row`]); in `f32` and `f64`, of a field held whole and per
    /// face, at coarse faces of odd sizes, of sizes below and above a chunk, and of 32.
    #[test]
    fn the_restriction_by_faces_is_the_restriction_by_rows() {
        fn by_rows<T: Real>(fine: &Layout, values: &[T], from: usize, coarse: &Layout) -> Vec<T> {
            let (m, mut out) = (coarse.m, vec![T::ZERO; coarse.len()]);
            for face in 0..6 {
                let f = if from == 6 { face } else { from };
                for y in 0..m {
                    let [a0, b0] = fine.children_of_row(f, y, 0);
                    let [a1, b1] = fine.children_of_row(f, y, 1);
                    let row: Vec<T> = (0..m)
                        .map(|x| {
                            (values[a0 + x] + values[b0 + x]) + (values[a1 + x] + values[b1 + x])
                        })
                        .collect();
                    scatter_row(coarse, face, y, &row, &mut out);
                }
            }
            out
        }
        for n in [2, 6, 8, 10, 24, 64] {
            let fine = Layout::of_grid(&CellSides::new(&CubeSphere::new(n)));
            let coarse = fine.coarser();
            let values: Vec<f64> = (0..fine.len())
                .map(|i| (((i * 7919) % 1000) as f64 - 500.0) / 37.0)
                .collect();
            let narrow: Vec<f32> = values.iter().map(|v| *v as f32).collect();
            let (mut out32, mut out, mut row32, mut row) = (
                vec![0.0f32; coarse.len()],
                vec![0.0; coarse.len()],
                Vec::new(),
                Vec::new(),
            );
            restrict(&fine, &narrow, &coarse, &mut out32, &mut row32);
            let bits32 = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let expected = by_rows(&fine, &narrow, 6, &coarse);
            assert_eq!(bits32(&out32), bits32(&expected), "n {n} f32");
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            for (per_face, from) in [(false, 6), (true, 0)] {
                let field = LevelField {
                    values: &values,
                    per_face,
                };
                restrict_field(&fine, field, &coarse, &mut out, &mut row);
                let expected = by_rows(&fine, &values, from, &coarse);
                assert_eq!(bits(&out), bits(&expected), "n {n} per face {per_face}");
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

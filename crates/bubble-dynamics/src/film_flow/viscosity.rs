//! The thin viscous sheet's stress `ν(−∇×∇×u + 2Ku + 4∇∇·u)` on the edge velocities,
//! explicit, in the stages of a first-order Runge–Kutta–Legendre step (RKL1, Meyer,
//! Balsara & Aslam 2014, J. Comput. Phys. 257, 594).
//!
//! Forward Euler is stable while `dt·λ ≤ 2` for the operator's largest rate `λ`, which
//! grows as n²: at n = 256 a 1/60 s step took 20-odd sub-steps. `s` RKL1 stages are
//! stable up to `dt·λ ≤ s² + s`, the span of `s(s + 1)/2` forward-Euler sub-steps, for
//! the cost of `s` of them: the stage count grows as n, not n². Each stage is a
//! forward-Euler sub-step of its own length plus a blend with the two stages before it.

use crate::avx2::with_avx2;

use super::face_rows::{FaceRows, SeamEdge, Side, face_order};
use super::flow::FilmFlow;
use super::grid::CubeSphere;

/// Largest `dt·λ` a forward-Euler sub-step is given under [`viscous_bound`] (of the 2 it
/// can take), kept for the stages' span. The bound is a Gershgorin row sum: the
/// operator's true largest rate is 0.61 of it at n = 32 and 0.64 at n = 64 (power
/// iteration, test `the_viscous_bound_is_loose_enough_for_its_limit`), so 1.9 keeps every
/// mode's true `dt·λ` within 1.2 of a sub-step, 0.61 of the stages' span, where each
/// is damped. (1.5 was kept before that was measured: 2 stages instead of 1 for
/// the bench's film at n = 64, whose `dt·λ` under the bound is 1.59.)
const EULER_RATE_LIMIT: f64 = 1.9;

/// Buffers of the viscous step, reused across steps.
#[derive(Clone, Debug, Default)]
pub(super) struct ViscousScratch {
    /// The stage before the one under way, in the face rows ([`FaceRows`]), or in the
    /// grid's numbering (its inner edges, [`FilmFlow::viscous_step_to_grid`], whose last
    /// stage leaves the grid's velocities here), m/s. Between steps, a buffer of the
    /// grid's (`FilmFlow::momentum_explicit` swaps it with the grid's velocities' buffer).
    pub(super) stage: Vec<f64>,
    /// Per local vertex: the vorticity on the unit sphere (m/s per rad), of the vertices
    /// on the faces' borders only (every copy); the inner ones are taken row by row into
    /// [`Self::window`].
    vorticity: Vec<f64>,
    /// Per cell, in the padded layout (`FaceRows::padded_cell`): 4 times the divergence
    /// on the unit sphere (m/s per rad) of the cells on the faces' borders, and in the
    /// halo of the cells across them ([`Self::inverse_areas_4`] says why); the inner ones
    /// are taken row by row into [`Self::window`].
    divergence: Vec<f64>,
    /// Per cell of face 0, which every face reads ([`FaceRows`] says why): 4 times its
    /// inverse area, per sr. The divergences are kept 4 times over, so that their
    /// differences are the stress's `4 grad div` without a multiplication an edge: a
    /// power of 2 scales a product exactly (short of the subnormals), so the bits are
    /// those of `4 · ((a − b) · id)`.
    inverse_areas_4: Vec<f64>,
    /// The rows of vertices and cells a face's edge rows read ([`Window`]).
    window: Window,
    /// Per face, per border of it (its left and right X-edge columns, its bottom and top
    /// Y-edge rows), along it: the value of the stage before last of that border's local
    /// copies, where [`FilmFlow::viscous_step_to_grid`] keeps the inner edges' in
    /// [`Self::stage`] in the grid's numbering (a copy's own slot: the other copy of its
    /// edge may have moved).
    border_prev: Vec<f64>,
    /// Per edge on the faces' borders ([`FaceRows::seam_edges`]): its grid edge, its first
    /// copy's slot in [`Self::border_prev`] and that copy's sign.
    seam_slots: Vec<(u32, u32, f64)>,
}

/// The vorticity and divergence rows that one face's edge rows under way read: each
/// taken just before the first edge row that reads it, from edges that have not moved yet,
/// so that a stage reads each edge once, where whole-grid passes of vorticity,
/// divergence and update read the velocities three times and wrote and read 0.4 MB of
/// fields besides (at n = 64, beyond the core's 1 MB L2 with the velocities).
#[derive(Clone, Debug, Default)]
struct Window {
    /// Vertex rows `j` at `j mod 2`, `n + 1` each.
    vertex: [Vec<f64>; 2],
    /// Padded cell rows `p` at `p mod 2`, `n + 2` each (the halo at both ends): 4 times
    /// the cells' divergences ([`ViscousScratch::inverse_areas_4`]).
    cell: [Vec<f64>; 2],
}

impl FilmFlow {
    /// `u ← u + ∫ viscous dt` over `dt_s` for kinematic viscosity `nu_m2_per_s`, on the
    /// edge velocities `u` in the face rows ([`FaceRows`]). The stages' faces go in
    /// alternate directions, the first in reverse where `first_reverse` ([`face_order`]:
    /// each stage starts on the faces the pass before ended on, so the first's reverse
    /// where that pass ended on face 5).
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn viscous_step(
        &self,
        u: &mut [f64],
        v: &mut ViscousScratch,
        nu_m2_per_s: f64,
        dt_s: f64,
        first_reverse: bool,
    ) {
        let (stages, w1) = self.legendre(nu_m2_per_s, dt_s);
        // The first stage reads no stage before last (it only writes Y₀ there, where a
        // stage follows), so `v.stage` needs its length, not a copy of u; a lone stage
        // touches it not at all.
        v.stage.resize(u.len(), 0.0);
        with_avx2(
            #[inline(always)]
            || {
                for j in 1..=stages {
                    let (order, weights, dt) = stage_of(j, stages, (w1, dt_s), first_reverse);
                    self.viscous_stage(u, v, nu_m2_per_s, dt, weights, order);
                }
            },
        );
    }

    /// [`Self::viscous_step`], its result left in `v.stage` in the grid's numbering and
    /// orientation ([`FaceRows::to_grid`] of it: the same bits), `u` then junk. The stages
    /// keep the stage before last in `v.stage` in the grid's numbering (the copies on the
    /// faces' borders in [`ViscousScratch::border_prev`]), and the last writes each edge
    /// there in place of it: the pass that copied the rows back (0.4 MB read and written
    /// at n = 64) is spared. For grids of at least 2 cells a face.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn viscous_step_to_grid(
        &self,
        u: &mut [f64],
        v: &mut ViscousScratch,
        nu_m2_per_s: f64,
        dt_s: f64,
        first_reverse: bool,
    ) {
        let rows = &self.rows;
        let n = rows.n;
        // Every entry is written (the inner edges by the faces' rows, the seams below).
        v.stage.resize(self.grid.edges().len(), 0.0);
        v.border_prev.resize(6 * 4 * n, 0.0);
        if v.seam_slots.len() != rows.seam_edges.len() {
            v.seam_slots = seam_slots(rows);
        }
        let (stages, w1) = self.legendre(nu_m2_per_s, dt_s);
        with_avx2(
            #[inline(always)]
            || {
                for j in 1..=stages {
                    let (order, weights, dt) = stage_of(j, stages, (w1, dt_s), first_reverse);
                    self.viscous_stage_grid(u, v, nu_m2_per_s, dt, weights, order);
                }
                for &(e, slot, sign) in &v.seam_slots {
                    v.stage[e as usize] = v.border_prev[slot as usize] * sign;
                }
            },
        );
    }

    /// The RKL1 stages for `nu_m2_per_s` over `dt_s`, and the first's weight `w₁`.
    fn legendre(&self, nu_m2_per_s: f64, dt_s: f64) -> (u32, f64) {
        let r = self.params.radius_m;
        let rate = self.viscous_bound * nu_m2_per_s / (r * r);
        let stages = legendre_stages((dt_s * rate / EULER_RATE_LIMIT).ceil().max(1.0));
        (stages, 2.0 / f64::from(stages * stages + stages))
    }

    /// A stage's set-up, the same for both of its passes: the border cells' vorticity
    /// and divergence from `u` (with [`ViscousScratch::inverse_areas_4`], taken here the
    /// first time), and the stage's [`Blend`].
    #[inline(always)]
    fn stage_set_up(
        &self,
        u: &[f64],
        v: &mut ViscousScratch,
        nu: f64,
        dt_s: f64,
        (mu, nu_prev): (f64, f64),
    ) -> Blend {
        let n = self.rows.n;
        if v.inverse_areas_4.len() != n * n {
            let ia = &self.grid.inverse_areas_per_sr()[..n * n];
            v.inverse_areas_4 = ia.iter().map(|a| 4.0 * a).collect();
        }
        border_fields(&self.rows, u, v);
        v.window.prepare(n);
        // Vorticity and divergence per R (of the unit sphere's), and each difference of
        // them per R again: every term of the stress carries 1/R², taken once here.
        let r = self.params.radius_m;
        Blend {
            rate: dt_s * nu / (r * r),
            mu,
            nu_prev,
        }
    }

    /// [`Self::viscous_stage`] with the stage before last in the grid's numbering
    /// ([`Self::viscous_step_to_grid`]).
    #[inline(always)]
    fn viscous_stage_grid(
        &self,
        u: &mut [f64],
        v: &mut ViscousScratch,
        nu: f64,
        dt_s: f64,
        (mu, nu_prev): (f64, f64),
        (last, reverse): (bool, bool),
    ) {
        let rows = &self.rows;
        let blend = self.stage_set_up(u, v, nu, dt_s, (mu, nu_prev));
        let n = rows.n;
        let (epf, vpf, cpf) = rows.per_face();
        let ViscousScratch {
            stage,
            vorticity,
            divergence,
            window,
            border_prev,
            inverse_areas_4: ia,
            ..
        } = v;
        // The grid's inner X-edges, then its inner Y-edges, `m` a face (`FaceLayout`).
        let m = n * (n - 1);
        for f in face_order(reverse) {
            let u = &mut u[f * epf..][..epf];
            // The face's inner X-edges and the one edge after them, which its last row
            // runs on through (`GridPrev::inner_x`), below its inner Y-edges.
            let (x_part, y_part) = stage.split_at_mut(6 * m + f * m);
            let prev = GridPrev {
                inner_x: &mut x_part[f * m..][..=m],
                inner_y: &mut y_part[..m],
                border: &mut border_prev[f * 4 * n..][..4 * n],
            };
            let borders = (&vorticity[f * vpf..][..vpf], &divergence[f * cpf..][..cpf]);
            let face = Face::new(rows, ia, borders);
            match (nu_prev != 0.0, !last) {
                (false, false) => blend.face_grid::<false, false, true>(face, u, prev, window),
                (false, true) => blend.face_grid::<false, true, false>(face, u, prev, window),
                (true, false) => blend.face_grid::<true, false, true>(face, u, prev, window),
                (true, true) => blend.face_grid::<true, true, false>(face, u, prev, window),
            }
        }
    }

    /// One stage on the rows: `u ← mu·u + nu_prev·stage + dt_s·M(u)` with the stage
    /// before last in `v.stage` (read only where `nu_prev` is not 0), which then holds the
    /// `u` this stage started from, unless the stage is the `last` (which no stage reads:
    /// 0.4 MB written and, with the portable blend's select, read a step at n = 64). The
    /// faces in reverse order where `reverse` ([`face_order`]).
    ///
    /// Every value is the grid-numbered pass's to rounding (the grid's constants are face
    /// 0's, [`FaceRows`]), in the rows' orientation (module `face_rows`): each edge's
    /// change is odd in the edge's orientation (a difference across it, one along it and
    /// its own velocity), and a border edge's two copies read the same constants, so a
    /// flipped copy's is the other's negated, exactly
    /// (`tests::the_stages_keep_a_border_edges_copies_alike`).
    #[inline(always)]
    pub(super) fn viscous_stage(
        &self,
        u: &mut [f64],
        v: &mut ViscousScratch,
        nu: f64,
        dt_s: f64,
        (mu, nu_prev): (f64, f64),
        (last, reverse): (bool, bool),
    ) {
        let rows = &self.rows;
        let blend = self.stage_set_up(u, v, nu, dt_s, (mu, nu_prev));
        let (epf, vpf, cpf) = rows.per_face();
        let ViscousScratch {
            stage,
            vorticity,
            divergence,
            window,
            inverse_areas_4: ia,
            ..
        } = v;
        // Each case its own loops: a test of the case per edge cost the reads and writes
        // it was to spare.
        for f in face_order(reverse) {
            let (u, stage) = (&mut u[f * epf..][..epf], &mut stage[f * epf..][..epf]);
            let borders = (&vorticity[f * vpf..][..vpf], &divergence[f * cpf..][..cpf]);
            let face = Face::new(rows, ia, borders);
            match (nu_prev != 0.0, !last) {
                (false, false) => blend.face::<false, false>(face, u, stage, window),
                (false, true) => blend.face::<false, true>(face, u, stage, window),
                (true, false) => blend.face::<true, false>(face, u, stage, window),
                (true, true) => blend.face::<true, true>(face, u, stage, window),
            }
        }
    }
}

/// One stage's update of an edge: `u ← mu·u + nu_prev·y_prev + change`, the change
/// `rate·(4 grad div − curl curl + 2u)`.
#[derive(Clone, Copy)]
struct Blend {
    /// The stage's `dt·ν/R²` (the stress per unit of the unit sphere's differences).
    rate: f64,
    /// The weight of the stage before (`μⱼ`).
    mu: f64,
    /// The weight of the stage before last (`νⱼ`; 0 in the first stage).
    nu_prev: f64,
}

impl Blend {
    /// One edge, from its `curl curl` and its `4 grad div` (the divergences are kept 4
    /// times over, [`ViscousScratch::inverse_areas_4`]): the stage before last `y_prev`
    /// read where `BLEND` (else the stage, the first, is a plain forward-Euler step), and
    /// replaced by the edge's `u` on entry where `KEEP` (a stage follows). Where `INTO`
    /// (the last stage, not `KEEP`), the new value goes to `y_prev`, `u` left as it is
    /// ([`FilmFlow::viscous_step_to_grid`]).
    #[inline(always)]
    fn step<const BLEND: bool, const KEEP: bool, const INTO: bool>(
        self,
        u: &mut f64,
        y_prev: &mut f64,
        curl_curl: f64,
        grad_div_4: f64,
    ) {
        let y = *u;
        let change = self.rate * (grad_div_4 - curl_curl + 2.0 * y);
        let new = if BLEND {
            self.mu * y + self.nu_prev * *y_prev + change
        } else {
            y + change
        };
        if INTO {
            *y_prev = new;
            return;
        }
        *u = new;
        if KEEP {
            *y_prev = y;
        }
    }

    /// One face's edges (`u` and `y_prev` its local edges), row by row ([`Self::walk`]),
    /// the stage before last kept in the face's rows.
    #[inline(always)]
    fn face<const BLEND: bool, const KEEP: bool>(
        self,
        face: Face,
        u: &mut [f64],
        y_prev: &mut [f64],
        window: &mut Window,
    ) {
        let (n, w) = (face.rows.n, face.rows.n + 1);
        let (p_x, p_y) = y_prev.split_at_mut(n * w);
        let rows = (p_x.chunks_exact_mut(w), p_y.chunks_exact_mut(n));
        self.walk::<BLEND, KEEP, false, _>(
            face,
            u,
            rows,
            window,
            |_, u, p, heads, cells, metric| {
                self.x_row::<BLEND, KEEP>(u, p, heads, cells, metric);
            },
        );
    }

    /// [`Self::face`] with the stage before last in `prev` (the grid's numbering), which
    /// the last stage (`INTO`) replaces with its values, `u` left as it is.
    #[inline(always)]
    fn face_grid<const BLEND: bool, const KEEP: bool, const INTO: bool>(
        self,
        face: Face,
        u: &mut [f64],
        prev: GridPrev,
        window: &mut Window,
    ) {
        let n = face.rows.n;
        let (left, border) = prev.border.split_at_mut(n);
        let (right, border) = border.split_at_mut(n);
        let (bottom, top) = border.split_at_mut(n);
        let y_prev = std::iter::once(bottom)
            .chain(prev.inner_y.chunks_exact_mut(n))
            .chain(std::iter::once(top));
        let (x_prev, inner_x) = (left.iter_mut().zip(right.iter_mut()), prev.inner_x);
        let rows = (x_prev, y_prev);
        self.walk::<BLEND, KEEP, INTO, _>(
            face,
            u,
            rows,
            window,
            move |y, u, (l, r), heads, cells, metric| {
                let p = &mut inner_x[y * (n - 1)..][..n];
                self.x_row_grid::<BLEND, KEEP, INTO>(u, (l, p, r), heads, cells, metric);
            },
        );
    }

    /// One face's edges (`u` its local edges), row by row, the stage before last of its
    /// rows from `prev`: per X-edge row (`n`), what `x_row` takes of it, and per Y-edge
    /// row (`n + 1`), its `n` edges'. X-edge row `y` moves by `x_row(y, u, prev, [heads,
    /// tails], cells, metric)`: Y-edge row `y` reads vertex row `y`
    /// and padded cell rows `y` and `y + 1`, X-edge row `y` vertex rows `y` (heads) and
    /// `y + 1` (tails) and padded cell row `y + 1`. Vertex row `y + 1` and padded cell row
    /// `y + 1` are taken into `window` from edges that have not moved yet: vertex row `j`
    /// reads X-edge rows `j − 1` and `j` and Y-edge row `j` (taken before Y-edge row `y`
    /// moves), padded cell row `p` X-edge row `p − 1` and Y-edge rows `p − 1` and `p`
    /// (taken in Y-edge row `y`'s loop, each cell just before its bottom edge moves).
    /// Every row of edges whole, the faces' borders' too: their cells across the border
    /// are in the divergence's halo. Every face reads face 0's metric `[1/length, 1/dual
    /// length]` ([`FaceRows`] says why).
    ///
    /// The face's arrays are split into their X- and Y-edge halves once, the rows of the
    /// metric and of the stage before last come from iterators, and the window's two rows
    /// of each kind swap places: each a bounds check or several a row less, where a row's
    /// set-up was a third of the stage's instructions.
    #[inline(always)]
    fn walk<'p, const BLEND: bool, const KEEP: bool, const INTO: bool, P>(
        self,
        face: Face,
        u: &mut [f64],
        (x_prev, y_prev): (impl Iterator<Item = P>, impl Iterator<Item = &'p mut [f64]>),
        window: &mut Window,
        mut x_row: impl FnMut(usize, &mut [f64], P, [&[f64]; 2], &[f64], [&[f64]; 2]),
    ) {
        let rows = face.rows;
        let (n, w, xs) = (rows.n, rows.n + 1, rows.n * (rows.n + 1));
        let (u_x, u_y) = u.split_at_mut(xs);
        let (il_x, il_y) = rows.inverse_length.split_at(xs);
        let (id_x, id_y) = rows.inverse_dual_length.split_at(xs);
        let metric_y = il_y.chunks_exact(n).zip(id_y.chunks_exact(n));
        let mut x_rows = x_prev.zip(il_x.chunks_exact(w).zip(id_x.chunks_exact(w)));
        let [va, vb] = &mut window.vertex;
        let (mut z, mut z_next) = (&mut va[..w], &mut vb[..w]);
        let [ca, cb] = &mut window.cell;
        let (mut from, mut into) = (&mut ca[..w + 1], &mut cb[..w + 1]);
        face.take_vertex_row(z, (u_x, u_y), 0);
        face.take_cell_row(from, (u_x, u_y), 0);
        for (y, (p, (il, id))) in y_prev.zip(metric_y).enumerate() {
            if y < n {
                face.take_vertex_row(z_next, (u_x, u_y), y + 1);
            }
            // Y-edge (x, y): tail the vertex (x, y), head (x + 1, y); from cell (x, y − 1)
            // (padded row y) into (x, y) (padded row y + 1: the halo row, or taken in the
            // edges' loop).
            if y == n {
                face.take_cell_row(into, (u_x, u_y), y + 1);
            }
            let (u, above) = u_y[y * n..].split_at_mut(n);
            let (vertices, from_cells) = ([&z[1..], &*z], &from[1..]);
            if y < n {
                let sides = (&u_x[y * w..][..w], &above[..n]);
                let (u, metric) = ((u, p), [il, id]);
                self.y_row_taking_cells::<BLEND, KEEP, INTO>(
                    face, u, vertices, from_cells, into, metric, sides, y,
                );
            } else {
                let cells = [&into[1..], from_cells];
                self.row::<BLEND, KEEP, INTO>(u, p, vertices, cells, [il, id]);
            }
            // X-edge (i, y): tail the vertex (i, y + 1), head (i, y); from cell (i − 1, y)
            // into (i, y) (padded row y + 1).
            let Some((p, (il, id))) = x_rows.next() else {
                break;
            };
            x_row(y, &mut u_x[y * w..][..w], p, [z, z_next], into, [il, id]);
            (z, z_next) = (z_next, z);
            (from, into) = (into, from);
        }
    }

    /// [`Self::x_row`] with the stage before last of the row's left border copy, its
    /// inner edges (the first `n − 1` of `inner`, in the grid's numbering) and its right
    /// border copy apart. The inner edges' loop runs on through the right border copy, `n`
    /// edges, which vectorise without the scalar tail of `n − 1`, its `inner` the grid's
    /// next edge: that entry and the copy's `u` are put back after, and the copy is then
    /// taken on its own.
    #[inline(always)]
    fn x_row_grid<const BLEND: bool, const KEEP: bool, const INTO: bool>(
        self,
        u: &mut [f64],
        (left, inner, right): (&mut f64, &mut [f64], &mut f64),
        [head, tail]: [&[f64]; 2],
        cells: &[f64],
        [il, id]: [&[f64]; 2],
    ) {
        let n = u.len() - 1;
        let (head, tail, cells) = (&head[..=n], &tail[..=n], &cells[..n + 2]);
        let (il, id, inner) = (&il[..=n], &id[..=n], &mut inner[..n]);
        let [into, from] = [&cells[1..], cells];
        let curl_curl = (head[0] - tail[0]) * il[0];
        let grad_div_4 = (into[0] - from[0]) * id[0];
        self.step::<BLEND, KEEP, INTO>(&mut u[0], left, curl_curl, grad_div_4);
        let kept = (u[n], inner[n - 1]);
        self.row::<BLEND, KEEP, INTO>(
            &mut u[1..],
            inner,
            [&head[1..], &tail[1..]],
            [&into[1..=n], &from[1..=n]],
            [&il[1..], &id[1..]],
        );
        (u[n], inner[n - 1]) = kept;
        let curl_curl = (head[n] - tail[n]) * il[n];
        let grad_div_4 = (into[n] - from[n]) * id[n];
        self.step::<BLEND, KEEP, INTO>(&mut u[n], right, curl_curl, grad_div_4);
    }

    /// Y-edge row `y < n` (`u` and `y_prev`) as [`Self::row`] takes it, and in the same
    /// loop padded cell row `y + 1` into `into` as [`Face::take_cell_row`] takes it, from
    /// its cells' sides: the edges (their bottoms, read before they move), X-edge row `y`
    /// and Y-edge row `y + 1` (`sides`). One loop where two each loaded the edges and
    /// cost a row's set-up.
    #[allow(clippy::too_many_arguments)] // the row's slices, each its own (see `row`)
    #[inline(always)]
    fn y_row_taking_cells<const BLEND: bool, const KEEP: bool, const INTO: bool>(
        self,
        face: Face,
        (u, y_prev): (&mut [f64], &mut [f64]),
        vertices: [&[f64]; 2],
        from: &[f64],
        into: &mut [f64],
        metric: [&[f64]; 2],
        (ux, above): (&[f64], &[f64]),
        y: usize,
    ) {
        let (n, w) = (u.len(), u.len() + 1);
        let [lx, ly] = face.length;
        let (lx, ly) = (&lx[y * w..][..w], &ly[y * n..][..2 * n]);
        let ls = [&ly[..n], &lx[..n], &lx[1..], &ly[n..]];
        let border = &face.borders.1[(y + 1) * (w + 1)..][..w + 1];
        (into[0], into[n + 1]) = (border[0], border[n + 1]);
        let cells = (
            [&ux[..n], &ux[1..], above],
            ls,
            &face.inverse_areas[y * n..][..n],
        );
        let out = &mut into[1..=n];
        self.y_row_cells::<BLEND, KEEP, INTO>(u, y_prev, out, vertices, from, metric, cells);
    }

    /// The loop of [`Self::y_row_taking_cells`]: the cells' `out`, their `[left, right,
    /// top]` sides' velocities, `[bottom, left, right, top]` lengths (the bottoms'
    /// velocities are `u`'s) and inverse areas. The outputs are arguments of their own
    /// (see [`Self::row`]; in a tuple, the compiler lost that they overlap nothing and
    /// did not vectorise the loop).
    #[allow(clippy::too_many_arguments)] // the outputs, each its own argument
    #[inline(always)]
    fn y_row_cells<const BLEND: bool, const KEEP: bool, const INTO: bool>(
        self,
        u: &mut [f64],
        y_prev: &mut [f64],
        out: &mut [f64],
        [head, tail]: [&[f64]; 2],
        from: &[f64],
        [il, id]: [&[f64]; 2],
        ([left, right, top], l, ia): ([&[f64]; 3], [&[f64]; 4], &[f64]),
    ) {
        let len = u.len();
        let (y_prev, out, head, tail, from) = (
            &mut y_prev[..len],
            &mut out[..len],
            &head[..len],
            &tail[..len],
            &from[..len],
        );
        let (il, id, ia) = (&il[..len], &id[..len], &ia[..len]);
        let (left, right, top) = (&left[..len], &right[..len], &top[..len]);
        let [lb, ll, lr, lt] = l.map(|l| &l[..len]);
        for x in 0..len {
            let b = u[x];
            // `(0 − a) − b` as `−(a + b)`: the same bits but for a zero's sign, one op fewer.
            let d = right[x] * lr[x] - (b * lb[x] + left[x] * ll[x]) + top[x] * lt[x];
            let into = d * ia[x];
            out[x] = into;
            let curl_curl = (head[x] - tail[x]) * il[x];
            let grad_div_4 = (into - from[x]) * id[x];
            self.step::<BLEND, KEEP, INTO>(&mut u[x], &mut y_prev[x], curl_curl, grad_div_4);
        }
    }

    /// A row of X-edges (`n + 1`) as [`Self::row`] takes them, from padded `cells`: the
    /// first `n` in its loop (vectorised whole where `n` is a multiple of the vector's
    /// width) and the last on its own, where the loop's scalar tail cost a row several
    /// times as much.
    #[inline(always)]
    fn x_row<const BLEND: bool, const KEEP: bool>(
        self,
        u: &mut [f64],
        y_prev: &mut [f64],
        [head, tail]: [&[f64]; 2],
        cells: &[f64],
        [il, id]: [&[f64]; 2],
    ) {
        let n = u.len() - 1;
        let (y_prev, head, tail, cells) =
            (&mut y_prev[..=n], &head[..=n], &tail[..=n], &cells[..n + 2]);
        let (il, id) = (&il[..=n], &id[..=n]);
        let ([into, from], metric) = ([&cells[1..], cells], [il, id]);
        self.row::<BLEND, KEEP, false>(
            &mut u[..n],
            &mut y_prev[..n],
            [head, tail],
            [into, from],
            metric,
        );
        let curl_curl = (head[n] - tail[n]) * il[n];
        let grad_div_4 = (into[n] - from[n]) * id[n];
        self.step::<BLEND, KEEP, false>(&mut u[n], &mut y_prev[n], curl_curl, grad_div_4);
    }

    /// A row of edges: the vorticities at their `[head, tail]`, the divergences of the
    /// cells `[into, from]`, their `[1/length, 1/dual length]`. Each slice is an
    /// argument of its own: the compiler then knows the outputs overlap no input, where
    /// slices of the scratch's vectors cost it a run-time test of each pair every row.
    #[inline(always)]
    fn row<const BLEND: bool, const KEEP: bool, const INTO: bool>(
        self,
        u: &mut [f64],
        y_prev: &mut [f64],
        [head, tail]: [&[f64]; 2],
        [into, from]: [&[f64]; 2],
        [il, id]: [&[f64]; 2],
    ) {
        let len = u.len();
        let y_prev = &mut y_prev[..len];
        let (head, tail, into, from) = (&head[..len], &tail[..len], &into[..len], &from[..len]);
        let (il, id) = (&il[..len], &id[..len]);
        for i in 0..len {
            let curl_curl = (head[i] - tail[i]) * il[i];
            let grad_div_4 = (into[i] - from[i]) * id[i];
            self.step::<BLEND, KEEP, INTO>(&mut u[i], &mut y_prev[i], curl_curl, grad_div_4);
        }
    }
}

/// What one face's stage reads besides its edges.
#[derive(Clone, Copy)]
struct Face<'a> {
    rows: &'a FaceRows,
    /// Face 0's cells' inverse areas, per sr, which every face reads.
    inverse_areas: &'a [f64],
    /// Face 0's edges' `[X-edge, Y-edge]` lengths ([`FaceRows::length`]), split once.
    length: [&'a [f64]; 2],
    /// Face 0's edges' `[X-edge, Y-edge]` dual lengths, split once.
    dual_length: [&'a [f64]; 2],
    /// The face's vertices' vorticities and padded cells' divergences on its borders and
    /// halo ([`ViscousScratch::vorticity`], [`ViscousScratch::divergence`]).
    borders: (&'a [f64], &'a [f64]),
}

impl<'a> Face<'a> {
    /// The face whose borders' fields are `borders`, with face 0's constants.
    fn new(rows: &'a FaceRows, inverse_areas: &'a [f64], borders: (&'a [f64], &'a [f64])) -> Self {
        let halves = |a: &'a [f64]| {
            let (x, y) = a.split_at(rows.n * (rows.n + 1));
            [x, y]
        };
        Face {
            rows,
            inverse_areas,
            length: halves(&rows.length),
            dual_length: halves(&rows.dual_length),
            borders,
        }
    }

    /// Vertex row `j` of the face (its local edges' `[X, Y]` halves `u`) into `out`
    /// (`n + 1`): an inner row's circulation as
    /// [`FaceRows::face_circulation_row`] sums it, its ends (on the face's borders) and
    /// the border rows `0` and `n` from the face's border vorticities.
    #[inline(always)]
    fn take_vertex_row(self, out: &mut [f64], (ux, uy): (&[f64], &[f64]), j: usize) {
        let (n, w) = (self.rows.n, self.rows.n + 1);
        let border = &self.borders.0[j * w..][..w];
        if j == 0 || j == n {
            out.copy_from_slice(border);
            return;
        }
        let [dx, dy] = self.dual_length;
        // X-edge rows j − 1 (below) and j (above) at once; Y-edge row j and the edge
        // before it (vertex 0's left, junk: the border's value replaces it).
        let (ux, dx) = (&ux[(j - 1) * w..][..w + n], &dx[(j - 1) * w..][..w + n]);
        let (uy, dy) = (&uy[j * n - 1..][..=n], &dy[j * n - 1..][..=n]);
        let u = [&ux[..n], &uy[..n], &uy[1..], &ux[w..]];
        let d = [&dx[..n], &dy[..n], &dy[1..], &dx[w..]];
        let scale = &self.rows.vertex_inverse_area[j * w..][..n];
        circulation_row(&mut out[..n], u, d, scale);
        (out[0], out[n]) = (border[0], border[n]);
    }

    /// Padded cell row `p` of the face (its local edges' `[X, Y]` halves `u`) into `out`
    /// (`n + 2`): cell row `p − 1`'s divergences, the halo at its ends and the halo rows
    /// `0` and `n + 1` from the face's border divergences.
    #[inline(always)]
    fn take_cell_row(self, out: &mut [f64], (ux, uy): (&[f64], &[f64]), p: usize) {
        let (n, w) = (self.rows.n, self.rows.n + 1);
        let border = &self.borders.1[p * (w + 1)..][..w + 1];
        if p == 0 || p == n + 1 {
            out.copy_from_slice(border);
            return;
        }
        let (y, [lx, ly]) = (p - 1, self.length);
        // X-edge row y (the cells' left and right sides), Y-edge rows y and y + 1 (bottom
        // and top) at once.
        let (ux, lx) = (&ux[y * w..][..w], &lx[y * w..][..w]);
        let (uy, ly) = (&uy[y * n..][..2 * n], &ly[y * n..][..2 * n]);
        let u = [&uy[..n], &ux[..n], &ux[1..], &uy[n..]];
        let l = [&ly[..n], &lx[..n], &lx[1..], &ly[n..]];
        divergence_row(&mut out[1..=n], u, l, &self.inverse_areas[y * n..][..n]);
        (out[0], out[n + 1]) = (border[0], border[n + 1]);
    }
}

/// A row of vertices' circulations times `scale` into `out`, from their sides'
/// velocities and dual lengths in the order `[below, left, right, above]`: the sum of
/// [`FaceRows::face_circulation_row`], in the same order. `out` is an argument of its
/// own, as in [`divergence_row`].
#[inline(always)]
fn circulation_row(out: &mut [f64], u: [&[f64]; 4], d: [&[f64]; 4], scale: &[f64]) {
    let len = out.len();
    let [ub, ul, ur, ua] = u.map(|u| &u[..len]);
    let [db, dl, dr, da] = d.map(|d| &d[..len]);
    let scale = &scale[..len];
    for i in 0..len {
        // `(0 − a) + b` as `b − a`: the same bits but for a zero's sign, one op fewer.
        let z = ul[i] * dl[i] - ub[i] * db[i] - ur[i] * dr[i] + ua[i] * da[i];
        out[i] = z * scale[i];
    }
}

/// One face's stage before last, as [`FilmFlow::viscous_step_to_grid`] keeps it.
struct GridPrev<'a> {
    /// The grid's inner X-edges of the face, `n − 1` a row
    /// ([`FaceLayout`](super::grid::FaceLayout)), and the grid's edge after them (the next
    /// face's first, or the first inner Y-edge), which the last row runs on through
    /// ([`Blend::x_row_grid`]).
    inner_x: &'a mut [f64],
    /// The grid's inner Y-edges of the face, rows `1..n`.
    inner_y: &'a mut [f64],
    /// The face's part of [`ViscousScratch::border_prev`]: its left and right X-edge
    /// columns, its bottom and top Y-edge rows, `n` each.
    border: &'a mut [f64],
}

/// RKL1 stage `j` of `stages` (from 1): its `(last, reverse)` (the faces' directions
/// alternate, the first's `first_reverse`), its weights `(μⱼ, νⱼ)` and its step, from
/// the first's weight `w₁` and the step `dt`. Y₁ = Y₀ + w₁ dt M(Y₀); Yⱼ = μⱼ Yⱼ₋₁ + νⱼ Yⱼ₋₂ + μⱼ w₁ dt M(Yⱼ₋₁),
/// μⱼ = (2j − 1)/j, νⱼ = (1 − j)/j.
fn stage_of(
    j: u32,
    stages: u32,
    (w1, dt_s): (f64, f64),
    first_reverse: bool,
) -> ((bool, bool), (f64, f64), f64) {
    let order = (j == stages, (j % 2 == 1) == first_reverse);
    if j == 1 {
        return (order, (1.0, 0.0), w1 * dt_s);
    }
    let j = f64::from(j);
    let mu = (2.0 * j - 1.0) / j;
    (order, (mu, (1.0 - j) / j), mu * w1 * dt_s)
}

/// [`ViscousScratch::seam_slots`] of `rows`.
fn seam_slots(rows: &FaceRows) -> Vec<(u32, u32, f64)> {
    let n = rows.n;
    let slot = |c: usize, side: Side| {
        let (f, x, y) = (c / (n * n), c % n, (c / n) % n);
        let (border, along) = match side {
            Side::Left => (0, y),
            Side::Right => (1, y),
            Side::Bottom => (2, x),
            Side::Top => (3, x),
        };
        ((f * 4 + border) * n + along) as u32
    };
    let first = |e: &SeamEdge| {
        let (c, side, k) = e.cells[0];
        (
            rows.edge[k as usize],
            slot(c as usize, side),
            rows.sign(k as usize),
        )
    };
    rows.seam_edges.iter().map(first).collect()
}

impl Window {
    /// Gives every row its length for `n` cells a face.
    fn prepare(&mut self, n: usize) {
        self.vertex.iter_mut().for_each(|r| r.resize(n + 1, 0.0));
        self.cell.iter_mut().for_each(|r| r.resize(n + 2, 0.0));
    }
}

/// The vorticity at the vertices on the faces' borders into `v.vorticity` (each copy),
/// and 4 times the divergence ([`ViscousScratch::inverse_areas_4`]) of the cells on the
/// faces' borders into `v.divergence`, its halo too, of the edge velocities `u` (in the
/// rows), on the unit sphere (m/s per rad): what
/// a face's rows read of the other faces' edges, taken before any face's edges move. A
/// cell's divergence sums its edges' `±u l` in the local order
/// ([`SIDES`](super::face_rows::SIDES)), `+` where the local normal points out of it (its
/// right and top sides): the faces' border cells whose edges the grid numbers otherwise
/// too ([`FaceRows::irregular_cells`]), which taken apart in the grid's order cost a tenth
/// of the viscous step, for sums that differ only in rounding.
#[inline(always)]
fn border_fields(rows: &FaceRows, u: &[f64], v: &mut ViscousScratch) {
    let vorticity = &mut v.vorticity;
    vorticity.resize(rows.vertices(), 0.0);
    rows.seam_circulation(u, vorticity, &rows.vertex_inverse_area, |z, ia| z * ia);
    let n = rows.n;
    let divergence = &mut v.divergence;
    divergence.resize(6 * rows.padded_cells_per_face(), 0.0);
    // Face 0's cells' inverse areas (4 times over), which every face reads ([`FaceRows`]
    // says why; `face_rows::tests::every_faces_constants_are_face_0s` checks them).
    let ia = &v.inverse_areas_4[..n * n];
    let (epf, cpf, pw) = (rows.edges_per_face(), rows.padded_cells_per_face(), n + 2);
    let faces = u.chunks_exact(epf).zip(divergence.chunks_exact_mut(cpf));
    for (u, out) in faces {
        for y in [0, n - 1] {
            divergence_cells(rows, u, ia, y, 0, &mut out[(y + 1) * pw + 1..][..n]);
        }
        divergence_columns(rows, u, ia, out);
    }
    for &[slot, across] in &rows.cell_halo {
        divergence[slot as usize] = divergence[across as usize];
    }
}

/// The divergences of cells `(x.., y)` of a face (its local edges `u`) into `out`, as
/// many as it holds, with face 0's lengths and cells' inverse areas `ia`.
#[inline(always)]
fn divergence_cells(rows: &FaceRows, u: &[f64], ia: &[f64], y: usize, x: usize, out: &mut [f64]) {
    let n = rows.n;
    let at = (n, x, y);
    divergence_row(out, sides(u, at), sides(&rows.length, at), &ia[y * n + x..]);
}

/// The divergences of the cells `(0, y)` and `(n − 1, y)`, `y` in `1..n − 1`, of a face
/// (its local edges `u`) into its padded cells `out`, as [`divergence_row`] takes each
/// (the same sum in the same order), with face 0's lengths and cells' inverse areas `ia`:
/// the columns of the face's border cells, where a call of [`divergence_cells`] a cell
/// cost several times the sum. Both columns a row at a time, the rows from iterators:
/// indexing the arrays cost a cell as much again in bounds checks.
#[inline(always)]
fn divergence_columns(rows: &FaceRows, u: &[f64], ia: &[f64], out: &mut [f64]) {
    let (n, w) = (rows.n, rows.n + 1);
    let ((ux, uy), (lx, ly)) = (u.split_at(n * w), rows.length.split_at(n * w));
    // From cell row 1: its bottom and top Y-edge rows, its X-edge row, its padded row.
    let bottom = uy[n..].chunks_exact(n).zip(ly[n..].chunks_exact(n));
    let top = uy[2 * n..].chunks_exact(n).zip(ly[2 * n..].chunks_exact(n));
    let sides = ux[w..].chunks_exact(w).zip(lx[w..].chunks_exact(w));
    let cells = ia[n..]
        .chunks_exact(n)
        .zip(out[2 * (n + 2)..].chunks_exact_mut(n + 2));
    let rows = bottom.zip(top).zip(sides).zip(cells);
    for ((((ub, lb), (ut, lt)), (us, ls)), (ia, out)) in rows.take(n.saturating_sub(2)) {
        for x in [0, n - 1] {
            // `(0 − a) − b` as `−(a + b)`: the same bits but for a zero's sign, one op fewer.
            let d = us[x + 1] * ls[x + 1] - (ub[x] * lb[x] + us[x] * ls[x]) + ut[x] * lt[x];
            out[1 + x] = d * ia[x];
        }
    }
}

/// From cell `(x, y)` of a face of `n` cells a side on, its sides' entries of `a` (per
/// local edge of the face), in [`SIDES`](super::face_rows::SIDES) order.
#[inline(always)]
fn sides(a: &[f64], (n, x, y): (usize, usize, usize)) -> [&[f64]; 4] {
    let (ax, ay) = a.split_at(n * (n + 1));
    let left = &ax[y * (n + 1) + x..];
    [&ay[y * n + x..], left, &left[1..], &ay[(y + 1) * n + x..]]
}

/// A row of cells' divergences into `out`, from their sides' velocities and lengths (in
/// [`SIDES`](super::face_rows::SIDES) order) and inverse areas `ia`. `out` is an argument
/// of its own: the compiler then knows it overlaps no input (a slice of the scratch's
/// vector cost a run-time test against each input every row).
#[inline(always)]
fn divergence_row(out: &mut [f64], u: [&[f64]; 4], l: [&[f64]; 4], ia: &[f64]) {
    let len = out.len();
    let [bottom, left, right, top] = u.map(|u| &u[..len]);
    let [lb, ll, lr, lt] = l.map(|l| &l[..len]);
    let ia = &ia[..len];
    for x in 0..len {
        // `(0 − a) − b` as `−(a + b)`: the same bits but for a zero's sign, one op fewer.
        let d = right[x] * lr[x] - (bottom[x] * lb[x] + left[x] * ll[x]) + top[x] * lt[x];
        out[x] = d * ia[x];
    }
}

/// The fewest RKL1 stages `s` whose span `s(s + 1)/2` covers `euler_substeps`.
pub(super) fn legendre_stages(euler_substeps: f64) -> u32 {
    let mut s = 1u32;
    while f64::from(s * (s + 1) / 2) < euler_substeps {
        s += 1;
    }
    s
}

/// The viscous operator's Gershgorin bound on the unit sphere for ν = 1: per edge, the
/// curl-curl, grad-div and curvature terms' row sums, the largest of them.
pub(super) fn viscous_bound(g: &CubeSphere) -> f64 {
    let (cells, verts) = (g.areas_sr(), g.vertex_areas_sr());
    g.edges()
        .iter()
        .map(|e| {
            let curl =
                2.0 * e.dual_length / e.length / verts[e.v0 as usize].min(verts[e.v1 as usize]);
            let div =
                4.0 * 2.0 * e.length / e.dual_length / cells[e.a as usize].min(cells[e.b as usize]);
            4.0 * (curl + div) + 2.0
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use crate::bits::differing_bits;
    use std::sync::Arc;

    use glam::DVec3;

    use super::super::flow::{FilmFlow, FlowParams};
    use super::super::{CubeSphere, Hierarchy};
    use super::{ViscousScratch, legendre_stages};

    /// Each stage count is the fewest whose span covers the sub-steps: 1 → 1, 2..3 → 2,
    /// 4..6 → 3, 22 → 7.
    #[test]
    fn stages_cover_the_euler_substeps() {
        let got: Vec<u32> = [1.0, 2.0, 3.0, 4.0, 6.0, 7.0, 21.0, 22.0]
            .map(legendre_stages)
            .to_vec();
        assert_eq!(got, [1, 2, 2, 3, 3, 4, 6, 7]);
    }

    /// A 1 cm film of viscosity 0.5 Pa·s on the n = 32 grid, at rest.
    fn viscous_film() -> (FilmFlow, f64) {
        viscous_film_of(32)
    }

    /// A 1 cm film of viscosity 0.5 Pa·s on a grid of `n` cells a face, at rest, and
    /// its kinematic viscosity, m²/s.
    fn viscous_film_of(n: usize) -> (FilmFlow, f64) {
        let grid = Arc::new(CubeSphere::new(n));
        let hierarchy = Arc::new(Hierarchy::new(&grid));
        let p = FlowParams {
            viscosity_pa_s: 0.5,
            ..FlowParams::water_film(0.01)
        };
        let nu = p.viscosity_pa_s / p.density_kg_per_m3;
        (FilmFlow::new(grid, hierarchy, p, |_| 1e-6), nu)
    }

    /// The step over which forward Euler would need `substeps` sub-steps.
    fn step_of(f: &FilmFlow, nu: f64, substeps: f64) -> f64 {
        let r = f.params.radius_m;
        substeps * super::EULER_RATE_LIMIT / (f.viscous_bound * nu / (r * r))
    }

    /// Σ u² l d over the edges: the velocity field's energy on the unit sphere.
    fn energy(f: &FilmFlow) -> f64 {
        let ea = f.grid.edge_arrays();
        let metric = ea.length.iter().zip(&ea.dual_length);
        let per_edge = f.u_m_per_s.iter().zip(metric);
        per_edge.map(|(u, (l, d))| u * u * l * d).sum()
    }

    /// A stage's edges against whole-grid passes of the same sums (the vorticity of every
    /// vertex, the divergence of every cell with its halo, then every edge's update, from
    /// the velocities the stage starts from), bit for bit: each case of stage (first,
    /// blended, last), the faces in either order, a rough field at n = 5 and 16. The
    /// window's rows must be taken before any edge they read moves.
    #[test]
    fn a_stage_is_the_whole_grid_passes() {
        for n in [5, 16] {
            let (f, nu) = viscous_film_of(n);
            let grid = Arc::clone(&f.grid);
            let rough = |seed: usize| -> Vec<f64> {
                let values = (0..grid.edges().len()).map(|e| ((e * seed) % 1000) as f64 * 1e-6);
                let mut out = Vec::new();
                f.rows.to_rows(&values.collect::<Vec<_>>(), &mut out);
                out
            };
            let (start, before_last) = (rough(7919), rough(104_729));
            for (weights, last) in [
                ((1.0, 0.0), false),
                ((1.5, -0.5), false),
                ((1.5, -0.5), true),
            ] {
                let want = whole_grid_stage(&f, &start, &before_last, nu, 0.01, weights, last);
                for reverse in [false, true] {
                    let (mut u, mut v) = (start.clone(), ViscousScratch::default());
                    v.stage = before_last.clone();
                    f.viscous_stage(&mut u, &mut v, nu, 0.01, weights, (last, reverse));
                    let got = (u, v.stage);
                    let what =
                        format!("n {n}, weights {weights:?}, last {last}, reverse {reverse}");
                    for (name, got, want) in [("u", &got.0, &want.0), ("stage", &got.1, &want.1)] {
                        let differ = differing_bits(got, want);
                        assert_eq!(differ, 0, "{what}: {name} differs");
                    }
                }
            }
        }
    }

    /// [`FilmFlow::viscous_stage`] as whole-grid passes: `(u, stage)` after it, from `u`
    /// and the stage before last `before_last`.
    fn whole_grid_stage(
        f: &FilmFlow,
        u: &[f64],
        before_last: &[f64],
        nu: f64,
        dt_s: f64,
        (mu, nu_prev): (f64, f64),
        last: bool,
    ) -> (Vec<f64>, Vec<f64>) {
        let (rows, n) = (&*f.rows, f.rows.n);
        let mut z = Vec::new();
        rows.circulation(u, &mut z, &rows.vertex_inverse_area, |z, ia| z * ia);
        let (epf, w) = (rows.edges_per_face(), n + 1);
        let ia = f.grid.inverse_areas_per_sr();
        let mut div = vec![0.0; 6 * rows.padded_cells_per_face()];
        for face in 0..6 {
            let ue = |k: usize| u[face * epf + k];
            for y in 0..n {
                for x in 0..n {
                    let [b, l, r, t] = [xs_y(n, x, y), y * w + x, y * w + x + 1, xs_y(n, x, y + 1)];
                    let len = &rows.length;
                    // The plain sum from zero (the passes take `(0 − a) − b` as `−(a + b)`).
                    let d = 0.0 - ue(b) * len[b] - ue(l) * len[l] + ue(r) * len[r] + ue(t) * len[t];
                    div[rows.padded_cell(face, x + 1, y + 1)] = d * ia[y * n + x];
                }
            }
        }
        for &[slot, across] in &rows.cell_halo {
            div[slot as usize] = div[across as usize];
        }
        let r = f.params.radius_m;
        let rate = dt_s * nu / (r * r);
        let (mut out, mut stage) = (u.to_vec(), before_last.to_vec());
        for face in 0..6 {
            let vz = |i: usize, j: usize| z[rows.vertex_at(face, i, j)];
            let d = |px: usize, py: usize| div[rows.padded_cell(face, px, py)];
            // Per local edge of the face: [head, tail] vorticities, [into, from] divergences.
            let mut fields = Vec::with_capacity(epf);
            for y in 0..n {
                for i in 0..=n {
                    fields.push(([vz(i, y), vz(i, y + 1)], [d(i + 1, y + 1), d(i, y + 1)]));
                }
            }
            for j in 0..=n {
                for x in 0..n {
                    fields.push(([vz(x + 1, j), vz(x, j)], [d(x + 1, j + 1), d(x + 1, j)]));
                }
            }
            for (k, ([head, tail], [into, from])) in fields.into_iter().enumerate() {
                let e = face * epf + k;
                let curl_curl = (head - tail) * rows.inverse_length[k];
                let grad_div = (into - from) * rows.inverse_dual_length[k];
                let y = u[e];
                let change = rate * (4.0 * grad_div - curl_curl + 2.0 * y);
                out[e] = if nu_prev == 0.0 {
                    y + change
                } else {
                    mu * y + nu_prev * before_last[e] + change
                };
                if !last {
                    stage[e] = y;
                }
            }
        }
        (out, stage)
    }

    /// Face 0's local Y-edge `(x, j)` of a grid of `n` cells a face, within the face.
    fn xs_y(n: usize, x: usize, j: usize) -> usize {
        n * (n + 1) + j * n + x
    }

    /// The stages that keep the stage before last in the grid's numbering, the last
    /// writing there, give the grid's numbering of the stages on the rows, bit for bit:
    /// 1, 2, 3 and 7 stages, the faces either way first, a rough field at n = 2, 5 and 16,
    /// the stage buffer's entries junk from the start.
    #[test]
    fn the_stages_into_the_grid_are_the_stages_on_the_rows() {
        for n in [2, 5, 16] {
            let (f, nu) = viscous_film_of(n);
            let edges = f.grid.edges().len();
            let rough: Vec<f64> = (0..edges)
                .map(|e| ((e * 7919) % 1000) as f64 * 1e-6 - 4e-4)
                .collect();
            let mut start = Vec::new();
            f.rows.to_rows(&rough, &mut start);
            for (substeps, first_reverse) in [1.0, 3.0, 6.0, 22.0]
                .into_iter()
                .flat_map(|s| [(s, false), (s, true)])
            {
                let dt = step_of(&f, nu, substeps);
                let (mut u, mut v) = (start.clone(), ViscousScratch::default());
                f.viscous_step(&mut u, &mut v, nu, dt, first_reverse);
                let mut want = vec![0.0; edges];
                f.rows.to_grid(&u, &mut want);
                let mut v = ViscousScratch {
                    stage: vec![f64::NAN; edges],
                    ..ViscousScratch::default()
                };
                f.viscous_step_to_grid(&mut start.clone(), &mut v, nu, dt, first_reverse);
                assert_ne!(want, rough, "n {n}: nothing moved");
                let differ = differing_bits(&want, &v.stage);
                let what = format!("n {n}, {substeps} sub-steps, first reverse {first_reverse}");
                assert_eq!(differ, 0, "{what}: edges differ");
            }
        }
    }

    /// The stages keep each edge on the faces' borders the same in both its copies (its
    /// value, or its negation, bit for bit): they read the same shared constants
    /// ([`FaceRows`](super::super::face_rows::FaceRows)). A rough field, at n = 5 and 32.
    #[test]
    fn the_stages_keep_a_border_edges_copies_alike() {
        for n in [5, 32] {
            let (f, nu) = viscous_film_of(n);
            let grid = Arc::clone(&f.grid);
            let rough: Vec<f64> = (0..grid.edges().len())
                .map(|e| ((e * 7919) % 1000) as f64 * 1e-6 - 4e-4)
                .collect();
            let (mut u, mut start) = (Vec::new(), Vec::new());
            f.rows.to_rows(&rough, &mut u);
            f.rows.to_rows(&rough, &mut start);
            f.viscous_step(&mut u, &mut ViscousScratch::default(), nu, 0.05, true);
            assert_ne!(u, start, "n {n}: nothing moved");
            for e in &f.rows.seam_edges {
                let [a, b] = e.cells.map(|(_, _, k)| k as usize);
                let (ua, ub) = (u[a] * f.rows.sign(a), u[b] * f.rows.sign(b));
                assert_eq!(
                    ua.to_bits(),
                    ub.to_bits(),
                    "n {n}: copies {a}, {b}: {ua} vs {ub}"
                );
            }
        }
    }

    /// The operator's largest rate, by power iteration on forward-Euler sub-steps
    /// (`L u = (E u − u)/dt`), is within 0.7 of [`viscous_bound`] (0.61 at n = 32): a
    /// bound at all (≤ 1), and loose enough that [`super::EULER_RATE_LIMIT`] keeps every
    /// mode's true `dt·λ` within 1.33 of the 2 forward Euler can take. Halving the bound
    /// (its factor 4 as 2) takes it to 1.22 and fails it.
    #[test]
    fn the_viscous_bound_is_loose_enough_for_its_limit() {
        let (mut f, nu) = viscous_film();
        let r = f.params.radius_m;
        let bound = f.viscous_bound * nu / (r * r);
        let dt = 1.0 / bound;
        // A rough start with every mode in it (a fixed pseudo-random sequence).
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for u in f.u_m_per_s.iter_mut() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            *u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        }
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let (mut s, mut u, mut rates) = (ViscousScratch::default(), Vec::new(), Vec::new());
        for _ in 0..200 {
            let before = f.u_m_per_s.clone();
            f.rows.to_rows(&f.u_m_per_s, &mut u);
            s.stage.resize(u.len(), 0.0);
            f.viscous_stage(&mut u, &mut s, nu, dt, (1.0, 0.0), (true, false));
            f.rows.to_grid(&u, &mut f.u_m_per_s);
            let after = f.u_m_per_s.iter().zip(&before);
            let lu: Vec<f64> = after.map(|(a, b)| (a - b) / dt).collect();
            let rate = norm(&lu) / norm(&before);
            rates.push(rate / bound);
            for (u, l) in f.u_m_per_s.iter_mut().zip(&lu) {
                *u = l / rate;
            }
        }
        let (last, earlier) = (rates[rates.len() - 1], rates[rates.len() - 51]);
        eprintln!("largest rate / bound: {last:.4} (50 iterations before: {earlier:.4})");
        assert!(
            (last - earlier).abs() < 1e-3,
            "not converged: {earlier} → {last}"
        );
        assert!(
            last > 0.3 && last <= 0.7,
            "largest rate {last} of the bound"
        );
        let true_rate_dt = last * super::EULER_RATE_LIMIT;
        assert!(true_rate_dt <= 1.33, "true dt·λ {true_rate_dt}");
    }

    /// A smooth vortex (l = 2) taken in one step of 10 stages (55 forward-Euler sub-steps'
    /// span) decays as in 100 forward-Euler steps, to 5 %; the
    /// roughest field (a sign that flips from edge to edge) loses energy in one step of
    /// 17 stages (150 sub-steps' span). A wrong stage weight (a sign, a factor 2) breaks
    /// one or the other. (The vortex is smoothed first by small Euler steps: its
    /// edge-wise projection carries grid-scale roughness, which small Euler steps damp
    /// almost at once and the stages only to a fraction, both stably.)
    #[test]
    fn legendre_stages_match_small_euler_steps_and_damp_the_roughest_field() {
        let (mut f, nu) = viscous_film();
        let mut s = ViscousScratch::default();
        let dt = step_of(&f, nu, 54.5);
        f.set_velocity(|d: DVec3| d.cross(DVec3::Z) * (3.0 * d.z) * 1e-3);
        // Steps of the grid's edge velocities, through the face rows.
        let mut u = Vec::new();
        let mut on_rows = |f: &mut FilmFlow, step: &mut dyn FnMut(&FilmFlow, &mut [f64])| {
            f.rows.to_rows(&f.u_m_per_s, &mut u);
            step(f, &mut u);
            f.rows.to_grid(&u, &mut f.u_m_per_s);
        };
        let mut euler_steps = |f: &FilmFlow, u: &mut [f64]| {
            // Plain forward-Euler sub-steps, not through the stage weights under test.
            s.stage.resize(u.len(), 0.0);
            for _ in 0..100 {
                f.viscous_stage(u, &mut s, nu, dt / 100.0, (1.0, 0.0), (true, false));
            }
        };
        on_rows(&mut f, &mut euler_steps);
        let smooth = f.u_m_per_s.clone();
        on_rows(&mut f, &mut euler_steps);
        let euler = std::mem::replace(&mut f.u_m_per_s, smooth.clone());
        let mut s = ViscousScratch::default();
        on_rows(&mut f, &mut |f, u| {
            f.viscous_step(u, &mut s, nu, dt, true);
        });
        // The vortex's decay over the step, by each: first order in time alike, they
        // differ by about dt·λ/4 of it (λ the vortex's rate, dt·λ 0.05 here).
        let decay = |u: &[f64]| {
            let weights = f.grid.edge_arrays().length.iter();
            let along = u.iter().zip(&smooth).zip(weights);
            let (dot, norm) = along.fold((0.0, 0.0), |(p, q), ((a, b), l)| {
                (p + a * b * l, q + b * b * l)
            });
            1.0 - dot / norm
        };
        let (by_euler, by_stages) = (decay(&euler), decay(&f.u_m_per_s));
        eprintln!("vortex decay: Euler {by_euler:.5e}, stages {by_stages:.5e}");
        assert!(
            (by_stages - by_euler).abs() < 0.05 * by_euler,
            "decay {by_stages:e} against {by_euler:e}"
        );
        for (k, u) in f.u_m_per_s.iter_mut().enumerate() {
            *u = if k % 2 == 0 { 1e-3 } else { -1e-3 };
        }
        let before = energy(&f);
        let long = step_of(&f, nu, 149.5);
        on_rows(&mut f, &mut |f, u| {
            f.viscous_step(u, &mut s, nu, long, true);
        });
        let after = energy(&f);
        assert!(after < before, "energy {before:e} → {after:e}");
    }
}

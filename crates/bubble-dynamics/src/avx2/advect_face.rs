//! One face's rows of an advection stage in AVX2 registers, in one call ([`face_stage`]):
//! the rows of `Stage::stage`, the same arithmetic in the same order, so the same bits.
//! There each row sliced some twenty arrays again, checked their bounds and chose its
//! starting velocities' and its destination's layouts: about 425 instructions a row, 19 M
//! of the advection's 94 M over `film_profile 64 0 9.81`'s 40 steps. Here the face's
//! arrays are checked once and each row's are its face's at fixed strides (85.1 M).
//! Where `n` is a multiple of four, each group of four cells' terms moves the edges they
//! complete as soon as they are taken ([`fused_row`]), where the row's terms were stored
//! and read back by two more loops (82.5 M).

use std::arch::x86_64::{
    __m256d, _mm256_add_pd, _mm256_blend_pd, _mm256_cvtsd_f64, _mm256_loadu_pd, _mm256_mul_pd,
    _mm256_permute4x64_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd, _mm256_sub_pd,
};

use super::{QUAD_WEIGHTS, coriolis_quad, coriolis_terms};

use crate::film_flow::advect::rk3_step;

/// What one face's part of a stage reads: the face's own values, and face 0's constants,
/// which every face reads ([`FaceRows`](crate::film_flow::face_rows::FaceRows) says why).
pub(crate) struct FaceInputs<'a> {
    /// Cells along a side of the face (at least 4).
    pub(crate) n: usize,
    /// The face's edge velocities the stage moves, where they are not its destination's
    /// (per local edge of the face).
    pub(crate) src: Option<&'a [f64]>,
    /// Where the face's starting velocities are.
    pub(crate) start: FaceStart<'a>,
    /// The vorticity of the face's border vertices, per local vertex of the face (the
    /// inner ones' unread).
    pub(crate) kept: &'a [f64],
    /// Face 0's dual lengths, per local edge.
    pub(crate) dual_length: &'a [f64],
    /// Face 0's `1/(A R)`, per local vertex.
    pub(crate) scale: &'a [f64],
    /// Face 0's Coriolis weights, by rows of cells.
    pub(crate) coriolis: &'a [f64],
    /// Face 0's `1/(l d)`, per local edge.
    pub(crate) inverse_norm: &'a [f64],
    /// Where the stage adds gravity: the step, s, `g` along the face's axis, m/s², and face
    /// 0's gradient component along it, per local edge.
    pub(crate) gravity: Option<(f64, f64, &'a [f64])>,
}

/// Where a face's stage reads each edge's starting velocity.
#[derive(Clone, Copy)]
pub(crate) enum FaceStart<'a> {
    /// The destination's entry, before it is written.
    Dst,
    /// These, per local edge of the face.
    Rows(&'a [f64]),
    /// The grid's numbering: from the grid's first inner X-edge of the face, its `n` rows
    /// of `n − 1` (and one value more, which a row's run through its right border copy
    /// reads), and from its first inner Y-edge, its `n − 1` rows of `n`.
    Grid { x: &'a [f64], y: &'a [f64] },
}

/// Where a stage's rows read and write, as pointers checked once for the whole face.
#[derive(Clone, Copy)]
struct Plan {
    /// Cells along a side of the face.
    n: usize,
    /// The velocities read (the destination's where moved in place).
    u: *const f64,
    /// The destination.
    dst: *mut f64,
    /// The starting velocity of X-edge `(1, 0)`, the stride between X-edge rows, and that
    /// of Y-edge `(0, 1)` (its rows `n` apart).
    start: (*const f64, usize, *const f64),
    /// [`FaceInputs::kept`].
    kept: *const f64,
    /// [`FaceInputs::dual_length`].
    dual_length: *const f64,
    /// [`FaceInputs::scale`].
    scale: *const f64,
    /// [`FaceInputs::coriolis`].
    coriolis: *const f64,
    /// [`FaceInputs::inverse_norm`].
    inverse_norm: *const f64,
    /// The step, `g` and the gradient component, all zero (and unread) without gravity.
    gravity: (f64, f64, *const f64),
    /// Two rows' vertex vorticity, `n + 1` each.
    z: [*mut f64; 2],
    /// Two rows' cell terms, per side (bottom, left, right, top), `n + 1` each.
    rate: [[*mut f64; 4]; 2],
    /// The face's kept border terms, per side, `n` each.
    border: *mut f64,
}

/// One face's rows of a stage, stage `STAGE` of [`rk3_step`] over `h`, as `Stage::stage`
/// takes them (the same bits), into the face's local edges `dst`: each row's vertex
/// vorticity, its cells' terms (the face's border terms kept into `border`, per side of
/// the face, `n` each), its X-edges and the Y-edges below it. Gravity is added where
/// `GRAVITY` (then given in `at`). `z` (two rows of `n + 1`) and `rate` (two rows' four
/// sides, `n + 1` each) are the rows' buffers.
///
/// # Panics
/// If `n < 4`, gravity is given or not against `GRAVITY`, or a slice is short of the
/// face's.
#[target_feature(enable = "avx2")]
pub(crate) fn face_stage<const STAGE: u8, const GRAVITY: bool>(
    at: &FaceInputs<'_>,
    h: f64,
    dst: &mut [f64],
    border: &mut [f64],
    z: [&mut [f64]; 2],
    rate: [&mut [f64]; 8],
) {
    let n = at.n;
    let (w, groups) = (n + 1, n.div_ceil(4));
    let (epf, vpf) = (2 * n * w, w * w);
    assert!(n >= 4, "a face of {n} cells a side");
    assert_eq!(
        GRAVITY,
        at.gravity.is_some(),
        "gravity given against GRAVITY"
    );
    let fits = dst.len() == epf
        && at.src.is_none_or(|s| s.len() == epf)
        && at.kept.len() == vpf
        && at.dual_length.len() >= epf
        && at.scale.len() >= vpf
        && at.coriolis.len() >= n * groups * QUAD_WEIGHTS
        && at.inverse_norm.len() >= epf
        && at.gravity.is_none_or(|(_, _, c)| c.len() >= epf)
        && border.len() == 4 * n
        && z.iter().all(|r| r.len() > n)
        && rate.iter().all(|r| r.len() > n);
    assert!(fits, "a face's slices do not fit n = {n}");
    let d = dst.as_mut_ptr();
    let start = match at.start {
        FaceStart::Dst => (
            d.cast_const().wrapping_add(1),
            w,
            d.cast_const().wrapping_add(n * w + n),
        ),
        FaceStart::Rows(r) => {
            assert_eq!(r.len(), epf, "starting velocities of another face size");
            (
                r.as_ptr().wrapping_add(1),
                w,
                r.as_ptr().wrapping_add(n * w + n),
            )
        }
        FaceStart::Grid { x, y } => {
            let fits = x.len() > n * (n - 1) && y.len() >= (n - 1) * n;
            assert!(fits, "the grid's runs do not fit n = {n}");
            (x.as_ptr(), n - 1, y.as_ptr())
        }
    };
    let [z0, z1] = z.map(<[f64]>::as_mut_ptr);
    let [b0, l0, r0, t0, b1, l1, r1, t1] = rate.map(<[f64]>::as_mut_ptr);
    let (g_dt, g, c) = at.gravity.unwrap_or((0.0, 0.0, &[]));
    let plan = Plan {
        n,
        u: at.src.map_or(d.cast_const(), <[f64]>::as_ptr),
        dst: d,
        start,
        kept: at.kept.as_ptr(),
        dual_length: at.dual_length.as_ptr(),
        scale: at.scale.as_ptr(),
        coriolis: at.coriolis.as_ptr(),
        inverse_norm: at.inverse_norm.as_ptr(),
        gravity: (g_dt, g, c.as_ptr()),
        z: [z0, z1],
        rate: [[b0, l0, r0, t0], [b1, l1, r1, t1]],
        border: border.as_mut_ptr(),
    };
    // SAFETY: every slice the plan points into is as long as checked above, and each row
    // reads and writes within those lengths (see `rows`).
    unsafe { rows::<STAGE, GRAVITY>(plan, h) };
}

/// The rows of [`face_stage`] from its checked plan.
///
/// # Safety
/// The processor has AVX2, and the plan's pointers are into slices of the lengths
/// [`face_stage`] checks.
#[target_feature(enable = "avx2")]
unsafe fn rows<const STAGE: u8, const GRAVITY: bool>(p: Plan, h: f64) {
    let n = p.n;
    let w = n + 1;
    // SAFETY (throughout): the offsets are those of local edges and vertices of one face,
    // of a row of `n + 1` cell terms, or of the face's `4n` border terms, within the
    // checked lengths: vertex row `j ≤ n` at `j (n + 1)`, X-edge row `y < n` at
    // `y (n + 1)`, `n + 1` long, Y-edge row `j ≤ n` at `n (n + 1) + j n`, `n` long, the
    // chunks of four within `n` (the last at `n − 4`).
    unsafe {
        let mut zb = p.kept;
        for y in 0..n {
            let zt = if y + 1 == n {
                p.kept.add(n * w)
            } else {
                let out = p.z[(y + 1) % 2];
                circulation_row(p, y + 1, out);
                out.cast_const()
            };
            // This row's cell terms (its tops read by the next row's Y-edges) and the row
            // before's.
            let (rate, before) = (p.rate[y % 2], p.rate[(y + 1) % 2]);
            if n % 4 == 0 {
                let (z, top) = ([zb, zt], (rate[3], before[3].cast_const()));
                if y == 0 {
                    fused_row::<STAGE, GRAVITY, false>(p, h, y, z, top);
                } else {
                    fused_row::<STAGE, GRAVITY, true>(p, h, y, z, top);
                }
            } else {
                row_apart::<STAGE, GRAVITY>(p, h, y, [zb, zt], rate, before[3]);
            }
            zb = zt;
        }
    }
}

/// Row `y`'s cells' terms (`z` its bottom and top vertices' vorticity) and the moves of
/// its X-edges and, where `BELOW` (`y > 0`), of the Y-edges below it (`before_top` the
/// row before's top terms), `n` a multiple of four. Each group of four cells moves its
/// cells' left and bottom edges as soon as its terms are taken, where a row's terms were
/// stored and read back by two loops of moves: an X-edge's other term, the right one of
/// the cell on its left, is the group's right terms a lane on, the group before's last
/// carried into lane 0. The row's tops go to `top` (for the next row's Y-edges), or to
/// the face's border terms on its last row, as its bottoms do on its first and its first
/// left and last right terms on every row.
///
/// # Safety
/// As [`rows`]: `y < n` (`BELOW` where `y > 0`), `n` a multiple of four, `top` and
/// `before_top` hold `n`.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn fused_row<const STAGE: u8, const GRAVITY: bool, const BELOW: bool>(
    p: Plan,
    h: f64,
    y: usize,
    z: [*const f64; 2],
    (top, before_top): (*mut f64, *const f64),
) {
    let n = p.n;
    let w = n + 1;
    let (kx, ky) = (y * w, n * w + y * n);
    // SAFETY: as [`rows`] says. X-edge `(i, y)`'s starting velocity is at `i − 1` of its
    // run; the first group's lane 0 (the left border copy, put back after) takes lane 1's
    // run, so that no run is read before its first.
    unsafe {
        let ld = |base: *const f64, at: usize| _mm256_loadu_pd(base.add(at));
        let u = [p.u.add(ky), p.u.add(kx), p.u.add(ky + n)];
        let weights = p.coriolis.add(y * (n / 4) * QUAD_WEIGHTS);
        let (start_x, start_y) = (p.start.0.add(y * p.start.1), p.start.2);
        let top = if y + 1 == n { p.border.add(3 * n) } else { top };
        let border_copy = *p.dst.add(kx);
        let moves = Moves::<STAGE, GRAVITY>::new(p, h);
        // The group before's right terms, turned a lane on (its last in lane 0).
        let mut carried = _mm256_setzero_pd();
        for g in 0..n / 4 {
            let x = 4 * g;
            let ([b, l, r, t], [ub, ul, _, _]) =
                coriolis_terms(weights.add(g * QUAD_WEIGHTS), z, u, x);
            let turned = _mm256_permute4x64_pd::<0b10_01_00_11>(r);
            let right_of_left = _mm256_blend_pd::<0b0001>(turned, carried);
            carried = turned;
            let start = || {
                if g == 0 {
                    _mm256_permute4x64_pd::<0b10_01_00_00>(ld(start_x, 0))
                } else {
                    ld(start_x, x - 1)
                }
            };
            let x_edges = moves.lanes(kx + x, ul, start, _mm256_add_pd(right_of_left, l));
            _mm256_storeu_pd(p.dst.add(kx + x), x_edges);
            if BELOW {
                let start = || ld(start_y, (y - 1) * n + x);
                let rates = _mm256_add_pd(ld(before_top, x), b);
                _mm256_storeu_pd(p.dst.add(ky + x), moves.lanes(ky + x, ub, start, rates));
            } else {
                _mm256_storeu_pd(p.border.add(x), b);
            }
            _mm256_storeu_pd(top.add(x), t);
            if g == 0 {
                *p.border.add(n + y) = _mm256_cvtsd_f64(l);
            }
        }
        *p.border.add(2 * n + y) = _mm256_cvtsd_f64(carried);
        *p.dst.add(kx) = border_copy;
    }
}

/// Row `y`'s cells' terms into `rate` (bottom, left, right, top; `z` its bottom and top
/// vertices' vorticity), its border cells' kept, then the moves of its X-edges and of the
/// Y-edges below it (`y > 0`, `before_top` the row before's top terms) from those: `n`
/// not a multiple of four, the last group of cells overlapping the one before.
///
/// # Safety
/// As [`rows`]: `y < n`, each of `rate` and `before_top` holds `n + 1`.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn row_apart<const STAGE: u8, const GRAVITY: bool>(
    p: Plan,
    h: f64,
    y: usize,
    z: [*const f64; 2],
    [rb, rl, rr, rt]: [*mut f64; 4],
    before_top: *const f64,
) {
    let n = p.n;
    let (w, groups) = (n + 1, n.div_ceil(4));
    // SAFETY: as [`rows`] says.
    unsafe {
        let (ux, uy) = (p.u.add(y * w), p.u.add(n * w + y * n));
        let weights = p.coriolis.add(y * groups * QUAD_WEIGHTS);
        let out = [rb, rl, rr, rt];
        let u = [uy, ux, uy.add(n)];
        for g in 0..n / 4 {
            coriolis_quad(weights.add(g * QUAD_WEIGHTS), z, u, out, 4 * g);
        }
        if n % 4 != 0 {
            coriolis_quad(weights.add(n / 4 * QUAD_WEIGHTS), z, u, out, n - 4);
        }
        keep_border_rates(p, out, y);
        let moves = Moves::<STAGE, GRAVITY>::new(p, h);
        // The X-edges inside the face and the right border copy (the row's `n`),
        // that copy's entry put back after (as `Stage::stage` does).
        let k = y * w + 1;
        let border_copy = *p.dst.add(k + n - 1);
        let start = p.start.0.add(y * p.start.1);
        moves.run(k, start, [rr.cast_const(), rl.add(1)]);
        *p.dst.add(k + n - 1) = border_copy;
        if y > 0 {
            let k = n * w + y * n;
            let start = p.start.2.add((y - 1) * n);
            moves.run(k, start, [before_top, rb]);
        }
    }
}

/// Keeps row `y`'s border cells' terms (`rate`: bottom, left, right, top) into the face's
/// border terms, as `keep_border_rates` does.
///
/// # Safety
/// As [`rows`]: `y < n`.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn keep_border_rates(p: Plan, [rb, rl, rr, rt]: [*mut f64; 4], y: usize) {
    let n = p.n;
    // SAFETY: as [`rows`] says: the face's `4n` border terms, the row's `n`.
    unsafe {
        *p.border.add(n + y) = *rl;
        *p.border.add(2 * n + y) = *rr.add(n - 1);
        if y == 0 {
            std::ptr::copy_nonoverlapping(rb, p.border, n);
        }
        if y == n - 1 {
            std::ptr::copy_nonoverlapping(rt, p.border.add(3 * n), n);
        }
    }
}

/// The vorticity of inner vertex row `j` into `out` (`n + 1`), as
/// `FaceRows::face_circulation_row` and `Stage::vertex_row` take it: its ends the kept
/// border vertices'.
///
/// # Safety
/// As [`rows`]: `0 < j < n`, `out` holds `n + 1`.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn circulation_row(p: Plan, j: usize, out: *mut f64) {
    let (n, w) = (p.n, p.n + 1);
    // X-edge rows `j − 1` and `j`, and Y-edge row `j` from the one before its first.
    let (xb, xa, yl) = ((j - 1) * w, j * w, n * w + j * n - 1);
    // SAFETY: as [`rows`] says; the Y-edge before row `j`'s first is row `j − 1`'s last.
    unsafe {
        let ld = |base: *const f64, at: usize| _mm256_loadu_pd(base.add(at));
        let (u, d) = (p.u, p.dual_length);
        let chunk = |i: usize| {
            let left = _mm256_mul_pd(ld(u, yl + i), ld(d, yl + i));
            let below = _mm256_mul_pd(ld(u, xb + i), ld(d, xb + i));
            let right = _mm256_mul_pd(ld(u, yl + 1 + i), ld(d, yl + 1 + i));
            let above = _mm256_mul_pd(ld(u, xa + i), ld(d, xa + i));
            let z = _mm256_add_pd(_mm256_sub_pd(_mm256_sub_pd(left, below), right), above);
            _mm256_storeu_pd(out.add(i), _mm256_mul_pd(z, ld(p.scale, j * w + i)));
        };
        for i in (0..n / 4).map(|q| 4 * q) {
            chunk(i);
        }
        // The last four again where `n` is not a multiple of four: the same values.
        if n % 4 != 0 {
            chunk(n - 4);
        }
        *out = *p.kept.add(j * w);
        *out.add(n) = *p.kept.add(j * w + n);
    }
}

/// The edge moves of stage `STAGE` of [`rk3_step`] (plus gravity where `GRAVITY`), as
/// `move_edges` takes them: `dst ← step(u, u0, (ra + rb)·s)`, `s` the edge's `1/(l d)`.
#[derive(Clone, Copy)]
struct Moves<const STAGE: u8, const GRAVITY: bool> {
    /// The plan whose edges move.
    p: Plan,
    /// The sub-step, s.
    h: f64,
    /// `h`, gravity's step and `g` in each lane.
    lanes: [__m256d; 3],
}

impl<const STAGE: u8, const GRAVITY: bool> Moves<STAGE, GRAVITY> {
    /// The moves of `p`'s edges over `h`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn new(p: Plan, h: f64) -> Self {
        let (g_dt, g, _) = p.gravity;
        let lanes = [h, g_dt, g].map(|v| _mm256_set1_pd(v));
        Self { p, h, lanes }
    }

    /// The moved velocities of local edges `k..k + 4`: `u` theirs, `start` their starting
    /// ones (read only by the stages that take them), `rates` their terms' sums.
    ///
    /// # Safety
    /// As [`rows`]: `k..k + 4` are a row's local edges.
    #[target_feature(enable = "avx2")]
    #[inline]
    unsafe fn lanes(
        self,
        k: usize,
        u: __m256d,
        start: impl FnOnce() -> __m256d,
        rates: __m256d,
    ) -> __m256d {
        let (add, mul, splat) = (_mm256_add_pd, _mm256_mul_pd, _mm256_set1_pd);
        let [h, g_dt, g] = self.lanes;
        // SAFETY: the caller's promise.
        unsafe {
            let r = mul(rates, _mm256_loadu_pd(self.p.inverse_norm.add(k)));
            let moved = add(u, mul(h, r));
            let v = match STAGE {
                1 => moved,
                2 => add(mul(splat(0.75), start()), mul(splat(0.25), moved)),
                _ => add(mul(splat(1.0 / 3.0), start()), mul(splat(2.0 / 3.0), moved)),
            };
            if GRAVITY {
                let c = _mm256_loadu_pd(self.p.gravity.2.add(k));
                add(v, mul(g_dt, mul(g, c)))
            } else {
                v
            }
        }
    }

    /// The `n` local edges from `k` moved: `start` their starting velocities, `terms`
    /// their two cells' terms. Four edges an instruction, the last `n mod 4` one by one
    /// (each edge's entry of the destination may be its source: a chunk taken twice would
    /// move its edges twice).
    ///
    /// # Safety
    /// As [`rows`]: the `n` edges from `k` are one row's, `start` holds `n` and `terms`
    /// `n` each.
    #[target_feature(enable = "avx2")]
    #[inline]
    unsafe fn run(self, k: usize, start: *const f64, [ra, rb]: [*const f64; 2]) {
        let (p, n) = (self.p, self.p.n);
        // SAFETY: as [`rows`] says, and the caller's promise.
        unsafe {
            let (u, dst) = (p.u.add(k), p.dst.add(k));
            let ld = |base: *const f64, i: usize| _mm256_loadu_pd(base.add(i));
            for i in (0..n / 4).map(|q| 4 * q) {
                let rates = _mm256_add_pd(ld(ra, i), ld(rb, i));
                let v = self.lanes(k + i, ld(u, i), || ld(start, i), rates);
                _mm256_storeu_pd(dst.add(i), v);
            }
            let (g_dt, g, c) = p.gravity;
            for i in n / 4 * 4..n {
                let r = (*ra.add(i) + *rb.add(i)) * *p.inverse_norm.add(k + i);
                let u0 = if STAGE == 1 { 0.0 } else { *start.add(i) };
                let mut v = rk3_step::<STAGE>(self.h, *u.add(i), u0, r);
                if GRAVITY {
                    v += g_dt * (g * *c.add(k + i));
                }
                *dst.add(i) = v;
            }
        }
    }
}

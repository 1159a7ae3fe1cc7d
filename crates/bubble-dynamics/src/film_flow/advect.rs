//! The film's momentum advection `u·∇u` on the C-grid, in vector-invariant form
//! `u·∇u = ζ k×u + ∇(|u|²/2)` (ζ the surface vorticity, k the outward normal), as C-grid
//! ocean models write it: the vorticity is the viscous operator's (the circulation
//! `Σ u d` about each grid vertex over its area), and each edge needs the velocity along
//! it, reconstructed from its two cells' vectors. For an edge with normal n and tangent
//! `t = k × n`, `(k × u)·n = −u_t`, so the rotation term gives `∂u_n/∂t = ζ u_t`.
//!
//! That circulation takes the velocity along each dual edge as the edge's normal
//! component, which near the cube's corners is up to 30° off: a solid rotation's
//! vorticity there is up to 4× wrong. Taking the full reconstructed velocity along each
//! chord instead gets it within 4 %, but then a solid rotation of 10 cm/s on a 1 cm film
//! under strong viscosity (ν = 5e-4 m²/s) lost energy at 0.23, 0.32 and 0.45 /s at
//! n = 16, 32 and 64, growing with n, where with the viscous operator's circulation it
//! loses 0.10, 0.11 and 0.12 /s (0.06 and 0.07 /s at n = 16 and 32 with no advection: the
//! rest is the splitting below).
//!
//! Only the rotation term is taken. The kinetic-energy gradient is a gradient, which the
//! Marangoni stress holds as the film's pressure: in the nearly incompressible film
//! (Marangoni waves at metres a second against flows of centimetres) it shifts the
//! surfactant by `ρh|u|²/(2E_f)` relative, 1e-4 at 10 cm/s on 1 µm, and leaves the flow
//! alone. Taken explicitly it is the pressureless Burgers term, which steepened a solid
//! rotation to NaN within ten 1/240 s steps at n = 32 without the Marangoni step.
//!
//! Explicit, strong-stability-preserving Runge–Kutta 3 (stable for the rotation-like
//! `ζ k×u`, which forward Euler would amplify), in sub-steps of at most 0.8 of the
//! narrowest dual edge at the fastest cell's speed. Two evaluations a step do not do: a
//! second-order two-stage scheme amplifies a rotation at any step (`|R(iωh)|² =
//! 1 + (ωh)⁴/4`), and one that damps it (`R = 1 + z + a z²`, `a > ½`) does so at first
//! order: at `a = 0.6` the term alone lost 6.0e-3 of a rotating film's energy in 0.25 s
//! (`tests::the_rotation_term_does_no_work`, which allows 1e-4). The weights are antisymmetric, so
//! the term does no work (`ζ k×u ⊥ u`), to the time scheme's error. The Marangoni step
//! that follows absorbs the gradient part of what it adds (a solid rotation's
//! centripetal push) only within its backward-Euler relaxation, which costs a rotating
//! film energy at about (ω dt)² a step: 3.3 % of a 5 rad/s rotation's rate in 0.2 s of
//! 1/240 s steps (`tests/film_flow_advection.rs`).

use glam::DVec3;

use crate::avx2::{PAIRS, QUAD_WEIGHTS, coriolis_row, quad_starts, with_avx2};

use super::compare::larger;
use super::face_rows::{AxisGravity, FaceRows, SIDES, Side, face_order};
use super::grid::CubeSphere;
#[cfg(target_arch = "x86_64")]
use crate::avx2::advect_face::{self, FaceInputs, FaceStart};

/// Largest fraction of the narrowest dual edge the fastest cell may cross in a sub-step.
/// SSP-RK3 damps (never amplifies) a rotation of `ω·sub_dt < √3`; the vorticity at the
/// grid scale is at most about twice the speed over the cell width, so 0.8 keeps
/// `ω·sub_dt ≤ 1.6`.
const MAX_COURANT: f64 = 0.8;

/// What the advection reads of the grid, per cell, derived once from it. Every weight
/// is in the face rows' orientation ([`FaceRows`]): the grid's, negated for each edge
/// whose copy in the rows is flipped.
#[derive(Clone, Debug)]
pub(crate) struct AdvectionGeometry {
    /// Per side of a cell (in [`SIDES`] order), per component, per cell: the weight by
    /// which the side's normal velocity enters the cell's velocity vector (Perot's
    /// reconstruction `U_c = Σ ± l (m − x_c) u / A_c`, exact for a uniform field on a flat
    /// cell).
    to_cell: [[Vec<f64>; 3]; 4],
    /// Per component, per cell: the cell's centre.
    centre: [Vec<f64>; 3],
    /// Per cell, per pair `[i, o]` of its sides ([`PAIRS`], in [`SIDES`] order): the
    /// weight of side `o` in side `i`'s `ζ k×u` term times side `i`'s weight `l d` in the
    /// energy norm, times ¼: the term takes the sum of the two edges' vorticities, each
    /// the sum of its two vertices' (the ½ of the mean and the ½ of each edge's mean,
    /// exact powers of two, folded into the weight, for the same bits as halving each sum
    /// in the loop). An edge's term sums over the other edges of its two cells; the
    /// weights are the reconstruction's `½ t·w` made antisymmetric under the energy norm
    /// `Σ l d u²`, so the term does no work, as `ζ k×u ⊥ u` in the continuum (with the
    /// reconstruction's own weights the advection alone lost 3.3e-4 of a rotating film's
    /// energy in 0.25 s: `tests::the_rotation_term_does_no_work`). Times `l d`, side
    /// `o`'s weight in side `i`'s term is minus side `i`'s in side `o`'s: one weight a
    /// pair, six a cell where twelve were read, each edge's rate then divided by its own
    /// `l d` ([`Self::inverse_norm`]). Taken cell by cell, each cell's four edges are read
    /// once for the twelve terms among them. Stored by rows of cells, in each row its
    /// groups of four cells ([`quad_starts`]) laid out as [`QUAD_WEIGHTS`] says
    /// ([`coriolis_row`]): separate arrays a row left the compiler's loop short of
    /// registers for their bases. Every cell sums its terms in this order, the
    /// faces' border cells whose edges the grid numbers otherwise too
    /// ([`FaceRows::irregular_cells`]): taken apart in the grid's order, those cost a
    /// fifth of the advection's instructions, for sums that differ only in rounding.
    ///
    /// Face 0's only, which every face reads: the grid is symmetric under the cube's
    /// rotations and each face's rows are in its own frame, so every face's weights are
    /// face 0's to rounding (within 1e-14 of the largest at n = 64:
    /// `tests::every_faces_coriolis_weights_are_face_0s`). Six faces' weights (twelve a
    /// cell) were 2.4 MB at n = 64, streamed from beyond the core's 1 MB L2 in each of a
    /// step's three stages; one face's twelve were 0.4 MB, its six are 0.2 MB.
    coriolis: Vec<f64>,
    /// Per local edge of face 0, which every face reads as it reads [`Self::coriolis`]
    /// (every face's within 1e-14 of face 0's:
    /// `tests::every_faces_coriolis_weights_are_face_0s`): `1/(l d)`, the inverse of the
    /// edge's weight in the energy norm, by which the sum of its two cells' terms becomes
    /// its rate.
    inverse_norm: Vec<f64>,
    /// [`Self::to_cell`] for the [`FaceRows::irregular_cells`], in the order the grid
    /// numbers their edges.
    irregular: Vec<IrregularWeights>,
    /// The narrowest dual edge, rad.
    min_dual_length: f64,
    /// A bound on any cell's speed per unit speed of its fastest edge: the largest sum of
    /// a cell's four reconstruction weights' lengths, with a margin of 1e-9 for the
    /// rounding of the velocities' sums.
    speed_bound: f64,
    /// The edges on the faces' borders, each with what it takes from the kept border
    /// rates ([`StageWork::border_rate`]).
    seams: Vec<SeamTerms>,
}

/// An edge on the faces' borders: its two cells' terms (the lower-numbered cell's
/// first) and its two local copies.
#[derive(Clone, Copy, Debug)]
struct SeamTerms {
    /// Per cell: the slot of its term of the edge's side in [`StageWork::border_rate`].
    slots: [u32; 2],
    /// Per cell: its face's copy of the edge.
    edges: [u32; 2],
    /// Per cell: the copy's orientation against the grid's (`±1`).
    signs: [f64; 2],
    /// The grid's edge (both copies'), for the starting velocities in the grid's
    /// numbering ([`Start::Grid`]).
    grid_edge: u32,
    /// [`AdvectionGeometry::inverse_norm`] of the grid's edge.
    inverse_norm: f64,
    /// The face of the first copy.
    first_face: u32,
}

/// An irregular cell's reconstruction weights, its sides in the grid's order.
#[derive(Clone, Copy, Debug)]
struct IrregularWeights {
    to_cell: [[f64; 3]; 4],
}

impl AdvectionGeometry {
    /// Derives the weights from `grid` and its face rows.
    pub(crate) fn new(grid: &CubeSphere, rows: &FaceRows) -> Self {
        Self::with_coriolis_faces(grid, rows, 1)
    }

    /// [`Self::new`], with [`Self::coriolis`] for the first `faces` faces (one is all the
    /// advection reads; the tests take six to compare them).
    fn with_coriolis_faces(grid: &CubeSphere, rows: &FaceRows, faces: usize) -> Self {
        let centres = grid.centres();
        let areas = grid.areas_sr();
        let edges = grid.edges();
        let to_cells: Vec<[DVec3; 2]> = edges
            .iter()
            .map(|e| {
                let (a, b) = (e.a as usize, e.b as usize);
                [
                    (e.midpoint - centres[a]) * (e.length / areas[a]),
                    (e.midpoint - centres[b]) * (-e.length / areas[b]),
                ]
            })
            .collect();
        let tangent: Vec<DVec3> = edges.iter().map(|e| e.midpoint.cross(e.normal)).collect();
        let cell_edges = cell_edges(grid);
        let stencil = coriolis_stencil(grid, &cell_edges, &to_cells, &tangent);
        // Per cell, per side: the local edge, its sign and its reconstruction weight.
        let side = |c: usize, i: usize| {
            let k = rows.cell_edge(c, SIDES[i]);
            let e = rows.edge[k] as usize;
            let w = to_cells[e][usize::from(edges[e].a as usize != c)];
            (e, rows.sign(k), w)
        };
        // The weight of side `o`'s velocity in side `i`'s term times side `i`'s `l d`, in
        // the rows' orientation.
        let coriolis = |c: usize, [i, o]: [usize; 2]| {
            let ((e, si, _), (other, so, _)) = (side(c, i), side(c, o));
            let half = if edges[e].a as usize == c { 0 } else { 3 };
            let (_, w) = stencil[e][half..half + 3]
                .iter()
                .copied()
                .find(|&(id, _)| id as usize == other)
                .expect("a cell's other edge in its edge's stencil");
            si * so * (0.25 * w)
        };
        let cells = grid.cells();
        let to_cell = std::array::from_fn(|i| {
            std::array::from_fn(|axis| {
                (0..cells)
                    .map(|c| (side(c, i).2 * side(c, i).1)[axis])
                    .collect()
            })
        });
        let face_cells = faces * rows.n * rows.n;
        let weights = PAIRS.map(|pair| (0..face_cells).map(|c| coriolis(c, pair)).collect());
        let irregular = rows
            .irregular_cells
            .iter()
            .map(|ic| {
                let c = ic.cell as usize;
                let slot = ic.order.map(|s| s as usize);
                IrregularWeights {
                    to_cell: slot.map(|i| (side(c, i).2 * side(c, i).1).to_array()),
                }
            })
            .collect();
        let speed_bound = (0..cells)
            .map(|c| (0..4).map(|i| side(c, i).2.length()).sum::<f64>())
            .fold(0.0, f64::max)
            * (1.0 + 1e-9);
        let seams = rows
            .seam_edges
            .iter()
            .map(|e| {
                let slot = |(c, side, _): (u32, Side, u32)| border_slot(rows.n, c as usize, side);
                SeamTerms {
                    slots: e.cells.map(slot),
                    edges: e.cells.map(|(_, _, k)| k),
                    signs: e.cells.map(|(_, _, k)| rows.sign(k as usize)),
                    grid_edge: rows.edge[e.cells[0].2 as usize],
                    inverse_norm: inverse_norm(&edges[rows.edge[e.cells[0].2 as usize] as usize]),
                    first_face: e.cells[0].2 / rows.edges_per_face() as u32,
                }
            })
            .collect();
        Self {
            speed_bound,
            seams,
            to_cell,
            centre: std::array::from_fn(|a| centres.iter().map(|c| c[a]).collect()),
            coriolis: interleave_quads(&weights, rows.n, faces),
            inverse_norm: (0..rows.edges_per_face())
                .map(|k| inverse_norm(&edges[rows.edge[k] as usize]))
                .collect(),
            irregular,
            min_dual_length: edges
                .iter()
                .map(|e| e.dual_length)
                .fold(f64::INFINITY, f64::min),
        }
    }
}

/// `1/(l d)` of `edge`: the inverse of its weight in the energy norm.
fn inverse_norm(edge: &super::grid::GridEdge) -> f64 {
    1.0 / (edge.length * edge.dual_length)
}

/// The Coriolis weights `w[pair][cell]` of the first `faces` faces laid out by rows of
/// `n` cells, each row by its groups of four ([`AdvectionGeometry::coriolis`]); zero past
/// a row of fewer than four.
fn interleave_quads(w: &[Vec<f64>; 6], n: usize, faces: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(faces * n * n.div_ceil(4) * QUAD_WEIGHTS);
    for row in 0..faces * n {
        for start in quad_starts(n) {
            let cell = |lane: usize| row * n + start + lane;
            for side in w {
                out.extend((0..4).map(|l| if l < n { side[cell(l)] } else { 0.0 }));
            }
        }
    }
    out
}

/// Each cell's four edges, in increasing order.
///
/// # Panics
/// If a cell does not have four edges.
fn cell_edges(grid: &CubeSphere) -> Vec<[u32; 4]> {
    let mut lists = vec![Vec::with_capacity(4); grid.cells()];
    for (i, e) in grid.edges().iter().enumerate() {
        lists[e.a as usize].push(i as u32);
        lists[e.b as usize].push(i as u32);
    }
    let four = |(c, l): (usize, Vec<u32>)| {
        <[u32; 4]>::try_from(l).unwrap_or_else(|l| panic!("cell {c} has {} edges", l.len()))
    };
    lists.into_iter().enumerate().map(four).collect()
}

/// The antisymmetric `ζ k×u` stencil (see [`AdvectionGeometry::coriolis`]) times each
/// edge's `l d`: per edge, cell `a`'s other edges, then cell `b`'s, each in increasing
/// order (so that an edge's weight of another is minus the other's of it).
fn coriolis_stencil(
    grid: &CubeSphere,
    cell_edges: &[[u32; 4]],
    to_cells: &[[DVec3; 2]],
    tangent: &[DVec3],
) -> Vec<[(u32, f64); 6]> {
    let edges = grid.edges();
    let centres = grid.centres();
    // M[e][e'] = l_e d_e · ½ t_e,c · w_c,e' for e' of shared cell c, with t_e,c the
    // edge's tangent in the cell's tangent plane (the reconstruction projects there).
    let m = |e: usize, other: usize, c: usize| {
        let (ed, od) = (&edges[e], &edges[other]);
        let x = centres[c];
        let t = tangent[e] - x * tangent[e].dot(x);
        let w = to_cells[other][usize::from(od.a as usize != c)];
        ed.length * ed.dual_length * 0.5 * t.dot(w)
    };
    edges
        .iter()
        .enumerate()
        .map(|(e, ed)| {
            let mut out = [(0u32, 0.0); 6];
            let mut k = 0;
            for c in [ed.a as usize, ed.b as usize] {
                for other in cell_edges[c]
                    .iter()
                    .map(|&o| o as usize)
                    .filter(|&o| o != e)
                {
                    let a = 0.5 * (m(e, other, c) - m(other, e, c));
                    out[k] = (other as u32, a);
                    k += 1;
                }
            }
            assert_eq!(k, 6, "edge {e}: its cells have {k} other edges, not 6");
            out
        })
        .collect()
}

/// Buffers of one advection step, reused across steps.
#[derive(Clone, Debug, Default)]
pub(crate) struct AdvectionScratch {
    /// The first stage's edge velocities, then the second's (which moves them where they
    /// are, [`Stage::stage`]), in the face rows, m/s: the sub-step's starting velocities
    /// stay where they are, and no copy of them is taken. Untouched where the stages
    /// read those from the grid's numbering ([`advect_momentum`]).
    stage: Vec<f64>,
    /// Per cell: its squared speed, m²/s².
    speed_squared: Vec<f64>,
    /// What a stage keeps besides the velocities.
    work: StageWork,
    /// Per local vertex of face 0, which every face reads (as it does face 0's areas,
    /// [`FaceRows::vertex_area`]): `1/(A R)` for the radius in [`Self::scale_radius_m`],
    /// by which a circulation becomes a vorticity (a multiplication where a division took
    /// several times as long, in each stage's pass over the vertices).
    vorticity_scale: Vec<f64>,
    /// The radius [`Self::vorticity_scale`] was taken for, m (zero for none).
    scale_radius_m: f64,
}

/// What a stage reads and writes besides the velocities.
#[derive(Clone, Debug, Default)]
struct StageWork {
    /// Per local vertex on the faces' borders (every copy; the inner ones are not
    /// kept): the vorticity of the velocities the stage under way starts from, 1/s.
    vorticity: Vec<f64>,
    /// Vertex rows `j` and `j + 1` of the face under way (at `j mod 2`, `n + 1` each):
    /// the vorticity of the velocities the stage starts from, each inner row taken from
    /// them as the stage reaches it ([`Stage::stage`]), where a whole-grid array of it
    /// was written by one stage and read by the next (0.2 MB each way at n = 64).
    vertex_rows: [Vec<f64>; 2],
    /// Per face, per side of it (in [`SIDES`] order), per cell along it ([`border_slot`]):
    /// the term of the border cell there of that side's rate, m/s², in the rows'
    /// orientation (12 KB at n = 64, where a slot for every cell's every side spread
    /// a row's two border terms over two lines of 0.8 MB).
    border_rate: Vec<f64>,
    /// The same for the row of cells under way and the one before (even and odd rows),
    /// and one slot more: the left side of the cell past the row's end, read (unset) for
    /// the right border copy a row's X-edges move through (junk until the seam pass).
    row_rate: [[Vec<f64>; 4]; 2],
}

impl StageWork {
    /// Gives every buffer its length (each entry read is written first).
    fn prepare(&mut self, rows: &FaceRows) {
        let n = rows.n;
        self.vorticity.resize(rows.vertices(), 0.0);
        for r in &mut self.vertex_rows {
            r.resize(n + 1, 0.0);
        }
        self.border_rate.resize(6 * 4 * n, 0.0);
        for r in self.row_rate.iter_mut().flatten() {
            r.resize(n + 1, 0.0);
        }
    }
}

/// Advances the edge velocities `u` (m/s, in the face rows) by `u·∇u` over `dt_s` on a
/// sphere of `radius_m`. Where `grid` is given, `u` is [`FaceRows::to_rows`] of it (the
/// same values in the grid's numbering and orientation): a lone sub-step then moves `u`
/// where it is in all three stages and reads its starting velocities from `grid`
/// ([`Start::Grid`]), where otherwise it writes a stage buffer of the rows from cold
/// (0.4 MB at n = 64); the same bits either way.
///
/// Then `gravity`, where given, is added as [`FaceRows::add_gravity`] adds it (the same
/// bits): by the last stage, to each edge as it moves it, where a pass of its own read
/// and wrote every edge again (0.4 MB each way at n = 64, beyond L2).
#[allow(clippy::too_many_arguments)] // each is a separate input of the step
pub(crate) fn advect_momentum(
    rows: &FaceRows,
    geo: &AdvectionGeometry,
    radius_m: f64,
    dt_s: f64,
    u: &mut [f64],
    grid: Option<&[f64]>,
    gravity: Option<&AxisGravity>,
    s: &mut AdvectionScratch,
) {
    let Some(substeps) = substeps(rows, geo, radius_m, dt_s, u, s) else {
        if let Some(gravity) = gravity {
            rows.add_axis_gravity(u, gravity);
        }
        return;
    };
    let h = dt_s / f64::from(substeps);
    // (A grid of one cell a face has no inner edges to run.)
    let grid = grid.filter(|_| substeps == 1 && rows.n >= 2);
    if grid.is_none() {
        s.stage.resize(u.len(), 0.0);
    }
    s.work.prepare(rows);
    if s.scale_radius_m != radius_m || s.vorticity_scale.len() != rows.vertex_area.len() {
        let scale = rows.vertex_area.iter().map(|a| 1.0 / (a * radius_m));
        s.vorticity_scale = scale.collect();
        s.scale_radius_m = radius_m;
    }
    with_avx2(
        #[inline(always)]
        || {
            let (w, scale) = (&mut s.work, &s.vorticity_scale);
            rows.seam_circulation(u, &mut w.vorticity, scale, |z, ia| z * ia);
            for k in 1..=substeps {
                let buffers = (&mut *u, grid.ok_or(&mut s.stage));
                let last = gravity.filter(|_| k == substeps);
                ssp_rk3(rows, geo, scale, h, buffers, w, (k < substeps, last));
            }
        },
    );
}

/// The sub-steps that keep the fastest cell within [`MAX_COURANT`] of the narrowest dual
/// edge (none for a film at rest, or whose speed is not finite).
///
/// Where the fastest edge's speed bounds the fastest cell's within that (a cell's
/// velocity is at most [`AdvectionGeometry::speed_bound`] times its fastest edge's), that
/// is one sub-step, without the cells' velocities: the count is what they give, since the
/// exact Courant number is at most the bound's. The one difference: a field whose every
/// cell velocity cancels to zero, which the speeds alone would leave as it is, is
/// advected.
fn substeps(
    rows: &FaceRows,
    geo: &AdvectionGeometry,
    radius_m: f64,
    dt_s: f64,
    u: &[f64],
    s: &mut AdvectionScratch,
) -> Option<u32> {
    let courant = |speed: f64| speed * dt_s / (geo.min_dual_length * radius_m);
    // `f64::max`'s largest: a speed that is not a number is passed over.
    let fastest_edge = with_avx2(
        #[inline(always)]
        || largest_magnitude(u),
    );
    if fastest_edge == 0.0 {
        return None;
    }
    if courant(geo.speed_bound * fastest_edge) <= MAX_COURANT {
        return Some(1);
    }
    // The largest squared speed's root: the same number as the largest root (the
    // rounded root is monotonic), for one root where there was one a cell.
    let fastest = with_avx2(
        #[inline(always)]
        || fastest_speed_squared(rows, geo, u, &mut s.speed_squared),
    );
    let speed = fastest.sqrt();
    if speed == 0.0 || !speed.is_finite() {
        return None;
    }
    Some((courant(speed) / MAX_COURANT).ceil().clamp(1.0, 64.0) as u32)
}

/// One Shu–Osher third-order step of `u`: `u₁ = u + hL(u)`, `u₂ = ¾u + ¼(u₁ + hL(u₁))`,
/// `u ← ⅓u + ⅔(u₂ + hL(u₂))`, from `u`'s vorticity on the faces' borders in
/// `w.vorticity`; it leaves the new `u`'s there where `next` (for the next sub-step),
/// and adds `gravity` to the new `u` where given (the last sub-step).
/// A stage reads no edge of its source once it has moved it, so it may move them where
/// they are: with `Ok(grid)` (`u` in the grid's numbering) every stage does, the
/// starting velocities read from `grid`; with `Err(stage)`, `u₁`, then `u₂`, goes to
/// `stage` (the second stage moves its edges where they are), so that one buffer is
/// written from cold a sub-step, not two (0.4 MB at n = 64).
#[inline(always)]
fn ssp_rk3(
    rows: &FaceRows,
    geo: &AdvectionGeometry,
    scale: &[f64],
    h: f64,
    (u, stage): (&mut [f64], Result<&[f64], &mut Vec<f64>>),
    w: &mut StageWork,
    (next, gravity): (bool, Option<&AxisGravity>),
) {
    let on = Stage { rows, geo, scale };
    // The stages' faces in alternate directions ([`face_order`]), the first forward:
    // [`FaceRows::to_rows`] copies them in reverse, so the first stage starts on the
    // faces still in the caches, and the last ends on face 5, where the viscous stage
    // then starts (reading its faces in reverse, the faces last moved first). The other
    // way round (`to_rows` forward, the first stage in reverse, the viscous stage
    // forward) missed the 1 MB LL 0.05 M more times in the momentum and 0.035 M more in
    // the Marangoni edge pass over `film_profile 64 0 9.81`'s 40 steps (callgrind).
    match stage {
        Ok(grid) => {
            on.stage::<1>(None, u, Start::Dst, w, (true, false, None), h);
            on.stage::<2>(None, u, Start::Grid(grid), w, (true, true, None), h);
            on.stage::<3>(None, u, Start::Grid(grid), w, (next, false, gravity), h);
        }
        Err(stage) => {
            // Stage 1 (what `stage` held is passed over) ignores the starting velocities:
            // given `u`'s, the rows may move the border copies too (see `Stage::stage`).
            on.stage::<1>(Some(u), stage, Start::Rows(u), w, (true, false, None), h);
            // Stage 2, `u₁` into `u₂` where it is.
            on.stage::<2>(None, stage, Start::Rows(u), w, (true, true, None), h);
            // Stage 3, onto `u`.
            on.stage::<3>(Some(stage), u, Start::Dst, w, (next, false, gravity), h);
        }
    }
}

/// Stage `STAGE` (1, 2 or 3) of [`ssp_rk3`] over `h` on one edge: its velocity `u` moved
/// at its rate `r`, then (stages 2 and 3) weighed with its starting velocity `u0`. Stage
/// 3 takes ⅓ as a multiplication: a division took several times as long.
#[inline(always)]
pub(crate) fn rk3_step<const STAGE: u8>(h: f64, u: f64, u0: f64, r: f64) -> f64 {
    match STAGE {
        1 => u + h * r,
        2 => 0.75 * u0 + 0.25 * (u + h * r),
        _ => (1.0 / 3.0) * u0 + (2.0 / 3.0) * (u + h * r),
    }
}

/// [`advect_face::face_stage`] of stage `STAGE` over `h`, with gravity where `at` gives it,
/// into `dst` and `border`, the rows' buffers (vertex rows, cell terms) those given.
///
/// # Safety
/// The processor has AVX2.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn face_stage<const STAGE: u8>(
    at: &FaceInputs,
    h: f64,
    dst: &mut [f64],
    border: &mut [f64],
    (z, rate): (&mut [Vec<f64>; 2], &mut [[Vec<f64>; 4]; 2]),
) {
    let z = z.each_mut().map(|r| &mut r[..]);
    let [[b0, l0, r0, t0], [b1, l1, r1, t1]] = rate;
    let rate = [b0, l0, r0, t0, b1, l1, r1, t1].map(|r| &mut r[..]);
    // SAFETY: the processor has AVX2 (the caller's promise).
    unsafe {
        if at.gravity.is_some() {
            advect_face::face_stage::<STAGE, true>(at, h, dst, border, z, rate);
        } else {
            advect_face::face_stage::<STAGE, false>(at, h, dst, border, z, rate);
        }
    }
}

/// Where a stage reads each edge's starting velocity (the sub-step's).
#[derive(Clone, Copy)]
enum Start<'a> {
    /// The edge's entry of the destination, before it is written.
    Dst,
    /// The edge's entry of these, in the face rows.
    Rows(&'a [f64]),
    /// These, in the grid's numbering and orientation ([`FaceRows::to_rows`] takes the
    /// rows from them): an inner edge's a run of the grid's ([`FaceLayout`](super::grid::FaceLayout)), a copy on a
    /// face's border its grid edge's times its sign.
    Grid(&'a [f64]),
}

impl<'a> Start<'a> {
    /// These for one face whose local edges are `face`: rows taken as that face's alone
    /// (a run's edges then counted from the face's first), the others as they are.
    #[inline(always)]
    fn face(self, face: std::ops::Range<usize>) -> Self {
        match self {
            Start::Rows(u0) => Start::Rows(&u0[face]),
            other => other,
        }
    }

    /// The starting velocities of the run of local edges `k` (of face `f`'s alone where
    /// [`Self::face`] took them), from `(1, y)` of face `f`'s X-edge row `y` (`x` true) or
    /// from `(0, y)` of its Y-edge row `y` (`x` false); `None` for [`Start::Dst`]. In the grid's numbering, an X-edge row's run on through
    /// its right border copy reads the grid's next inner edge (junk, in bounds: the last
    /// face's last X-edge row is followed by the Y-edges).
    #[inline(always)]
    fn run(
        self,
        rows: &FaceRows,
        (f, y, x): (usize, usize, bool),
        k: std::ops::Range<usize>,
    ) -> Option<&'a [f64]> {
        match self {
            Start::Dst => None,
            Start::Rows(u0) => Some(&u0[k]),
            Start::Grid(grid) => {
                let at = if x {
                    rows.grid_x_run(f, y)
                } else {
                    rows.grid_y_run(f, y)
                };
                Some(&grid[at..at + k.len()])
            }
        }
    }

    /// Local edge `k`'s starting velocity, `dst` the destination, `(e, sign)` its grid
    /// edge and its orientation against it.
    #[inline(always)]
    fn at(self, dst: &[f64], k: usize, (e, sign): (usize, f64)) -> f64 {
        match self {
            Start::Dst => dst[k],
            Start::Rows(u0) => u0[k],
            Start::Grid(grid) => grid[e] * sign,
        }
    }
}

/// What every stage reads of the grid.
#[derive(Clone, Copy)]
struct Stage<'a> {
    rows: &'a FaceRows,
    geo: &'a AdvectionGeometry,
    /// Per local vertex of face 0: `1/(A R)` ([`AdvectionScratch::vorticity_scale`]).
    scale: &'a [f64],
}

impl Stage<'_> {
    /// One stage, in one pass over each face's rows: `dst ← step(src, u0, rate)` on every
    /// local edge, `step` stage `STAGE` of [`rk3_step`] over `h` (`src` the edge's entry
    /// of `dst` before it is written where `None`: the
    /// stage moves the edges where they are), the rate the rotation term `−ζ (k×u)·n` of
    /// `src` (with its vorticity
    /// on the faces' borders in `w.vorticity`) summed over the edge's two cells (the
    /// lower-numbered cell's term first), `u0` the edge's starting velocity ([`Start`]);
    /// where `next`, the vorticity of `dst` on the
    /// faces' borders then replaces it. The faces in reverse order where `reverse`
    /// ([`face_order`]). Where `gravity` is given, each row adds it to the edges it has
    /// just moved, and the seam pass to each border edge's first copy, the second then
    /// the first's in its orientation (as [`FaceRows::add_gravity`] leaves them); no row
    /// reads a moved edge, so the stage's rates are the same.
    ///
    /// Row `y` of a face takes the vorticity of its vertex row `y + 1` from `src` (row
    /// `y`'s it took the row before), then its cells' terms, then moves its X-edges (both
    /// their cells are in the row) and its Y-edges below it (the row before holds their
    /// other cells). The edges on the faces' borders move last, from their two faces'
    /// cells' terms, kept for that in `w.border_rate`. No row reads an edge of `src` that
    /// a row before it has moved: vertex row `y + 1` reads X-edge rows `y` and `y + 1` and
    /// Y-edge row `y + 1`, cell row `y` X-edge row `y` and Y-edge rows `y` and `y + 1`, and
    /// row `y` moves X-edge row `y` and Y-edge row `y` (a face reads no other face's
    /// edges, and its border vertices' vorticity is kept from the stage before), so a
    /// stage may move the edges where they are.
    ///
    /// Each face's rows in one call in AVX2 registers where the processor has it
    /// ([`advect_face`]), row by row in portable code else ([`Self::face_rows`]): the same
    /// bits.
    #[inline(always)]
    fn stage<const STAGE: u8>(
        self,
        src: Option<&[f64]>,
        dst: &mut [f64],
        u0: Start,
        w: &mut StageWork,
        (next, reverse, gravity): (bool, bool, Option<&AxisGravity>),
        h: f64,
    ) {
        let (rows, n) = (self.rows, self.rows.n);
        let (epf, vpf) = (rows.edges_per_face(), rows.vertices_per_face());
        let step = |u, u0, r| rk3_step::<STAGE>(h, u, u0, r);
        #[cfg(target_arch = "x86_64")]
        let fast = n >= 4 && crate::avx2::has_avx2();
        for f in face_order(reverse) {
            // The face's own parts, sliced once (a row's offsets are then the face's rows',
            // from 0), where each row sliced the whole arrays again: 2.7 M of the
            // advection's 99 M instructions over film_profile 64 0 9.81's 40 steps.
            let face = f * epf..(f + 1) * epf;
            let (dst, src) = (&mut dst[face.clone()], src.map(|s| &s[face.clone()]));
            let vorticity = &w.vorticity[f * vpf..][..vpf];
            let border = &mut w.border_rate[f * 4 * n..][..4 * n];
            let u0 = u0.face(f * epf..(f + 1) * epf);
            let buffers = (&mut w.vertex_rows, &mut w.row_rate);
            #[cfg(target_arch = "x86_64")]
            if fast {
                let at = self.face_inputs(f, src, u0, vorticity, gravity);
                // SAFETY: the processor has AVX2 (`has_avx2`).
                unsafe { face_stage::<STAGE>(&at, h, dst, border, buffers) };
                continue;
            }
            let io = (src, dst, u0, vorticity, border);
            self.face_rows(f, io, buffers, gravity, &step);
        }
        self.move_seam_edges(src, dst, u0, &w.border_rate, &step, gravity);
        if next {
            rows.seam_circulation(dst, &mut w.vorticity, self.scale, |z, ia| z * ia);
        }
    }

    /// Face `f`'s rows of a stage ([`Self::stage`]) in portable code: `src`, `dst` and
    /// `u0` the face's alone, `vorticity` its kept border vertices' and `border` its
    /// border terms.
    #[inline(always)]
    #[allow(clippy::type_complexity)] // the face's parts, as the stage slices them
    fn face_rows(
        self,
        f: usize,
        (src, dst, u0, vorticity, border): (Option<&[f64]>, &mut [f64], Start, &[f64], &mut [f64]),
        (z_rows, rate_rows): (&mut [Vec<f64>; 2], &mut [[Vec<f64>; 4]; 2]),
        gravity: Option<&AxisGravity>,
        step: &impl Fn(f64, f64, f64) -> f64,
    ) {
        let (rows, n) = (self.rows, self.rows.n);
        let [even, odd] = rate_rows;
        let [z_even, z_odd] = z_rows;
        self.vertex_row(src.unwrap_or(dst), vorticity, 0, z_even);
        for y in 0..n {
            let (rate, before, z, z_next) = if y % 2 == 0 {
                (&mut *even, &*odd, &*z_even, &mut *z_odd)
            } else {
                (&mut *odd, &*even, &*z_odd, &mut *z_even)
            };
            let from = src.unwrap_or(dst);
            self.vertex_row(from, vorticity, y + 1, z_next);
            self.cell_row(from, [z, z_next], y, rate);
            keep_border_rates(border, rate, n, y);
            let [_, left, right, _] = &*rate;
            // The X-edges inside the face: cell (i − 1, y)'s right side and (i, y)'s left.
            // The row runs on through the right border copy, n edges, which vectorise
            // without the scalar tail of n − 1: that copy's entry of `dst` (which the
            // seam pass may read, as the source or the start) is put back after.
            let k = y * (n + 1) + 1..(y + 1) * (n + 1);
            let border_copy = dst[k.end - 1];
            let u0x = u0.run(rows, (f, y, true), k.clone());
            let srcx = src.map(|s| &s[k.clone()]);
            let at = (f, k.start);
            let rates = (&right[..], &left[1..], &self.geo.inverse_norm[k.start..]);
            move_edges(&mut dst[k.clone()], srcx, u0x, rates, step, gravity, at);
            dst[k.end - 1] = border_copy;
            if y == 0 {
                continue;
            }
            // The Y-edges below: cell (x, y − 1)'s top and (x, y)'s bottom.
            let k = n * (n + 1) + y * n..n * (n + 1) + (y + 1) * n;
            let (top, bottom) = (&before[Side::Top as usize], &rate[Side::Bottom as usize]);
            let u0y = u0.run(rows, (f, y, false), k.clone());
            let srcy = src.map(|s| &s[k.clone()]);
            let at = (f, k.start);
            let rates = (&top[..], &bottom[..], &self.geo.inverse_norm[k.start..]);
            move_edges(&mut dst[k], srcy, u0y, rates, step, gravity, at);
        }
    }

    /// What [`face_stage`] reads of face `f` (`src` and `u0` the face's alone, `kept` its
    /// border vertices' vorticity) and of face 0's constants.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn face_inputs<'a>(
        self,
        f: usize,
        src: Option<&'a [f64]>,
        u0: Start<'a>,
        kept: &'a [f64],
        gravity: Option<&AxisGravity<'a>>,
    ) -> FaceInputs<'a>
    where
        Self: 'a,
    {
        let (rows, n) = (self.rows, self.rows.n);
        let epf = rows.edges_per_face();
        let start = match u0 {
            Start::Dst => FaceStart::Dst,
            Start::Rows(u0) => FaceStart::Rows(u0),
            // (`n ≥ 2`: a grid of one cell a face reads no runs.)
            Start::Grid(grid) => FaceStart::Grid {
                x: &grid[rows.grid_x_run(f, 0)..],
                y: &grid[rows.grid_y_run(f, 1)..],
            },
        };
        FaceInputs {
            n,
            src,
            start,
            kept,
            dual_length: &rows.dual_length,
            scale: self.scale,
            coriolis: &self.geo.coriolis,
            inverse_norm: &self.geo.inverse_norm,
            gravity: gravity.map(|g| g.row(f, 0, epf)),
        }
    }

    /// The vorticity of a face's vertex row `j` of its edge velocities `u` (the face's
    /// local edges) into `out`: an inner row's taken from `u`, its ends (on the face's
    /// borders) and the border rows `0` and `n` from `border` (the face's local vertices'
    /// kept on the faces' borders).
    #[inline(always)]
    fn vertex_row(self, u: &[f64], border: &[f64], j: usize, out: &mut [f64]) {
        let (rows, n, w) = (self.rows, self.rows.n, self.rows.n + 1);
        let border = &border[j * w..][..w];
        let out = &mut out[..w];
        if j == 0 || j == n {
            out.copy_from_slice(border);
            return;
        }
        let scale = &self.scale[j * w..][..n];
        rows.face_circulation_row(u, j, &mut out[..n], scale, |z, ia| z * ia);
        (out[0], out[n]) = (border[0], border[n]);
    }

    /// Row `y` of a face's cells' terms of their sides' rates into `rate` (per side, per
    /// cell of the row), from the face's edge velocities `u` and the vorticity `z` of the
    /// row's bottom and top vertices.
    #[inline(always)]
    fn cell_row(self, u: &[f64], z: [&[f64]; 2], y: usize, rate: &mut [Vec<f64>; 4]) {
        let n = self.rows.n;
        let (uy, ux) = (n * (n + 1) + y * n, y * (n + 1));
        let len = n.div_ceil(4) * QUAD_WEIGHTS;
        // Every face's weights are face 0's ([`AdvectionGeometry::coriolis`]).
        let w = &self.geo.coriolis[y * len..][..len];
        let [ob, ol, or, ot] = rate;
        coriolis_row(
            w,
            [&z[0][..n + 1], &z[1][..n + 1]],
            [&u[uy..uy + n], &u[ux..ux + n + 1], &u[uy + n..uy + 2 * n]],
            [&mut ob[..n], &mut ol[..n], &mut or[..n], &mut ot[..n]],
        );
    }

    /// The edges on the faces' borders: each from its two cells' terms in `border`, both
    /// copies (`dst ← step(src, u0, rate)` as in [`Self::stage`]); where `gravity` is
    /// given, it is added to the first copy, and the second made the first's in its
    /// orientation (as [`FaceRows::add_gravity`] leaves them), in the same pass, where a
    /// pass of its own read every seam's copies again (and found its face by a division).
    #[inline(always)]
    fn move_seam_edges(
        self,
        src: Option<&[f64]>,
        dst: &mut [f64],
        u0: Start,
        border: &[f64],
        step: &impl Fn(f64, f64, f64) -> f64,
        gravity: Option<&AxisGravity>,
    ) {
        let epf = self.rows.edges_per_face();
        for e in &self.geo.seams {
            let ([ia, ib], [sa, sb]) = (e.slots.map(|i| i as usize), e.signs);
            let r = (sa * border[ia] + sb * border[ib]) * e.inverse_norm;
            let [ka, kb] = e.edges.map(|k| k as usize);
            let (at_a, at_b) = ((e.grid_edge as usize, sa), (e.grid_edge as usize, sb));
            let (start_a, start_b) = (u0.at(dst, ka, at_a), u0.at(dst, kb, at_b));
            let (from_a, from_b) = src.map_or((dst[ka], dst[kb]), |s| (s[ka], s[kb]));
            let (first, second) = (step(from_a, start_a, sa * r), step(from_b, start_b, sb * r));
            (dst[ka], dst[kb]) = match gravity {
                None => (first, second),
                Some(gravity) => {
                    let first = first
                        + gravity.term(e.first_face as usize, ka - e.first_face as usize * epf);
                    (first, first * sa * sb)
                }
            };
        }
    }
}

/// Keeps the terms of row `y`'s cells on their face's borders into `border` (the face's
/// part of [`StageWork::border_rate`]): the left of its first cell, the right of its
/// last, and the bottoms or tops of the first and last rows.
#[inline(always)]
fn keep_border_rates(border: &mut [f64], rate: &[Vec<f64>; 4], n: usize, y: usize) {
    let [bottom, left, right, top] = rate;
    let side = |side: Side| side as usize * n;
    border[side(Side::Left) + y] = left[0];
    border[side(Side::Right) + y] = right[n - 1];
    if y == 0 {
        border[side(Side::Bottom)..][..n].copy_from_slice(&bottom[..n]);
    }
    if y == n - 1 {
        border[side(Side::Top)..][..n].copy_from_slice(&top[..n]);
    }
}

/// The slot in [`StageWork::border_rate`] of side `side` of cell `c` (of a grid of `n`
/// cells a face), on its face's border: per face, per side, along the side (`x` for the
/// bottom and top, `y` for the left and right).
fn border_slot(n: usize, c: usize, side: Side) -> u32 {
    let (f, x, y) = (c / (n * n), c % n, (c / n) % n);
    let along = match side {
        Side::Bottom | Side::Top => x,
        Side::Left | Side::Right => y,
    };
    ((f * 4 + side as usize) * n + along) as u32
}

/// `dst ← step(src, u0, (ra + rb)·s)` edge by edge, each of `dst`, `src`, `u0` and
/// `rates = (ra, rb, s)` the edge's entry (`s` its
/// [`inverse_norm`](AdvectionGeometry::inverse_norm)), `src` and `u0` that of `dst`
/// before it is written where `None` (the two terms added directly: summed from zero, as
/// they were, the rate differed only in a zero's sign where both terms are −0, for one
/// addition more each four edges); plus
/// `dt·(g·c)` where `gravity` is given (`dst` face `f`'s local edges from `from`), as
/// [`FaceRows::add_gravity`] adds it.
#[inline(always)]
fn move_edges(
    dst: &mut [f64],
    src: Option<&[f64]>,
    u0: Option<&[f64]>,
    rates: (&[f64], &[f64], &[f64]),
    step: &impl Fn(f64, f64, f64) -> f64,
    gravity: Option<&AxisGravity>,
    (f, from): (usize, usize),
) {
    match gravity {
        None => move_edges_by(dst, src, u0, rates, |_, u, u0, r| step(u, u0, r)),
        Some(gravity) => {
            let (dt, g, c) = gravity.row(f, from, dst.len());
            let step = |i: usize, u, u0, r| step(u, u0, r) + dt * (g * c[i]);
            move_edges_by(dst, src, u0, rates, step);
        }
    }
}

/// [`move_edges`], each edge's `dst ← step(i, src, u0, rate)` given its index `i`.
#[inline(always)]
fn move_edges_by(
    dst: &mut [f64],
    src: Option<&[f64]>,
    u0: Option<&[f64]>,
    (ra, rb, inv): (&[f64], &[f64], &[f64]),
    step: impl Fn(usize, f64, f64, f64) -> f64,
) {
    let len = dst.len();
    let (ra, rb, inv) = (&ra[..len], &rb[..len], &inv[..len]);
    match (src, u0) {
        (Some(src), Some(u0)) => {
            let (src, u0) = (&src[..len], &u0[..len]);
            for i in 0..len {
                dst[i] = step(i, src[i], u0[i], (ra[i] + rb[i]) * inv[i]);
            }
        }
        (Some(src), None) => {
            let src = &src[..len];
            for i in 0..len {
                dst[i] = step(i, src[i], dst[i], (ra[i] + rb[i]) * inv[i]);
            }
        }
        (None, Some(u0)) => {
            let u0 = &u0[..len];
            for i in 0..len {
                dst[i] = step(i, dst[i], u0[i], (ra[i] + rb[i]) * inv[i]);
            }
        }
        (None, None) => {
            for i in 0..len {
                dst[i] = step(i, dst[i], dst[i], (ra[i] + rb[i]) * inv[i]);
            }
        }
    }
}

/// Each cell's squared speed into `out`, m²/s², and the largest (`f64::max`'s: one that
/// is not a number is passed over): the velocity vector from the cell's edges' normal
/// velocities (`u`, in the rows), in its tangent plane.
#[inline(always)]
fn fastest_speed_squared(
    rows: &FaceRows,
    geo: &AdvectionGeometry,
    u: &[f64],
    out: &mut Vec<f64>,
) -> f64 {
    let n = rows.n;
    out.resize(6 * n * n, 0.0);
    let [wb, wl, wr, wt] = &geo.to_cell;
    for f in 0..6 {
        for y in 0..n {
            let c = f * n * n + y * n;
            let (uy, ux) = (rows.y_edge(f, 0, y), rows.x_edge(f, 0, y));
            let (bottom, top) = (&u[uy..uy + n], &u[uy + n..uy + 2 * n]);
            let (left, right) = (&u[ux..ux + n], &u[ux + 1..ux + n + 1]);
            let out = &mut out[c..c + n];
            let [wb, wl, wr, wt] = [wb, wl, wr, wt].map(|w| slices(w, c..c + n));
            let centre = slices(&geo.centre, c..c + n);
            for x in 0..n {
                let w = [
                    [wb[0][x], wb[1][x], wb[2][x]],
                    [wl[0][x], wl[1][x], wl[2][x]],
                    [wr[0][x], wr[1][x], wr[2][x]],
                    [wt[0][x], wt[1][x], wt[2][x]],
                ];
                let u = [bottom[x], left[x], right[x], top[x]];
                let v = velocity(&w, u, [centre[0][x], centre[1][x], centre[2][x]]);
                out[x] = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            }
        }
    }
    for (ic, w) in rows.irregular_cells.iter().zip(&geo.irregular) {
        let c = ic.cell as usize;
        let v = velocity(
            &w.to_cell,
            ic.edges.map(|k| u[k as usize]),
            geo.centre.each_ref().map(|a| a[c]),
        );
        out[c] = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    }
    out.iter().fold(0.0, |m, &v| larger(v, m))
}

/// A cell's velocity from its four edges' weights `w` (per side, per component) and
/// velocities `u` (each in [`AdvectionGeometry::to_cell`]'s order), projected onto the
/// tangent plane at its centre `c`: the sum from zero in side order, then `v − c (v·c)`,
/// as `DVec3` takes them.
#[inline(always)]
fn velocity(w: &[[f64; 3]; 4], u: [f64; 4], c: [f64; 3]) -> [f64; 3] {
    let mut v = [0.0; 3];
    for (a, v) in v.iter_mut().enumerate() {
        *v = 0.0 + w[0][a] * u[0] + w[1][a] * u[1] + w[2][a] * u[2] + w[3][a] * u[3];
    }
    let along = v[0] * c[0] + v[1] * c[1] + v[2] * c[2];
    [
        v[0] - c[0] * along,
        v[1] - c[1] * along,
        v[2] - c[2] * along,
    ]
}

/// The same range of each of `arrays`.
#[inline(always)]
fn slices<const N: usize>(arrays: &[Vec<f64>; N], r: std::ops::Range<usize>) -> [&[f64]; N] {
    arrays.each_ref().map(|a| &a[r.clone()])
}

/// The largest `|v|` of `values` (`f64::max`'s: one that is not a number is passed
/// over), zero for none: in four running maxima, then the largest of them (the same
/// number: the largest is the largest in any order), so that the loop vectorises.
#[inline(always)]
fn largest_magnitude(values: &[f64]) -> f64 {
    let mut m = [0.0; 4];
    let chunks = values.chunks_exact(4);
    let rest = chunks.remainder();
    for chunk in chunks {
        for (m, v) in m.iter_mut().zip(chunk) {
            *m = larger(v.abs(), *m);
        }
    }
    for v in rest {
        m[0] = larger(v.abs(), m[0]);
    }
    m.into_iter().fold(0.0, |a, b| larger(b, a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bits::differing_bits;

    fn rotation_about_z(grid: &CubeSphere, omega: f64) -> Vec<f64> {
        grid.edges()
            .iter()
            .map(|e| (DVec3::Z * omega).cross(e.midpoint).dot(e.normal))
            .collect()
    }

    #[test]
    fn the_reconstruction_recovers_a_solid_rotation_at_cell_centres() {
        let grid = CubeSphere::new(16);
        let rows = FaceRows::new(&grid);
        let geo = AdvectionGeometry::new(&grid, &rows);
        let mut u = Vec::new();
        rows.to_rows(&rotation_about_z(&grid, 1.0), &mut u);
        let mut speeds = Vec::new();
        fastest_speed_squared(&rows, &geo, &u, &mut speeds);
        // Each cell's velocity as the step takes it, its sides in the local order (or
        // the grid's, in an irregular cell).
        let mut v = (0..grid.cells())
            .map(|c| {
                let w = geo.to_cell.each_ref().map(|w| [w[0][c], w[1][c], w[2][c]]);
                let u = SIDES.map(|side| u[rows.cell_edge(c, side)]);
                velocity(&w, u, grid.centres()[c].to_array())
            })
            .collect::<Vec<_>>();
        for (ic, w) in rows.irregular_cells.iter().zip(&geo.irregular) {
            let c = ic.cell as usize;
            let u = ic.edges.map(|k| u[k as usize]);
            v[ic.cell as usize] = velocity(&w.to_cell, u, grid.centres()[c].to_array());
        }
        let worst = v
            .iter()
            .zip(grid.centres())
            .map(|(v, c)| (DVec3::from_array(*v) - DVec3::Z.cross(*c)).length())
            .fold(0.0, f64::max);
        let squared = v.iter().map(|v| DVec3::from_array(*v).length_squared());
        assert!(squared.eq(speeds), "the squared speeds are the velocities'");
        assert!(worst < 0.02, "worst reconstruction error {worst:.3e}");
    }

    /// The fastest cell is never faster than the bound the sub-steps take from the fastest
    /// edge: a rotation, a rough field and one edge alone.
    #[test]
    fn the_fastest_edge_bounds_the_fastest_cell() {
        for n in [3, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let geo = AdvectionGeometry::new(&grid, &rows);
            let edges = grid.edges().len();
            let rough = (0..edges).map(|e| ((e * 7919) % 1000) as f64 * 1e-3 - 0.5);
            let single = (0..edges).map(|e| if e == edges / 2 { 1.0 } else { 0.0 });
            for field in [
                rotation_about_z(&grid, 1.0),
                rough.collect(),
                single.collect(),
            ] {
                let mut u = Vec::new();
                rows.to_rows(&field, &mut u);
                let fastest = fastest_speed_squared(&rows, &geo, &u, &mut Vec::new()).sqrt();
                let edge = u.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
                eprintln!(
                    "n {n}: fastest cell {fastest:.4}, bound {:.4}",
                    geo.speed_bound * edge
                );
                assert!(
                    fastest <= geo.speed_bound * edge,
                    "n {n}: {fastest} > bound"
                );
            }
        }
    }

    #[test]
    fn the_largest_magnitude_passes_over_nan() {
        assert_eq!(largest_magnitude(&[]), 0.0);
        let v = [1.0, -7.5, f64::NAN, 3.0, -2.0, 7.0, 0.5, -0.25, 6.0];
        assert_eq!(largest_magnitude(&v), 7.5);
        assert_eq!(largest_magnitude(&v[3..]), 7.0);
        assert_eq!(largest_magnitude(&[f64::NAN, -0.5]), 0.5);
    }

    #[test]
    fn the_rotation_term_does_no_work() {
        // A solid rotation with a degree-2 pattern on it, advected alone for 0.25 s: the
        // energy Σ l d u² changes only by the time scheme's error (with the
        // reconstruction's own weights, not made antisymmetric, it lost 3.3e-4).
        let grid = CubeSphere::new(16);
        let rows = FaceRows::new(&grid);
        let geo = AdvectionGeometry::new(&grid, &rows);
        let axis = DVec3::new(1.0, 0.0, 1.0).normalize();
        let field = |d: DVec3| {
            let g = DVec3::new(2.0 * d.x, -2.0 * d.y, 0.0);
            (axis * 0.05).cross(d) + d.cross(g - d * g.dot(d)) * 0.015
        };
        let mut u: Vec<f64> = grid
            .edges()
            .iter()
            .map(|e| field(e.midpoint).dot(e.normal))
            .collect();
        let w: Vec<f64> = grid
            .edges()
            .iter()
            .map(|e| e.length * e.dual_length)
            .collect();
        let energy = |u: &[f64]| u.iter().zip(&w).map(|(u, w)| u * u * w).sum::<f64>();
        let e0 = energy(&u);
        let mut s = AdvectionScratch::default();
        // Short steps, so what is left is the space scheme's (Runge–Kutta 3's own loss
        // at 1/240 s was 3.6e-4 here).
        let mut in_rows = Vec::new();
        rows.to_rows(&u, &mut in_rows);
        for _ in 0..240 {
            advect_momentum(
                &rows,
                &geo,
                0.01,
                1.0 / 960.0,
                &mut in_rows,
                None,
                None,
                &mut s,
            );
        }
        rows.to_grid(&in_rows, &mut u);
        let change = energy(&u) / e0 - 1.0;
        assert!(change.abs() < 1e-4, "energy changed by {change:+.3e}");
    }

    /// The advection with AVX2 (the face kernel, `advect_face`) gives the portable code's
    /// bits: at n = 4 (one group of four cells a row), 5 (two overlapping groups, rows of
    /// edges one past whole chunks of four), 7 and 16, a rotation with a rough field on
    /// it, through the stage buffer and from the grid's numbering (its starting
    /// velocities read there), with gravity added by the last stage and without.
    #[test]
    fn the_avx2_advection_gives_the_portable_bits() {
        use super::super::flow::FilmGradient;
        for n in [4, 5, 7, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let geo = AdvectionGeometry::new(&grid, &rows);
            let rough = grid.edges().iter().enumerate();
            let field: Vec<f64> = rough
                .map(|(e, ed)| {
                    (DVec3::Z * 0.05).cross(ed.midpoint).dot(ed.normal)
                        + ((e * 7919) % 1000) as f64 * 1e-5
                })
                .collect();
            let g = DVec3::NEG_Y * 9.81;
            let gravity = rows.gravity(&grid, FilmGradient::TwoPoint, g, 1.0 / 60.0);
            let along = gravity.along_axes().expect("gravity along an axis");
            for (from_grid, with_gravity) in [(false, false), (true, false), (true, true)] {
                let run = |portable: bool| {
                    crate::avx2::set_portable_only(portable);
                    let mut u = Vec::new();
                    rows.to_rows(&field, &mut u);
                    let from = from_grid.then_some(&field[..]);
                    let g = with_gravity.then_some(&along);
                    let s = &mut AdvectionScratch::default();
                    advect_momentum(&rows, &geo, 0.01, 1.0 / 60.0, &mut u, from, g, s);
                    crate::avx2::set_portable_only(false);
                    u
                };
                let (fast, plain) = (run(false), run(true));
                let what = format!("n {n}, from the grid {from_grid}, gravity {with_gravity}");
                assert!(
                    fast != run_unchanged(&rows, &field),
                    "{what}: the field moved"
                );
                let differ = differing_bits(&fast, &plain);
                assert_eq!(differ, 0, "{what}: edges differ");
            }
        }
    }

    /// `field` in the face rows, as given.
    fn run_unchanged(rows: &FaceRows, field: &[f64]) -> Vec<f64> {
        let mut u = Vec::new();
        rows.to_rows(field, &mut u);
        u
    }

    /// Every face's Coriolis weights are face 0's to rounding, and so is every face's
    /// local edges' inverse norm.
    #[test]
    fn every_faces_coriolis_weights_are_face_0s() {
        for n in [1, 5, 16, 64] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let face_0 = AdvectionGeometry::new(&grid, &rows).inverse_norm;
            let epf = rows.edges_per_face();
            for (k, &e) in rows.edge.iter().enumerate() {
                let (got, want) = (inverse_norm(&grid.edges()[e as usize]), face_0[k % epf]);
                let off = (got - want).abs() / want;
                assert!(off <= 1e-14, "n = {n}, local edge {k}: off by {off:e}");
            }
            let w = AdvectionGeometry::with_coriolis_faces(&grid, &rows, 6).coriolis;
            let face = w.len() / 6;
            let (first, rest) = w.split_at(face);
            let largest = first.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
            assert!(largest > 0.0, "n = {n}: no weights");
            for (k, (a, b)) in first.iter().cycle().zip(rest).enumerate() {
                let off = (a - b).abs() / largest;
                assert!(
                    off <= 1e-14,
                    "n = {n}, face {}, weight {}: {b} against face 0's {a} (off by {off:e} \
                     of the largest)",
                    1 + k / face,
                    k % face
                );
            }
        }
    }

    /// A rough field on a rotation at n = `n`, in the face rows (`seed` picks the roughness).
    fn rough_rows(rows: &FaceRows, grid: &CubeSphere, seed: usize) -> Vec<f64> {
        let field: Vec<f64> = grid
            .edges()
            .iter()
            .enumerate()
            .map(|(e, ed)| {
                (DVec3::Z * 0.05).cross(ed.midpoint).dot(ed.normal)
                    + ((e * seed) % 1000) as f64 * 1e-5
            })
            .collect();
        let mut u = Vec::new();
        rows.to_rows(&field, &mut u);
        u
    }

    /// A stage's scratch, its border vorticity that of `src`, and the vorticity scale for
    /// a radius of 1 cm.
    fn stage_work(rows: &FaceRows, src: &[f64]) -> (StageWork, Vec<f64>) {
        let scale: Vec<f64> = rows.vertex_area.iter().map(|a| 1.0 / (a * 0.01)).collect();
        let mut w = StageWork::default();
        w.prepare(rows);
        rows.seam_circulation(src, &mut w.vorticity, &scale, |z, ia| z * ia);
        (w, scale)
    }

    /// A stage that moves the edges where they are (its source its destination) gives
    /// the bits of one that reads them apart, and so does one over the faces in reverse
    /// order, or one that reads its starting velocities in the grid's numbering, the kept
    /// border vorticity too: no row reads an edge that a row before it has moved, and a
    /// row's run through its right border copy leaves it as it was. Each case with AVX2
    /// (the face kernel, `advect_face`) and without, against the portable stage apart. At
    /// n = 5 and 16.
    #[test]
    fn a_stage_in_place_or_in_reverse_is_the_stage_apart() {
        for n in [5, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let geo = AdvectionGeometry::new(&grid, &rows);
            let (src, u0) = (
                rough_rows(&rows, &grid, 7919),
                rough_rows(&rows, &grid, 104_729),
            );
            let mut u0_grid = vec![0.0; grid.edges().len()];
            rows.to_grid(&u0, &mut u0_grid);
            let run = |in_place: bool, reverse: bool, from_grid: bool, portable: bool| {
                let (mut w, scale) = stage_work(&rows, &src);
                let on = Stage {
                    rows: &rows,
                    geo: &geo,
                    scale: &scale,
                };
                let mut dst = if in_place {
                    src.clone()
                } else {
                    vec![0.0; src.len()]
                };
                let from = (!in_place).then_some(&src[..]);
                let start = if from_grid {
                    Start::Grid(&u0_grid)
                } else {
                    Start::Rows(&u0)
                };
                crate::avx2::set_portable_only(portable);
                on.stage::<2>(from, &mut dst, start, &mut w, (true, reverse, None), 0.01);
                crate::avx2::set_portable_only(false);
                (dst, w.vorticity)
            };
            let apart = run(false, false, false, true);
            assert_ne!(apart.0, src, "n {n}: nothing moved");
            let cases = [(false, false), (true, false), (false, true), (true, true)];
            let cases = cases.map(|(a, b)| (a, b, false)).into_iter();
            let cases = cases.chain([(true, true, true)]);
            let cases = cases.flat_map(|c| [(c, true), (c, false)]).skip(1);
            for ((in_place, reverse, from_grid), portable) in cases {
                let (dst, vorticity) = run(in_place, reverse, from_grid, portable);
                let what = format!(
                    "n {n}, in place {in_place}, reverse {reverse}, from the grid {from_grid}, \
                     portable {portable}"
                );
                for (name, got, want) in
                    [("edges", dst, &apart.0), ("vorticity", vorticity, &apart.1)]
                {
                    let differ = differing_bits(&got, want);
                    assert_eq!(differ, 0, "{what}: {name} differ");
                }
            }
        }
    }

    /// The vertex rows a stage takes are the whole grid's circulation's rows, bit for bit,
    /// the faces' border vertices' from the kept border vorticity: at n = 5 and 16.
    #[test]
    fn a_stages_vertex_rows_are_the_whole_grids() {
        for n in [5, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let geo = AdvectionGeometry::new(&grid, &rows);
            let u = rough_rows(&rows, &grid, 7919);
            let (w, scale) = stage_work(&rows, &u);
            let mut want = Vec::new();
            rows.circulation(&u, &mut want, &scale, |z, ia| z * ia);
            let on = Stage {
                rows: &rows,
                geo: &geo,
                scale: &scale,
            };
            let mut row = vec![0.0; n + 1];
            for f in 0..6 {
                for j in 0..=n {
                    let face = &u[f * rows.edges_per_face()..][..rows.edges_per_face()];
                    let kept = &w.vorticity[rows.vertex_at(f, 0, 0)..][..rows.vertices_per_face()];
                    on.vertex_row(face, kept, j, &mut row);
                    let want = &want[rows.vertex_at(f, 0, j)..][..n + 1];
                    let same = row
                        .iter()
                        .zip(want)
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(same, "n {n}, face {f}, row {j}: {row:?} against {want:?}");
                }
            }
        }
    }

    /// Each edge on the faces' borders reads, for each of its cells, the term that cell's
    /// row kept for the edge's side ([`keep_border_rates`], [`border_slot`]): at n = 1, 5
    /// and 16.
    #[test]
    fn each_seam_edge_reads_its_cells_kept_terms() {
        for n in [1, 5, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let geo = AdvectionGeometry::new(&grid, &rows);
            // A term that names its cell and side.
            let term = |c: usize, side: usize| (4 * c + side) as f64;
            let mut border = vec![f64::NAN; 6 * 4 * n];
            for f in 0..6 {
                for y in 0..n {
                    let c = (f * n + y) * n;
                    let rate: [Vec<f64>; 4] =
                        std::array::from_fn(|side| (0..n).map(|x| term(c + x, side)).collect());
                    keep_border_rates(&mut border[f * 4 * n..][..4 * n], &rate, n, y);
                }
            }
            for (e, terms) in rows.seam_edges.iter().zip(&geo.seams) {
                for ((c, side, _), slot) in e.cells.into_iter().zip(terms.slots) {
                    let got = border[slot as usize];
                    let want = term(c as usize, side as usize);
                    assert_eq!(got, want, "n {n}: cell {c}, side {side:?}");
                }
            }
        }
    }

    /// The advection that reads its starting velocities in the grid's numbering (every
    /// stage in place) gives the bits of the one through the stage buffer: one sub-step
    /// and (on a small sphere) several, at n = 2, 5 and 16.
    #[test]
    fn the_advection_from_the_grids_numbering_is_the_advection_through_a_buffer() {
        for n in [2, 5, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let geo = AdvectionGeometry::new(&grid, &rows);
            let start = rough_rows(&rows, &grid, 7919);
            let mut start_grid = vec![0.0; grid.edges().len()];
            rows.to_grid(&start, &mut start_grid);
            for radius in [1.0, 1e-4] {
                let run = |from_grid: bool| {
                    let mut u = start.clone();
                    let g = from_grid.then_some(&start_grid[..]);
                    let s = &mut AdvectionScratch::default();
                    advect_momentum(&rows, &geo, radius, 1.0 / 60.0, &mut u, g, None, s);
                    u
                };
                let (through, from_grid) = (run(false), run(true));
                assert_ne!(through, start, "n {n}, radius {radius}: nothing moved");
                let differ = differing_bits(&through, &from_grid);
                assert_eq!(differ, 0, "n {n}, radius {radius}: edges differ");
            }
        }
    }

    /// Gravity added by the advection's last stage gives the bits of the advection and
    /// then a pass of gravity of its own: one sub-step and several, through the stage
    /// buffer and from the grid's numbering, a film at rest (no advection), gravity along
    /// each axis, at n = 2, 5 and 16.
    #[test]
    fn gravity_in_the_last_stage_is_a_pass_of_its_own() {
        use super::super::flow::FilmGradient;
        for n in [2, 5, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let geo = AdvectionGeometry::new(&grid, &rows);
            let rough = rough_rows(&rows, &grid, 7919);
            for start in [rough, vec![0.0; rows.edge.len()]] {
                let mut start_grid = vec![0.0; grid.edges().len()];
                rows.to_grid(&start, &mut start_grid);
                let cases = [1.0, 1e-4].into_iter().zip([false, true]);
                let axes = [DVec3::X, DVec3::NEG_Y, DVec3::Z].map(|axis| axis * 9.81);
                for ((radius, from_grid), g) in cases.flat_map(|c| axes.map(|g| (c, g))) {
                    let kind = FilmGradient::TwoPoint;
                    let gravity = rows.gravity(&grid, kind, g, 1.0 / 60.0);
                    let along = gravity.along_axes().expect("gravity along an axis");
                    let run = |fused: bool| {
                        let mut u = start.clone();
                        let from = from_grid.then_some(&start_grid[..]);
                        let s = &mut AdvectionScratch::default();
                        let g = fused.then_some(&along);
                        advect_momentum(&rows, &geo, radius, 1.0 / 60.0, &mut u, from, g, s);
                        if !fused {
                            rows.add_gravity(&mut u, &gravity);
                        }
                        u
                    };
                    let (fused, apart) = (run(true), run(false));
                    assert_ne!(fused, start, "n {n}, radius {radius}: nothing moved");
                    let differ = differing_bits(&fused, &apart);
                    let what = format!("n {n}, radius {radius}, from grid {from_grid}, g {g}");
                    assert_eq!(differ, 0, "{what}: edges differ");
                }
            }
        }
    }
}

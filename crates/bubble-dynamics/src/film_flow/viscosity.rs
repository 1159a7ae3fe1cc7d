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

use super::face_rows::FaceRows;
use super::flow::FilmFlow;
use super::grid::CubeSphere;

/// Largest `dt·λ` a forward-Euler sub-step is given (of the 2 it can take): the margin
/// the sub-stepped scheme kept, kept for the stages' span.
const EULER_RATE_LIMIT: f64 = 1.5;

/// Buffers of the viscous step, reused across steps.
#[derive(Clone, Debug, Default)]
pub(super) struct ViscousScratch {
    /// The stage before the one under way, in the face rows ([`FaceRows`]), m/s.
    pub(super) stage: Vec<f64>,
    /// Per local vertex: the vorticity on the unit sphere (m/s per rad).
    vorticity: Vec<f64>,
    /// Per cell, in the padded layout (`FaceRows::padded_cell`): the divergence on the
    /// unit sphere (m/s per rad), the halo holding the cells across the faces' borders.
    divergence: Vec<f64>,
}

impl FilmFlow {
    /// `u ← u + ∫ viscous dt` over `dt_s` for kinematic viscosity `nu_m2_per_s`, on the
    /// edge velocities `u` in the face rows ([`FaceRows`]).
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn viscous_step(
        &self,
        u: &mut [f64],
        v: &mut ViscousScratch,
        nu_m2_per_s: f64,
        dt_s: f64,
    ) {
        let r = self.params.radius_m;
        let rate = self.viscous_bound * nu_m2_per_s / (r * r);
        let stages = legendre_stages((dt_s * rate / EULER_RATE_LIMIT).ceil().max(1.0));
        let w1 = 2.0 / f64::from(stages * stages + stages);
        // Y₁ = Y₀ + w₁ dt M(Y₀), with Y₀ = u. The first stage reads no stage before last
        // (it only writes Y₀ there, where a stage follows), so `v.stage` needs its length,
        // not a copy of u; a lone stage touches it not at all.
        v.stage.resize(u.len(), 0.0);
        with_avx2(
            #[inline(always)]
            || {
                let last = stages == 1;
                self.viscous_stage(u, v, nu_m2_per_s, w1 * dt_s, (1.0, 0.0), last);
                for j in 2..=stages {
                    // Yⱼ = μⱼ Yⱼ₋₁ + νⱼ Yⱼ₋₂ + μⱼ w₁ dt M(Yⱼ₋₁), μⱼ = (2j − 1)/j,
                    // νⱼ = (1 − j)/j.
                    let last = j == stages;
                    let j = f64::from(j);
                    let mu = (2.0 * j - 1.0) / j;
                    let weights = (mu, (1.0 - j) / j);
                    self.viscous_stage(u, v, nu_m2_per_s, mu * w1 * dt_s, weights, last);
                }
            },
        );
    }

    /// One stage on the rows: `u ← mu·u + nu_prev·stage + dt_s·M(u)` with the stage
    /// before last in `v.stage` (read only where `nu_prev` is not 0), which then holds the
    /// `u` this stage started from, unless the stage is the `last` (which no stage reads:
    /// 0.4 MB written and, with the portable blend's select, read a step at n = 64).
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
        last: bool,
    ) {
        let rows = &self.rows;
        vorticity_and_divergence(&self.grid, rows, u, v);
        let (vorticity, divergence) = (&v.vorticity, &v.divergence);
        // Vorticity and divergence per R (of the unit sphere's), and each difference of
        // them per R again: every term of the stress carries 1/R², taken once here.
        let r = self.params.radius_m;
        let blend = Blend {
            rate: dt_s * nu / (r * r),
            mu,
            nu_prev,
        };
        let n = rows.n;
        let (epf, vpf, cpf) = (
            rows.edges_per_face(),
            rows.vertices_per_face(),
            rows.padded_cells_per_face(),
        );
        // Every face reads face 0's metric ([`FaceRows`] says why).
        let metric = (&rows.inverse_length[..], &rows.inverse_dual_length[..]);
        let faces = u.chunks_exact_mut(epf).zip(v.stage.chunks_exact_mut(epf));
        let fields = vorticity
            .chunks_exact(vpf)
            .zip(divergence.chunks_exact(cpf));
        // Each case its own loops: a test of the case per edge cost the reads and writes
        // it was to spare.
        for ((u, stage), fields) in faces.zip(fields) {
            match (nu_prev != 0.0, !last) {
                (false, false) => blend.face::<false, false>(n, u, stage, metric, fields),
                (false, true) => blend.face::<false, true>(n, u, stage, metric, fields),
                (true, false) => blend.face::<true, false>(n, u, stage, metric, fields),
                (true, true) => blend.face::<true, true>(n, u, stage, metric, fields),
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
    /// One edge: the stage before last `y_prev` read where `BLEND` (else the stage, the
    /// first, is a plain forward-Euler step), and replaced by the edge's `u` on entry where
    /// `KEEP` (a stage follows).
    #[inline(always)]
    fn step<const BLEND: bool, const KEEP: bool>(
        self,
        u: &mut f64,
        y_prev: &mut f64,
        curl_curl: f64,
        grad_div: f64,
    ) {
        let y = *u;
        let change = self.rate * (4.0 * grad_div - curl_curl + 2.0 * y);
        *u = if BLEND {
            self.mu * y + self.nu_prev * *y_prev + change
        } else {
            y + change
        };
        if KEEP {
            *y_prev = y;
        }
    }

    /// One face's edges (`u` and `y_prev` its local edges, the metric
    /// `[1/length, 1/dual length]` face 0's, `fields` its vertices' vorticities and its
    /// padded cells' divergences), row by row. Every row of edges whole, the faces'
    /// borders' too: their cells across the border are in the divergence's halo. The rows
    /// come from chunk iterators over the face, where slicing each from the whole arrays
    /// cost bounds checks and reloads of every base each row.
    #[inline(always)]
    fn face<const BLEND: bool, const KEEP: bool>(
        self,
        n: usize,
        u: &mut [f64],
        y_prev: &mut [f64],
        (il, id): (&[f64], &[f64]),
        (vorticity, divergence): (&[f64], &[f64]),
    ) {
        let (u_x, u_y) = u.split_at_mut(n * (n + 1));
        let (y_x, y_y) = y_prev.split_at_mut(n * (n + 1));
        let ((il_x, il_y), (id_x, id_y)) = (il.split_at(n * (n + 1)), id.split_at(n * (n + 1)));
        // X-edge (i, y): tail the vertex (i, y + 1), head (i, y); from cell (i − 1, y)
        // into (i, y) (padded row y + 1).
        let (w, p) = (n + 1, n + 2);
        let edges = u_x.chunks_exact_mut(w).zip(y_x.chunks_exact_mut(w));
        let metric = il_x.chunks_exact(w).zip(id_x.chunks_exact(w));
        let ends = vorticity
            .chunks_exact(w)
            .zip(vorticity[w..].chunks_exact(w));
        let cells = divergence[p..].chunks_exact(p);
        for (((u, y_prev), (il, id)), ((head, tail), d)) in edges.zip(metric).zip(ends.zip(cells)) {
            self.row::<BLEND, KEEP>(u, y_prev, [head, tail], [&d[1..], d], [il, id]);
        }
        // Y-edge (x, j): tail the vertex (x, j), head (x + 1, j); from cell (x, j − 1)
        // (padded row j) into (x, j).
        let edges = u_y.chunks_exact_mut(n).zip(y_y.chunks_exact_mut(n));
        let metric = il_y.chunks_exact(n).zip(id_y.chunks_exact(n));
        let ends = vorticity.chunks_exact(w);
        let cells = divergence[1..].chunks(p).zip(divergence[p + 1..].chunks(p));
        for (((u, y_prev), (il, id)), (z, (from, into))) in edges.zip(metric).zip(ends.zip(cells)) {
            self.row::<BLEND, KEEP>(u, y_prev, [&z[1..], z], [into, from], [il, id]);
        }
    }

    /// A row of edges: the vorticities at their `[head, tail]`, the divergences of the
    /// cells `[into, from]`, their `[1/length, 1/dual length]`. Each slice is an
    /// argument of its own: the compiler then knows the outputs overlap no input, where
    /// slices of the scratch's vectors cost it a run-time test of each pair every row.
    #[inline(always)]
    fn row<const BLEND: bool, const KEEP: bool>(
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
            let grad_div = (into[i] - from[i]) * id[i];
            self.step::<BLEND, KEEP>(&mut u[i], &mut y_prev[i], curl_curl, grad_div);
        }
    }
}

/// The vorticity at each local vertex into `v.vorticity` and the divergence of each cell
/// into `v.divergence` (its halo too), of the edge velocities `u` (in the rows), on the unit sphere
/// (m/s per rad). A cell's divergence sums its edges' `±u l` in the local order
/// ([`SIDES`](super::face_rows::SIDES)), `+` where the local normal points out of it (its
/// right and top sides): the faces' border cells whose edges the grid numbers otherwise
/// too ([`FaceRows::irregular_cells`]), which taken apart in the grid's order cost a tenth
/// of the viscous step, for sums that differ only in rounding.
#[inline(always)]
fn vorticity_and_divergence(grid: &CubeSphere, rows: &FaceRows, u: &[f64], v: &mut ViscousScratch) {
    rows.circulation(u, &mut v.vorticity, &rows.vertex_inverse_area, |z, ia| {
        z * ia
    });
    let n = rows.n;
    let divergence = &mut v.divergence;
    divergence.resize(6 * rows.padded_cells_per_face(), 0.0);
    // Face 0's lengths and cells' inverse areas, which every face reads ([`FaceRows`]
    // says why; `face_rows::tests::every_faces_constants_are_face_0s` checks the areas
    // too).
    let (l, ia) = (&rows.length[..], &grid.inverse_areas_per_sr()[..n * n]);
    let (epf, cpf) = (rows.edges_per_face(), rows.padded_cells_per_face());
    let faces = u.chunks_exact(epf).zip(divergence.chunks_exact_mut(cpf));
    for (u, out) in faces {
        divergence_face(n, u, l, ia, out);
    }
    for &[slot, across] in &rows.cell_halo {
        divergence[slot as usize] = divergence[across as usize];
    }
}

/// One face's divergences into its padded cells `out` (the halo left as it is), from
/// its local edges' velocities `u`, and face 0's lengths `l` and cells' inverse areas
/// `ia`, row by row from chunk iterators over the face (slicing each row from the whole
/// arrays cost bounds checks and reloads of every base each row).
#[inline(always)]
fn divergence_face(n: usize, u: &[f64], l: &[f64], ia: &[f64], out: &mut [f64]) {
    let ((ux, uy), (lx, ly)) = (u.split_at(n * (n + 1)), l.split_at(n * (n + 1)));
    let x_sides = ux.chunks_exact(n + 1).zip(lx.chunks_exact(n + 1));
    let bottoms = uy.chunks_exact(n).zip(ly.chunks_exact(n));
    let tops = uy[n..].chunks_exact(n).zip(ly[n..].chunks_exact(n));
    let cells = ia.chunks_exact(n).zip(out[n + 3..].chunks_mut(n + 2));
    for (((x, b), t), (ia, out)) in x_sides.zip(bottoms).zip(tops).zip(cells) {
        divergence_row(
            &mut out[..n],
            [b.0, x.0, &x.0[1..], t.0],
            [b.1, x.1, &x.1[1..], t.1],
            ia,
        );
    }
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
        let d = 0.0 - bottom[x] * lb[x] - left[x] * ll[x] + right[x] * lr[x] + top[x] * lt[x];
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
        let grid = Arc::new(CubeSphere::new(32));
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

    /// The stages keep each edge on the faces' borders the same in both its copies (its
    /// value, or its negation, bit for bit): they read the same shared constants
    /// ([`FaceRows`](super::super::face_rows::FaceRows)). A rough field, at n = 5 and 32.
    #[test]
    fn the_stages_keep_a_border_edges_copies_alike() {
        for n in [5, 32] {
            let grid = Arc::new(CubeSphere::new(n));
            let hierarchy = Arc::new(Hierarchy::new(&grid));
            let p = FlowParams {
                viscosity_pa_s: 0.5,
                ..FlowParams::water_film(0.01)
            };
            let f = FilmFlow::new(grid.clone(), hierarchy, p, |_| 1e-6);
            let rough: Vec<f64> = (0..grid.edges().len())
                .map(|e| ((e * 7919) % 1000) as f64 * 1e-6 - 4e-4)
                .collect();
            let (mut u, mut start) = (Vec::new(), Vec::new());
            f.rows.to_rows(&rough, &mut u);
            f.rows.to_rows(&rough, &mut start);
            let nu = p.viscosity_pa_s / p.density_kg_per_m3;
            f.viscous_step(&mut u, &mut ViscousScratch::default(), nu, 0.05);
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
                f.viscous_stage(u, &mut s, nu, dt / 100.0, (1.0, 0.0), true);
            }
        };
        on_rows(&mut f, &mut euler_steps);
        let smooth = f.u_m_per_s.clone();
        on_rows(&mut f, &mut euler_steps);
        let euler = std::mem::replace(&mut f.u_m_per_s, smooth.clone());
        let mut s = ViscousScratch::default();
        on_rows(&mut f, &mut |f, u| f.viscous_step(u, &mut s, nu, dt));
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
        on_rows(&mut f, &mut |f, u| f.viscous_step(u, &mut s, nu, long));
        let after = energy(&f);
        assert!(after < before, "energy {before:e} → {after:e}");
    }
}

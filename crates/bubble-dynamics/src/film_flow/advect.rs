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
//! narrowest dual edge at the fastest cell's speed. The weights are antisymmetric, so
//! the term does no work (`ζ k×u ⊥ u`), to the time scheme's error. The Marangoni step
//! that follows absorbs the gradient part of what it adds (a solid rotation's
//! centripetal push) only within its backward-Euler relaxation, which costs a rotating
//! film energy at about (ω dt)² a step: 3.3 % of a 5 rad/s rotation's rate in 0.2 s of
//! 1/240 s steps (`tests/film_flow_advection.rs`).

use glam::DVec3;

use super::grid::CubeSphere;

/// Largest fraction of the narrowest dual edge the fastest cell may cross in a sub-step.
/// SSP-RK3 damps (never amplifies) a rotation of `ω·sub_dt < √3`; the vorticity at the
/// grid scale is at most about twice the speed over the cell width, so 0.8 keeps
/// `ω·sub_dt ≤ 1.6`.
const MAX_COURANT: f64 = 0.8;

/// What the advection reads of the grid, per edge and cell, derived once from it.
#[derive(Clone, Debug)]
pub(crate) struct AdvectionGeometry {
    /// Per edge: the weights by which its normal velocity enters cell `a`'s and cell
    /// `b`'s velocity vector (Perot's reconstruction `U_c = Σ ± l (m − x_c) u / A_c`,
    /// exact for a uniform field on a flat cell).
    to_cells: Vec<[DVec3; 2]>,
    /// Per cell: its four edges.
    cell_edges: Vec<[u32; 4]>,
    /// Per cell, per edge `i` of it: the weights of the cell's three other edges (in
    /// [`OTHERS`] order) in edge `i`'s `ζ k×u` term (times the mean of the two edges'
    /// vorticities, and times the ½ of that mean: exact, a power of two). An edge's term
    /// sums over the other edges of its two cells; the weights are the reconstruction's
    /// `½ t·w` made antisymmetric under the energy norm `Σ l d u²`, so the term does no
    /// work, as `ζ k×u ⊥ u` in the continuum (with the reconstruction's own weights the
    /// advection alone lost 3.3e-4 of a rotating film's energy in 0.25 s:
    /// `tests::the_rotation_term_does_no_work`). Taken cell by cell, each cell's four
    /// edges are read once for the twelve terms among them, where edge by edge each
    /// edge read six others through an index. Stored `[k][i]`, the `k`-th other edge's
    /// weight for each of the four edges `i` side by side, so a cell's four terms of each
    /// `k` are one vector operation ([`cell_rates`]).
    coriolis: Vec<[[f64; 4]; 3]>,
    /// The narrowest dual edge, rad.
    min_dual_length: f64,
}

impl AdvectionGeometry {
    /// Derives the weights from `grid`.
    pub(crate) fn new(grid: &CubeSphere) -> Self {
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
        let coriolis = per_cell_weights(grid, &cell_edges, &stencil);
        Self {
            cell_edges,
            coriolis,
            to_cells,
            min_dual_length: edges
                .iter()
                .map(|e| e.dual_length)
                .fold(f64::INFINITY, f64::min),
        }
    }
}

/// For each of a cell's four edges, the other three, in increasing order.
const OTHERS: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

/// [`OTHERS`] transposed: `OTHER_K[k][i] = OTHERS[i][k]`, the `k`-th other edge of each
/// edge `i`.
const OTHER_K: [[usize; 4]; 3] = [[1, 0, 0, 0], [2, 2, 1, 1], [3, 3, 3, 2]];

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

/// The stencil's weights by cell: `stencil[e]` lists cell `a`'s other edges, then cell
/// `b`'s, each in increasing order, as [`OTHERS`] does.
fn per_cell_weights(
    grid: &CubeSphere,
    cell_edges: &[[u32; 4]],
    stencil: &[[(u32, f64); 6]],
) -> Vec<[[f64; 4]; 3]> {
    let edges = grid.edges();
    let weights = |(c, es): (usize, &[u32; 4])| {
        std::array::from_fn(|k| {
            std::array::from_fn(|i| {
                let e = es[i] as usize;
                let half = if edges[e].a as usize == c { 0 } else { 3 };
                let (other, w) = stencil[e][half + k];
                assert_eq!(other, es[OTHERS[i][k]], "edge {e}: stencil out of order");
                0.5 * w
            })
        })
    };
    cell_edges.iter().enumerate().map(weights).collect()
}

/// The antisymmetric `ζ k×u` stencil (see [`AdvectionGeometry::coriolis`]).
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
                    out[k] = (other as u32, a / (ed.length * ed.dual_length));
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
    cell_velocity: Vec<DVec3>,
    vorticity: Vec<f64>,
    /// Per edge: the mean vorticity of its two vertices, 1/s, and its velocity, m/s,
    /// side by side (each of a cell's four edges is then one read, not two).
    edge_vorticity_velocity: Vec<[f64; 2]>,
    rate: Vec<f64>,
    u0: Vec<f64>,
}

/// Advances the edge velocities `u` (m/s) by `u·∇u` over `dt_s` on a sphere of
/// `radius_m`.
pub(crate) fn advect_momentum(
    grid: &CubeSphere,
    geo: &AdvectionGeometry,
    radius_m: f64,
    dt_s: f64,
    u: &mut [f64],
    s: &mut AdvectionScratch,
) {
    cell_velocities(grid, geo, u, &mut s.cell_velocity);
    // The largest squared speed's root: the same number as the largest root (the
    // rounded root is monotonic), for one root where there was one a cell.
    let speed = s
        .cell_velocity
        .iter()
        .map(|v| v.length_squared())
        .fold(0.0, f64::max)
        .sqrt();
    if speed == 0.0 || !speed.is_finite() {
        return;
    }
    let courant = speed * dt_s / (geo.min_dual_length * radius_m);
    let substeps = (courant / MAX_COURANT).ceil().clamp(1.0, 64.0) as u32;
    let h = dt_s / f64::from(substeps);
    for _ in 0..substeps {
        ssp_rk3(grid, geo, radius_m, h, u, s);
    }
}

/// One Shu–Osher third-order step: `u₁ = u + hL(u)`, `u₂ = ¾u + ¼(u₁ + hL(u₁))`,
/// `u ← ⅓u + ⅔(u₂ + hL(u₂))`.
fn ssp_rk3(
    grid: &CubeSphere,
    geo: &AdvectionGeometry,
    radius_m: f64,
    h: f64,
    u: &mut [f64],
    s: &mut AdvectionScratch,
) {
    s.u0.clear();
    s.u0.extend_from_slice(u);
    // Stage 1: u holds u₁.
    acceleration(grid, geo, radius_m, u, s);
    for (u, r) in u.iter_mut().zip(&s.rate) {
        *u += h * r;
    }
    // Stage 2: u holds u₂.
    acceleration(grid, geo, radius_m, u, s);
    for ((u, r), u0) in u.iter_mut().zip(&s.rate).zip(&s.u0) {
        *u = 0.75 * u0 + 0.25 * (*u + h * r);
    }
    // Stage 3.
    acceleration(grid, geo, radius_m, u, s);
    for ((u, r), u0) in u.iter_mut().zip(&s.rate).zip(&s.u0) {
        *u = u0 / 3.0 + (2.0 / 3.0) * (*u + h * r);
    }
}

/// Each cell's velocity vector from its edges' normal velocities, in its tangent plane.
fn cell_velocities(grid: &CubeSphere, geo: &AdvectionGeometry, u: &[f64], out: &mut Vec<DVec3>) {
    out.clear();
    out.resize(grid.cells(), DVec3::ZERO);
    let cells = &grid.edge_arrays().cells;
    for ((&u, [a, b]), [wa, wb]) in u.iter().zip(cells).zip(&geo.to_cells) {
        out[*a as usize] += *wa * u;
        out[*b as usize] += *wb * u;
    }
    for (v, c) in out.iter_mut().zip(grid.centres()) {
        *v -= *c * v.dot(*c);
    }
}

/// The rotation term `−ζ (k×u)·n` on every edge into `s.rate`, m/s².
fn acceleration(
    grid: &CubeSphere,
    geo: &AdvectionGeometry,
    radius_m: f64,
    u: &[f64],
    s: &mut AdvectionScratch,
) {
    vertex_vorticity(grid, radius_m, u, &mut s.vorticity);
    let ea = grid.edge_arrays();
    let vorticity = &s.vorticity;
    let zeta_u = &mut s.edge_vorticity_velocity;
    zeta_u.resize(u.len(), [0.0; 2]);
    for ((zu, [v0, v1]), &u) in zeta_u.iter_mut().zip(&ea.vertices).zip(u) {
        *zu = [0.5 * (vorticity[*v0 as usize] + vorticity[*v1 as usize]), u];
    }
    let zeta_u = &s.edge_vorticity_velocity;
    let rate = &mut s.rate;
    rate.clear();
    rate.resize(u.len(), 0.0);
    for (es, weights) in geo.cell_edges.iter().zip(&geo.coriolis) {
        let rates = cell_rates(es.map(|e| zeta_u[e as usize]), weights);
        for (&e, r) in es.iter().zip(rates) {
            rate[e as usize] += r;
        }
    }
}

/// A cell's terms of its four edges' rates, from the edges' `[ζ, u]` and the cell's
/// weights: `Σ_k w[k][i] (ζ_i + ζ_o) u_o` over the other edges `o = OTHER_K[k][i]`,
/// summed in `k` order: the same operations per edge as edge by edge, so the same bits,
/// in four independent chains the core overlaps (29 M fewer instructions over 40 steps
/// at n = 64; the compiler keeps them scalar, with or without AVX2).
#[inline(always)]
fn cell_rates(zu: [[f64; 2]; 4], w: &[[f64; 4]; 3]) -> [f64; 4] {
    let (z, u) = (zu.map(|p| p[0]), zu.map(|p| p[1]));
    let term = |k: usize| -> [f64; 4] {
        let o = OTHER_K[k];
        std::array::from_fn(|i| w[k][i] * (z[i] + z[o[i]]) * u[o[i]])
    };
    let (t0, t1, t2) = (term(0), term(1), term(2));
    std::array::from_fn(|i| t0[i] + t1[i] + t2[i])
}

/// The vorticity at each grid vertex, 1/s: the circulation `Σ u d` along its dual edges
/// over its area, as the viscous operator takes it.
fn vertex_vorticity(grid: &CubeSphere, radius_m: f64, u: &[f64], vorticity: &mut Vec<f64>) {
    let ea = grid.edge_arrays();
    vorticity.clear();
    vorticity.resize(grid.vertex_areas_sr().len(), 0.0);
    for ((&u, d), [v0, v1]) in u.iter().zip(&ea.dual_length).zip(&ea.vertices) {
        // Counter-clockwise about v1 seen from outside.
        vorticity[*v1 as usize] += u * d;
        vorticity[*v0 as usize] -= u * d;
    }
    for (z, a) in vorticity.iter_mut().zip(grid.vertex_areas_sr()) {
        *z /= a * radius_m;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotation_about_z(grid: &CubeSphere, omega: f64) -> Vec<f64> {
        grid.edges()
            .iter()
            .map(|e| (DVec3::Z * omega).cross(e.midpoint).dot(e.normal))
            .collect()
    }

    #[test]
    fn the_reconstruction_recovers_a_solid_rotation_at_cell_centres() {
        let grid = CubeSphere::new(16);
        let geo = AdvectionGeometry::new(&grid);
        let u = rotation_about_z(&grid, 1.0);
        let mut v = Vec::new();
        cell_velocities(&grid, &geo, &u, &mut v);
        let worst = v
            .iter()
            .zip(grid.centres())
            .map(|(v, c)| (*v - DVec3::Z.cross(*c)).length())
            .fold(0.0, f64::max);
        assert!(worst < 0.02, "worst reconstruction error {worst:.3e}");
    }

    #[test]
    fn the_rotation_term_does_no_work() {
        // A solid rotation with a degree-2 pattern on it, advected alone for 0.25 s: the
        // energy Σ l d u² changes only by the time scheme's error (with the
        // reconstruction's own weights, not made antisymmetric, it lost 3.3e-4).
        let grid = CubeSphere::new(16);
        let geo = AdvectionGeometry::new(&grid);
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
        for _ in 0..240 {
            advect_momentum(&grid, &geo, 0.01, 1.0 / 960.0, &mut u, &mut s);
        }
        let change = energy(&u) / e0 - 1.0;
        assert!(change.abs() < 1e-4, "energy changed by {change:+.3e}");
    }
}

//! The thin viscous sheet's stress `ν(−∇×∇×u + 2Ku + 4∇∇·u)` on the edge velocities,
//! explicit, in the stages of a first-order Runge–Kutta–Legendre step (RKL1, Meyer,
//! Balsara & Aslam 2014, J. Comput. Phys. 257, 594).
//!
//! Forward Euler is stable while `dt·λ ≤ 2` for the operator's largest rate `λ`, which
//! grows as n²: at n = 256 a 1/60 s step took 20-odd sub-steps. `s` RKL1 stages are
//! stable up to `dt·λ ≤ s² + s`, the span of `s(s + 1)/2` forward-Euler sub-steps, for
//! the cost of `s` of them: the stage count grows as n, not n². Each stage is a
//! forward-Euler sub-step of its own length plus a blend with the two stages before it.

use super::flow::{FilmFlow, Scratch};
use super::grid::CubeSphere;

/// Largest `dt·λ` a forward-Euler sub-step is given (of the 2 it can take): the margin
/// the sub-stepped scheme kept, kept for the stages' span.
const EULER_RATE_LIMIT: f64 = 1.5;

impl FilmFlow {
    /// `u ← u + ∫ viscous dt` over `dt_s` for kinematic viscosity `nu_m2_per_s`.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn viscous_step(&mut self, s: &mut Scratch, nu_m2_per_s: f64, dt_s: f64) {
        let r = self.params.radius_m;
        let rate = self.viscous_bound * nu_m2_per_s / (r * r);
        let stages = legendre_stages((dt_s * rate / EULER_RATE_LIMIT).ceil().max(1.0));
        let w1 = 2.0 / f64::from(stages * stages + stages);
        // Y₁ = Y₀ + w₁ dt M(Y₀), with Y₀ = u. The first stage reads no stage before last
        // (it only writes Y₀ there), so `s.stage` needs its length, not a copy of u.
        s.stage.resize(self.u_m_per_s.len(), 0.0);
        self.viscous_stage(s, nu_m2_per_s, w1 * dt_s, 1.0, 0.0);
        for j in 2..=stages {
            // Yⱼ = μⱼ Yⱼ₋₁ + νⱼ Yⱼ₋₂ + μⱼ w₁ dt M(Yⱼ₋₁), μⱼ = (2j − 1)/j, νⱼ = (1 − j)/j.
            let j = f64::from(j);
            let mu = (2.0 * j - 1.0) / j;
            self.viscous_stage(s, nu_m2_per_s, mu * w1 * dt_s, mu, (1.0 - j) / j);
        }
    }

    /// One stage: `u ← mu·u + nu_prev·s.stage + dt_s·M(u)` with the stage before last in
    /// `s.stage`, which then holds the `u` this stage started from.
    fn viscous_stage(&mut self, s: &mut Scratch, nu: f64, dt_s: f64, mu: f64, nu_prev: f64) {
        self.vorticity_and_divergence(s);
        let ea = self.grid.edge_arrays();
        let (vorticity, divergence) = (&s.vertex, &s.cell);
        // Vorticity and divergence per R (of the unit sphere's), and each difference of
        // them per R again: every term of the stress carries 1/R², taken once here.
        let r = self.params.radius_m;
        let rate = dt_s * nu / (r * r);
        let per_length = ea.inverse_length.iter().zip(&ea.inverse_dual_length);
        let ends = ea.cells.iter().zip(&ea.vertices);
        let velocities = self.u_m_per_s.iter_mut().zip(s.stage.iter_mut());
        for ((u, y_prev), ((il, id), ([a, b], [v0, v1]))) in velocities.zip(per_length.zip(ends)) {
            let curl_curl = (vorticity[*v1 as usize] - vorticity[*v0 as usize]) * il;
            let grad_div = (divergence[*b as usize] - divergence[*a as usize]) * id;
            let y = *u;
            let change = rate * (4.0 * grad_div - curl_curl + 2.0 * y);
            // The first stage (mu 1, nu_prev 0) is a plain forward-Euler step: no blend.
            *u = if nu_prev == 0.0 {
                y + change
            } else {
                mu * y + nu_prev * *y_prev + change
            };
            *y_prev = y;
        }
    }

    /// The vorticity at each grid vertex into `s.vertex` and the divergence of each cell
    /// into `s.cell`, of the edge velocities, on the unit sphere (m/s per rad).
    fn vorticity_and_divergence(&self, s: &mut Scratch) {
        let g = &self.grid;
        let vorticity = &mut s.vertex;
        vorticity.clear();
        vorticity.resize(g.vertex_areas_sr().len(), 0.0);
        let divergence = &mut s.cell;
        divergence.clear();
        divergence.resize(g.cells(), 0.0);
        let ea = g.edge_arrays();
        let lengths = ea.length.iter().zip(&ea.dual_length);
        let ends = ea.cells.iter().zip(&ea.vertices);
        for ((&u, (l, d)), ([a, b], [v0, v1])) in self.u_m_per_s.iter().zip(lengths).zip(ends) {
            vorticity[*v1 as usize] += u * d;
            vorticity[*v0 as usize] -= u * d;
            divergence[*a as usize] += u * l;
            divergence[*b as usize] -= u * l;
        }
        for (z, ia) in vorticity.iter_mut().zip(g.inverse_vertex_areas_per_sr()) {
            *z *= ia;
        }
        for (d, ia) in divergence.iter_mut().zip(g.inverse_areas_per_sr()) {
            *d *= ia;
        }
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

    use super::super::flow::{FilmFlow, FlowParams, Scratch};
    use super::super::{CubeSphere, Hierarchy};
    use super::legendre_stages;

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
        let mut s = Scratch::default();
        let dt = step_of(&f, nu, 54.5);
        f.set_velocity(|d: DVec3| d.cross(DVec3::Z) * (3.0 * d.z) * 1e-3);
        let euler_steps = |f: &mut FilmFlow, s: &mut Scratch| {
            // Plain forward-Euler sub-steps, not through the stage weights under test.
            s.stage.resize(f.u_m_per_s.len(), 0.0);
            for _ in 0..100 {
                f.viscous_stage(s, nu, dt / 100.0, 1.0, 0.0);
            }
        };
        euler_steps(&mut f, &mut s);
        let smooth = f.u_m_per_s.clone();
        euler_steps(&mut f, &mut s);
        let euler = std::mem::replace(&mut f.u_m_per_s, smooth.clone());
        f.viscous_step(&mut s, nu, dt);
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
        f.viscous_step(&mut s, nu, step_of(&f, nu, 149.5));
        let after = energy(&f);
        assert!(after < before, "energy {before:e} → {after:e}");
    }
}

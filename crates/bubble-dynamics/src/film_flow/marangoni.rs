//! The backward-Euler Marangoni step: the surfactant the step ends with from one linear
//! system (`solve`), the velocities from its gradient, and the surfactant moved with
//! fluxes that sum to zero.
//!
//! First the surfactant moves upwind with the step's starting velocity, in sub-steps of
//! its own (`transport_surfactant`). Then the edges are walked twice: the fluxes'
//! central part with the system's edge weights and right-hand side; the velocity
//! correction with the surfactant's move (into a copy, so the correction still reads the
//! surfactant the solve started from and the rare redo needs no restore).

use super::flow::{
    FilmFlow, H_FLOOR_M, SOLVE_MAX_ITERATIONS, SOLVE_TOLERANCE, Scratch, apply_limited_fluxes,
};
use super::solve::{SolveLimits, SolveReport};

impl FilmFlow {
    /// Backward-Euler Marangoni step: solves for the surfactant the step ends with, sets
    /// the velocities from its gradient, and moves the surfactant with fluxes that sum to
    /// zero (so it is conserved to rounding whatever the solver's residual).
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn marangoni_implicit(&mut self, s: &mut Scratch, dt_s: f64) -> SolveReport {
        self.transport_surfactant(s, dt_s);
        self.fluxes_weights_and_right_hand_side(s, dt_s);
        let report = self.solve_surfactant(s);
        self.correct_velocity_and_move_surfactant(s, dt_s);
        report
    }

    /// Moves Γ upwind with the velocity the step started with, in sub-steps of per-edge
    /// Courant ≤ ½ like the thickness, each donor limited to half its content.
    ///
    /// Why sub-steps: this transport used to be the upwind part of the solve's one flux,
    /// its donors limited over the whole step. Where a fast flow crossed the narrow corner
    /// cells at a Courant number near 1 the limit cut that flux, Γ no longer saw the
    /// velocity's divergence there, no Marangoni stress resisted it, and the film piled up
    /// at the cube's corners: a 10 cm/s solid rotation on a 1 cm film at n = 64 and 1 ms
    /// steps blew up within 80 steps
    /// (`a_fast_solid_rotation_keeps_the_film_uniform_at_the_cube_corners`).
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn transport_surfactant(&mut self, s: &mut Scratch, dt_s: f64) {
        let dt_per_r = dt_s / self.params.radius_m;
        let g = std::sync::Arc::clone(&self.grid);
        let ea = g.edge_arrays();
        let fastest = g.fastest_crossing(&s.u_start);
        if fastest == 0.0 {
            return;
        }
        let substeps = (2.0 * fastest * dt_per_r).ceil().clamp(1.0, 64.0) as u32;
        let sub_dt_per_r = dt_per_r / f64::from(substeps);
        for _ in 0..substeps {
            let flux = &mut s.edge2;
            flux.clear();
            let edges = ea.cells.iter().zip(&ea.length);
            flux.extend(edges.zip(&s.u_start).map(|(([a, b], l), &u0)| {
                let up = if u0 >= 0.0 { *a } else { *b } as usize;
                self.gamma[up] * u0 * l
            }));
            apply_limited_fluxes(&g, flux, sub_dt_per_r, &mut self.gamma, &mut s.cell);
        }
    }

    /// Per edge: the surfactant flux (per R) into `s.edge`, central with the step's change
    /// of velocity (the forces' part, which the implicit solve treats centrally: an
    /// upwind flux there would diffuse Γ at |g dt| and no gradient could hold a film at
    /// rest); `dt·E/(ρh)/(1 + dt k)` into `s.stiffness` (the weights and the velocity
    /// correction both use it) and the system's weight `dt² E l/(ρ h d R²)/(1 + dt k)`
    /// into `s.weight`; and, in the same pass over the edges, the system's right-hand
    /// side `A Γ − dt Σ F/R` (rows divided by R²) into `s.rhs`.
    fn fluxes_weights_and_right_hand_side(&self, s: &mut Scratch, dt_s: f64) {
        let p = &self.params;
        let per_r2 = 1.0 / (p.radius_m * p.radius_m);
        let dt_per_r = dt_s / p.radius_m;
        let g = &self.grid;
        let ea = g.edge_arrays();
        let (gamma, h) = (&self.gamma, &self.h_m);
        // Written in place through resized buffers: three pushes an edge each checked
        // the capacity.
        let n = ea.cells.len();
        s.edge.resize(n, 0.0);
        s.stiffness.resize(n, 0.0);
        s.weight.resize(n, 0.0);
        let outputs = s.edge.iter_mut().zip(&mut s.stiffness).zip(&mut s.weight);
        let rhs = &mut s.rhs;
        rhs.clear();
        rhs.extend(g.areas_sr().iter().zip(gamma).map(|(a, gm)| a * gm));
        let velocities = self.u_m_per_s.iter().zip(&s.u_start).zip(&s.drag);
        let lengths = ea.length.iter().zip(&ea.inverse_dual_length);
        let edges = velocities.zip(ea.cells.iter().zip(lengths));
        for ((((&u, &u0), drag), ([a, b], (l, id))), ((flux, stiffness), weight)) in
            edges.zip(outputs)
        {
            let (a, b) = (*a as usize, *b as usize);
            let f = 0.5 * (gamma[a] + gamma[b]) * (u - u0) * l;
            *flux = f;
            rhs[a] -= dt_per_r * f;
            rhs[b] += dt_per_r * f;
            let h_edge = (0.5 * (h[a] + h[b])).max(H_FLOOR_M);
            let k = dt_s * p.elasticity_n_per_m / (p.density_kg_per_m3 * h_edge) * drag;
            *stiffness = k;
            *weight = dt_s * k * l * id * per_r2;
        }
    }

    /// Solves for the surfactant the step ends with into `s.cell2`, from the last step's
    /// change again as the first guess (a film in steady motion changes alike from step
    /// to step; the tolerance stays relative to Γⁿ's residual), and keeps this change.
    fn solve_surfactant(&mut self, s: &mut Scratch) -> SolveReport {
        let g = &self.grid;
        let solution = &mut s.cell2;
        solution.clear();
        solution.extend_from_slice(&self.gamma);
        let guess = &mut s.guess;
        guess.clear();
        let change = &self.surfactant_change;
        guess.extend(self.gamma.iter().zip(change).map(|(gm, d)| gm + d));
        let report = self.hierarchy.solve_with_guess(
            &mut s.work,
            g.areas_sr(),
            &s.weight,
            &s.rhs,
            solution,
            Some(guess.as_slice()),
            SolveLimits {
                tolerance: SOLVE_TOLERANCE,
                max_iterations: SOLVE_MAX_ITERATIONS,
            },
        );
        self.surfactant_change.clear();
        let changes = solution.iter().zip(&self.gamma).map(|(x, gm)| x - gm);
        self.surfactant_change.extend(changes);
        report
    }

    /// The velocity correction `−k ∇Γ'/Γ` and the conservative surfactant update with the
    /// transport fluxes plus the correction's; a step that would leave Γ negative anywhere
    /// is redone upwind and limited instead.
    fn correct_velocity_and_move_surfactant(&mut self, s: &mut Scratch, dt_s: f64) {
        let r = self.params.radius_m;
        let g = std::sync::Arc::clone(&self.grid);
        let (ea, per_area) = (g.edge_arrays(), g.inverse_areas_per_sr());
        let (solution, gamma) = (&s.cell2, &self.gamma);
        let next = &mut s.rhs;
        next.clear();
        next.extend_from_slice(gamma);
        let scale = dt_s / r;
        let per_edge = self.u_m_per_s.iter_mut().zip(&s.edge).zip(&s.stiffness);
        let edges = ea
            .cells
            .iter()
            .zip(ea.length.iter().zip(&ea.inverse_dual_length));
        for (((u, f_adv), k), ([a, b], (l, id))) in per_edge.zip(edges) {
            let (a, b) = (*a as usize, *b as usize);
            let gamma_c = 0.5 * (gamma[a] + gamma[b]);
            let slope = (solution[b] - solution[a]) * id / r;
            let du = -k * slope / gamma_c.max(f64::MIN_POSITIVE);
            *u += du;
            let moved = scale * (f_adv + gamma_c * du * l);
            next[a] -= moved * per_area[a];
            next[b] += moved * per_area[b];
        }
        if !next.iter().any(|&x| x < 0.0) {
            std::mem::swap(&mut self.gamma, next);
            return;
        }
        // A violent step (a film torn near zero thickness, where the waves run at
        // hundreds of m/s) overshot: redo it with every flux upwind and each donor
        // limited, which keeps Γ positive and still conserves it. (The starting
        // velocity's transport is done: this moves Γ with the step's change only.)
        let flux = &mut s.edge2;
        flux.clear();
        let edges = ea.cells.iter().zip(&ea.length);
        let changes = self.u_m_per_s.iter().zip(&s.u_start);
        flux.extend(changes.zip(edges).map(|((&u, &u0), ([a, b], l))| {
            let du = u - u0;
            let up = if du >= 0.0 { *a } else { *b } as usize;
            self.gamma[up] * du * l
        }));
        apply_limited_fluxes(&g, flux, scale, &mut self.gamma, &mut s.cell);
    }
}

//! The backward-Euler Marangoni step: the surfactant the step ends with from one linear
//! system (`solve`), the velocities from its gradient, and the surfactant moved with
//! fluxes that sum to zero.
//!
//! First, at the step's start, the surfactant moves upwind with the step's starting
//! velocity, in sub-steps of its own (`transport_surfactant`). Then the edges are
//! walked: the air's drag where it was left to this pass ([`super::flow::Drag`]), the
//! fluxes' central part with the system's edge weights and right-hand side (gathered
//! band by band, [`super::fluxes::net_inflow`]); with the normal gradient
//! ([`FilmGradient::Normal`]) the cross term of the gradient again from each solution
//! until the system with it is solved (defect correction, `correct_the_cross_term`); the
//! velocity correction with the surfactant's move (into a copy, so the correction still
//! reads the surfactant the solve started from and the rare redo needs no restore).

use std::ops::Range;

use super::compare::{larger, pick};
use super::face_geometry::{EdgeConstant, FaceGeometry};
use super::flow::{
    Drag, FilmFlow, FilmGradient, GUESS_REST, H_FLOOR_M, SOLVE_MAX_ITERATIONS, SOLVE_TOLERANCE,
    Scratch,
};
use super::fluxes::{EdgeValues, apply_limited, net_inflow};
use super::grid::CubeSphere;
use super::sides::{EdgeBlock, EdgeRun, SeamEnds, Seams};
use super::solve::{MassTerm, SolveLimits, SolveReport, Weights};

/// Most solves a step's defect correction of the cross term takes (it takes about 11 on
/// the swirl film at n = 64: each cuts the error by about 0.35, the cross operator's
/// share of the gradient where grid lines are most askew).
const MAX_SWEEPS: u32 = 30;
/// A re-solve's residual relative to its start: each sweep's error is only ~0.35 of the
/// last's, so solving it tighter is wasted (one or two PCG iterations a sweep; solved
/// to the final tolerance each time, the swirl film took 35 iterations a step, 17 so).
const SWEEP_TOLERANCE: f64 = 0.3;

impl FilmFlow {
    /// Backward-Euler Marangoni step: solves for the surfactant the step ends with, sets
    /// the velocities from its gradient, and moves the surfactant with fluxes that sum to
    /// zero (so it is conserved to rounding whatever the solver's residual).
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn marangoni_implicit(&mut self, s: &mut Scratch, dt_s: f64) -> SolveReport {
        let report = match self.params.gradient {
            FilmGradient::TwoPoint => {
                self.fluxes_weights_and_right_hand_side::<false>(s, dt_s);
                self.solve_surfactant(s)
            }
            FilmGradient::Normal => {
                // The cross term first from the surfactant the step starts from (from the
                // one the last step's change anticipates, the swirl film took as many
                // sweeps: its first correction is 4–5 % of the step's residual either way).
                s.cell2.clear();
                s.cell2.extend_from_slice(&self.gamma);
                self.fluxes_weights_and_right_hand_side::<true>(s, dt_s);
                let first = self.solve_surfactant(s);
                self.correct_the_cross_term(s, dt_s, first)
            }
        };
        match self.params.gradient {
            FilmGradient::TwoPoint => self.correct_velocity_and_move_surfactant::<false>(s, dt_s),
            FilmGradient::Normal => self.correct_velocity_and_move_surfactant::<true>(s, dt_s),
        }
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
    ///
    /// `fastest` is the starting velocity's
    /// [`CubeSphere::fastest_crossing`](super::grid::CubeSphere::fastest_crossing). The
    /// step takes this transport first, before the explicit momentum (which neither
    /// reads Γ nor changes the starting velocity): where the last step's thickness
    /// transport and the Courant number's pass have just read the starting velocity,
    /// rather than after the momentum's passes had pushed it out of cache. Over `film_profile 64 0 9.81`'s 40 steps the step then took 12.51 M LL misses
    /// against 12.63 M, though the right-hand side's pass reads Γ colder.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn transport_surfactant(&mut self, s: &mut Scratch, dt_s: f64, fastest: f64) {
        let dt_per_r = dt_s / self.params.radius_m;
        let g = std::sync::Arc::clone(&self.grid);
        let fg = g.face_geometry();
        if fastest == 0.0 {
            return;
        }
        let substeps = (2.0 * fastest * dt_per_r).ceil().clamp(1.0, 64.0) as u32;
        let sub_dt_per_r = dt_per_r / f64::from(substeps);
        let sides = &self.sides;
        for _ in 0..substeps {
            let u = &s.u_start;
            let mut fluxes = UpwindFluxes::new(fg, u, &mut s.seam_ends);
            let (gamma, gather) = (&mut self.gamma, &mut s.gather);
            apply_limited(sides, &g, &mut fluxes, sub_dt_per_r, gamma, gather);
        }
    }

    /// Per edge: with the normal gradient (`NORMAL`), the cross term of the Marangoni
    /// gradient added to the velocity (below); the surfactant flux (per R) into `s.edge`,
    /// central with the step's change of velocity (the forces' part, which the implicit
    /// solve treats centrally: an upwind flux there would diffuse Γ at |g dt| and no
    /// gradient could hold a film at rest); with the normal gradient, `dt·E/(ρh)/(1 + dt
    /// k)` into `s.stiffness` (the cross term uses it; the velocity correction takes
    /// `k/(d R)` from the weight instead, the very numbers the system is solved with) and
    /// the system's weight `dt² E l/(ρ h d R²)/(1 + dt k)` (`d cos θ` for `d` with the
    /// normal gradient), rounded to `f32`, into `s.weight`; and, in the same pass over the
    /// edges, the system's right-hand side `A Γ − dt Σ F/R` (rows divided by R²) into
    /// `s.rhs`.
    ///
    /// Why the weights are rounded here: the solve and the correction then read the same
    /// numbers, and the solve needs no `f64` copy of them ([`Weights::F32`]); each is moved
    /// by 6e-8 of itself at most, a perturbation of the step's coefficients far below
    /// their own accuracy.
    ///
    /// The gradient along the edge's normal is `(Γ_b − Γ_a)/(d cos θ) − (tan θ/l)(Γ_v1 −
    /// Γ_v0)` ([`CubeSphere::normal_gradient`](super::grid::CubeSphere::normal_gradient)).
    /// The first part is implicit (the system stays symmetric, solved by CG); the
    /// second, along the edge, from the Γ in `s.cell2` (first the step's start, then each
    /// solution in turn: `correct_the_cross_term`). Lagged once only, the cross term left
    /// a velocity `k·(tan θ/l)·ΔΓ` of the step's change ΔΓ that no gradient holds, and
    /// `k = dt E/(ρh)` is huge in a stiff step: a perturbed film at rest kept 3.5 mm/s
    /// forever and most film tests blew up.
    ///
    /// The fluxes go straight into the gather of the right-hand side, band by band
    /// ([`net_inflow`]); with the normal gradient they are also kept whole in `s.edge`
    /// (the defect correction adds to them), with the two-point one the velocity
    /// correction takes them again from the velocities (the same bits).
    fn fluxes_weights_and_right_hand_side<const NORMAL: bool>(
        &mut self,
        s: &mut Scratch,
        dt_s: f64,
    ) {
        let p = &self.params;
        let g = &self.grid;
        let n = g.edge_arrays().cells.len();
        if NORMAL {
            g.cells_to_vertices(&s.cell2, &mut s.vertex);
            s.cross.resize(n, 0.0);
            s.edge.resize(n, 0.0);
            s.stiffness.resize(n, 0.0);
        }
        s.weight.resize(n, 0.0);
        let mut fluxes = CentralFluxes::<NORMAL> {
            edges: CentralEdges {
                grid: g,
                u: &mut self.u_m_per_s,
                u0: &s.u_start,
                drag: (s.drag_by, &s.drag),
                vertex: &s.vertex,
                c: EdgeConstants {
                    // `dt E/ρ`: over the edge's thickness, the stiffness `k`.
                    dt_e_per_rho: dt_s * p.elasticity_n_per_m / p.density_kg_per_m3,
                    dt_per_r2: dt_s / (p.radius_m * p.radius_m),
                    per_r: 1.0 / p.radius_m,
                },
                stiffness: &mut s.stiffness,
                weight: &mut s.weight,
                cross: &mut s.cross,
                flux: &mut s.edge,
            },
            h: &self.h_m,
            seam_ends: &mut s.seam_ends,
        };
        // `A Γ − dt Σ F/R`: each cell's net inflow of the fluxes, gathered; each face's
        // cells with face 0's areas (the same on every face).
        let dt_per_r = dt_s / p.radius_m;
        let (areas, gamma, n) = (&g.face_geometry().area_sr[..], &self.gamma, self.sides.n());
        let pass = (&mut fluxes, &gamma[..]);
        // Every entry is written below: the buffer needs its length, not a fill.
        let rhs = &mut s.rhs;
        rhs.resize(gamma.len(), 0.0);
        net_inflow(&self.sides, pass, &mut s.gather, |_, face, rows, inflow| {
            let cells = rows.start * n..rows.end * n;
            let at = face * n * n + cells.start..face * n * n + cells.end;
            let (areas, gamma, rhs) = (&areas[cells], &gamma[at.clone()], &mut rhs[at]);
            let (gamma, inflow) = (&gamma[..rhs.len()], &inflow[..rhs.len()]);
            for i in 0..rhs.len() {
                rhs[i] = areas[i] * gamma[i] + dt_per_r * inflow[i];
            }
        });
    }

    /// Solves for the surfactant the step ends with into `s.cell2`, from the last step's
    /// change again as the first guess (a film in steady motion changes alike from step
    /// to step; the tolerance stays relative to Γⁿ's residual).
    fn solve_surfactant(&mut self, s: &mut Scratch) -> SolveReport {
        let g = &self.grid;
        // The guess offered only where the last ones paid ([`GUESS_REST`]).
        let offer = self.guess_wait == 0 && !self.surfactant_change.is_empty();
        self.guess_wait = self.guess_wait.saturating_sub(1);
        let change = offer.then_some(&self.surfactant_change[..]);
        s.cell2.resize(self.gamma.len(), 0.0);
        // The cells' areas, alike on every face to the bit: face 0's.
        let n = self.sides.n();
        let areas = MassTerm::EveryFace(&g.areas_sr()[..n * n]);
        // The weights are `f32` values (rounded where they are made): the solve holds
        // them once, in its V-cycle's copy, and its last iterations run in `f32`
        // ([`Weights::F32`]); the velocity correction reads the same numbers.
        let report = self.hierarchy.solve_from_start_and_change(
            &mut s.work,
            (areas, Weights::F32(&s.weight), &s.rhs),
            (&self.gamma, change),
            &mut s.cell2,
            SolveLimits {
                tolerance: SOLVE_TOLERANCE,
                max_iterations: SOLVE_MAX_ITERATIONS,
            },
        );
        if offer && !report.from_guess {
            self.guess_wait = GUESS_REST;
        }
        report
    }

    /// Defect correction: the cross term again from the solution, and the system solved
    /// again from it, until the change of the right-hand side and the solve's residual
    /// together are within the solve's tolerance of the first residual (the nonsymmetric
    /// system solved as tightly as the symmetric one was: an error in the cross term is a
    /// velocity `k ∇Γ` that no tension gradient holds, and `k` is `dt E/(ρh)`, huge in a
    /// stiff step).
    fn correct_the_cross_term(
        &mut self,
        s: &mut Scratch,
        dt_s: f64,
        first: SolveReport,
    ) -> SolveReport {
        let goal = SOLVE_TOLERANCE * first.start_residual;
        let mut report = first;
        for _ in 1..MAX_SWEEPS {
            let left = report.start_residual * report.relative_residual;
            let change = self.update_cross_term(s, dt_s);
            let estimate = left + change;
            if estimate <= goal {
                break;
            }
            let again = self.hierarchy.solve_prepared(
                &mut s.work,
                &s.rhs,
                &mut s.cell2,
                None,
                SolveLimits {
                    tolerance: (goal / estimate).max(SWEEP_TOLERANCE),
                    max_iterations: SOLVE_MAX_ITERATIONS,
                },
            );
            report.iterations += again.iterations;
            report.relative_residual = again.relative_residual;
            report.start_residual = again.start_residual;
        }
        report
    }

    /// The cross term's velocity from the surfactant in `s.cell2`, its change folded into
    /// the fluxes and the right-hand side; returns the norm of that change of the
    /// right-hand side.
    fn update_cross_term(&self, s: &mut Scratch, dt_s: f64) -> f64 {
        let per_r = 1.0 / self.params.radius_m;
        let dt_per_r = dt_s * per_r;
        let g = &self.grid;
        let ea = g.edge_arrays();
        let gamma = &self.gamma;
        g.cells_to_vertices(&s.cell2, &mut s.vertex);
        let at_vertex = &s.vertex;
        let delta = &mut s.cell;
        delta.clear();
        delta.resize(gamma.len(), 0.0);
        let per_edge = s.cross.iter_mut().zip(&mut s.edge).zip(&s.stiffness);
        let ends = ea.cells.iter().zip(&ea.vertices);
        let geometry = ends.zip(ea.length.iter().zip(&ea.cross_per_length));
        for (((du_cross, flux), k), (([a, b], [v0, v1]), (l, cross))) in per_edge.zip(geometry) {
            let (a, b) = (*a as usize, *b as usize);
            let gamma_c = 0.5 * (gamma[a] + gamma[b]);
            let along = at_vertex[*v1 as usize] - at_vertex[*v0 as usize];
            let du = k * cross * along * per_r / gamma_c.max(f64::MIN_POSITIVE);
            let df = gamma_c * (du - *du_cross) * l;
            *du_cross = du;
            *flux += df;
            delta[a] -= dt_per_r * df;
            delta[b] += dt_per_r * df;
        }
        for (r, d) in s.rhs.iter_mut().zip(delta.iter()) {
            *r += d;
        }
        delta.iter().map(|d| d * d).sum::<f64>().sqrt()
    }

    /// The velocity correction `−k ∇Γ'/Γ` (with the normal gradient, `NORMAL`, its
    /// implicit part, plus the cross term) and the conservative surfactant update with
    /// the transport fluxes plus the correction's; a step that would leave Γ negative
    /// anywhere is redone upwind and limited instead.
    fn correct_velocity_and_move_surfactant<const NORMAL: bool>(
        &mut self,
        s: &mut Scratch,
        dt_s: f64,
    ) {
        let r = self.params.radius_m;
        let g = std::sync::Arc::clone(&self.grid);
        let sides = std::sync::Arc::clone(&self.sides);
        let (fg, sides) = (g.face_geometry(), &*sides);
        let scale = dt_s / r;
        let mut correction = Correction::<NORMAL> {
            edges: CorrectionEdges {
                length: &fg.length,
                u0: &s.u_start,
                flux: &s.edge,
                weight: &s.weight,
                cross: &s.cross,
                u: &mut self.u_m_per_s,
                scale,
            },
            solution: &mut s.cell2,
            seam_ends: &mut s.seam_ends,
        };
        // Each cell's net inflow gathered band by band, and the surfactant after the
        // step from it while the band is in cache, in place of the solution (the band
        // has just read it: written into a field of its own, every line of it missed);
        // each face's cells with face 0's inverse areas (the same on every face).
        let (gamma, n) = (&self.gamma[..], sides.n());
        // The change recorded only where the next solve takes it as its guess.
        let record = self.guess_wait == 0;
        let change = &mut self.surfactant_change;
        // Every entry is written below: the buffer needs its length, not a fill.
        change.resize(gamma.len(), 0.0);
        let per_area = &fg.inverse_area_per_sr[..];
        let mut negative = false;
        let pass = (&mut correction, gamma);
        net_inflow(sides, pass, &mut s.gather, |pass, face, rows, inflow| {
            let cells = face * n * n + rows.start * n..face * n * n + rows.end * n;
            let per_area = &per_area[rows.start * n..rows.end * n];
            let before = (&gamma[cells.clone()], inflow);
            let change = record.then(|| &mut change[cells.clone()]);
            let after = (&mut pass.solution[cells], change);
            negative |= next_surfactant(before, per_area, after);
        });
        if !negative {
            std::mem::swap(&mut self.gamma, &mut s.cell2);
            return;
        }
        // A violent step (a film torn near zero thickness, where the waves run at
        // hundreds of m/s) overshot: redo it with every flux upwind and each donor
        // limited, which keeps Γ positive and still conserves it. (The starting
        // velocity's transport is done: this moves Γ with the step's change only.)
        let change = &mut s.edge;
        change.clear();
        change.extend(self.u_m_per_s.iter().zip(&s.u_start).map(|(u, u0)| u - u0));
        let mut fluxes = UpwindFluxes::new(fg, change, &mut s.seam_ends);
        let (gamma, gather) = (&mut self.gamma, &mut s.gather);
        apply_limited(sides, &g, &mut fluxes, scale, gamma, gather);
    }
}

/// [`FilmFlow::fluxes_weights_and_right_hand_side`]'s edge pass ([`EdgeValues`]: the
/// central fluxes, from the surfactant at the edges' ends), with the stiffnesses and
/// weights (and, with the normal gradient, the cross term and the fluxes kept whole).
struct CentralFluxes<'a, const NORMAL: bool> {
    /// What it reads and writes per edge.
    edges: CentralEdges<'a, NORMAL>,
    /// The thickness per cell, m.
    h: &'a [f64],
    /// The seams' ends.
    seam_ends: &'a mut SeamEnds,
}

/// [`CentralFluxes`]' per-edge inputs and outputs.
struct CentralEdges<'a, const NORMAL: bool> {
    /// The grid (its constants, and its edges' vertices for the cross term).
    grid: &'a CubeSphere,
    /// The velocity after the explicit forces, m/s: dragged here where the drag was
    /// left to this pass ([`Drag::Deferred`]).
    u: &'a mut [f64],
    /// The step's starting velocity, m/s.
    u0: &'a [f64],
    /// Where each edge's drag comes from, and the factors where they are kept
    /// ([`FilmFlow::air_shear`]).
    drag: (Drag, &'a [f64]),
    /// The surfactant at the vertices (the cross term's, with the normal gradient).
    vertex: &'a [f64],
    /// The pass's constants.
    c: EdgeConstants,
    /// Each edge's stiffness `k`, out.
    stiffness: &'a mut [f64],
    /// Each edge's weight in the system, rounded to `f32`, out.
    weight: &'a mut [f32],
    /// The cross term's velocity, out (with the normal gradient).
    cross: &'a mut [f64],
    /// The fluxes kept whole, out (with the normal gradient).
    flux: &'a mut [f64],
}

impl<const NORMAL: bool> EdgeValues for CentralFluxes<'_, NORMAL> {
    #[inline(always)]
    fn seams(&mut self, seams: Seams, gamma: &[f64], out: &mut [f64]) {
        let [[ga, gb], [ha, hb]] = self.seam_ends.gather_many(seams, [gamma, self.h]);
        self.edges.block(seams, [ga, gb, ha, hb], out);
    }

    #[inline(always)]
    fn run(&mut self, run: EdgeRun, _rows: Range<usize>, gamma: &[f64], out: &mut [f64]) {
        // With the two-point gradient an x-run runs padded ([`EdgeRun::padded`]), the
        // extra edge's velocity and weight, which it writes, put back after: they are
        // the next x-edge's, taken by its own run (the cross term's arrays are more).
        let padded = run.padded(if NORMAL { 0 } else { out.len() }, gamma.len());
        let ((ga, gb), (ha, hb)) = (padded.ends(gamma), padded.ends(self.h));
        let extra = padded.first() + run.len;
        let kept = (padded.len > run.len).then(|| (self.edges.u[extra], self.edges.weight[extra]));
        self.edges.block(padded, [ga, gb, ha, hb], out);
        if let Some(kept) = kept {
            (self.edges.u[extra], self.edges.weight[extra]) = kept;
        }
    }
}

impl<const NORMAL: bool> CentralEdges<'_, NORMAL> {
    /// The pass over a block of edges, with the surfactant and thickness at their ends:
    /// the fluxes (per R) into `flux`. A loop for each source of the drag
    /// ([`Drag`]), so that each vectorises.
    #[inline(always)]
    fn block(&mut self, run: impl EdgeBlock, ends: [&[f64]; 4], flux: &mut [f64]) {
        let len = run.count();
        match self.drag {
            (Drag::None, _) => self.block_with::<false>(run, ends, flux, |_, u, _| (u, 1.0)),
            (Drag::Stored, factors) => {
                let factors = &run.values(factors)[..len];
                self.block_with::<false>(run, ends, flux, |i, u, _| (u, factors[i]));
            }
            (Drag::Deferred(shear), _) if shear.still() => {
                self.block_with::<true>(run, ends, flux, |_, u, h| shear.drag_in_still_air(u, h));
            }
            (Drag::Deferred(shear), _) => {
                let along = shear.along(self.grid.face_geometry(), &run);
                self.block_with::<true>(run, ends, flux, |i, u, h| along.drag(i, u, h));
            }
        }
    }

    /// [`Self::block`] with each edge's velocity dragged and its factor by `drag(i, u,
    /// h)` (the edge, its velocity and its floored thickness), the dragged velocities
    /// written back where `DRAGGED`.
    #[inline(always)]
    fn block_with<const DRAGGED: bool>(
        &mut self,
        run: impl EdgeBlock,
        [ga, gb, ha, hb]: [&[f64]; 4],
        flux: &mut [f64],
        drag: impl Fn(usize, f64, f64) -> (f64, f64),
    ) {
        let (ea, fg, c) = (self.grid.edge_arrays(), self.grid.face_geometry(), self.c);
        let len = run.count();
        let (ga, gb, ha, hb) = (&ga[..len], &gb[..len], &ha[..len], &hb[..len]);
        let l = run.constant(&fg.length);
        let inverse_dual = if NORMAL {
            &fg.inverse_normal_dual_length
        } else {
            &fg.inverse_dual_length
        };
        let id = run.constant(inverse_dual);
        let (u0, l, id) = (&run.values(self.u0)[..len], &l[..len], &id[..len]);
        let flux = &mut flux[..len];
        let u = &mut run.values_mut(self.u)[..len];
        let weight = run.values_mut(self.weight);
        // The cross term's arrays and the stiffnesses along the block (empty with the
        // two-point gradient).
        let (vertices, cross_per_length, cross, stiffness) = if NORMAL {
            let edges = run.first()..run.first() + len;
            let cross = &mut self.cross[edges.clone()];
            let stiffness = &mut self.stiffness[edges.clone()];
            (
                &ea.vertices[edges.clone()],
                &ea.cross_per_length[edges],
                cross,
                stiffness,
            )
        } else {
            (&[][..], &[][..], &mut [][..], &mut [][..])
        };
        for i in 0..len {
            let gamma_c = 0.5 * (ga[i] + gb[i]);
            let h_edge = larger(0.5 * (ha[i] + hb[i]), H_FLOOR_M);
            let (u_dragged, factor) = drag(i, u[i], h_edge);
            if DRAGGED {
                u[i] = u_dragged;
            }
            let k = c.dt_e_per_rho / h_edge * factor;
            let u = if NORMAL {
                let [v0, v1] = vertices[i];
                let along = self.vertex[v1 as usize] - self.vertex[v0 as usize];
                let du = k * cross_per_length[i] * along * c.per_r;
                cross[i] = du / gamma_c.max(f64::MIN_POSITIVE);
                u_dragged + cross[i]
            } else {
                u_dragged
            };
            flux[i] = gamma_c * (u - u0[i]) * l[i];
            if NORMAL {
                stiffness[i] = k;
            }
            weight[i] = (c.dt_per_r2 * k * l[i] * id[i]) as f32;
        }
        if NORMAL {
            run.values_mut(self.flux).copy_from_slice(flux);
        }
    }
}

/// [`FilmFlow::correct_velocity_and_move_surfactant`]'s edge pass ([`EdgeValues`]: the
/// volume of surfactant the transport flux and the correction move, from the surfactant
/// at the edges' ends), with the velocity correction.
struct Correction<'a, const NORMAL: bool> {
    /// What it reads and writes per edge.
    edges: CorrectionEdges<'a, NORMAL>,
    /// The surfactant the step ends with (the solve's solution), which the gather
    /// replaces, a stretch of rows at a time once the pass has read them, by the
    /// surfactant after the step.
    solution: &'a mut [f64],
    /// The seams' ends.
    seam_ends: &'a mut SeamEnds,
}

/// [`Correction`]'s per-edge inputs and outputs.
struct CorrectionEdges<'a, const NORMAL: bool> {
    /// The edges' lengths, rad.
    length: &'a EdgeConstant,
    /// The step's starting velocity (the transport flux's, again), m/s.
    u0: &'a [f64],
    /// The transport flux kept whole (with the normal gradient only).
    flux: &'a [f64],
    /// Each edge's weight in the system, `w = dt·k·l/(d·R²)` rounded to `f32` (`d cos θ`
    /// for `d` with the normal gradient): the correction's `k/(d·R)` as `w/(l·dt/R)`.
    weight: &'a [f32],
    /// The cross term's velocity (with the normal gradient only).
    cross: &'a [f64],
    /// The velocity, corrected in place, m/s.
    u: &'a mut [f64],
    /// The step over R, s/m.
    scale: f64,
}

impl<const NORMAL: bool> EdgeValues for Correction<'_, NORMAL> {
    #[inline(always)]
    fn seams(&mut self, seams: Seams, gamma: &[f64], out: &mut [f64]) {
        let [[ga, gb], [xa, xb]] = self.seam_ends.gather_many(seams, [gamma, &*self.solution]);
        self.edges.block(seams, [ga, gb, xa, xb], out);
    }

    #[inline(always)]
    fn run(&mut self, run: EdgeRun, _rows: Range<usize>, gamma: &[f64], out: &mut [f64]) {
        // An x-run runs padded ([`EdgeRun::padded`]), the extra edge's velocity, which
        // it corrects in place, put back after: it is the next x-edge's, corrected by its
        // own run.
        let padded = run.padded(out.len(), gamma.len());
        let ((ga, gb), (xa, xb)) = (padded.ends(gamma), padded.ends(&*self.solution));
        let extra = padded.first() + run.len;
        let kept = (padded.len > run.len).then(|| self.edges.u[extra]);
        self.edges.block(padded, [ga, gb, xa, xb], out);
        if let Some(kept) = kept {
            self.edges.u[extra] = kept;
        }
    }
}

impl<const NORMAL: bool> CorrectionEdges<'_, NORMAL> {
    /// The pass over a block of edges, with the surfactant before (`g`) and after (`x`)
    /// at their ends: the velocity corrected, and the volume of surfactant it and the
    /// transport flux move into `moved`.
    ///
    /// The two-point gradient's transport flux is taken again as the central pass took
    /// it, from the velocity before the correction (the same bits): kept whole, it was a
    /// per-edge array written and read back (0.4 MB at n = 64).
    #[inline(always)]
    fn block(&mut self, run: impl EdgeBlock, [ga, gb, xa, xb]: [&[f64]; 4], moved: &mut [f64]) {
        let len = run.count();
        let (ga, gb, xa, xb) = (&ga[..len], &gb[..len], &xa[..len], &xb[..len]);
        let l = &run.constant(self.length)[..len];
        let (u0, w) = (&run.values(self.u0)[..len], &run.values(self.weight)[..len]);
        let (u, moved) = (&mut run.values_mut(self.u)[..len], &mut moved[..len]);
        let scale = self.scale;
        // The kept fluxes and cross term along the block with the normal gradient.
        let (flux, cross) = if NORMAL {
            (run.values(self.flux), run.values(self.cross))
        } else {
            (&[][..], &[][..])
        };
        for i in 0..len {
            let gamma_c = 0.5 * (ga[i] + gb[i]);
            let f_adv = if NORMAL {
                flux[i]
            } else {
                gamma_c * (u[i] - u0[i]) * l[i]
            };
            let gamma_c_floored = larger(gamma_c, f64::MIN_POSITIVE);
            // `k/(d R)` (`d cos θ` for `d` with the normal gradient) is `w/(l dt/R)`:
            // from the very weights the system was solved with (rounded to `f32`), the
            // surfactant this moves is the solve's answer but for its residual.
            let du = -f64::from(w[i]) * (xb[i] - xa[i]) / (scale * l[i] * gamma_c_floored);
            u[i] += if NORMAL { du + cross[i] } else { du };
            moved[i] = scale * (f_adv + gamma_c * du * l[i]);
        }
    }
}

/// A stretch of cells' surfactant after the step, `Γ + inflow/area` (`per_area` the
/// cells' inverse areas), into `next`, which holds the solve's solution before, and,
/// where `change` is given, the step's change of the solve, `solution − Γ` (the next
/// step's first guess), while the stretch is in cache; returns whether any cell went
/// negative.
#[inline(always)]
fn next_surfactant(
    (gamma, inflow): (&[f64], &[f64]),
    per_area: &[f64],
    (next, change): (&mut [f64], Option<&mut [f64]>),
) -> bool {
    let m = next.len();
    let (gamma, inflow, per_area) = (&gamma[..m], &inflow[..m], &per_area[..m]);
    if let Some(change) = change {
        let change = &mut change[..m];
        for i in 0..m {
            change[i] = next[i] - gamma[i];
        }
    }
    let mut negative = false;
    for i in 0..m {
        next[i] = gamma[i] + inflow[i] * per_area[i];
        negative |= next[i] < 0.0;
    }
    negative
}

/// The constants of the Marangoni step's edge pass.
#[derive(Clone, Copy)]
struct EdgeConstants {
    /// `dt·E_f/ρ`, m³/s·… : over an edge's thickness, its stiffness `k`.
    dt_e_per_rho: f64,
    /// The step over R², s/m².
    dt_per_r2: f64,
    /// 1/R, per m.
    per_r: f64,
}

/// The upwind volume `Γ_up·u·l` (per R and time) across every edge at speeds `u`, from
/// the surfactant the limited apply moves ([`EdgeValues`]).
struct UpwindFluxes<'a> {
    /// The grid's constants.
    fg: &'a FaceGeometry,
    /// The speeds, m/s.
    u: &'a [f64],
    /// The seams' ends.
    seam_ends: &'a mut SeamEnds,
}

impl<'a> UpwindFluxes<'a> {
    /// The fluxes at speeds `u`.
    fn new(fg: &'a FaceGeometry, u: &'a [f64], seam_ends: &'a mut SeamEnds) -> Self {
        Self { fg, u, seam_ends }
    }
}

impl EdgeValues for UpwindFluxes<'_> {
    #[inline(always)]
    fn seams(&mut self, seams: Seams, gamma: &[f64], out: &mut [f64]) {
        let ends = self.seam_ends.gather(seams, gamma);
        upwind_fluxes_block(seams, ends, (self.fg, self.u), out);
    }

    #[inline(always)]
    fn run(&mut self, run: EdgeRun, _rows: Range<usize>, gamma: &[f64], out: &mut [f64]) {
        let run = run.padded(out.len(), gamma.len());
        let (ga, gb) = run.ends(gamma);
        upwind_fluxes_block(run, [ga, gb], (self.fg, self.u), out);
    }
}

/// [`UpwindFluxes`] over a block of edges, with the surfactant `[ga, gb]` at their ends,
/// into `out`.
#[inline(always)]
fn upwind_fluxes_block(
    run: impl EdgeBlock,
    [ga, gb]: [&[f64]; 2],
    (fg, u): (&FaceGeometry, &[f64]),
    out: &mut [f64],
) {
    let len = run.count();
    let (u, l, f) = (run.values(u), run.constant(&fg.length), &mut out[..len]);
    let (ga, gb) = (&ga[..len], &gb[..len]);
    for i in 0..len {
        f[i] = pick(u[i] >= 0.0, ga[i], gb[i]) * u[i] * l[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DVec3;
    use crate::film_flow::flow::{FlowParams, Forcing, test_film};

    /// The most a number's rounding to `f32` moves it, relative to itself (half an `f32`
    /// unit in the last place).
    const F32_ROUNDING: f64 = f32::EPSILON as f64 / 2.0;

    /// A draining film turning in a wind ([`test_film`]), a few steps in.
    fn film() -> FilmFlow {
        let mut f = test_film(FlowParams {
            drainage_viscosity_pa_s: 1e-6,
            ..FlowParams::water_film(0.05)
        });
        f.set_velocity(|d| DVec3::Y.cross(d) * 0.05);
        f.set_surfactant(|d| 1.0 + 0.1 * d.z);
        let forcing = Forcing {
            g_eff_m_per_s2: DVec3::new(0.0, -9.81, 0.0),
            air_m_per_s: DVec3::new(0.3, 0.0, 0.1),
        };
        for _ in 0..3 {
            f.step(1.0 / 60.0, &forcing);
        }
        f
    }

    /// A guess that does not beat its start rests the guess for [`GUESS_REST`] solves, and
    /// the change is recorded again in time for the solve that offers it next: a wild
    /// change put in its place is gone by then. Where the guess pays (on this film, at
    /// n = 12, in some steps), it is taken.
    #[test]
    fn a_guess_that_does_not_pay_rests_and_comes_back_recorded_anew() {
        let forcing = Forcing {
            g_eff_m_per_s2: DVec3::new(0.0, -9.81, 0.0),
            air_m_per_s: DVec3::new(0.3, 0.0, 0.1),
        };
        let mut f = film();
        let paid = (0..30).any(|_| f.step(1.0 / 60.0, &forcing).from_guess);
        assert!(paid, "the guess never paid");
        assert_eq!(f.guess_wait, 0);
        f.surfactant_change.iter_mut().for_each(|c| *c = 1e3);
        assert!(!f.step(1.0 / 60.0, &forcing).from_guess);
        for wait in (0..GUESS_REST).rev() {
            assert_eq!(f.guess_wait, wait + 1);
            assert!(!f.step(1.0 / 60.0, &forcing).from_guess, "rested");
        }
        assert_eq!(f.guess_wait, 0);
        let largest = f
            .surfactant_change
            .iter()
            .fold(0.0f64, |m, c| m.max(c.abs()));
        assert!(
            largest < 1.0,
            "a stale change of {largest} would be offered"
        );
        assert!(
            f.step(1.0 / 60.0, &forcing).from_guess,
            "the guess pays again"
        );
    }

    /// The central pass's weights against the plain `dt² E l/(ρ h d R²)` times the drag's
    /// factor, to their rounding to `f32` (face 0's constants), and the velocities untouched with the
    /// factors kept: on a grid of three bands, whose x-runs run padded, each row's extra
    /// edge put back (a face's last row's is the next face's first x-edge, whose band
    /// came before).
    #[test]
    fn the_central_weights_are_the_plain_ones_on_every_edge() {
        let dt_s = 1.0 / 60.0;
        let n = 2 * crate::film_flow::fluxes::BAND + 3;
        let grid = std::sync::Arc::new(CubeSphere::new(n));
        let hierarchy = std::sync::Arc::new(crate::film_flow::Hierarchy::new(&grid));
        let params = FlowParams::water_film(0.05);
        let mut f = FilmFlow::new(grid, hierarchy, params, |d| {
            20e-6 * (1.0 + 0.3 * (4.0 * d.x + d.y).sin())
        });
        f.set_velocity(|d| DVec3::Y.cross(d) * 0.05);
        f.set_surfactant(|d| 1.0 + 0.1 * d.z);
        let mut s = Scratch::default();
        s.u_start.clone_from(&f.u_m_per_s);
        let edges = f.u_m_per_s.len();
        s.drag = (0..edges)
            .map(|e| 1.0 / (1.0 + 0.1 * (e % 7) as f64))
            .collect();
        s.drag_by = Drag::Stored;
        let u_before = f.u_m_per_s.clone();
        f.fluxes_weights_and_right_hand_side::<false>(&mut s, dt_s);
        assert_eq!(f.u_m_per_s, u_before, "velocities written");
        let (p, ea, h) = (f.params, f.grid.edge_arrays(), &f.h_m);
        let per_r2 = 1.0 / (p.radius_m * p.radius_m);
        for (e, &[a, b]) in ea.cells.iter().enumerate() {
            let h_edge = (0.5 * (h[a as usize] + h[b as usize])).max(H_FLOOR_M);
            let k = dt_s * p.elasticity_n_per_m / p.density_kg_per_m3 / h_edge * s.drag[e];
            let plain = dt_s * per_r2 * k * ea.length[e] * ea.inverse_dual_length[e];
            let off = (f64::from(s.weight[e]) - plain).abs();
            assert!(
                off <= (F32_ROUNDING + 1e-12) * plain,
                "edge {e}: {} against {plain}",
                s.weight[e]
            );
        }
    }

    /// The two-point gradient's velocity correction, taken from the system's weights,
    /// is the plain `−k (Γ'_b − Γ'_a)/(d R Γ_c)` with `k = dt E/(ρ h)` times the drag's
    /// factor, to the weights' rounding to `f32`, and the surfactant moves with the plain
    /// fluxes `dt/R (Γ_c (u − u₀) l + Γ_c Δu l)`, to that rounding of `Δu`.
    #[test]
    fn the_two_point_correction_from_the_weights_is_the_plain_one() {
        let dt_s = 1.0 / 60.0;
        let mut f = film();
        let mut s = Scratch::default();
        // The step's start, and the velocity after some explicit forces, the drag's
        // factors kept per edge.
        s.u_start.clone_from(&f.u_m_per_s);
        let edges = f.u_m_per_s.len();
        for (e, u) in f.u_m_per_s.iter_mut().enumerate() {
            *u = 1.1 * *u + 1e-3 * ((e % 5) as f64 - 2.0);
        }
        s.drag = (0..edges)
            .map(|e| 1.0 / (1.0 + 0.1 * (e % 7) as f64))
            .collect();
        s.drag_by = Drag::Stored;
        f.fluxes_weights_and_right_hand_side::<false>(&mut s, dt_s);
        f.solve_surfactant(&mut s);
        let (u_before, gamma_before) = (f.u_m_per_s.clone(), f.gamma.clone());
        // The solution, which the correction replaces by the surfactant after the step.
        let solution = s.cell2.clone();
        // The next solve offers the guess, so the change is recorded ([`GUESS_REST`]).
        f.guess_wait = 0;
        f.correct_velocity_and_move_surfactant::<false>(&mut s, dt_s);

        let (p, g) = (f.params, std::sync::Arc::clone(&f.grid));
        let (ea, r) = (g.edge_arrays(), p.radius_m);
        let (x, h) = (&solution, &f.h_m);
        let mut du_plain = vec![0.0; edges];
        let mut inflow = vec![0.0; gamma_before.len()];
        // Per cell, how far the weights' rounding may move its inflow.
        let mut slack = vec![0.0; gamma_before.len()];
        for (e, &[a, b]) in ea.cells.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let h_edge = (0.5 * (h[a] + h[b])).max(H_FLOOR_M);
            let k = dt_s * p.elasticity_n_per_m / p.density_kg_per_m3 / h_edge * s.drag[e];
            let gamma_c = 0.5 * (gamma_before[a] + gamma_before[b]);
            du_plain[e] = -k * (x[b] - x[a]) * ea.inverse_dual_length[e] / r / gamma_c;
            let moved =
                dt_s / r * gamma_c * ((u_before[e] - s.u_start[e]) + du_plain[e]) * ea.length[e];
            inflow[a] -= moved;
            inflow[b] += moved;
            let rounding = F32_ROUNDING * (dt_s / r * gamma_c * du_plain[e] * ea.length[e]).abs();
            slack[a] += rounding;
            slack[b] += rounding;
        }
        let largest = du_plain.iter().fold(0.0, |m: f64, d| m.max(d.abs()));
        assert!(largest > 1e-6, "no correction to compare: {largest}");
        for e in 0..edges {
            let du = f.u_m_per_s[e] - u_before[e];
            let off = (du - du_plain[e]).abs();
            assert!(
                off <= F32_ROUNDING * du_plain[e].abs() + 1e-12 * largest,
                "edge {e}: {du} against {}",
                du_plain[e]
            );
        }
        let areas = g.areas_sr();
        for (c, moved) in inflow.iter().enumerate() {
            let plain = gamma_before[c] + moved / areas[c];
            let off = (f.gamma[c] - plain).abs();
            assert!(
                off <= slack[c] / areas[c] + 1e-12 * plain.abs(),
                "cell {c}: {} against {plain}",
                f.gamma[c]
            );
        }
        // The step's change of the solve, taken from the solution before the surfactant
        // after the step replaced it: the same bits as the plain difference.
        let change: Vec<u64> = (solution.iter().zip(&gamma_before))
            .map(|(x, g)| (x - g).to_bits())
            .collect();
        let got: Vec<u64> = f.surfactant_change.iter().map(|d| d.to_bits()).collect();
        assert_eq!(got, change, "the solve's change");
    }
}

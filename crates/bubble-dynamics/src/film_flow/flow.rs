//! The film's state on the cube-sphere and one time step of its flow.
//!
//! Per cell: thickness `h` and surfactant concentration `Γ` (relative to the rest
//! value). Per edge: the surfaces' velocity `u` normal to the edge (the liquid moves with
//! the surfaces as a plug, plus the Poiseuille drainage flux relative to them).
//!
//! Momentum, per unit film mass: gravity `g_t`, the Marangoni stress `∇T/(ρh)` with the
//! film tension `T = T₀ − E_f ln Γ` (insoluble surfactant, constant Gibbs elasticity
//! `E_f = dT/d ln A`), the thin viscous sheet's stress `ν(−∇×∇×u + 2Ku + 4∇∇·u)`, and the
//! air's shear. The Marangoni term is the stiff one (waves at `√(E_f/(ρh))`, 10 m/s on a
//! 500 nm film): it is taken backward-Euler, which leaves one linear system per step (see
//! `solve`, `marangoni`), and is then stable for any step. Viscosity is explicit, in the
//! stages of one Runge–Kutta–Legendre step under its bound (`viscosity`); transport is
//! upwind under a Courant bound of 1/2 an edge (`transport`).

use glam::DVec3;

use super::advect::{AdvectionGeometry, AdvectionScratch, advect_momentum};
use super::burst::{BurstParams, BurstState, Hole};
use super::capillary::{
    Capillary, CapillaryScratch, Mobility, Shared, one_substep, smooth_thickness,
};
use super::compare::larger;
use super::face_geometry::{EdgeVector, FaceGeometry};
use super::face_rows::FaceRows;
use super::fluxes::GatherScratch;
use super::grid::{CubeSphere, dot_at};
use super::meniscus::MeniscusState;
use super::sides::{CellSides, EdgeBlock, SeamEnds};
use super::solve::{Hierarchy, SolveReport, Work};
use super::thermal::{ThermalParams, up_from};
use super::transport::Joined;
use super::upwind::{Rises, UpwindGeometry};
use super::viscosity::{ViscousScratch, viscous_bound};
use crate::avx2::with_avx2;

/// Thickness floor of the Marangoni coefficient `E_f/(ρh)`, m: a hole or a Newton black
/// film keeps a finite (if huge) stiffness.
pub(super) const H_FLOOR_M: f64 = 1e-9;
/// Largest fraction of a cell's content that may leave it in one transport sub-step.
pub(super) const MAX_OUTFLOW_FRACTION: f64 = 0.5;
/// Residual of the Marangoni solve relative to its warm start's (the previous step's
/// surfactant): the step's change to 6 digits. The velocity takes the gradient of this
/// solution, so an inexact one is an inexact backward-Euler step: at 1e-4 the swirl film
/// at n = 64 blew up within 20 steps (`film_profile 64 0 9.81`), at 1e-6 it holds.
pub(super) const SOLVE_TOLERANCE: f64 = 1e-6;
/// Marangoni solves that go without the guess after one whose guess did not beat its
/// start. Why: where the film's change does not persist from step to step the guess
/// only costs its residual's pass and the change's record (on the bench's swirl film at
/// n = 32 its residual was 0.38× the start's in the median step, at n = 16 0.29×; at
/// n = 64 and 128 1.6× while the solve took its start's residual with the weights
/// rounded to `f32`, whose error made each step's change alternate). Since, over
/// `film_profile 64 0 9.81`'s 40 steps, 15 solves start from the guess; offering it to
/// every solve took 134 iterations against 138, but 622.7 M instructions against
/// 620.7 M and 13.15 M LL misses against 12.74 M (at n = 32, 175.4 M against 175.1 M).
pub(super) const GUESS_REST: u32 = 7;
/// Iteration cap of the Marangoni solve (it takes 3–8).
pub(super) const SOLVE_MAX_ITERATIONS: u32 = 40;

/// Which discrete gradient drives the film (the Marangoni, gravity and thermal stresses).
///
/// The trade-off: [`FilmGradient::TwoPoint`] keeps one symmetric solve a step but holds the
/// Marangoni wave-speed error near 2.7 % at any grid (4.16/3.03/2.77/2.71 % at n =
/// 8/16/32/64); [`FilmGradient::Normal`] makes it fall at second order (1.73/0.44/0.12/
/// 0.037 %) at 4.9× the instructions a step (95.3 M against 19.4 M at n = 64, 14.8 PCG
/// iterations a step against 4.4, on 2026-11-29: its defect correction's passes were
/// not sped up with the rest), on a step already over its real-time budget
/// (docs/dynamics.md, "Film flow").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FilmGradient {
    /// The difference across an edge over the centre distance (along the line of
    /// centres, up to 30° off the normal near the cube's corners): one symmetric solve a
    /// step, the real-time default.
    #[default]
    TwoPoint,
    /// Along the edge's normal, the cross term along the edge by defect correction
    /// around the symmetric solve: second-order wave speed at about 4.9× the step's
    /// instructions.
    Normal,
}

/// The physical constants of one bubble's film.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlowParams {
    /// Radius of the material sphere the grid lies on, m.
    pub radius_m: f64,
    /// Density of the film liquid, kg/m³.
    pub density_kg_per_m3: f64,
    /// Gibbs elasticity of the film, `E_f = dT/d ln A` (twice one surface's), N/m.
    pub elasticity_n_per_m: f64,
    /// Viscosity of the film liquid, Pa·s: the sheet's 2D shear viscosity is `μh`.
    pub viscosity_pa_s: f64,
    /// Effective viscosity of the Poiseuille drainage flux `ρ g_t h³/(3μ)`, Pa·s
    /// (infinite: no drainage).
    pub drainage_viscosity_pa_s: f64,
    /// Evaporative thinning, nm/s.
    pub evaporation_nm_per_s: f64,
    /// Viscosity of the outside air, Pa·s.
    pub air_viscosity_pa_s: f64,
    /// Density of the outside air, kg/m³.
    pub air_density_kg_per_m3: f64,
    /// Black film and rupture.
    pub burst: BurstParams,
    /// The film's temperature: the warming it sees and how it answers.
    pub thermal: ThermalParams,
    /// Seed of the spontaneous rupture.
    pub seed: u64,
    /// The discrete gradient that drives the film.
    pub gradient: FilmGradient,
}

impl FlowParams {
    /// A water-like film on a sphere of `radius_m`: ρ 1000 kg/m³, E_f 0.05 N/m, μ 1 mPa·s,
    /// no drainage or evaporation, still air (μ 18 µPa·s, 1.2 kg/m³), σ 0.025 N/m, black
    /// below 30 nm at 12 nm, rupture under 5 nm, no spontaneous holes, the two-point
    /// gradient.
    pub fn water_film(radius_m: f64) -> Self {
        Self {
            radius_m,
            density_kg_per_m3: 1000.0,
            elasticity_n_per_m: 0.05,
            viscosity_pa_s: 1e-3,
            drainage_viscosity_pa_s: f64::INFINITY,
            evaporation_nm_per_s: 0.0,
            air_viscosity_pa_s: 1.8e-5,
            air_density_kg_per_m3: 1.2,
            burst: BurstParams {
                sigma_n_per_m: 0.025,
                black_threshold_nm: 30.0,
                black_film_nm: 12.0,
                rupture_thickness_nm: 5.0,
                nucleation_per_m2_s: 0.0,
            },
            thermal: ThermalParams::isothermal(),
            seed: 0,
            gradient: FilmGradient::TwoPoint,
        }
    }
}

/// What drives the film during one step, in the film's material frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Forcing {
    /// Gravity minus the bubble's acceleration, m/s².
    pub g_eff_m_per_s2: DVec3,
    /// The air's velocity far from the bubble relative to the bubble, m/s.
    pub air_m_per_s: DVec3,
}

/// The film's flow state on a cube-sphere.
#[derive(Clone, Debug)]
pub struct FilmFlow {
    pub(crate) grid: std::sync::Arc<CubeSphere>,
    pub(super) hierarchy: std::sync::Arc<Hierarchy>,
    /// The grid's edges and vertices face by face in rows, for the momentum passes.
    pub(super) rows: std::sync::Arc<FaceRows>,
    /// The momentum advection's weights, fixed by the grid.
    advection: std::sync::Arc<AdvectionGeometry>,
    /// Each cell's sides in its face, for the passes laid out by faces.
    pub(super) sides: std::sync::Arc<CellSides>,
    /// The thickness transport's weights, fixed by the grid.
    pub(super) transport: std::sync::Arc<UpwindGeometry>,
    pub(crate) params: FlowParams,
    pub(super) burst: Option<Box<BurstState>>,
    /// The meniscus of a film standing on a wet surface.
    pub(super) meniscus: Option<Box<MeniscusState>>,
    /// The viscous operator's Gershgorin bound per unit ν/R², fixed by the grid.
    pub(super) viscous_bound: f64,
    pub(crate) h_m: Vec<f64>,
    pub(crate) gamma: Vec<f64>,
    pub(crate) u_m_per_s: Vec<f64>,
    /// The film's temperature excess over the ambient per cell, K (empty when isothermal).
    pub(super) temperature_k: Vec<f64>,
    /// The last Marangoni solve's change of Γ (empty before the first; stale where the
    /// solve did not record it, [`FilmFlow::guess_wait`]): the next solve's first guess.
    pub(super) surfactant_change: Vec<f64>,
    /// How many coming Marangoni solves go without the guess (the last change added
    /// to the start): set to [`GUESS_REST`] when a solve's guess did not beat its
    /// start. Part of the film's state, so a copy steps on as the original does.
    pub(super) guess_wait: u32,
    /// The sub-steps the last thickness transport took: the next one's first guess
    /// (`FilmFlow::take_last_count`).
    pub(super) transport_substeps: u32,
    scratch: Scratch,
}

/// Buffers a step reuses from step to step (no allocation once the first has run).
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    pub(super) work: Work,
    pub(super) edge: Vec<f64>,
    pub(super) edge2: Vec<f64>,
    pub(super) cell: Vec<f64>,
    pub(super) cell2: Vec<f64>,
    pub(super) vertex: Vec<f64>,
    /// The Marangoni system's edge weights, rounded to `f32` where they are made.
    pub(super) weight: Vec<f32>,
    pub(super) u_start: Vec<f64>,
    pub(super) stiffness: Vec<f64>,
    /// The thickness transport's limited rises ([`Rises`]).
    pub(super) rises: Rises,
    /// Per edge: the air's drag factor, where [`FilmFlow::air_shear`] took the drag
    /// ([`Drag::Stored`]).
    pub(super) drag: Vec<f64>,
    /// Where the Marangoni step takes the drag from ([`Drag`]).
    pub(super) drag_by: Drag,
    /// Tests: take the drag in [`FilmFlow::air_shear`] even without a meniscus.
    #[cfg(test)]
    drag_here: bool,
    /// The edge velocities in the face rows during the explicit momentum step, m/s.
    rows_u: Vec<f64>,
    /// The viscous step's buffers.
    viscous: ViscousScratch,
    /// Per edge: the Marangoni gradient's cross term (along the edge) as a velocity
    /// change, m/s, from the surfactant of the last sweep.
    pub(super) cross: Vec<f64>,
    /// The Marangoni system's right-hand side, then the surfactant the step ends with.
    pub(super) rhs: Vec<f64>,
    advect: AdvectionScratch,
    capillary: CapillaryScratch,
    /// The cell-by-cell gathers' buffers ([`GatherScratch`]).
    pub(super) gather: GatherScratch,
    /// The seam edges' end values for the edge passes ([`SeamEnds`]).
    pub(super) seam_ends: SeamEnds,
    /// Per cell: the velocity on its left x-edge (the temperature's transport,
    /// [`super::fluxes::spread_x_volumes`]).
    pub(super) spread: Vec<f64>,
}

impl FilmFlow {
    /// A film at rest with thickness `h_m(centre direction)` and uniform surfactant.
    ///
    /// # Panics
    /// If `grid` and `hierarchy` differ in size.
    pub fn new(
        grid: std::sync::Arc<CubeSphere>,
        hierarchy: std::sync::Arc<Hierarchy>,
        params: FlowParams,
        h_m: impl Fn(DVec3) -> f64,
    ) -> Self {
        let h: Vec<f64> = grid.centres().iter().map(|&c| h_m(c)).collect();
        let cells = grid.cells();
        let edges = grid.edges().len();
        let rows = FaceRows::new(&grid);
        let sides = CellSides::new(&grid);
        Self {
            burst: Some(Box::new(BurstState::new(params.burst, cells, params.seed))),
            meniscus: None,
            viscous_bound: viscous_bound(&grid),
            advection: std::sync::Arc::new(AdvectionGeometry::new(&grid, &rows)),
            rows: std::sync::Arc::new(rows),
            transport: std::sync::Arc::new(UpwindGeometry::new(&grid, &sides)),
            sides: std::sync::Arc::new(sides),
            params,
            h_m: h,
            gamma: vec![1.0; cells],
            u_m_per_s: vec![0.0; edges],
            temperature_k: if params.thermal.is_active() {
                vec![0.0; cells]
            } else {
                Vec::new()
            },
            surfactant_change: Vec::new(),
            guess_wait: 0,
            transport_substeps: 1,
            hierarchy,
            grid,
            scratch: Scratch::default(),
        }
    }

    /// The grid.
    pub fn grid(&self) -> &CubeSphere {
        &self.grid
    }

    /// The constants.
    pub fn params(&self) -> &FlowParams {
        &self.params
    }

    /// Thickness of each cell, m.
    pub fn thickness_m(&self) -> &[f64] {
        &self.h_m
    }

    /// Surfactant concentration of each cell, relative to the rest value.
    pub fn surfactant(&self) -> &[f64] {
        &self.gamma
    }

    /// The film's temperature excess over the ambient per cell, K (empty: isothermal).
    pub fn temperature_excess_k(&self) -> &[f64] {
        &self.temperature_k
    }

    /// Surface velocity normal to each edge (along the edge's normal), m/s.
    pub fn edge_velocity_m_per_s(&self) -> &[f64] {
        &self.u_m_per_s
    }

    /// Sets the edge velocities from a tangential velocity field `u(direction)`, m/s.
    pub fn set_velocity(&mut self, u: impl Fn(DVec3) -> DVec3) {
        for (v, e) in self.u_m_per_s.iter_mut().zip(self.grid.edges()) {
            let mid =
                (self.grid.centres()[e.a as usize] + self.grid.centres()[e.b as usize]).normalize();
            *v = u(mid).dot(e.normal);
        }
    }

    /// Sets the surfactant concentration from `gamma(direction)`.
    pub fn set_surfactant(&mut self, gamma: impl Fn(DVec3) -> f64) {
        for (g, &c) in self.gamma.iter_mut().zip(self.grid.centres()) {
            *g = gamma(c);
        }
    }

    /// Film coverage of each cell: 1 where film is, 0 in a hole, between on a rim.
    pub fn coverage(&self) -> &[f64] {
        self.burst_state().coverage()
    }

    /// The holes burst into the film.
    pub fn holes(&self) -> &[Hole] {
        self.burst_state().holes()
    }

    /// Liquid the rims have swept off the film, m³.
    pub fn burst_volume_m3(&self) -> f64 {
        self.burst_state().burst_volume_m3()
    }

    /// Thickness of the film where the first hole opened on its own, m.
    pub fn first_hole_thickness_m(&self) -> Option<f64> {
        self.burst_state().first_hole_thickness_m()
    }

    /// Whether the rims have swept the whole film away.
    pub fn fully_burst(&self) -> bool {
        self.burst_state().fully_burst()
    }

    /// Opens a hole at direction `site`; its rim retracts from the next step on.
    pub fn nucleate(&mut self, site: DVec3) {
        if let Some(b) = self.burst.as_mut() {
            b.nucleate(site);
        }
    }

    fn burst_state(&self) -> &BurstState {
        self.burst
            .as_ref()
            .expect("a film always has its burst state")
    }

    /// Liquid volume ∫h dA over the material sphere, m³.
    pub fn liquid_volume_m3(&self) -> f64 {
        let r2 = self.params.radius_m * self.params.radius_m;
        self.h_m
            .iter()
            .zip(self.grid.areas_sr())
            .map(|(h, a)| h * a)
            .sum::<f64>()
            * r2
    }

    /// Surfactant amount ∫Γ dA, relative concentration × m².
    pub fn surfactant_amount_m2(&self) -> f64 {
        let r2 = self.params.radius_m * self.params.radius_m;
        self.gamma
            .iter()
            .zip(self.grid.areas_sr())
            .map(|(g, a)| g * a)
            .sum::<f64>()
            * r2
    }

    /// Advances the film by `dt_s` under `forcing`; returns the Marangoni solve's report.
    /// A film the rims have swept away stays as it is.
    pub fn step(&mut self, dt_s: f64, forcing: &Forcing) -> SolveReport {
        if self.fully_burst() {
            return SolveReport {
                iterations: 0,
                relative_residual: 0.0,
                start_residual: 0.0,
                from_guess: false,
            };
        }
        let mut s = std::mem::take(&mut self.scratch);
        // The step's starting velocities swapped aside, not copied (0.4 MB a step at
        // n = 64): the explicit momentum reads them from `s.u_start` and writes every
        // edge of `u` anew.
        s.u_start.resize(self.u_m_per_s.len(), 0.0);
        std::mem::swap(&mut s.u_start, &mut self.u_m_per_s);
        // The surfactant's transport and the temperature's read the starting velocities
        // and their own field alone: here, where the last step's thickness transport
        // has just read those velocities ([`Self::transport_surfactant`]).
        let fastest = self.grid.fastest_crossing(&s.u_start);
        self.transport_surfactant(&mut s, dt_s, fastest);
        let up = up_from(forcing.g_eff_m_per_s2);
        let start = (&s.u_start[..], fastest);
        self.exchange_heat(start, (&mut s.cell, &mut s.spread), dt_s, up);
        self.momentum_explicit(&mut s, dt_s, forcing);
        self.air_shear(&mut s, dt_s, forcing.air_m_per_s);
        if let Some(m) = &self.meniscus {
            m.hold(&mut self.u_m_per_s, &mut s.drag);
        }
        let report = self.marangoni_implicit(&mut s, dt_s);
        // The smoothing joins the transport's sub-step where each takes one
        // ([`capillary::Term`]: the splitting and its stability), else runs after it.
        // A uniform evaporation joins the smoothing's last apply, where it has one.
        let thin = self.uniform_evaporation(dt_s);
        let capillary = self.capillary_term(&mut s, dt_s);
        let joined = capillary.map(|(capillary, share)| Joined {
            capillary,
            share,
            thin,
        });
        let g_eff = forcing.g_eff_m_per_s2;
        if self.transport_thickness(&mut s, (dt_s, g_eff), joined) {
            if thin.is_none() {
                self.evaporate(dt_s);
            }
        } else if !self.capillary_smoothing(&mut s, dt_s, thin) {
            self.evaporate(dt_s);
        }
        self.feed_meniscus(dt_s);
        if let Some(mut burst) = self.burst.take() {
            burst.step(self, dt_s);
            self.burst = Some(burst);
        }
        self.scratch = s;
        report
    }

    /// What the step's evaporation takes from every cell where it is the same for all
    /// (the film has no temperature), m; `None` where it takes nothing or varies.
    fn uniform_evaporation(&self, dt_s: f64) -> Option<f64> {
        let evaporated = self.params.evaporation_nm_per_s * 1e-9 * dt_s;
        (evaporated > 0.0 && self.temperature_k.is_empty()).then_some(evaporated)
    }

    /// Thins every cell by the evaporation rate, scaled by its temperature's vapour
    /// pressure where the film has a temperature.
    fn evaporate(&mut self, dt_s: f64) {
        let evaporated = self.params.evaporation_nm_per_s * 1e-9 * dt_s;
        if evaporated <= 0.0 {
            return;
        }
        if self.temperature_k.is_empty() {
            self.h_m
                .iter_mut()
                .for_each(|h| *h = (*h - evaporated).max(0.0));
            return;
        }
        let th = self.params.thermal;
        // One exponential a cell, vectorised (`crate::exp`).
        with_avx2(
            #[inline(always)]
            || {
                for (h, theta) in self.h_m.iter_mut().zip(&self.temperature_k) {
                    *h = (*h - evaporated * th.evaporation_factor(*theta)).max(0.0);
                }
            },
        );
    }

    /// `u ← u + dt (−u·∇u + g_t + thermal Marangoni + viscous)`.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn momentum_explicit(&mut self, s: &mut Scratch, dt_s: f64, forcing: &Forcing) {
        let r = self.params.radius_m;
        // On the face rows from here to the end (module `face_rows`).
        let u = &mut s.rows_u;
        // From the step's start (`step` swapped it aside: `u_m_per_s` is stale until the
        // rows are written back below).
        self.rows.to_rows(&s.u_start, u);
        let start = Some(&s.u_start[..]);
        let nu = self.params.viscosity_pa_s / self.params.density_kg_per_m3;
        let g = forcing.g_eff_m_per_s2;
        let two_point = matches!(self.params.gradient, FilmGradient::TwoPoint);
        // Gravity as the discrete gradient of the potential g·x between cell centres, so a
        // discrete Marangoni gradient can balance it exactly (the edge projection g·n
        // carries an O(Δx) curl that no tension gradient can hold): added by the
        // advection's last stage, edge by edge (`advect_momentum`), where it is along an
        // axis of every face (else in a pass of its own).
        let gravity = two_point.then(|| {
            self.rows
                .gravity(&self.grid, FilmGradient::TwoPoint, g, dt_s)
        });
        let along = gravity.as_ref().and_then(|g| g.along_axes());
        advect_momentum(
            &self.rows,
            &self.advection,
            r,
            dt_s,
            u,
            start,
            along.as_ref(),
            &mut s.advect,
        );
        // Whether the last pass over the rows ended on face 5 ([`face_order`]), where the
        // next should start: the advection's last stage ends on face 5, and so does a
        // gravity pass of its own; the rows taken anew after the thermal stress end on
        // face 0.
        let mut after_face_5 = true;
        if let (Some(gravity), None) = (&gravity, &along) {
            self.rows.add_gravity(u, gravity);
        }
        match self.params.gradient {
            FilmGradient::TwoPoint => {
                if !self.temperature_k.is_empty() {
                    self.rows.to_grid(u, &mut self.u_m_per_s);
                    self.thermal_stress(dt_s, &mut s.vertex);
                    self.rows.to_rows(&self.u_m_per_s, u);
                    after_face_5 = false;
                }
                // (A grid of one cell a face has no inner edges to keep in the grid's
                // numbering.)
                if nu > 0.0 && self.rows.n >= 2 {
                    // Into the viscous stage buffer, in the grid's numbering, which then
                    // holds the grid's velocities; the grid's old buffer is the next step's
                    // stage buffer.
                    self.viscous_step_to_grid(u, &mut s.viscous, nu, dt_s, after_face_5);
                    std::mem::swap(&mut s.viscous.stage, &mut self.u_m_per_s);
                } else {
                    if nu > 0.0 {
                        self.viscous_step(u, &mut s.viscous, nu, dt_s, after_face_5);
                    }
                    self.rows.to_grid(u, &mut self.u_m_per_s);
                }
            }
            FilmGradient::Normal => {
                if nu > 0.0 {
                    self.viscous_step(u, &mut s.viscous, nu, dt_s, after_face_5);
                }
                // Gravity as the normal gradient of the cells' g·x, after the viscous
                // stress: that gradient has a grid-scale circulation where grid lines are askew,
                // which the viscous operator would turn into a flow no tension can hold.
                let kind = FilmGradient::Normal;
                self.rows.add_gradient(u, &self.grid, kind, g, dt_s);
                self.rows.to_grid(u, &mut self.u_m_per_s);
                self.thermal_stress(dt_s, &mut s.vertex);
            }
        }
    }

    /// The air on both sides drags the film towards the air's surface velocity: outside,
    /// the potential flow's `1.5 (U − (U·n)n)`; inside, the gas moving with the bubble.
    /// Each side's shear is `μ_air Δu/δ` through a laminar boundary layer
    /// `δ = √(ν_air ℓ/|Δu|)` over the eddy scale `ℓ = R/4`, at most R. Implicit per edge
    /// (with δ from the step's starting slip), so stable however thin the film. Each
    /// edge's implicit factor `1/(1 + dt k)` damps the Marangoni step's own velocity
    /// change too: drag and Marangoni stress are then one backward-Euler step, and a film
    /// they hold together stays at rest.
    ///
    /// Without a meniscus the drag is left to the Marangoni step's edge pass, which
    /// reads each edge's velocity and thickness anyway and drags it there ([`Drag`]): a
    /// pass of its own read and wrote the velocities and wrote the factors (0.4 MB each
    /// at n = 64), which that pass read back. A meniscus holds its walls with the
    /// factors ([`super::meniscus::MeniscusState::hold`]), so with one the drag is taken
    /// here and its factors kept.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn air_shear(&mut self, s: &mut Scratch, dt_s: f64, air_m_per_s: DVec3) {
        let p = &self.params;
        if p.air_viscosity_pa_s <= 0.0 {
            s.drag_by = Drag::None;
            if self.meniscus.is_some() {
                s.drag.clear();
                s.drag.resize(self.u_m_per_s.len(), 1.0);
                s.drag_by = Drag::Stored;
            }
            return;
        }
        let nu_air = p.air_viscosity_pa_s / p.air_density_kg_per_m3.max(f64::MIN_POSITIVE);
        let (r, eddy) = (p.radius_m, 0.25 * p.radius_m);
        let shear = AirShear {
            per_slip: 1.0 / (nu_air * eddy),
            floor: 1.0 / r,
            per_layer: p.air_viscosity_pa_s / p.density_kg_per_m3,
            dt_s,
            air: air_m_per_s,
            gradient: p.gradient,
        };
        if self.drag_deferrable(s) {
            s.drag_by = Drag::Deferred(shear);
            return;
        }
        s.drag_by = Drag::Stored;
        // Every factor is written below: the buffer needs its length, not a fill.
        s.drag.resize(self.u_m_per_s.len(), 1.0);
        let fg = self.grid.face_geometry();
        let (sides, u, drag) = (&self.sides, &mut self.u_m_per_s, &mut s.drag);
        sides.for_each_edge_run(
            #[inline(always)]
            |run| {
                let (ha, hb) = run.ends(&self.h_m);
                shear.block(fg, run, [ha, hb], (u, drag));
            },
        );
        let seams = sides.seams();
        let ends = s.seam_ends.gather(seams, &self.h_m);
        with_avx2(
            #[inline(always)]
            || shear.block(fg, seams, ends, (u, drag)),
        );
    }

    /// Whether the drag may be left to the Marangoni step: no meniscus holds its walls
    /// with the factors (and, in tests, none asked for it here to compare).
    fn drag_deferrable(&self, s: &Scratch) -> bool {
        #[cfg(test)]
        if s.drag_here {
            return false;
        }
        let _ = s;
        self.meniscus.is_none()
    }

    /// The capillary smoothing's one sub-step from the thickness the transport starts
    /// from, its Laplacian into `s.cell2` (module `capillary`); `None` without drainage,
    /// where the step cannot see it, or where it takes more sub-steps.
    ///
    /// Why `s.cell2`: the Marangoni step has just read the surfactant the step started
    /// with from it (swapped there), so it is spent and partly in cache, where a buffer
    /// of the smoothing's own was written cold.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn capillary_term(&mut self, s: &mut Scratch, dt_s: f64) -> Option<((Mobility, f64), f64)> {
        let c = self.capillary()?;
        let shared = Shared {
            gather: &mut s.gather,
            seam_ends: &mut s.seam_ends,
            laplacian: &mut s.cell2,
        };
        let buffers = (&mut s.capillary, shared);
        let grid = (&*self.grid, &*self.sides);
        one_substep(grid, c, dt_s, &self.h_m, buffers)
    }

    /// The smoothing's parameters; `None` without drainage (immobile liquid between the
    /// surfaces) or surface tension.
    fn capillary(&self) -> Option<Capillary> {
        let p = &self.params;
        let mu = p.drainage_viscosity_pa_s;
        if !(mu.is_finite() && mu > 0.0 && p.burst.sigma_n_per_m > 0.0) {
            return None;
        }
        Some(Capillary {
            sigma_n_per_m: p.burst.sigma_n_per_m,
            drainage_viscosity_pa_s: mu,
            radius_m: p.radius_m,
        })
    }

    /// The capillary pressure's flow relative to the surfaces (module `capillary`); none
    /// without drainage (immobile liquid between the surfaces). Where `thin`, its last
    /// apply thins every cell by it too (kept ≥ 0, as [`Self::evaporate`]): returns
    /// whether it did.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn capillary_smoothing(&mut self, s: &mut Scratch, dt_s: f64, thin: Option<f64>) -> bool {
        let Some(c) = self.capillary() else {
            return false;
        };
        let sides = &self.sides;
        let h = &mut self.h_m;
        let shared = Shared {
            gather: &mut s.gather,
            seam_ends: &mut s.seam_ends,
            laplacian: &mut s.cell,
        };
        let scratch = (&mut s.capillary, shared);
        smooth_thickness(&self.grid, sides, c, (dt_s, thin), h, scratch)
    }
}

/// Where the Marangoni step's edge pass takes each edge's drag from
/// ([`FilmFlow::air_shear`]).
#[derive(Clone, Copy, Debug, Default)]
pub(super) enum Drag {
    /// No air: every factor is 1.
    #[default]
    None,
    /// The velocities are dragged and their factors in [`Scratch::drag`].
    Stored,
    /// Not taken yet: the pass drags each velocity as it reads it, and takes its factor.
    Deferred(AirShear),
}

/// The air shear's constants ([`FilmFlow::air_shear`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct AirShear {
    /// `1/(ν_air ℓ)`: the slip times this is `1/δ²`.
    per_slip: f64,
    /// `1/R`, the least `1/δ`.
    floor: f64,
    /// `μ_air/ρ`: over the film's thickness and δ, the drag's rate.
    per_layer: f64,
    /// The step, s.
    dt_s: f64,
    /// The air's velocity far from the bubble, m/s.
    air: DVec3,
    /// The film's gradient: the potential flow's surface velocity is taken with it.
    gradient: FilmGradient,
}

/// [`AirShear`] along a block of edges: the potential flow's slopes there.
#[derive(Clone, Copy)]
pub(super) struct AirShearAlong<'a> {
    /// The constants.
    shear: AirShear,
    /// The air's velocity in the block's frame ([`EdgeBlock::frame`]).
    air: DVec3,
    /// The slopes of a linear potential across the edges, as components in that frame
    /// ([`EdgeBlock::vector`]).
    slopes: [&'a [f64]; 3],
}

impl AirShear {
    /// The constants along `block`, with the grid's constants `fg`.
    #[inline(always)]
    pub(super) fn along<'a>(
        &self,
        fg: &'a FaceGeometry,
        block: &impl EdgeBlock,
    ) -> AirShearAlong<'a> {
        let slopes: &EdgeVector = match self.gradient {
            FilmGradient::TwoPoint => &fg.centre_gradient,
            FilmGradient::Normal => &fg.centre_normal_gradient,
        };
        let len = block.count();
        AirShearAlong {
            shear: *self,
            air: block.frame(self.air),
            slopes: block.vector(slopes).map(|c| &c[..len]),
        }
    }

    /// Whether the air is still: the potential flow's surface velocity is then zero on
    /// every edge ([`Self::drag_in_still_air`]).
    #[inline(always)]
    pub(super) fn still(&self) -> bool {
        self.air == DVec3::ZERO
    }

    /// [`AirShearAlong::drag`] in still air ([`Self::still`]), without the potential
    /// flow's slopes: its surface velocity is ±0, so the slip outside is `|u|` as inside,
    /// and `u + dt k_out·(±0)` is `u + 0` (but for a velocity of exactly −0, which may
    /// come out +0 where the full drag kept −0: the sign of a zero).
    #[inline(always)]
    pub(super) fn drag_in_still_air(&self, u: f64, h: f64) -> (f64, f64) {
        let k = self.per_layer / h;
        let k_in = k * self.per_layer_depth(u.abs());
        let factor = 1.0 / (1.0 + self.dt_s * (k_in + k_in));
        ((u + 0.0) * factor, factor)
    }

    /// `1/δ = max(√(|Δu|/(ν_air ℓ)), 1/R)` at slip `slip`: a multiply where `1/δ` was a
    /// division.
    #[inline(always)]
    fn per_layer_depth(&self, slip: f64) -> f64 {
        larger((slip * self.per_slip).sqrt(), self.floor)
    }

    /// The shear over a block of edges with thicknesses `[ha, hb]` at their ends: each
    /// edge's velocity `u` dragged, its implicit factor into `drag`.
    #[inline(always)]
    fn block(
        &self,
        fg: &FaceGeometry,
        block: impl EdgeBlock,
        [ha, hb]: [&[f64]; 2],
        (u, drag): (&mut [f64], &mut [f64]),
    ) {
        let len = block.count();
        let (ha, hb) = (&ha[..len], &hb[..len]);
        let along = self.along(fg, &block);
        let (u, factor) = (block.values_mut(u), block.values_mut(drag));
        for i in 0..len {
            let h = larger(0.5 * (ha[i] + hb[i]), H_FLOOR_M);
            (u[i], factor[i]) = along.drag(i, u[i], h);
        }
    }
}

impl AirShearAlong<'_> {
    /// Edge `i` of the block's velocity `u` dragged, and its implicit factor, at its
    /// thickness `h` (floored at [`H_FLOOR_M`]).
    #[inline(always)]
    pub(super) fn drag(&self, i: usize, u: f64, h: f64) -> (f64, f64) {
        let s = &self.shear;
        // The potential flow's surface velocity is the gradient of 1.5 U·x: taken as
        // the discrete gradient between cell centres, curl-free like the real one.
        let outside = 1.5 * dot_at(self.air, self.slopes, i);
        let k = s.per_layer / h;
        let k_out = k * s.per_layer_depth((u - outside).abs());
        let k_in = k * s.per_layer_depth(u.abs());
        let factor = 1.0 / (1.0 + s.dt_s * (k_out + k_in));
        ((u + s.dt_s * k_out * outside) * factor, factor)
    }
}

/// A film of 20 µm ± 30 % under `params` on a grid of n = 12 (rows of ten inside cells:
/// vector chunks and odd ends, the rim, the seams), the tests' common start.
#[cfg(test)]
pub(super) fn test_film(params: FlowParams) -> FilmFlow {
    let grid = std::sync::Arc::new(CubeSphere::new(12));
    let hierarchy = std::sync::Arc::new(Hierarchy::new(&grid));
    FilmFlow::new(grid, hierarchy, params, |d| {
        20e-6 * (1.0 + 0.3 * (4.0 * d.x + d.y).sin())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A warmed, draining, evaporating film turning in a wind ([`test_film`]).
    fn film() -> FilmFlow {
        let mut params = FlowParams {
            drainage_viscosity_pa_s: 1e-6,
            evaporation_nm_per_s: 40.0,
            ..FlowParams::water_film(0.05)
        };
        params.thermal.bottom_warming_k = 5.0;
        let mut f = test_film(params);
        f.set_velocity(|d| DVec3::Y.cross(d) * 0.05);
        f.set_surfactant(|d| 1.0 + 0.1 * d.z);
        f
    }

    /// Where the capillary smoothing's share of its stability bound and the transport's
    /// Courant share sum past 1, the transport does not take the smoothing's term
    /// ([`super::transport::joins`]): the thickness is the transport's and then the
    /// smoothing's apart, to the bit; with a small share the two join, and the thickness
    /// differs from the split one (a different splitting).
    #[test]
    fn a_smoothing_that_would_overdraw_the_joined_step_runs_after_the_transport() {
        let mut params = FlowParams {
            drainage_viscosity_pa_s: 1e-6,
            ..FlowParams::water_film(0.05)
        };
        params.thermal.bottom_warming_k = 0.0;
        let mut start = test_film(params);
        let mut s = std::mem::take(&mut start.scratch);
        // A step the smoothing takes in one sub-step (its share, `rate·dt/1.8`, ≤ 1).
        let (dt0, share) = (1..12)
            .map(|k| 10f64.powi(-k))
            .find_map(|dt| Some((dt, start.capillary_term(&mut s, dt)?.1)))
            .expect("a step of one smoothing sub-step");
        let split_and_joined = |target: f64, courant: f64| {
            let dt = dt0 * target / share;
            // A uniform speed at `courant` of the narrowest cell's width a step.
            let width = start.params.radius_m * 0.7 * std::f64::consts::FRAC_PI_2 / 12.0;
            let mut f = start.clone();
            f.set_velocity(|d| DVec3::Y.cross(d).normalize_or_zero() * courant * width / dt);
            let (mut joined, mut apart) = (f.clone(), f);
            let g = DVec3::ZERO;
            let mut s = Scratch::default();
            let (term, share) = joined.capillary_term(&mut s, dt).expect("one sub-step");
            assert!((share - target).abs() < 1e-9 * target, "share {share}");
            let join = Joined {
                capillary: term,
                share,
                thin: None,
            };
            let took = joined.transport_thickness(&mut s, (dt, g), Some(join));
            let mut s = Scratch::default();
            assert!(!apart.transport_thickness(&mut s, (dt, g), None));
            if !took {
                joined.capillary_smoothing(&mut Scratch::default(), dt, None);
            }
            apart.capillary_smoothing(&mut s, dt, None);
            (took, joined.h_m == apart.h_m)
        };
        // 0.9 + 2·0.1: past 1, apart; 0.1 + 2·0.1: joined.
        assert_eq!(split_and_joined(0.9, 0.1), (false, true));
        assert_eq!(split_and_joined(0.1, 0.1), (true, false));
    }

    /// The drag left to the Marangoni step's edge pass gives the bits of the drag taken
    /// in a pass of its own, as with a meniscus ([`Drag`]), with either gradient, in a
    /// wind and in still air ([`AirShear::drag_in_still_air`]).
    #[test]
    fn the_drag_left_to_the_marangoni_pass_gives_the_drag_pass_bits() {
        let airs = [DVec3::new(0.3, 0.0, 0.1), DVec3::ZERO];
        let cases = airs.into_iter().flat_map(|air| {
            [FilmGradient::TwoPoint, FilmGradient::Normal].map(|gradient| (air, gradient))
        });
        for (air, gradient) in cases {
            let forcing = Forcing {
                g_eff_m_per_s2: DVec3::new(0.0, -9.81, 0.0),
                air_m_per_s: air,
            };
            let run = |here: bool| {
                let mut f = film();
                f.params.gradient = gradient;
                f.scratch.drag_here = here;
                for _ in 0..5 {
                    f.step(1.0 / 60.0, &forcing);
                }
                assert!(matches!(f.scratch.drag_by, Drag::Deferred(_)) != here);
                f
            };
            let (left, here) = (run(false), run(true));
            let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            let what = format!("{gradient:?}, air {air}");
            assert_eq!(bits(&left.h_m), bits(&here.h_m), "{what}: thickness");
            assert_eq!(bits(&left.gamma), bits(&here.gamma), "{what}: surfactant");
            assert_eq!(
                bits(&left.u_m_per_s),
                bits(&here.u_m_per_s),
                "{what}: velocity"
            );
        }
    }

    /// Every pass the step compiles for AVX2 gives the portable build's bits: IEEE
    /// additions and multiplications in a fixed order, minima and maxima by comparisons.
    #[test]
    fn the_avx2_step_gives_the_portable_steps_bits() {
        let forcing = Forcing {
            g_eff_m_per_s2: DVec3::new(0.0, -9.81, 0.0),
            air_m_per_s: DVec3::new(0.3, 0.0, 0.1),
        };
        let run = |portable: bool| {
            crate::avx2::set_portable_only(portable);
            let mut f = film();
            for _ in 0..5 {
                f.step(1.0 / 60.0, &forcing);
            }
            crate::avx2::set_portable_only(false);
            f
        };
        let (fast, portable) = (run(false), run(true));
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&fast.h_m), bits(&portable.h_m), "thickness");
        assert_eq!(bits(&fast.gamma), bits(&portable.gamma), "surfactant");
        assert_eq!(bits(&fast.u_m_per_s), bits(&portable.u_m_per_s), "velocity");
        assert_eq!(
            bits(&fast.temperature_k),
            bits(&portable.temperature_k),
            "temperature"
        );
        let start = film();
        assert_ne!(bits(&fast.h_m), bits(&start.h_m), "the film did not move");
    }
}

//! Transport of the film's thickness: liquid moves with the surfaces and by the drainage
//! flux relative to them, each part upwind along its own characteristic (second order:
//! the upwind cell's Barth–Jespersen-limited gradient), in sub-steps under a Courant
//! bound, each donor's outflow limited to a fraction of its content.
//!
//! A sub-step is four passes ([`super::upwind`]): each cell's limited rises to its sides;
//! the volume across each edge; each donor's outflow factor; each cell's gathered
//! volumes. Inside a face each pass reads slices and vectorises.

use glam::DVec3;

use super::compare::larger;
use super::flow::{FilmFlow, Scratch};
use super::fluxes::apply_limited;
use super::upwind;
use crate::avx2::with_avx2;

/// Most sub-steps one thickness transport takes.
const MAX_SUBSTEPS: u32 = 64;

impl FilmFlow {
    /// Moves liquid with the surfaces (upwind) and by the drainage flux relative to them,
    /// in sub-steps that keep each cell's outflow below half its content.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn transport_thickness(&mut self, s: &mut Scratch, dt_s: f64, g_eff: DVec3) {
        let p = self.params;
        let drain = if p.drainage_viscosity_pa_s.is_finite() && p.drainage_viscosity_pa_s > 0.0 {
            p.density_kg_per_m3 / (3.0 * p.drainage_viscosity_pa_s)
        } else {
            0.0
        };
        // The drainage flux's coefficient `c = drain·g_eff·n` of every edge, fixed over
        // the step: each sub-step's flux is `u·h + c·h³`.
        let ea = self.grid.edge_arrays();
        s.drain_rate.clear();
        s.drain_rate
            .extend(ea.normal.iter().map(|normal| drain * g_eff.dot(*normal)));
        let courant = self.courant_number(&s.drain_rate, dt_s);
        // A cell drains through at most two edges of a smooth flow: 2·courant per step, kept
        // within one sub-step's content; the outflow limit guards the rest.
        let substeps = (2.0 * courant).ceil().clamp(1.0, f64::from(MAX_SUBSTEPS)) as u32;
        let h_dt = dt_s / f64::from(substeps);
        for _ in 0..substeps {
            self.upwind_substep(s, h_dt);
        }
    }

    /// The largest fraction of a cell's width any edge's characteristic speed, `|u|` plus
    /// the drainage's `3|c|h²`, carries over `dt_s`.
    fn courant_number(&self, drain_rate: &[f64], dt_s: f64) -> f64 {
        let ea = self.grid.edge_arrays();
        let (h, u) = (&self.h_m, &self.u_m_per_s);
        // Four running maxima, lane by lane, so the loop vectorises (a maximum is exact in
        // any order: the same number as one running maximum).
        let mut lanes = [0.0; 4];
        self.sides.for_each_edge_run(
            #[inline(always)]
            |run| {
                let len = run.len;
                let (ha, hb) = run.ends(h);
                let (ha, hb) = (&ha[..len], &hb[..len]);
                let (u, c) = (run.along(u), run.along(drain_rate));
                let per_area = run.along(&ea.length_per_smaller_area);
                for i in 0..len {
                    let h = larger(hb[i], ha[i]);
                    let speed = (u[i].abs() + 3.0 * c[i].abs() * h * h) * per_area[i];
                    // Skips a NaN speed as `max` does.
                    lanes[i % 4] = larger(speed, lanes[i % 4]);
                }
            },
        );
        let fastest = lanes.into_iter().fold(0.0, |a, b| larger(b, a));
        fastest * dt_s / self.params.radius_m
    }

    /// One transport of `h` over `dt_s`: second-order upwind (the upwind cell's
    /// Green–Gauss gradient, limited to its neighbours' range, carried to the edge
    /// midpoint and clamped between the two cells' values), outflow-limited. Four passes,
    /// each structured inside the faces ([`super::upwind`]).
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn upwind_substep(&mut self, s: &mut Scratch, dt_s: f64) {
        let (sides, geo) = (&*self.sides, &*self.transport);
        let dt_per_r = dt_s / self.params.radius_m;
        with_avx2(
            #[inline(always)]
            || {
                upwind::limited_rises(sides, geo, &self.h_m, &mut s.limited_rise);
                let speeds = upwind::EdgeSpeeds {
                    u: &self.u_m_per_s,
                    drain_rate: &s.drain_rate,
                    dt_per_r,
                };
                let ea = self.grid.edge_arrays();
                upwind::volumes(sides, ea, &self.h_m, &s.limited_rise, speeds, &mut s.edge2);
                let (areas, per_area) = (self.grid.areas_sr(), self.grid.inverse_areas_per_sr());
                let (volume, h) = (&s.edge2, &mut self.h_m);
                apply_limited(sides, areas, per_area, volume, 1.0, h, &mut s.cell);
            },
        )
    }
}

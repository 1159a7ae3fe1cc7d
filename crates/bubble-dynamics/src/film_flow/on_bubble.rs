//! A bubble's film flow: the cube-sphere state, where its cells sit on the particle
//! mesh, and the thickness field it hands to renderers (the flow's thickness times the
//! mesh's local stretch).

use std::sync::Arc;

use glam::DVec3;

use super::cell_map::CellMap;
use super::{CubeSphere, FilmFlow, FlowParams, Forcing, Hierarchy};
use crate::geometry::barycentric_vertex_areas_m2;

/// The flow of one bubble's film on its material sphere.
#[derive(Clone, Debug)]
pub(crate) struct GridFilm {
    pub(crate) flow: FilmFlow,
    map: CellMap,
    /// Rest directions of the mesh vertices: where each vertex sits on the film grid.
    pub(crate) material_dirs: Vec<DVec3>,
    rest_vertex_area_m2: Vec<f64>,
    /// World time gathered since the last flow step, s, and the forcing's integral.
    pending_s: f64,
    pending_forcing: Forcing,
    /// How far into the world step under way the rims have been advanced, s.
    rim_ahead_s: f64,
}

impl GridFilm {
    /// A film at rest on grid `n` with thickness `h_m(direction)`.
    pub(crate) fn new(
        n: usize,
        params: FlowParams,
        unit_positions: &[DVec3],
        rest_positions_m: &[DVec3],
        triangles: &[[u32; 3]],
        h_m: impl Fn(DVec3) -> f64,
    ) -> Self {
        let grid = Arc::new(CubeSphere::new(n));
        let hierarchy = Arc::new(Hierarchy::new(&grid));
        let map = CellMap::new(grid.centres(), unit_positions, triangles);
        let mut flow = FilmFlow::new(grid, hierarchy, params, h_m);
        flow.with_burst(|burst, _| burst.drive_rims_outside());
        Self {
            flow,
            map,
            material_dirs: unit_positions.iter().map(|u| u.normalize()).collect(),
            rest_vertex_area_m2: barycentric_vertex_areas_m2(rest_positions_m, triangles),
            pending_s: 0.0,
            pending_forcing: Forcing::default(),
            rim_ahead_s: 0.0,
        }
    }

    /// Advances the rims of the holes over the world step of `dt_s` (from wherever
    /// [`GridFilm::advance_rims`] left them), then gathers the step; once `film_dt_s`
    /// has passed, steps the flow over the gathered time with the forcing's mean over it.
    pub(crate) fn step(&mut self, dt_s: f64, film_dt_s: f64, forcing: &Forcing) {
        self.advance_rims(dt_s, dt_s);
        self.rim_ahead_s = 0.0;
        self.pending_s += dt_s;
        self.pending_forcing.g_eff_m_per_s2 += forcing.g_eff_m_per_s2 * dt_s;
        self.pending_forcing.air_m_per_s += forcing.air_m_per_s * dt_s;
        // A relative margin: 4 steps of 1/240 s sum to 1/60 s only to rounding.
        if self.pending_s >= film_dt_s * (1.0 - 1e-9) {
            let t = self.pending_s;
            let mean = Forcing {
                g_eff_m_per_s2: self.pending_forcing.g_eff_m_per_s2 / t,
                air_m_per_s: self.pending_forcing.air_m_per_s / t,
            };
            self.flow.step(t, &mean);
            self.pending_s = 0.0;
            self.pending_forcing = Forcing::default();
        }
    }

    /// Advances the rims `to_s` into the world step of `step_s` that comes next (s from
    /// its start), in the sub-steps that step will take, so that the step later goes on
    /// from there to the same state. Never moves them back.
    pub(crate) fn advance_rims(&mut self, to_s: f64, step_s: f64) {
        let from_s = self.rim_ahead_s;
        let at_s = self
            .flow
            .with_burst(|burst, flow| burst.advance_rims(flow, from_s, to_s, step_s));
        self.rim_ahead_s = at_s.max(from_s);
    }

    /// The film's thickness at every cell in nm, stretched by the mesh's deformation
    /// (rest vertex area / current vertex area, interpolated to the cell).
    pub(crate) fn thickness_nm(&self, positions_m: &[DVec3], triangles: &[[u32; 3]]) -> Vec<f64> {
        let now = barycentric_vertex_areas_m2(positions_m, triangles);
        let stretch: Vec<f64> = self
            .rest_vertex_area_m2
            .iter()
            .zip(&now)
            .map(|(rest, a)| if *a > 0.0 { rest / a } else { 1.0 })
            .collect();
        let mut at_cells = Vec::new();
        self.map.interpolate(triangles, &stretch, &mut at_cells);
        at_cells
            .iter()
            .zip(self.flow.thickness_m())
            .map(|(s, h)| s * h * 1e9)
            .collect()
    }
}

//! A bubble's film flow: the cube-sphere state, where its cells sit on the particle
//! mesh, and the thickness field it hands to renderers (the flow's thickness times the
//! mesh's local stretch).

use std::sync::Arc;

use glam::DVec3;

use super::cell_map::CellMap;
use super::{CubeSphere, FilmFlow, Forcing, FlowParams, Hierarchy};
use crate::geometry::barycentric_vertex_areas_m2;

/// The flow of one bubble's film on its material sphere.
#[derive(Clone, Debug)]
pub(crate) struct GridFilm {
    pub(crate) flow: FilmFlow,
    map: CellMap,
    /// Rest directions of the mesh vertices: where each vertex sits on the film grid.
    pub(crate) material_dirs: Vec<DVec3>,
    rest_vertex_area_m2: Vec<f64>,
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
        Self {
            flow: FilmFlow::new(grid, hierarchy, params, h_m),
            map,
            material_dirs: unit_positions.iter().map(|u| u.normalize()).collect(),
            rest_vertex_area_m2: barycentric_vertex_areas_m2(rest_positions_m, triangles),
        }
    }

    /// One step of the flow.
    pub(crate) fn step(&mut self, dt_s: f64, forcing: &Forcing) {
        self.flow.step(dt_s, forcing);
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

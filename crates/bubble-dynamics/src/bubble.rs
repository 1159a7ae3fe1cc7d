//! One bubble: its mesh, particle state, film and gas, and read-only views of them.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;

use crate::film::Slosh;
use crate::film_flow::on_bubble::GridFilm;
use crate::film_flow::{BurstParams, FilmFlow, FlowParams, ThermalParams};
use crate::geometry::{self, barycentric_vertex_areas_m2, enclosed_volume_m3, surface_area_m2};
use crate::params::{BubbleParams, GAS_CONSTANT_J_PER_MOL_K, MassDistribution, WorldParams};
use crate::rng::SphereField;
use crate::topology::Topology;

/// Material constants of one bubble's film, copied from its parameters.
#[derive(Clone, Debug)]
pub(crate) struct Film {
    pub(crate) sigma_n_per_m: f64,
    pub(crate) gibbs_elasticity_n_per_m: f64,
    pub(crate) damping_per_s: f64,
    pub(crate) deformation_damping_per_s: f64,
    pub(crate) density_kg_per_m3: f64,
    pub(crate) drainage_viscosity_pa_s: f64,
    pub(crate) rupture_thickness_nm: f64,
    pub(crate) evaporation_nm_per_s: f64,
}

/// What the triangle pass sums at each vertex (one cache line per vertex).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(crate) struct VertexSums {
    /// Tension, hydrostatic and drag forces, N.
    pub(crate) force_n: DVec3,
    /// ∂V/∂x, m².
    pub(crate) volume_gradient_m2: DVec3,
    /// Bound on the drag force's derivative with respect to this vertex's velocity, N·s/m.
    pub(crate) drag_n_s_per_m: f64,
    /// Gershgorin row sum of the tension/elasticity Hessian, N/m (first substep only).
    pub(crate) stiffness_n_per_m: f64,
}

/// Work buffers, kept to avoid allocating every substep.
#[derive(Clone, Debug, Default)]
pub(crate) struct Scratch {
    pub(crate) sums: Vec<VertexSums>,
    /// Enclosed volume at the state the sums were taken at, m³.
    pub(crate) volume_m3: f64,
    pub(crate) relative_velocity_m_per_s: Vec<DVec3>,
    pub(crate) solve: Vec<DVec3>,
    pub(crate) vertex_area_m2: Vec<f64>,
    /// Twice the cotangent of every corner, `3·face + slot` (see `film::FilmGeometry`).
    pub(crate) corner_cot2: Vec<f64>,
    pub(crate) film_thickness_m: Vec<f64>,
    pub(crate) stream_m2_per_s: Vec<f64>,
    pub(crate) flux_kg_per_s: Vec<f64>,
    pub(crate) outflow_kg: Vec<f64>,
    pub(crate) momentum_kg_m_per_s: Vec<DVec3>,
}

/// A soap bubble: a closed triangle mesh whose vertices are particles carrying film
/// mass, plus the share of the enclosed gas and entrained air that moves with them.
#[derive(Clone, Debug)]
pub struct Bubble {
    pub(crate) id: u64,
    pub(crate) topology: Arc<Topology>,
    pub(crate) positions_m: Vec<DVec3>,
    pub(crate) velocities_m_per_s: Vec<DVec3>,
    pub(crate) film_mass_kg: Vec<f64>,
    pub(crate) inertial_mass_kg: Vec<f64>,
    /// Rest barycentric area fraction: how the gas and added mass ride on the vertices.
    pub(crate) carried_fraction: Vec<f64>,
    pub(crate) gas_mass_kg: f64,
    pub(crate) added_mass_kg: f64,
    /// 1 / rest face area, 1/m² (the elasticity needs the ratio every substep).
    pub(crate) inv_rest_face_area: Vec<f64>,
    pub(crate) rest_radius_m: f64,
    pub(crate) rest_volume_m3: f64,
    /// p_in·V of the enclosed ideal gas, constant (isothermal).
    pub(crate) gas_pv_j: f64,
    pub(crate) p_out_pa: f64,
    pub(crate) volume_m3: f64,
    pub(crate) thickness_nm: Vec<f64>,
    pub(crate) film: Film,
    pub(crate) slosh: Option<Slosh>,
    pub(crate) scratch: Scratch,
    /// The open contact episode with each static collider, by collider index.
    pub(crate) episodes: Vec<crate::collide::Episode>,
    /// The film flow on its cube-sphere, when `film_grid > 0`.
    pub(crate) grid_film: Option<Box<GridFilm>>,
    /// Where the wet surface a bubble with a meniscus stands on holds its mesh's
    /// centre, m.
    pub(crate) anchor_m: Option<DVec3>,
}

/// A bubble's film thickness over its material sphere, as the cube map renderers read.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmField {
    /// Cells along a face edge, n.
    pub face_size: usize,
    /// Thickness of cell `face·n² + y·n + x` in nm, stretched by the mesh's deformation
    /// (faces in OpenGL cube-map order, see `film_flow::grid`).
    pub thickness_nm: Vec<f64>,
    /// Film coverage of each cell: 1 where film is, 0 in a burst hole, between on a rim.
    pub coverage: Vec<f64>,
}

impl Bubble {
    /// Builds bubble `id` on the unit icosphere `unit_positions` with connectivity `topology`.
    pub(crate) fn new(
        id: u64,
        params: &BubbleParams,
        world: &WorldParams,
        topology: Arc<Topology>,
        unit_positions: &[DVec3],
    ) -> Self {
        let triangles = topology.triangles();
        // Scale so the polyhedron's volume is that of the sphere of radius_m.
        let unit_volume = enclosed_volume_m3(unit_positions, triangles);
        let scale = params.radius_m * (4.0 / 3.0 * PI / unit_volume).cbrt();
        let rest: Vec<DVec3> = unit_positions.iter().map(|&u| u * scale).collect();
        let rest_face_area_m2 = geometry::face_areas_m2(&rest, triangles);
        let rest_area = rest_face_area_m2.iter().sum::<f64>();
        let rest_volume_m3 = enclosed_volume_m3(&rest, triangles);
        let p_in_pa = world.p_out_pa
            + rest_pressure_excess_pa(params.sigma_n_per_m, rest_area, rest_volume_m3);
        let gas_density = p_in_pa * params.gas_molar_mass_kg_per_mol
            / (GAS_CONSTANT_J_PER_MOL_K * params.gas_temperature_k);
        let carried_fraction: Vec<f64> = barycentric_vertex_areas_m2(&rest, triangles)
            .iter()
            .map(|a| a / rest_area)
            .collect();
        let film_mass_kg =
            initial_film_mass_kg(params, unit_positions, &carried_fraction, rest_area);
        let n = unit_positions.len();
        let mut bubble = Self {
            id,
            positions_m: rest
                .iter()
                .map(|&x| params.center_m + x * params.initial_scale)
                .collect(),
            velocities_m_per_s: vec![params.velocity_m_per_s; n],
            inertial_mass_kg: vec![0.0; n],
            film_mass_kg,
            carried_fraction,
            gas_mass_kg: gas_density * rest_volume_m3,
            added_mass_kg: world.added_mass_coefficient
                * world.air_density_kg_per_m3
                * rest_volume_m3,
            inv_rest_face_area: rest_face_area_m2.iter().map(|a| 1.0 / a).collect(),
            rest_radius_m: params.radius_m,
            rest_volume_m3,
            gas_pv_j: p_in_pa * rest_volume_m3,
            p_out_pa: world.p_out_pa,
            volume_m3: rest_volume_m3,
            thickness_nm: vec![0.0; n],
            film: Film {
                sigma_n_per_m: params.sigma_n_per_m,
                gibbs_elasticity_n_per_m: params.gibbs_elasticity_n_per_m,
                damping_per_s: params.damping_per_s,
                deformation_damping_per_s: params.deformation_damping_per_s,
                density_kg_per_m3: params.film_density_kg_per_m3,
                drainage_viscosity_pa_s: params.drainage_viscosity_pa_s,
                rupture_thickness_nm: params.rupture_thickness_nm,
                evaporation_nm_per_s: params.evaporation_nm_per_s,
            },
            slosh: (params.slosh_speed_m_per_s > 0.0)
                .then(|| Slosh::new(params, topology.triangles(), unit_positions)),
            topology: Arc::clone(&topology),
            scratch: Scratch::default(),
            episodes: Vec::new(),
            grid_film: (params.film_grid > 0)
                .then(|| Box::new(grid_film(params, world, unit_positions, &rest, triangles))),
            anchor_m: None,
        };
        bubble.refresh_inertial_mass();
        if params.meniscus.is_some() {
            bubble.anchor_m = Some(bubble.mean_position_m());
        }
        bubble.volume_m3 = enclosed_volume_m3(&bubble.positions_m, bubble.topology.triangles());
        bubble.update_thickness();
        bubble
    }

    pub(crate) fn refresh_inertial_mass(&mut self) {
        let carried = self.gas_mass_kg + self.added_mass_kg;
        for ((m, film), frac) in self
            .inertial_mass_kg
            .iter_mut()
            .zip(&self.film_mass_kg)
            .zip(&self.carried_fraction)
        {
            *m = film + carried * frac;
        }
    }

    /// Seed 000 eq. 2 with per-vertex mass: d_i = c_d·m_i / Σ_{j∈F(i)} A_j, c_d = 3/ρ.
    pub(crate) fn update_thickness(&mut self) {
        let areas = barycentric_vertex_areas_m2(&self.positions_m, self.topology.triangles());
        self.update_thickness_with_areas(&areas);
    }

    /// As `update_thickness`, with the barycentric vertex areas already at hand.
    pub(crate) fn update_thickness_with_areas(&mut self, areas: &[f64]) {
        let rho = self.film.density_kg_per_m3;
        for ((d, m), a) in self
            .thickness_nm
            .iter_mut()
            .zip(&self.film_mass_kg)
            .zip(areas)
        {
            *d = if *a > 0.0 {
                1e9 * m / (rho * a)
            } else {
                f64::INFINITY
            };
        }
    }

    /// The film flow, when the bubble has one (`film_grid > 0`).
    pub fn film_flow(&self) -> Option<&FilmFlow> {
        self.grid_film.as_ref().map(|g| &g.flow)
    }

    /// The film's thickness field for renderers, when the bubble has a film flow.
    pub fn film_field(&self) -> Option<FilmField> {
        self.grid_film.as_ref().map(|g| FilmField {
            face_size: g.flow.grid().face_size(),
            thickness_nm: g.thickness_nm(&self.positions_m, self.topology.triangles()),
            coverage: g.flow.coverage().to_vec(),
        })
    }

    /// Where each mesh vertex sits on the film grid (its unit rest direction), when the
    /// bubble has a film flow.
    pub fn material_dirs(&self) -> Option<&[DVec3]> {
        self.grid_film.as_ref().map(|g| &g.material_dirs[..])
    }

    /// Stable identifier: the bubble's index in the list given to `World::try_new`.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Vertex positions, m.
    pub fn positions_m(&self) -> &[DVec3] {
        &self.positions_m
    }

    /// Vertex velocities, m/s.
    pub fn velocities_m_per_s(&self) -> &[DVec3] {
        &self.velocities_m_per_s
    }

    /// Triangles (vertex indices), counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        self.topology.triangles()
    }

    /// The mesh connectivity (edges, adjacency).
    pub fn topology(&self) -> &Topology {
        &self.topology
    }

    /// Film thickness at each vertex, nm, as of the end of the last step: the per-vertex
    /// film's. A bubble with a film flow keeps this as its flow started it (stretched
    /// with the mesh); its flowing film is [`Bubble::film_field`].
    pub fn thickness_nm(&self) -> &[f64] {
        &self.thickness_nm
    }

    /// Smallest film thickness, nm: of the vertices, or with a film flow of the cells
    /// that still hold film.
    pub fn min_thickness_nm(&self) -> f64 {
        match self.film_field() {
            Some(field) => field
                .thickness_nm
                .iter()
                .zip(&field.coverage)
                .filter(|&(_, &c)| c > 0.0)
                .map(|(&h, _)| h)
                .fold(f64::INFINITY, f64::min),
            None => self
                .thickness_nm
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// Largest film thickness, nm: of the vertices, or with a film flow of the cells.
    pub fn max_thickness_nm(&self) -> f64 {
        match self.film_field() {
            Some(field) => field.thickness_nm.iter().copied().fold(0.0, f64::max),
            None => self.thickness_nm.iter().copied().fold(0.0, f64::max),
        }
    }

    /// Area-weighted mean thickness (film volume / area), nm; with a film flow, of the
    /// flow's liquid.
    pub fn mean_thickness_nm(&self) -> f64 {
        if let Some(flow) = self.film_flow() {
            return 1e9 * flow.liquid_volume_m3() / self.area_m2();
        }
        1e9 * self.film_mass_kg() / (self.film.density_kg_per_m3 * self.area_m2())
    }

    /// Area-weighted unit vertex normals.
    pub fn vertex_normals(&self) -> Vec<DVec3> {
        geometry::vertex_normals(&self.positions_m, self.topology.triangles())
    }

    /// Per-vertex film mass, kg.
    pub fn film_masses_kg(&self) -> &[f64] {
        &self.film_mass_kg
    }

    /// Per-vertex inertial mass (film + carried gas and added air), kg.
    pub fn vertex_masses_kg(&self) -> &[f64] {
        &self.inertial_mass_kg
    }

    /// Total film mass, kg.
    pub fn film_mass_kg(&self) -> f64 {
        self.film_mass_kg.iter().sum()
    }

    /// Mass of the enclosed gas, kg.
    pub fn gas_mass_kg(&self) -> f64 {
        self.gas_mass_kg
    }

    /// Total inertial mass (film + gas + added air), kg.
    pub fn inertial_mass_kg(&self) -> f64 {
        self.inertial_mass_kg.iter().sum()
    }

    /// Holds a bubble standing on a wet surface where it stands: the particles' common
    /// motion removed (the meniscus pins the foot to the surface, which bears whatever
    /// force that takes), their motion relative to the centre of mass kept.
    pub(crate) fn hold_at_anchor(&mut self) {
        let Some(anchor) = self.anchor_m else {
            return;
        };
        let (shift, drift) = (anchor - self.mean_position_m(), self.velocity_m_per_s());
        for (x, v) in self
            .positions_m
            .iter_mut()
            .zip(&mut self.velocities_m_per_s)
        {
            *x += shift;
            *v -= drift;
        }
    }

    /// The particles' mean position, m: the mesh's centre, which the film's liquid moving
    /// from vertex to vertex does not shift as it shifts the centre of mass.
    fn mean_position_m(&self) -> DVec3 {
        self.positions_m.iter().sum::<DVec3>() / self.positions_m.len() as f64
    }

    /// Centre of mass of the particles, m.
    pub fn center_m(&self) -> DVec3 {
        let m = self.inertial_mass_kg();
        self.positions_m
            .iter()
            .zip(&self.inertial_mass_kg)
            .map(|(x, w)| *x * *w)
            .sum::<DVec3>()
            / m
    }

    /// Centre-of-mass velocity, m/s.
    pub fn velocity_m_per_s(&self) -> DVec3 {
        self.momentum_kg_m_per_s() / self.inertial_mass_kg()
    }

    /// Linear momentum Σ m_i v_i, kg·m/s.
    pub fn momentum_kg_m_per_s(&self) -> DVec3 {
        self.velocities_m_per_s
            .iter()
            .zip(&self.inertial_mass_kg)
            .map(|(v, m)| *v * *m)
            .sum()
    }

    /// Angular momentum Σ m_i x_i × v_i about the origin, kg·m²/s.
    pub fn angular_momentum_kg_m2_per_s(&self) -> DVec3 {
        self.positions_m
            .iter()
            .zip(&self.velocities_m_per_s)
            .zip(&self.inertial_mass_kg)
            .map(|((x, v), m)| x.cross(*v) * *m)
            .sum()
    }

    /// Enclosed volume, m³.
    pub fn volume_m3(&self) -> f64 {
        self.volume_m3
    }

    /// Rest (gas-free equilibrium) volume, m³.
    pub fn rest_volume_m3(&self) -> f64 {
        self.rest_volume_m3
    }

    /// Volume-equivalent radius (3V/4π)^⅓, m.
    pub fn radius_m(&self) -> f64 {
        (3.0 * self.volume_m3 / (4.0 * PI)).cbrt()
    }

    /// Film area (one side), m².
    pub fn area_m2(&self) -> f64 {
        surface_area_m2(&self.positions_m, self.topology.triangles())
    }

    /// Gas pressure inside, Pa (isothermal ideal gas).
    pub fn pressure_in_pa(&self) -> f64 {
        self.gas_pv_j / self.volume_m3
    }

    /// Gas pressure inside minus the ambient pressure, Pa.
    pub fn pressure_excess_pa(&self) -> f64 {
        self.pressure_in_pa() - self.p_out_pa
    }

    /// Kinetic energy ½ Σ m_i |v_i|² of the particles (film + carried mass), J.
    pub fn kinetic_energy_j(&self) -> f64 {
        0.5 * self
            .velocities_m_per_s
            .iter()
            .zip(&self.inertial_mass_kg)
            .map(|(v, m)| m * v.length_squared())
            .sum::<f64>()
    }
}

/// The pressure excess that holds a discrete rest mesh in equilibrium, Pa.
///
/// Virtual work of a uniform dilation x → (1+ε)x: the film tension 2σ does work
/// 2σ·dA = 2σ·2A·ε, the gas p·dV = p·3V·ε (A and V are homogeneous of degrees 2 and 3 in
/// the vertex positions, exactly, for any mesh), so Δp = 4σA/(3V), which for a sphere
/// (A = 4πR², V = 4πR³/3) is Laplace's 4σ/R.
pub fn rest_pressure_excess_pa(sigma_n_per_m: f64, area_m2: f64, volume_m3: f64) -> f64 {
    4.0 * sigma_n_per_m * area_m2 / (3.0 * volume_m3)
}

/// Film mass per vertex, kg: ρ·h·A in total, shared by `distribution`, modulated by a
/// smooth seeded pattern of relative amplitude `thickness_variation`.
/// The film flow of a new bubble: the initial thickness pattern of the per-vertex film
/// (same seed, same smooth field), evaluated at every cell and scaled to the mean.
fn grid_film(
    params: &BubbleParams,
    world: &WorldParams,
    unit_positions: &[DVec3],
    rest: &[DVec3],
    triangles: &[[u32; 3]],
) -> GridFilm {
    // The per-vertex film's few broad lobes, plus the fine streaks a freshly blown film
    // carries (too fine for the 642-vertex mesh, which is why only the grid has them).
    let broad = SphereField::new(params.seed, 6, 0.0);
    let fine = SphereField::with_wavenumbers(params.seed ^ 0x5_7EA4, 24, 0.0, (10.0, 30.0));
    let pattern = |d: DVec3| 0.6 * broad.value(d, 0.0) + 0.4 * fine.value(d, 0.0);
    let flow = FlowParams {
        radius_m: params.radius_m,
        density_kg_per_m3: params.film_density_kg_per_m3,
        elasticity_n_per_m: params.gibbs_elasticity_n_per_m,
        viscosity_pa_s: params.film_viscosity_pa_s,
        drainage_viscosity_pa_s: params.drainage_viscosity_pa_s,
        evaporation_nm_per_s: params.evaporation_nm_per_s,
        air_viscosity_pa_s: world.air_viscosity_pa_s,
        air_density_kg_per_m3: world.air_density_kg_per_m3,
        burst: BurstParams {
            sigma_n_per_m: params.sigma_n_per_m,
            black_threshold_nm: params.black_threshold_nm,
            black_film_nm: params.black_film_nm,
            rupture_thickness_nm: params.rupture_thickness_nm,
            nucleation_per_m2_s: params.nucleation_per_m2_s,
        },
        thermal: ThermalParams {
            bottom_warming_k: params.bottom_warming_k,
            ambient_k: params.gas_temperature_k,
            ..ThermalParams::isothermal()
        },
        seed: params.seed,
        gradient: params.film_gradient,
    };
    let h0 = params.mean_thickness_nm * 1e-9;
    let variation = params.thickness_variation;
    let mut film = GridFilm::new(
        params.film_grid as usize,
        flow,
        unit_positions,
        rest,
        triangles,
        |d| h0 * (1.0 + variation * pattern(d)),
    );
    // The pattern's mean over the sphere is not exactly zero: rescale to the mean.
    let area = 4.0 * PI * params.radius_m * params.radius_m;
    let scale = h0 * area / film.flow.liquid_volume_m3();
    film.flow.h_m.iter_mut().for_each(|h| *h *= scale);
    // Start where a film of the mean thickness rests on its surfactant gradient
    // (ln Γ = ρ h̄ g·x/E_f): only the thickness pattern's excess weight then moves it, not
    // a whole-film sag in the first instants.
    if params.gibbs_elasticity_n_per_m > 0.0 {
        let k =
            params.film_density_kg_per_m3 * h0 * params.radius_m / params.gibbs_elasticity_n_per_m;
        let g = world.gravity_m_per_s2;
        film.flow.set_surfactant(|d| (k * g.dot(d)).exp());
    }
    if let Some(m) = params.meniscus {
        // The material frame is the world's at rest: up is against gravity.
        film.flow.stand_on_wet_surface(m, -world.gravity_m_per_s2);
    }
    film
}

fn initial_film_mass_kg(
    params: &BubbleParams,
    unit_positions: &[DVec3],
    area_fraction: &[f64],
    area_m2: f64,
) -> Vec<f64> {
    let pattern = SphereField::new(params.seed, 6, 0.0);
    let n = unit_positions.len() as f64;
    let mut mass: Vec<f64> = unit_positions
        .iter()
        .zip(area_fraction)
        .map(|(&u, &frac)| {
            let share = match params.mass_distribution {
                MassDistribution::AreaWeighted => frac,
                MassDistribution::Equal => 1.0 / n,
            };
            share * (1.0 + params.thickness_variation * pattern.value(u, 0.0))
        })
        .collect();
    let total = params.film_density_kg_per_m3 * params.mean_thickness_nm * 1e-9 * area_m2;
    let sum: f64 = mass.iter().sum();
    mass.iter_mut().for_each(|m| *m *= total / sum);
    mass
}

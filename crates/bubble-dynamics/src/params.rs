//! World and bubble parameters, SI units with the unit in every name, and their validation.

use glam::DVec3;

use crate::collider::Collider;
use crate::error::ParamError;
use crate::film_flow::{FilmGradient, Meniscus};
use crate::icosphere::MAX_SUBDIVISIONS;
use crate::validate::{finite_vec, non_negative, nonzero_vec, positive, unit_interval};
use crate::wind::Wind;

/// Standard gravity, m/s².
pub const STANDARD_GRAVITY_M_PER_S2: f64 = 9.806_65;
/// Standard atmosphere, Pa.
pub const STANDARD_PRESSURE_PA: f64 = 101_325.0;
/// Molar gas constant, J/(mol·K).
pub const GAS_CONSTANT_J_PER_MOL_K: f64 = 8.314_462_618;
/// Molar mass of dry air, kg/mol.
pub const AIR_MOLAR_MASS_KG_PER_MOL: f64 = 0.028_964_7;

/// How the time step is integrated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// Seed 000's scheme: every force explicit, positions advanced with the old velocity.
    /// Unconditionally unstable for undamped oscillation; kept for comparison.
    ExplicitEuler,
    /// Symplectic (semi-implicit) Euler: velocities first, then positions with the new
    /// velocity; the stiff ideal-gas mode and the drag are implicit (see docs/dynamics.md).
    #[default]
    SymplecticEuler,
}

/// How the film mass is first shared among the vertices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MassDistribution {
    /// Each vertex carries the film of its barycentric area: uniform rest thickness.
    #[default]
    AreaWeighted,
    /// Seed 000: every particle has the same mass; the rest thickness then varies with
    /// the icosphere's uneven vertex areas (its area-weighted mean is still the target).
    Equal,
}

/// Parameters shared by the whole world.
#[derive(Debug)]
pub struct WorldParams {
    /// Gravitational acceleration, m/s² (default −9.80665 ŷ: y is up).
    pub gravity_m_per_s2: DVec3,
    /// Ambient air pressure, Pa.
    pub p_out_pa: f64,
    /// Ambient air density, kg/m³ (drag, buoyancy, added mass).
    pub air_density_kg_per_m3: f64,
    /// Ambient air dynamic viscosity, Pa·s (the linear, Stokes-like drag).
    pub air_viscosity_pa_s: f64,
    /// Quadratic (form) drag coefficient C_d of a sphere, dimensionless.
    pub drag_coefficient: f64,
    /// Multiplier on the linear drag 6πμR (1 = Stokes' law, 0 = off), dimensionless.
    pub linear_drag_factor: f64,
    /// Added mass of the entrained air as a fraction of the displaced air (½ for a sphere
    /// in potential flow), dimensionless.
    pub added_mass_coefficient: f64,
    /// Whether the air's buoyancy and the gas's weight act (hydrostatic pressures).
    pub buoyancy: bool,
    /// Fixed time step, s (each step is split into automatic substeps).
    pub dt_s: f64,
    /// Time integrator.
    pub integrator: Integrator,
    /// Step of the film flow, s: the flow gathers world steps until this much time has
    /// passed (its stiff terms are implicit, so a display frame is one step).
    pub film_dt_s: f64,
    /// Largest number of substeps one step may take before it is an error.
    pub max_substeps: u32,
    /// Vertex speed judged to be an energy blow-up, m/s (default: speed of sound in air).
    pub max_speed_m_per_s: f64,
    /// Restitution of bubble–bubble contacts, in [0, 1]: the ratio of the centres of
    /// mass's relative normal speeds after and before.
    pub bubble_restitution: f64,
    /// Coulomb friction coefficient of bubble–bubble contacts.
    pub bubble_friction: f64,
    /// The air's motion.
    pub wind: Wind,
    /// Static obstacles.
    pub colliders: Vec<Collider>,
}

impl Default for WorldParams {
    fn default() -> Self {
        Self {
            gravity_m_per_s2: DVec3::new(0.0, -STANDARD_GRAVITY_M_PER_S2, 0.0),
            p_out_pa: STANDARD_PRESSURE_PA,
            air_density_kg_per_m3: 1.204,
            air_viscosity_pa_s: 1.81e-5,
            drag_coefficient: 0.47,
            linear_drag_factor: 1.0,
            added_mass_coefficient: 0.5,
            buoyancy: true,
            dt_s: 1.0 / 240.0,
            integrator: Integrator::SymplecticEuler,
            max_substeps: 2000,
            film_dt_s: 1.0 / 60.0,
            max_speed_m_per_s: 343.0,
            bubble_restitution: 0.5,
            bubble_friction: 0.1,
            wind: Wind::default(),
            colliders: Vec::new(),
        }
    }
}

impl WorldParams {
    pub(crate) fn validate(&self) -> Result<(), ParamError> {
        finite_vec("gravity_m_per_s2", self.gravity_m_per_s2)?;
        positive("p_out_pa", self.p_out_pa)?;
        non_negative("air_density_kg_per_m3", self.air_density_kg_per_m3)?;
        non_negative("air_viscosity_pa_s", self.air_viscosity_pa_s)?;
        non_negative("drag_coefficient", self.drag_coefficient)?;
        non_negative("linear_drag_factor", self.linear_drag_factor)?;
        non_negative("added_mass_coefficient", self.added_mass_coefficient)?;
        positive("dt_s", self.dt_s)?;
        positive("film_dt_s", self.film_dt_s)?;
        if self.max_substeps == 0 {
            return Err(ParamError::new(
                "max_substeps",
                self.max_substeps,
                "must be at least 1",
            ));
        }
        positive("max_speed_m_per_s", self.max_speed_m_per_s)?;
        unit_interval("bubble_restitution", self.bubble_restitution)?;
        non_negative("bubble_friction", self.bubble_friction)?;
        self.wind.validate().map_err(|e| e.within("wind"))?;
        for (i, c) in self.colliders.iter().enumerate() {
            c.validate()
                .map_err(|e| e.within(&format!("colliders[{i}]")))?;
        }
        Ok(())
    }
}

/// Largest film-flow grid: 6·512² cells, 1.6 M.
pub const MAX_FILM_GRID: usize = 512;
/// Largest `bottom_warming_k`, K: the film's temperature stays within tens of kelvin of
/// room temperature, where its constants (dσ/dθ, the vapour pressure's slope) hold.
pub const MAX_WARMING_K: f64 = 30.0;

/// Parameters of one bubble.
#[derive(Clone, Debug, PartialEq)]
pub struct BubbleParams {
    /// Initial centre, m.
    pub center_m: DVec3,
    /// Initial velocity of every vertex, m/s.
    pub velocity_m_per_s: DVec3,
    /// Rest radius (volume-equivalent), m.
    pub radius_m: f64,
    /// Rest mean film thickness (area-weighted), nm.
    pub mean_thickness_nm: f64,
    /// Icosphere subdivision level (3 = 642 vertices, 1280 triangles as in seed 000).
    pub subdivisions: u32,
    /// Surface tension of one film surface, N/m (the film has two).
    pub sigma_n_per_m: f64,
    /// Gibbs film elasticity E = dT/d ln A of the film tension T, N/m (0 = pure tension).
    pub gibbs_elasticity_n_per_m: f64,
    /// Seed 000's damping −γẋ per unit mass (γ/m), 1/s: slows the bubble through the air.
    pub damping_per_s: f64,
    /// Viscous damping of deformation only (motion relative to the rigid-body motion), 1/s.
    pub deformation_damping_per_s: f64,
    /// Density of the film liquid, kg/m³.
    pub film_density_kg_per_m3: f64,
    /// Effective viscosity of the lubrication drainage flux, Pa·s (see docs/dynamics.md).
    /// The default, 5e-8, is the per-vertex film's, which stands for its surfaces sliding
    /// too; a flowing film (`film_grid` > 0) moves its surfaces itself, and scene files
    /// give it 1e-6 (at 5e-8 it drains into a thick pool and its steps slow about
    /// tenfold).
    pub drainage_viscosity_pa_s: f64,
    /// Thickness below which the film ruptures, nm.
    pub rupture_thickness_nm: f64,
    /// Relative amplitude of the initial smooth random thickness variation, in [0, 1).
    pub thickness_variation: f64,
    /// Typical speed of the seeded swirling (sloshing) film flow, m/s (0 = none).
    pub slosh_speed_m_per_s: f64,
    /// Typical period over which the swirl pattern changes, s.
    pub slosh_period_s: f64,
    /// Evaporative thinning rate, nm/s (0 = none; removes film mass).
    pub evaporation_nm_per_s: f64,
    /// Molar mass of the gas inside, kg/mol (air 0.02896, helium 0.004).
    pub gas_molar_mass_kg_per_mol: f64,
    /// Temperature of the gas inside (isothermal), K.
    pub gas_temperature_k: f64,
    /// Initial per-axis stretch of the rest sphere; the gas amount is the rest sphere's,
    /// so a non-unit stretch starts the bubble wobbling.
    pub initial_scale: DVec3,
    /// How the film mass is first shared among the vertices.
    pub mass_distribution: MassDistribution,
    /// Seed of the initial thickness pattern and of the sloshing.
    pub seed: u64,
    /// Cells along a face of the film-flow cube-sphere (0: no flow; the per-vertex
    /// drainage and sloshing move the film instead). Must halve down to at most 8.
    pub film_grid: u32,
    /// Viscosity of the film liquid for the flow's viscous sheet stress, Pa·s.
    pub film_viscosity_pa_s: f64,
    /// Film-flow thickness under which the film turns black, nm (0: no black film).
    pub black_threshold_nm: f64,
    /// Thickness of the film-flow's common black film, nm.
    pub black_film_nm: f64,
    /// Rate of spontaneous holes per area of black film, 1/(m²·s) (film flow only).
    pub nucleation_per_m2_s: f64,
    /// How much warmer the air at the bubble's bottom is than at its top, K (film flow
    /// only; 0: isothermal). Drives thermal convection (docs/dynamics.md).
    pub bottom_warming_k: f64,
    /// The discrete gradient that drives the film flow (film flow only; default the
    /// two-point one, [`FilmGradient`]).
    pub film_gradient: FilmGradient,
    /// Stands the film on a wet surface, with a meniscus below its contact line that
    /// regenerates it (film flow only; `None`: a free bubble).
    pub meniscus: Option<Meniscus>,
}

impl Default for BubbleParams {
    fn default() -> Self {
        Self {
            center_m: DVec3::ZERO,
            velocity_m_per_s: DVec3::ZERO,
            radius_m: 0.05,
            mean_thickness_nm: 500.0,
            subdivisions: 3,
            sigma_n_per_m: 0.025,
            gibbs_elasticity_n_per_m: 0.05,
            damping_per_s: 0.0,
            deformation_damping_per_s: 10.0,
            film_density_kg_per_m3: 1000.0,
            drainage_viscosity_pa_s: 5.0e-8,
            rupture_thickness_nm: 10.0,
            thickness_variation: 0.2,
            slosh_speed_m_per_s: 0.002,
            slosh_period_s: 4.0,
            evaporation_nm_per_s: 0.0,
            gas_molar_mass_kg_per_mol: AIR_MOLAR_MASS_KG_PER_MOL,
            gas_temperature_k: 293.15,
            initial_scale: DVec3::ONE,
            mass_distribution: MassDistribution::AreaWeighted,
            seed: 0,
            film_grid: 0,
            film_viscosity_pa_s: 1.0e-3,
            black_threshold_nm: 30.0,
            black_film_nm: 12.0,
            nucleation_per_m2_s: 0.0,
            bottom_warming_k: 0.0,
            film_gradient: FilmGradient::TwoPoint,
            meniscus: None,
        }
    }
}

impl BubbleParams {
    pub(crate) fn validate(&self) -> Result<(), ParamError> {
        finite_vec("center_m", self.center_m)?;
        finite_vec("velocity_m_per_s", self.velocity_m_per_s)?;
        positive("radius_m", self.radius_m)?;
        positive("mean_thickness_nm", self.mean_thickness_nm)?;
        if self.subdivisions > MAX_SUBDIVISIONS {
            return Err(ParamError::new(
                "subdivisions",
                self.subdivisions,
                format!("must be at most {MAX_SUBDIVISIONS}"),
            ));
        }
        positive("sigma_n_per_m", self.sigma_n_per_m)?;
        non_negative("gibbs_elasticity_n_per_m", self.gibbs_elasticity_n_per_m)?;
        non_negative("damping_per_s", self.damping_per_s)?;
        non_negative("deformation_damping_per_s", self.deformation_damping_per_s)?;
        positive("film_density_kg_per_m3", self.film_density_kg_per_m3)?;
        positive("drainage_viscosity_pa_s", self.drainage_viscosity_pa_s)?;
        non_negative("rupture_thickness_nm", self.rupture_thickness_nm)?;
        if self.rupture_thickness_nm >= self.mean_thickness_nm {
            return Err(ParamError::new(
                "rupture_thickness_nm",
                self.rupture_thickness_nm,
                format!(
                    "must be below mean_thickness_nm = {}",
                    self.mean_thickness_nm
                ),
            ));
        }
        if !(0.0..1.0).contains(&self.thickness_variation) {
            return Err(ParamError::new(
                "thickness_variation",
                self.thickness_variation,
                "must lie in [0, 1)",
            ));
        }
        non_negative("slosh_speed_m_per_s", self.slosh_speed_m_per_s)?;
        positive("slosh_period_s", self.slosh_period_s)?;
        non_negative("evaporation_nm_per_s", self.evaporation_nm_per_s)?;
        positive("gas_molar_mass_kg_per_mol", self.gas_molar_mass_kg_per_mol)?;
        positive("gas_temperature_k", self.gas_temperature_k)?;
        nonzero_vec("initial_scale", self.initial_scale)?;
        let grid = self.film_grid as usize;
        if grid > MAX_FILM_GRID || (grid > 0 && !crate::film_flow::Hierarchy::supports(grid)) {
            return Err(ParamError::new(
                "film_grid",
                self.film_grid,
                format!(
                    "must be 0 (off) or at most {MAX_FILM_GRID}, halving down to 8 or less (e.g. 32, 64, 128, 256)"
                ),
            ));
        }
        non_negative("film_viscosity_pa_s", self.film_viscosity_pa_s)?;
        non_negative("black_threshold_nm", self.black_threshold_nm)?;
        non_negative("black_film_nm", self.black_film_nm)?;
        if self.black_threshold_nm > 0.0 && self.black_film_nm >= self.black_threshold_nm {
            return Err(ParamError::new(
                "black_film_nm",
                self.black_film_nm,
                format!(
                    "must be below black_threshold_nm = {}",
                    self.black_threshold_nm
                ),
            ));
        }
        non_negative("nucleation_per_m2_s", self.nucleation_per_m2_s)?;
        if !(self.bottom_warming_k.is_finite() && self.bottom_warming_k.abs() <= MAX_WARMING_K) {
            return Err(ParamError::new(
                "bottom_warming_k",
                self.bottom_warming_k,
                format!("must lie in [-{MAX_WARMING_K}, {MAX_WARMING_K}] K"),
            ));
        }
        if let Some(m) = self.meniscus {
            if let Some((name, value)) = m.invalid() {
                return Err(ParamError::new(
                    format!("meniscus.{name}"),
                    value,
                    "is out of range (contact_height in (-1, 1), regeneration_per_m_s >= 0, \
                     regenerated_fraction in (0, 1], patch_radius_m > 0)",
                ));
            }
            if self.film_grid == 0 {
                return Err(ParamError::new(
                    "meniscus",
                    self.film_grid,
                    "needs the film flow (film_grid > 0)",
                ));
            }
        }
        if self.initial_scale.min_element() <= 0.0 {
            return Err(ParamError::new(
                "initial_scale",
                self.initial_scale.to_array(),
                "must have positive components",
            ));
        }
        Ok(())
    }
}

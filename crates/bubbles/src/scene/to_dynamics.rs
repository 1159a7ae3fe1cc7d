//! Scene → `bubble_dynamics::World`.

use super::Scene;
use super::schema::{BubbleSpec, ObjectSpec};
use crate::error::CliError;
use bubble_dynamics::{BubbleParams, Collider, DVec3, Gusts, Integrator, Wind, World, WorldParams};

impl Scene {
    /// Builds the solver's world: the bubbles, the ground and box/sphere objects as colliders.
    pub fn dynamics_world(&self) -> Result<World, CliError> {
        let bubbles = self.file.bubbles.iter().map(bubble_params).collect();
        World::try_new(self.world_params()?, bubbles)
            .map_err(|e| CliError::input(format!("{}: {e}", self.origin)))
    }

    fn world_params(&self) -> Result<WorldParams, CliError> {
        let defaults = WorldParams::default();
        let d = &self.file.dynamics;
        let integrator = match d.integrator.as_deref() {
            None | Some("symplectic-euler") => Integrator::SymplecticEuler,
            Some("explicit-euler") => Integrator::ExplicitEuler,
            Some(other) => {
                return Err(CliError::input(format!(
                    "{}: unknown integrator {other:?}: use symplectic-euler or explicit-euler",
                    self.origin
                )));
            }
        };
        Ok(WorldParams {
            gravity_m_per_s2: d
                .gravity_m_per_s2
                .map_or(defaults.gravity_m_per_s2, |g| dvec(g.get())),
            dt_s: d.dt_s.map_or(defaults.dt_s, |v| v.get()),
            integrator,
            wind: self.wind(),
            colliders: self.colliders(),
            ..defaults
        })
    }

    fn wind(&self) -> Wind {
        let w = &self.file.wind;
        let uniform = w.velocity_m_per_s.map_or(DVec3::ZERO, |v| dvec(v.get()));
        let gusts = Gusts {
            amplitude_m_per_s: w.gust_m_per_s.map_or(0.0, |a| a.get()),
            seed: w.seed,
            ..Gusts::default()
        };
        Wind::uniform(uniform).with_gusts(gusts)
    }

    fn colliders(&self) -> Vec<Collider> {
        let ground = self
            .file
            .ground
            .iter()
            .map(|g| Collider::ground(g.height_m.get()));
        let objects = self.file.objects.iter().filter_map(|o| match o {
            ObjectSpec::Sphere {
                center_m, radius_m, ..
            } => Some(Collider::sphere(dvec(center_m.get()), radius_m.get())),
            ObjectSpec::Box { min_m, max_m, .. } => {
                Some(Collider::cuboid(dvec(min_m.get()), dvec(max_m.get())))
            }
            // Meshes are drawn but do not collide: the solver has no mesh collider.
            ObjectSpec::Mesh { .. } => None,
        });
        ground.chain(objects).collect()
    }
}

/// The solver's parameters for one bubble of the scene file.
pub(crate) fn bubble_params(spec: &BubbleSpec) -> BubbleParams {
    let defaults = BubbleParams::default();
    BubbleParams {
        center_m: dvec(spec.center_m.get()),
        velocity_m_per_s: dvec(spec.velocity_m_per_s.get()),
        radius_m: spec.radius_m.get(),
        mean_thickness_nm: spec.mean_thickness_nm.get(),
        subdivisions: spec.subdivisions,
        sigma_n_per_m: spec
            .sigma_n_per_m
            .map_or(defaults.sigma_n_per_m, |v| v.get()),
        damping_per_s: spec
            .damping_per_s
            .map_or(defaults.damping_per_s, |v| v.get()),
        seed: spec.seed,
        gibbs_elasticity_n_per_m: or(
            spec.gibbs_elasticity_n_per_m.map(|v| v.get()),
            defaults.gibbs_elasticity_n_per_m,
        ),
        drainage_viscosity_pa_s: or(
            spec.drainage_viscosity_pa_s.map(|v| v.get()),
            defaults.drainage_viscosity_pa_s,
        ),
        rupture_thickness_nm: or(
            spec.rupture_thickness_nm.map(|v| v.get()),
            defaults.rupture_thickness_nm,
        ),
        thickness_variation: or(
            spec.thickness_variation.map(|v| v.get()),
            defaults.thickness_variation,
        ),
        slosh_speed_m_per_s: or(
            spec.slosh_speed_m_per_s.map(|v| v.get()),
            defaults.slosh_speed_m_per_s,
        ),
        evaporation_nm_per_s: or(
            spec.evaporation_nm_per_s.map(|v| v.get()),
            defaults.evaporation_nm_per_s,
        ),
        gas_molar_mass_kg_per_mol: or(
            spec.gas_molar_mass_kg_per_mol.map(|v| v.get()),
            defaults.gas_molar_mass_kg_per_mol,
        ),
        ..defaults
    }
}

fn or(value: Option<f64>, default: f64) -> f64 {
    value.unwrap_or(default)
}

fn dvec(v: [f64; 3]) -> DVec3 {
    DVec3::from_array(v)
}

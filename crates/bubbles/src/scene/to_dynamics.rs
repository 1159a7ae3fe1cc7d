//! Scene → `bubble_dynamics::World`.

use super::Scene;
use super::schema::{BubbleSpec, FilmGradientSpec, MeniscusSpec, ObjectSpec};
use super::values::{numbers, plain};
use crate::error::CliError;
use crate::limits;
use bubble_dynamics::film_flow::{FilmGradient, Meniscus};
use bubble_dynamics::{
    BubbleParams, Collider, DVec3, Gusts, Integrator, SimError, Wind, World, WorldParams,
};

impl Scene {
    /// Builds the solver's world: the bubbles, the ground, box/sphere objects and the
    /// water's rest plane as colliders.
    pub fn dynamics_world(&self) -> Result<World, CliError> {
        let grid = default_film_grid(&self.file.bubbles);
        let bubbles = self
            .file
            .bubbles
            .iter()
            .map(|b| bubble_params(b, grid))
            .collect();
        World::try_new(self.world_params()?, bubbles).map_err(|e| {
            let message = scene_names(&e.to_string(), &self.collider_names());
            CliError::input(format!("{}: {message}", self.origin))
        })
    }

    /// The scene's name for each solver collider, in [`Scene::colliders`]'s order.
    fn collider_names(&self) -> Vec<String> {
        // Each name carries the keys that place the collider: a refusal caused by a
        // bad ground height or box corner must name the key the user wrote.
        let ground = self
            .file
            .ground
            .iter()
            .map(|g| format!("the ground (ground.height_m = {})", plain(g.height_m.get())));
        let objects = self.file.objects.iter().enumerate().filter_map(|(i, o)| {
            let place = match o {
                ObjectSpec::Sphere {
                    center_m, radius_m, ..
                } => format!(
                    "sphere, center_m = {}, radius_m = {}",
                    numbers(&center_m.get()),
                    plain(radius_m.get())
                ),
                ObjectSpec::Box { min_m, max_m, .. } => format!(
                    "box, min_m = {}, max_m = {}",
                    numbers(&min_m.get()),
                    numbers(&max_m.get())
                ),
                ObjectSpec::Mesh { .. } => return None,
            };
            Some(format!("[[objects]] #{} ({place})", i + 1))
        });
        let water = self.file.water.iter().map(|w| {
            format!(
                "the water's rest plane (water.rest_height_m = {})",
                plain(w.rest_height_m.get())
            )
        });
        ground.chain(objects).chain(water).collect()
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
            film_dt_s: d.film_dt_s.map_or(defaults.film_dt_s, |v| v.get()),
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
        // Bubbles bounce on the water's rest plane, everywhere (the solver's planes are
        // infinite): a wave's height is not felt.
        let water = self
            .file
            .water
            .iter()
            .map(|w| Collider::ground(w.rest_height_m.get()));
        ground.chain(objects).chain(water).collect()
    }
}

/// A scene bubble's film-flow grid when its entry gives none: every bubble's film flows
/// unless its scene says `film_grid = 0`. 6 × 32² cells resolve a 5 cm bubble's film at
/// 2.5 mm, and a step costs about a sixth of n = 64's (docs/dynamics.md, "Film flow").
pub(crate) const SCENE_FILM_GRID: u32 = 32;

/// A flowing film's drainage viscosity when its entry gives none, Pa·s. The per-vertex
/// film's 5e-8 stands for the whole film sliding down, its surfaces too; the flow moves
/// the surfaces itself, so only the liquid's drainage between them is left. At 5e-8 the
/// flow drained every scene bubble's liquid into a pool tens of µm thick at its bottom
/// within two seconds, and its steps then ran at their sub-step limits (8 s of `paper`
/// took 49 s, against 6 s at this value); `swirl`'s colour bands drain at it over its 12 s.
pub(crate) const FLOW_DRAINAGE_VISCOSITY_PA_S: f64 = 1e-6;

/// The film grid of the scene's bubbles that give none: [`SCENE_FILM_GRID`], or the
/// largest of 16 and 8 that keeps the scene's film cells (those given included) within
/// the limit, or 0 (the per-vertex film) when even 8 would not. A scene of many bubbles
/// written before films flowed then still loads: at 32 a 257-bubble scene would
/// have gone over the limit.
pub(crate) fn default_film_grid(bubbles: &[BubbleSpec]) -> u32 {
    let defaulted = bubbles.iter().filter(|b| b.film_grid.is_none()).count();
    let room = limits::MAX_FILM_CELLS.saturating_sub(given_film_cells(bubbles));
    [SCENE_FILM_GRID, 16, 8]
        .into_iter()
        .find(|&n| defaulted * limits::film_cells(n) <= room)
        .unwrap_or(0)
}

/// Film-flow cells of the bubbles that give their `film_grid`, summed.
pub(crate) fn given_film_cells(bubbles: &[BubbleSpec]) -> usize {
    bubbles
        .iter()
        .filter_map(|b| b.film_grid)
        .map(|n| limits::film_cells(n.get()))
        .sum()
}

/// The solver's parameters for one bubble of the scene file, `default_grid` its film
/// grid if it gives none ([`default_film_grid`]).
pub(crate) fn bubble_params(spec: &BubbleSpec, default_grid: u32) -> BubbleParams {
    let defaults = BubbleParams::default();
    let film_grid = spec.film_grid.map_or(default_grid, |v| v.get());
    BubbleParams {
        center_m: dvec(spec.center_m.get()),
        velocity_m_per_s: dvec(spec.velocity_m_per_s.get()),
        radius_m: spec.radius_m.get(),
        mean_thickness_nm: spec.mean_thickness_nm.get(),
        subdivisions: spec.subdivisions.get(),
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
            if film_grid > 0 {
                FLOW_DRAINAGE_VISCOSITY_PA_S
            } else {
                defaults.drainage_viscosity_pa_s
            },
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
        initial_scale: spec
            .initial_scale
            .map_or(defaults.initial_scale, |v| dvec(v.get())),
        film_grid,
        film_viscosity_pa_s: or(
            spec.film_viscosity_pa_s.map(|v| v.get()),
            defaults.film_viscosity_pa_s,
        ),
        black_threshold_nm: or(
            spec.black_threshold_nm.map(|v| v.get()),
            defaults.black_threshold_nm,
        ),
        black_film_nm: or(spec.black_film_nm.map(|v| v.get()), defaults.black_film_nm),
        nucleation_per_m2_s: or(
            spec.nucleation_per_m2_s.map(|v| v.get()),
            defaults.nucleation_per_m2_s,
        ),
        bottom_warming_k: or(
            spec.bottom_warming_k.map(|v| v.get()),
            defaults.bottom_warming_k,
        ),
        film_gradient: spec
            .film_gradient
            .map_or(defaults.film_gradient, |g| match g {
                FilmGradientSpec::TwoPoint => FilmGradient::TwoPoint,
                FilmGradientSpec::Normal => FilmGradient::Normal,
            }),
        meniscus: spec.meniscus.as_ref().map(meniscus),
        ..defaults
    }
}

/// A `[bubbles.meniscus]`, each field omitted taken from [`Meniscus::hemisphere`].
fn meniscus(spec: &MeniscusSpec) -> Meniscus {
    let d = Meniscus::hemisphere();
    Meniscus {
        contact_height: or(spec.contact_height.map(|v| v.get()), d.contact_height),
        regeneration_per_m_s: or(
            spec.regeneration_per_m_s.map(|v| v.get()),
            d.regeneration_per_m_s,
        ),
        regenerated_fraction: or(
            spec.regenerated_fraction.map(|v| v.get()),
            d.regenerated_fraction,
        ),
        patch_radius_m: or(spec.patch_radius_m.map(|v| v.get()), d.patch_radius_m),
    }
}

fn or(value: Option<f64>, default: f64) -> f64 {
    value.unwrap_or(default)
}

fn dvec(v: [f64; 3]) -> DVec3 {
    DVec3::from_array(v)
}

/// Replaces the solver's `bubbles[i]` and `colliders[k]` with the scene's own names:
/// `[[bubbles]] #i+1` and `colliders[k]` (the ground or an object).
fn scene_names(message: &str, colliders: &[String]) -> String {
    let mut out = String::new();
    let mut rest = message;
    while let Some(start) = rest.find(['b', 'c']) {
        out.push_str(&rest[..start]);
        rest = &rest[start..];
        let named = ["bubbles[", "colliders["].iter().find_map(|prefix| {
            let tail = rest.strip_prefix(prefix)?;
            let end = tail.find(']')?;
            let index: usize = tail[..end].parse().ok()?;
            let name = if prefix.starts_with('b') {
                format!("[[bubbles]] #{}", index + 1)
            } else {
                colliders.get(index)?.clone()
            };
            Some((name, prefix.len() + end + 1))
        });
        match named {
            Some((name, len)) => {
                out.push_str(&name);
                rest = &rest[len..];
            }
            None => {
                out.push_str(&rest[..1]);
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// A solver failure as the user's error: a time step too coarse for a bubble is bad
/// input (exit code 2, naming `dynamics.dt_s`); a divergence is a runtime failure.
pub fn sim_error(scene: &Scene, error: SimError) -> CliError {
    match error {
        SimError::TooManySubsteps {
            bubble_id,
            needed,
            limit,
            ..
        } => {
            let needed = if needed == u64::MAX {
                "an unbounded number of".to_string()
            } else {
                needed.to_string()
            };
            CliError::input(format!(
                "{}: dynamics.dt_s = {} s is too coarse for [[bubbles]] #{}: it needs {needed} substeps per step, above the solver's {limit}; lower dt_s, or check that bubble's radius_m, sigma_n_per_m and mean_thickness_nm",
                scene.origin,
                scene
                    .file
                    .dynamics
                    .dt_s
                    .map_or(WorldParams::default().dt_s, |v| v.get()),
                bubble_id + 1
            ))
        }
        other => CliError::runtime(format!(
            "{}: simulation failed: {}",
            scene.origin,
            scene_names(&other.to_string(), &[])
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene of `count` bubbles 12 cm apart on a row, `extra` added to each entry.
    fn row_of_bubbles(count: usize, extra: &str) -> Scene {
        let mut text =
            String::from("[camera]\neye_m = [0.0, 0.5, 2.0]\ntarget_m = [0.0, 0.5, 0.0]\n");
        for k in 0..count {
            text.push_str(&format!(
                "[[bubbles]]\ncenter_m = [{}, 0.5, 0.0]\nradius_m = 0.05\n{extra}\n",
                0.12 * k as f64
            ));
        }
        Scene::from_toml_str(&text, "test", std::path::Path::new(".")).unwrap()
    }

    #[test]
    fn film_gradient_is_two_point_unless_the_bubble_asks_for_normal() {
        let gradient = |extra: &str| {
            let scene = row_of_bubbles(1, extra);
            bubble_params(&scene.file.bubbles[0], SCENE_FILM_GRID).film_gradient
        };
        assert_eq!(gradient(""), FilmGradient::TwoPoint);
        assert_eq!(
            gradient("film_gradient = \"two-point\""),
            FilmGradient::TwoPoint
        );
        assert_eq!(gradient("film_gradient = \"normal\""), FilmGradient::Normal);
    }

    /// Regression: at a fixed default of 32, a scene of 257 or more bubbles that gives no
    /// film grid, valid before films flowed, would hold more film cells than the limit.
    #[test]
    fn many_bubbles_without_a_film_grid_get_a_coarser_one_within_the_limit() {
        let grid = |count: usize, extra: &str| {
            default_film_grid(&row_of_bubbles(count, extra).file.bubbles)
        };
        assert_eq!(grid(2, ""), SCENE_FILM_GRID);
        assert_eq!(grid(256, ""), 32);
        assert_eq!(grid(257, ""), 16);
        assert_eq!(grid(1000, ""), 16);
        // Grids given count against the limit first: three at 256 leave room for 300
        // bubbles at 8 but not at 16; four leave none.
        let mixed = |given: usize| {
            let mut bubbles = row_of_bubbles(given, "film_grid = 256").file.bubbles;
            bubbles.extend(row_of_bubbles(300, "").file.bubbles);
            default_film_grid(&bubbles)
        };
        assert_eq!(mixed(3), 8);
        assert_eq!(mixed(4), 0);
        let world = row_of_bubbles(300, "").dynamics_world().unwrap();
        let cells: usize = world
            .bubbles()
            .iter()
            .map(|b| b.film_flow().map_or(0, |f| f.grid().cells()))
            .sum();
        assert!(cells <= limits::MAX_FILM_CELLS, "{cells} film cells");
        assert!(cells > 0, "no bubble's film flows");
    }

    #[test]
    fn solver_names_become_the_scene_names() {
        let names = vec!["the ground".to_string(), "[[objects]] #2 (box)".to_string()];
        let message = "bubbles[1].center_m = [0.0, 0.1, 0.0] is 0.0100 m from colliders[1], closer";
        assert_eq!(
            scene_names(message, &names),
            "[[bubbles]] #2.center_m = [0.0, 0.1, 0.0] is 0.0100 m from [[objects]] #2 (box), closer"
        );
        assert_eq!(
            scene_names("colliders[7] bubbles[x]", &names),
            "colliders[7] bubbles[x]"
        );
    }
}

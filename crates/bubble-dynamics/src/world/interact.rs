//! Changes from outside between steps (an interactive viewer): add a bubble, poke one,
//! set the steady wind.

use glam::DVec3;

use super::{World, unit_meshes};
use crate::bubble::Bubble;
use crate::error::ParamError;
use crate::params::BubbleParams;

/// Fraction of a bubble's radius over which a poke's impulse is spread (a fingertip, not
/// a needle: one vertex alone would take the whole impulse and tear the mesh).
const POKE_SPREAD_PER_RADIUS: f64 = 0.5;

impl World {
    /// Adds a bubble at the current time and returns its id (ids are never reused).
    ///
    /// # Errors
    /// A [`ParamError`] naming the bad value, or `center_m` when the new bubble would
    /// overlap a living bubble or a collider.
    pub fn try_add_bubble(&mut self, params: BubbleParams) -> Result<u64, ParamError> {
        params.validate()?;
        let meshes = unit_meshes(std::slice::from_ref(&params));
        let mesh = &meshes[&params.subdivisions];
        let reach =
            mesh.circumradius_per_radius * params.radius_m * params.initial_scale.max_element();
        for b in &self.bubbles {
            let gap = b.center_m().distance(params.center_m);
            let other = farthest_vertex_m(b);
            if gap < reach + other {
                return Err(ParamError::new(
                    "center_m",
                    params.center_m,
                    format!(
                        "overlaps bubble {} ({gap:.4} m apart, reach {:.4} m)",
                        b.id,
                        reach + other
                    ),
                ));
            }
        }
        for (k, c) in self.params.colliders.iter().enumerate() {
            let (d, _) = c.signed_distance_m(params.center_m);
            if d < reach {
                return Err(ParamError::new(
                    "center_m",
                    params.center_m,
                    format!("overlaps collider {k} (distance {d:.4} m, reach {reach:.4} m)"),
                ));
            }
        }
        let id = self.next_id;
        let bubble = Bubble::new(
            id,
            &params,
            &self.params,
            std::sync::Arc::clone(&mesh.topology),
            &mesh.unit_positions,
        );
        self.bubbles.push(bubble);
        self.next_id += 1;
        Ok(id)
    }

    /// Gives bubble `bubble_id` the impulse `impulse_kg_m_per_s`, spread over the vertices
    /// near `point_m` with weights falling linearly to zero at half its radius; the
    /// bubble's momentum changes by exactly the impulse. Returns false (and changes
    /// nothing) when no such bubble lives or an input is not finite.
    pub fn poke(&mut self, bubble_id: u64, point_m: DVec3, impulse_kg_m_per_s: DVec3) -> bool {
        if !(point_m.is_finite() && impulse_kg_m_per_s.is_finite()) {
            return false;
        }
        let Some(b) = self.bubbles.iter_mut().find(|b| b.id == bubble_id) else {
            return false;
        };
        let spread_m = POKE_SPREAD_PER_RADIUS * b.radius_m();
        let nearest_m = b
            .positions_m
            .iter()
            .map(|x| x.distance(point_m))
            .fold(f64::INFINITY, f64::min);
        // Measured from the nearest vertex, so a point off the surface still pokes.
        let weights: Vec<f64> = b
            .positions_m
            .iter()
            .map(|x| (1.0 - (x.distance(point_m) - nearest_m) / spread_m).max(0.0))
            .collect();
        let weighted_mass_kg: f64 = weights
            .iter()
            .zip(&b.inertial_mass_kg)
            .map(|(w, m)| w * m)
            .sum();
        if weighted_mass_kg.is_nan() || weighted_mass_kg <= 0.0 {
            return false;
        }
        let dv_per_weight = impulse_kg_m_per_s / weighted_mass_kg;
        for (v, w) in b.velocities_m_per_s.iter_mut().zip(&weights) {
            *v += dv_per_weight * *w;
        }
        true
    }

    /// The steady part of the wind, m/s.
    pub fn uniform_wind_m_per_s(&self) -> DVec3 {
        self.wind.uniform_m_per_s()
    }

    /// Replaces the steady part of the wind (gusts and a user field stay).
    ///
    /// # Errors
    /// A [`ParamError`] naming `uniform_m_per_s` when it is not finite.
    pub fn set_uniform_wind_m_per_s(&mut self, velocity_m_per_s: DVec3) -> Result<(), ParamError> {
        if !velocity_m_per_s.is_finite() {
            return Err(ParamError::new(
                "uniform_m_per_s",
                velocity_m_per_s,
                "must be finite",
            ));
        }
        self.wind.set_uniform_m_per_s(velocity_m_per_s);
        Ok(())
    }
}

fn farthest_vertex_m(b: &Bubble) -> f64 {
    let c = b.center_m();
    b.positions_m
        .iter()
        .map(|x| x.distance(c))
        .fold(0.0, f64::max)
}

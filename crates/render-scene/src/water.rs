//! [`WaterSurface`]: a water mesh to draw (geometry from elsewhere, e.g. the `water` crate)
//! and its optics: Snell refraction onto a floor plane with Beer–Lambert absorption,
//! reflection, and the exact unpolarised Fresnel blend of one interface from `thinfilm`.

use glam::Vec3;
use num_complex::Complex64;
use thinfilm::fresnel::Interface;

use crate::environment::check_rgb;
use crate::mesh::{check_triangles, check_vertices};
use crate::{Material, RenderError};

/// Refractive index of water used when a scene gives none.
pub const WATER_IOR: f32 = 1.333;

/// A water surface: an upward-facing mesh over a flat floor `floor_depth_m` below its
/// rest plane, seen through water of index `ior` that absorbs `absorption_per_m`.
#[derive(Debug, Clone, PartialEq)]
pub struct WaterSurface {
    /// Vertex positions in metres.
    pub positions: Vec<Vec3>,
    /// Upward vertex normals (normalised per pixel).
    pub normals: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Height of the unperturbed surface, in metres: the mirror plane of the reflection
    /// cube map and the reference for the floor depth.
    pub rest_height_m: f32,
    /// Refractive index of the water (air is 1).
    pub ior: f32,
    /// Depth of the floor below the rest plane, in metres.
    pub floor_depth_m: f32,
    /// The floor's surface (its pattern repeats along X and Z as on the ground).
    pub floor: Material,
    /// Beer–Lambert absorption coefficient per metre of water path, per channel.
    pub absorption_per_m: [f32; 3],
}

impl WaterSurface {
    /// Height of the floor plane, in metres.
    pub fn floor_height_m(&self) -> f32 {
        self.rest_height_m - self.floor_depth_m
    }

    /// Checks the surface's mesh, indices and numbers, naming the first bad one.
    pub fn validate(&self) -> Result<(), RenderError> {
        let what = "water";
        if self.normals.len() != self.positions.len() {
            return Err(RenderError::scene(
                what,
                format!(
                    "{} positions but {} normals",
                    self.positions.len(),
                    self.normals.len()
                ),
            ));
        }
        check_vertices(what, &self.positions, &self.normals)?;
        check_triangles(what, &self.triangles, self.positions.len())?;
        let scalars = [
            ("rest_height_m", self.rest_height_m, f32::MIN),
            ("ior", self.ior, 0.0),
            ("floor_depth_m", self.floor_depth_m, 0.0),
        ];
        for (name, v, above) in scalars {
            if !(v.is_finite() && v > above) {
                return Err(RenderError::scene(
                    what,
                    format!("{name} {v} must be finite and > {above}"),
                ));
            }
        }
        check_rgb("water absorption_per_m", self.absorption_per_m)?;
        self.floor.validate("water floor")
    }
}

/// Snell refraction of unit direction `incident` at a surface with unit normal `normal`
/// facing the incident side (`incident · normal < 0`), for index ratio
/// `eta = n_incident / n_transmitted`; `None` under total internal reflection.
#[inline]
pub fn refract(incident: Vec3, normal: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -incident.dot(normal);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(incident * eta + normal * (eta * cos_i - cos_t))
}

/// Seed 002 listing 1: texture coordinates `((r_x + 1)/2, (r_y + 1)/2)` of a reflected
/// direction `r_view` in view space (x right, y up, z towards the viewer), normalised
/// first; `r_z` is dropped, as in the seed. `v` counts up from the image's bottom row.
///
/// Convention: `r_view` is the physical reflected ray, `d − 2(d·n)n` for the incident
/// ray `d` from the eye to the surface. Seed 002 starts from the inverted incident ray
/// `c = −d` (surface to eye, for drawing rays while debugging) but then takes
/// `2(c·n)n − c`, the reflection of `c` about the normal line, which is the same vector:
/// the map is not mirrored. Any finite direction lands in `[0, 1]²`; a zero or
/// non-finite one lands at the centre.
#[inline]
pub fn sphere_map_uv(r_view: Vec3) -> [f32; 2] {
    let r = r_view.normalize_or_zero();
    [
        ((r.x + 1.0) * 0.5).clamp(0.0, 1.0),
        ((r.y + 1.0) * 0.5).clamp(0.0, 1.0),
    ]
}

/// The view-space direction a seed 002 texture coordinate stands for: `(x, y)` from
/// [`sphere_map_uv`] and the `z` it dropped, taken on the far side (`z ≤ 0`, away from
/// the viewer, where a reflection of the water seen from above points). Outside the
/// unit disc, the rim.
#[inline]
pub fn sphere_map_direction(uv: [f32; 2]) -> Vec3 {
    let (x, y) = (2.0 * uv[0] - 1.0, 2.0 * uv[1] - 1.0);
    let r2 = x * x + y * y;
    if r2 >= 1.0 {
        return Vec3::new(x, y, 0.0).normalize_or(Vec3::NEG_Z);
    }
    Vec3::new(x, y, -(1.0 - r2).sqrt())
}

/// Samples of the exact unpolarised reflectance `R(cos θ)` of one interface, linearly
/// interpolated (tabulated from `thinfilm` once per frame: per pixel it would cost a
/// complex f64 Fresnel evaluation).
#[derive(Debug, Clone, PartialEq)]
pub struct FresnelTable {
    r: Vec<f32>,
}

/// Intervals of [`FresnelTable`] over `cos θ ∈ [0, 1]` (the GPU backend reads the table
/// with the same count, injected into its shader).
pub const FRESNEL_STEPS: usize = 1024;

impl FresnelTable {
    /// `R(cos θ)` from a medium of index `n_incident` into one of `n_transmitted`.
    ///
    /// # Panics
    /// If either index is not finite and positive (callers pass validated indices).
    pub fn new(n_incident: f32, n_transmitted: f32) -> Self {
        let interface = Interface::new(
            f64::from(n_incident),
            Complex64::new(f64::from(n_transmitted), 0.0),
        )
        .unwrap_or_else(|e| panic!("water Fresnel interface: {e}"));
        let r = (0..=FRESNEL_STEPS)
            .map(|i| interface.response(i as f64 / FRESNEL_STEPS as f64).r() as f32)
            .collect();
        Self { r }
    }

    /// The table's samples: `R` at `cos θ = i / FRESNEL_STEPS`, `i = 0 ..= FRESNEL_STEPS`
    /// (what the GPU backend uploads and interpolates as [`FresnelTable::reflectance`]).
    pub fn samples(&self) -> &[f32] {
        &self.r
    }

    /// Unpolarised reflectance at `cos_theta` (clamped to `[0, 1]`; NaN reads as grazing).
    #[inline]
    pub fn reflectance(&self, cos_theta: f32) -> f32 {
        let x = if cos_theta >= 0.0 {
            cos_theta.min(1.0)
        } else {
            0.0
        } * FRESNEL_STEPS as f32;
        let i = (x as usize).min(FRESNEL_STEPS - 1);
        let t = x - i as f32;
        self.r[i] + (self.r[i + 1] - self.r[i]) * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_table_matches_thinfilm_between_its_nodes() {
        for (n1, n2) in [(1.0, 1.333), (1.333, 1.0)] {
            let table = FresnelTable::new(n1, n2);
            let exact = Interface::new(f64::from(n1), Complex64::new(f64::from(n2), 0.0)).unwrap();
            for k in 0..=997 {
                let c = k as f64 / 997.0;
                let want = exact.response(c).r();
                let got = f64::from(table.reflectance(c as f32));
                // Linear interpolation error ≤ h²/8·|R''|, worst at the critical angle.
                let tol = if n1 > n2 { 2e-2 } else { 1e-5 };
                assert!(
                    (got - want).abs() < tol,
                    "n {n1}->{n2} cos {c}: {got} vs {want}"
                );
            }
        }
        let normal = FresnelTable::new(1.0, 1.333).reflectance(1.0);
        let want = ((1.333f32 - 1.0) / (1.333 + 1.0)).powi(2);
        assert!((normal - want).abs() < 1e-6, "R(0°) {normal} vs {want}");
    }
}

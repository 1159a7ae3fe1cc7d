//! [`WaterShading`]: what a water pixel must equal: the exact Fresnel blend of the
//! reflected scene and the floor refracted through the water with Beer–Lambert absorption
//! (docs/water.md).

use glam::{Mat3, Vec3};

use crate::shading::{ground_albedo, lit_facing};
use crate::water::{FresnelTable, refract, sphere_map_direction, sphere_map_uv};
use crate::{CubeMap, Environment, Light, SphereMap, WaterSurface};

/// Where the water's reflections come from.
#[derive(Debug, Clone, Copy)]
pub enum WaterReflection<'a> {
    /// The cube map seen from the mirrored eye.
    Cube(&'a CubeMap),
    /// The environment alone.
    Env(&'a Environment),
    /// A sphere map read through seed 002's view-space coordinates (`eye_from_world`).
    Sphere(&'a SphereMap, Mat3),
}

impl WaterReflection<'_> {
    /// Radiance reflected along unit `dir`.
    #[inline]
    pub fn sample(&self, dir: Vec3) -> [f32; 3] {
        match self {
            Self::Cube(c) => c.sample(dir),
            Self::Env(e) => e.radiance(dir),
            Self::Sphere(map, eye_from_world) => {
                // Seed 002's coordinates, read back as the direction they stand for.
                let uv = sphere_map_uv(*eye_from_world * dir);
                map.sample(eye_from_world.transpose() * sphere_map_direction(uv))
            }
        }
    }
}

/// Everything a water pixel reads.
#[derive(Debug, Clone, Copy)]
pub struct WaterShading<'a> {
    /// The surface.
    pub surface: &'a WaterSurface,
    /// `R(cos θ)` from air into water.
    pub from_air: &'a FresnelTable,
    /// `R(cos θ)` from water into air.
    pub from_water: &'a FresnelTable,
    /// Where reflections come from.
    pub reflection: WaterReflection<'a>,
    /// The ambient light's diffuse radiance on the floor, `Irradiance::diffuse(Vec3::Y)`
    /// (one value for the whole floor, so it is not evaluated per pixel).
    pub floor_ambient: [f32; 3],
}

impl WaterShading<'_> {
    /// Radiance towards the eye from surface point `p` with unit normal `n` (up), seen
    /// along unit `v`; `footprint_m` is a pixel's width there (for floor filtering).
    pub fn radiance(
        &self,
        p: Vec3,
        v: Vec3,
        n: Vec3,
        footprint_m: f32,
        lights: &[Light],
    ) -> [f32; 3] {
        let ior = self.surface.ior;
        let floor = |dir: Vec3| self.floor_radiance(p, dir, footprint_m, lights);
        let c = v.dot(n);
        let (r, reflected, transmitted) = if c <= 0.0 {
            // From the air: reflect the scene, refract onto the floor.
            let r = self.from_air.reflectance(-c);
            let t = refract(v, n, 1.0 / ior).map_or([0.0; 3], floor);
            (r, self.reflection.sample(v - n * (2.0 * c)), t)
        } else {
            // From under the water: reflect the floor, refract the scene above; total
            // internal reflection (no refracted ray) reflects everything.
            let m = -n;
            match refract(v, m, ior) {
                Some(t) => (
                    self.from_water.reflectance(c),
                    floor(v - m * (2.0 * v.dot(m))),
                    self.reflection.sample(t),
                ),
                None => (1.0, floor(v - m * (2.0 * v.dot(m))), [0.0; 3]),
            }
        };
        std::array::from_fn(|k| r * reflected[k] + (1.0 - r) * transmitted[k])
    }

    /// Lit floor seen from `p` along `dir` through the water, dimmed by Beer–Lambert
    /// absorption over the path; black when the ray never reaches the floor.
    fn floor_radiance(&self, p: Vec3, dir: Vec3, footprint_m: f32, lights: &[Light]) -> [f32; 3] {
        let Some((q, path_m)) = floor_hit(p, dir, self.surface.floor_height_m()) else {
            return [0.0; 3];
        };
        let floor = &self.surface.floor;
        let albedo = ground_albedo(floor, q.x, q.z, [footprint_m; 2]);
        // The ray goes down (`floor_hit`), so the floor's upper side faces it.
        let lit = lit_facing(floor, albedo, self.floor_ambient, q, Vec3::Y, dir, lights);
        std::array::from_fn(|k| lit[k] * (-self.surface.absorption_per_m[k] * path_m).exp())
    }
}

/// Where the ray from `p` along unit `dir` meets the floor plane `y = floor_y`, and the
/// path length; `None` when it does not go down towards the floor.
#[inline]
pub fn floor_hit(p: Vec3, dir: Vec3, floor_y: f32) -> Option<(Vec3, f32)> {
    if dir.y >= 0.0 || !dir.is_finite() {
        return None;
    }
    let s = ((floor_y - p.y) / dir.y).max(0.0);
    Some((p + dir * s, s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Irradiance, Material};
    use num_complex::Complex64;
    use thinfilm::fresnel::Interface;

    fn pond(absorption_per_m: [f32; 3]) -> WaterSurface {
        WaterSurface {
            positions: Vec::new(),
            normals: Vec::new(),
            triangles: Vec::new(),
            rest_height_m: 0.0,
            ior: 1.333,
            floor_depth_m: 0.5,
            floor: Material::matte([0.5; 3]),
            absorption_per_m,
        }
    }

    #[test]
    fn straight_down_the_floor_hit_is_directly_below() {
        let p = Vec3::new(0.3, 0.01, -0.7);
        let t = refract(-Vec3::Y, Vec3::Y, 1.0 / 1.333).unwrap();
        let (q, path) = floor_hit(p, t, -0.5).unwrap();
        assert!((q - Vec3::new(0.3, -0.5, -0.7)).length() < 1e-6, "hit {q}");
        assert!((path - 0.51).abs() < 1e-6, "path {path}");
        assert!(floor_hit(p, Vec3::X, -0.5).is_none());
    }

    #[test]
    fn beer_lambert_dims_the_floor_by_the_exponential_of_the_path() {
        let env = Environment::Uniform([0.0; 3]);
        let (from_air, from_water) = (FresnelTable::new(1.0, 1.333), FresnelTable::new(1.333, 1.0));
        let radiance = |absorption: [f32; 3]| {
            let surface = pond(absorption);
            let shading = WaterShading {
                surface: &surface,
                from_air: &from_air,
                from_water: &from_water,
                reflection: WaterReflection::Env(&env),
                floor_ambient: white_ambient(),
            };
            shading.radiance(Vec3::ZERO, -Vec3::Y, Vec3::Y, 0.0, &[])
        };
        let clear = radiance([0.0; 3]);
        let murky = radiance([0.0, 1.0, 2.0]);
        let r0 = ((1.333f32 - 1.0) / 2.333).powi(2);
        assert!(
            (clear[0] - 0.5 * (1.0 - r0)).abs() < 1e-6,
            "clear {clear:?}"
        );
        for (k, alpha) in [0.0f32, 1.0, 2.0].into_iter().enumerate() {
            let want = clear[k] * (-alpha * 0.5).exp();
            assert!(
                (murky[k] - want).abs() < 1e-6,
                "channel {k}: {} vs {want}",
                murky[k]
            );
        }
    }

    #[test]
    fn under_water_beyond_the_critical_angle_everything_is_reflected_without_nan() {
        let env = Environment::Uniform([7.0; 3]);
        let (from_air, from_water) = (FresnelTable::new(1.0, 1.333), FresnelTable::new(1.333, 1.0));
        let surface = pond([0.0; 3]);
        let shading = WaterShading {
            surface: &surface,
            from_air: &from_air,
            from_water: &from_water,
            reflection: WaterReflection::Env(&env),
            floor_ambient: white_ambient(),
        };
        let p = Vec3::new(0.0, 0.0, 0.0);
        let critical = (1.0f32 / 1.333).asin();
        for deg in [0.0f32, 20.0, 45.0, 49.0, 60.0, 89.9] {
            let a = deg.to_radians();
            // Looking up from under the water at `deg` from the vertical.
            let v = Vec3::new(a.sin(), a.cos(), 0.0);
            let c = shading.radiance(p, v, Vec3::Y, 0.0, &[]);
            assert!(c.iter().all(|x| x.is_finite()), "{deg}°: {c:?}");
            if a > critical {
                // Only the (dark, downward) floor is seen: no sky gets through.
                assert!(c[0] < 1.0, "{deg}°: sky leaked through TIR: {c:?}");
            } else {
                assert!(c[0] > 3.0, "{deg}°: sky should show: {c:?}");
            }
        }
    }

    /// Shading of `surface` with reflections `reflection`, lit by a uniform ambient 1.
    fn shade(
        surface: &WaterSurface,
        reflection: WaterReflection<'_>,
        p: Vec3,
        v: Vec3,
        n: Vec3,
    ) -> [f32; 3] {
        let (from_air, from_water) = (
            FresnelTable::new(1.0, surface.ior),
            FresnelTable::new(surface.ior, 1.0),
        );
        let shading = WaterShading {
            surface,
            from_air: &from_air,
            from_water: &from_water,
            reflection,
            floor_ambient: white_ambient(),
        };
        shading.radiance(p, v, n, 0.0, &[])
    }

    /// A uniform ambient 1's diffuse radiance on the floor.
    fn white_ambient() -> [f32; 3] {
        Irradiance::uniform([1.0; 3]).diffuse(Vec3::Y)
    }

    #[test]
    fn at_normal_incidence_the_pixel_shows_the_floor_directly_below() {
        // 10 cm stripes along X: the floor's colour tells where the ray landed.
        let mut surface = pond([0.0; 3]);
        surface.floor = Material::checker([0.9, 0.0, 0.0], [0.0, 0.0, 0.9], 0.1);
        let black = Environment::Uniform([0.0; 3]);
        let t0 = 1.0 - FresnelTable::new(1.0, 1.333).reflectance(1.0);
        let albedo = |x: f32| ground_albedo(&surface.floor, x, 0.05, [0.0; 2]);
        assert!(
            albedo(0.05) != albedo(0.15),
            "neighbouring stripes must differ"
        );
        for x in [0.05f32, 0.15, 0.25, 0.35, -0.05, -0.15] {
            let p = Vec3::new(x, 0.0, 0.05);
            let c = shade(&surface, WaterReflection::Env(&black), p, -Vec3::Y, Vec3::Y);
            let under = albedo(x);
            for k in 0..3 {
                assert!(
                    (c[k] - t0 * under[k]).abs() < 1e-5,
                    "x {x}: {c:?} vs floor below {under:?} × T {t0}"
                );
            }
        }
    }

    #[test]
    fn oblique_rays_land_where_snell_says() {
        // Independent truth: sin θt = sin θi / n, and the ray drops `depth` over a
        // horizontal run of depth·tan θt.
        let (n, depth) = (1.333f32, 0.5f32);
        for deg in [10.0f32, 30.0, 45.0, 60.0, 80.0] {
            let a = deg.to_radians();
            let v = Vec3::new(a.sin(), -a.cos(), 0.0);
            let t = refract(v, Vec3::Y, 1.0 / n).unwrap();
            let (q, path) = floor_hit(Vec3::ZERO, t, -depth).unwrap();
            let theta_t = (a.sin() / n).asin();
            let run = depth * theta_t.tan();
            assert!(
                (q.x - run).abs() < 1e-5,
                "{deg}°: lands at x {} not {run}",
                q.x
            );
            assert!(
                q.z.abs() < 1e-6 && (q.y + depth).abs() < 1e-6,
                "{deg}°: {q}"
            );
            let want_path = depth / theta_t.cos();
            assert!(
                (path - want_path).abs() < 1e-5,
                "{deg}°: path {path} vs {want_path}"
            );
        }
    }

    #[test]
    fn oblique_view_rays_shade_the_floor_where_snell_lands_them() {
        // 5 cm checker: each ray aims at the middle of a square from where Snell's law
        // (sin θt = sin θi / n, computed here with scalar trigonometry) says it lands.
        let mut surface = pond([0.0; 3]);
        surface.floor = Material::checker([0.9, 0.0, 0.0], [0.0, 0.0, 0.9], 0.05);
        let black = Environment::Uniform([0.0; 3]);
        let from_air = FresnelTable::new(1.0, 1.333);
        let mut colours = Vec::new();
        for (k, deg) in [15.0f32, 30.0, 45.0, 60.0, 75.0].into_iter().enumerate() {
            let a = deg.to_radians();
            let v = Vec3::new(a.sin(), -a.cos(), 0.0);
            let run = surface.floor_depth_m * (a.sin() / 1.333).asin().tan();
            let landing_x = 0.025 + 0.05 * k as f32;
            let p = Vec3::new(landing_x - run, 0.0, 0.025);
            let c = shade(&surface, WaterReflection::Env(&black), p, v, Vec3::Y);
            let t = 1.0 - from_air.reflectance(a.cos());
            let under = ground_albedo(&surface.floor, landing_x, 0.025, [0.0; 2]);
            colours.push(under);
            for ch in 0..3 {
                assert!(
                    (c[ch] - t * under[ch]).abs() < 1e-3,
                    "{deg}°: {c:?} vs the square Snell lands on {under:?} × T {t}"
                );
            }
        }
        assert!(colours.windows(2).all(|w| w[0] != w[1]), "{colours:?}");
    }

    #[test]
    fn blend_weights_are_thinfilms_single_interface_reflectance() {
        // A black floor leaves only the reflected term R(θ)·E of a uniform sky E.
        let mut surface = pond([0.0; 3]);
        surface.floor = Material::matte([0.0; 3]);
        let e = 3.0f32;
        let sky = Environment::Uniform([e; 3]);
        let exact = Interface::new(1.0, Complex64::new(1.333, 0.0)).unwrap();
        for deg in [0.0f32, 20.0, 40.0, 60.0, 75.0, 85.0] {
            let a = deg.to_radians();
            let v = Vec3::new(a.sin(), -a.cos(), 0.0);
            let c = shade(&surface, WaterReflection::Env(&sky), Vec3::ZERO, v, Vec3::Y);
            let want = exact.response(f64::from(a.cos())).r() as f32 * e;
            assert!(
                (c[0] - want).abs() < 1e-4 * e,
                "{deg}°: {} vs R·E = {want}",
                c[0]
            );
        }
    }

    #[test]
    fn sphere_mapped_water_seen_from_above_reflects_the_sky_not_the_ground() {
        // Our convention (and seed 002's, see `sphere_map_uv`): the physical reflected
        // ray. A camera looking down at flat water sees rays reflected upwards, so the
        // bright sky; the mirrored convention (−r) would read the dark ground.
        let env = Environment::Sky(crate::Sky {
            zenith_rgb: [5.0; 3],
            horizon_rgb: [5.0; 3],
            nadir_rgb: [0.0; 3],
            sun_rgb: [0.0; 3],
            ..crate::Sky::default()
        });
        let camera = crate::Camera::look_at(Vec3::new(0.0, 1.0, 2.0), Vec3::ZERO, Vec3::Y, 40.0);
        let map = SphereMap::from_environment(&env, 128, Mat3::IDENTITY).unwrap();
        let eye_from_world = camera.world_from_eye().transpose();
        let mut surface = pond([0.0; 3]);
        surface.floor = Material::matte([0.0; 3]);
        for p in [
            Vec3::ZERO,
            Vec3::new(0.3, 0.0, -0.5),
            Vec3::new(-0.4, 0.0, 0.6),
        ] {
            let v = (p - camera.eye()).normalize();
            let c = shade(
                &surface,
                WaterReflection::Sphere(&map, eye_from_world),
                p,
                v,
                Vec3::Y,
            );
            let r = FresnelTable::new(1.0, 1.333).reflectance(-v.y);
            assert!(
                (c[0] - 5.0 * r).abs() < 0.05 * 5.0 * r,
                "at {p}: {c:?}, want the sky 5 × R {r}"
            );
        }
    }
}

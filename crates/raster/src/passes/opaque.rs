//! The opaque pass: the environment and the ground behind every sample of a strip, then
//! the opaque triangles (objects, light spheres, water) with a depth test.

use glam::Vec3;
use render_scene::camera::View;
use render_scene::ground_view::GroundView;
use render_scene::index_f32::index_f32;
use render_scene::shader_constants::{EMISSIVE, WATER};
use render_scene::shading::{ground_albedo_over_pixel, lit, object_albedo, surface_footprint};
use render_scene::water_shading::WaterShading;
use render_scene::{Environment, Irradiance, Light, Material, Pattern};

use super::SPAN;
use super::ground_span::{ground_span, span_supported};
use super::sky_span::sky_span;
use crate::raster::{SamplePattern, SetupTri, for_each_covered_in_row};
use crate::strip::{Bins, STRIP_ROWS};

/// Everything the opaque pass of one view reads.
pub(crate) struct OpaqueCtx<'a> {
    pub view: View,
    pub pattern: SamplePattern,
    pub env: &'a Environment,
    /// Precomputed environment radiance per pixel (single-sample views only).
    pub sky_texels: Option<&'a [[f32; 3]]>,
    pub ground: Option<GroundView<'a>>,
    /// Environment and ambient light on opaque surfaces.
    pub ambient: &'a Irradiance,
    pub lights: &'a [Light],
    pub materials: &'a [&'a Material],
    pub tris: &'a [SetupTri],
    pub bins: &'a Bins,
    /// How water triangles are shaded (`None` draws them black).
    pub water: Option<WaterShading<'a>>,
}

impl OpaqueCtx<'_> {
    /// Renders strip `strip` (rows from `strip·STRIP_ROWS`) into its sample buffers.
    pub fn render_strip(&self, strip: usize, color: &mut [[f32; 3]], depth: &mut [f32]) {
        let y0 = strip * STRIP_ROWS;
        let rows = color.len() / (self.view.width * self.pattern.count);
        // Fixed sample counts let the per-pixel fills and loops unroll (same arithmetic).
        match self.pattern.count {
            1 => self.background::<1>(y0, rows, color, depth),
            4 => self.background::<4>(y0, rows, color, depth),
            _ => self.background::<0>(y0, rows, color, depth),
        }
        for &t in self.bins.strip(strip) {
            self.triangle(&self.tris[t as usize], y0, rows, color, depth);
        }
    }

    /// Ground and environment behind every sample of the strip; `N` is the sample count,
    /// or 0 for the pattern's own.
    #[inline(always)]
    fn background<const N: usize>(
        &self,
        y0: usize,
        rows: usize,
        color: &mut [[f32; 3]],
        depth: &mut [f32],
    ) {
        let s_count = if N == 0 { self.pattern.count } else { N };
        let width = self.view.width;
        let fast = self.ground.as_ref().filter(|g| span_supported(g));
        // Inverse depth is affine: each sample's differs from the centre's by a constant.
        let mut dz = [0.0f32; 16];
        if let Some(g) = &self.ground {
            for (d, &(ox, oy)) in dz.iter_mut().zip(&self.pattern.offsets_px).take(s_count) {
                *d = g.gx * (ox - 0.5) + g.gy * (oy - 0.5);
            }
        }
        let dz = &dz[..s_count];
        let min_dz = dz.iter().copied().fold(f32::INFINITY, f32::min);
        let max_dz = dz.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let mut centre = [[0.0f32; 3]; SPAN];
        let mut sky = [[0.0f32; 3]; SPAN];
        // Inverse depth of the ground at each pixel centre; −1 (behind) without a ground.
        let mut z = [-1.0f32; SPAN];
        for row in 0..rows {
            let y = y0 + row;
            let cy = y as f32 + 0.5;
            for x0 in (0..width).step_by(SPAN) {
                let n = SPAN.min(width - x0);
                let z = &mut z[..n];
                if let Some(g) = &self.ground {
                    for (i, z) in z.iter_mut().enumerate() {
                        *z = g.inv_depth(index_f32(x0 + i) + 0.5, cy);
                    }
                }
                // Centres seeing the ground form one contiguous run (inverse depth is affine).
                let run = positive_run(z);
                if let (Some(g), Some((a, b))) = (fast, run) {
                    ground_span(
                        &self.view,
                        self.ambient,
                        self.lights,
                        g,
                        y,
                        x0 + a,
                        &mut centre[a..b],
                    );
                }
                // The environment outside the run, by the span kernel unless precomputed;
                // pixels inside it that see some sky (the horizon's) look it up one by one.
                let (a, b) = run.unwrap_or((n, n));
                let texels = self.sky_texels.map(|t| &t[y * width + x0..][..n]);
                if texels.is_none() {
                    sky_span(&self.view, self.env, y, x0, &mut sky[..a]);
                    sky_span(&self.view, self.env, y, x0 + b, &mut sky[b..n]);
                }
                let sky_at = |i: usize| match texels {
                    Some(t) => t[i],
                    None if i < a || i >= b => sky[i],
                    None => self.sky(x0 + i, y),
                };
                // The pixels whose centres the span kernel shaded.
                let (ga, gb) = fast.and(run).unwrap_or((0, 0));
                for (i, (c, &z)) in centre.iter().zip(z.iter()).enumerate() {
                    let x = x0 + i;
                    let base = (row * width + x) * s_count;
                    let (color, depth) = (
                        &mut color[base..base + s_count],
                        &mut depth[base..base + s_count],
                    );
                    let in_run = ga <= i && i < gb;
                    if in_run && z + min_dz > 0.0 {
                        // Every sample on the ground, shaded at the centre by the span kernel.
                        color.fill(*c);
                        for (d, o) in depth.iter_mut().zip(dz) {
                            *d = z + o;
                        }
                    } else if z + max_dz <= 0.0 {
                        // Every sample sees the environment.
                        color.fill(sky_at(i));
                        depth.fill(0.0);
                    } else {
                        let centre = in_run.then_some(*c);
                        self.background_pixel(x, y, centre, sky_at(i), color, depth);
                    }
                }
            }
        }
    }

    /// Fills one pixel's samples with ground or environment `sky`; `centre` is the ground
    /// radiance at the pixel centre when already computed.
    #[inline]
    fn background_pixel(
        &self,
        x: usize,
        y: usize,
        centre: Option<[f32; 3]>,
        sky: [f32; 3],
        color: &mut [[f32; 3]],
        depth: &mut [f32],
    ) {
        let s_count = self.pattern.count;
        let full = self.pattern.full_mask();
        let (px, py) = (x as f32, y as f32);
        let mut ground_mask = 0u32;
        let mut first_ground = 0usize;
        if let Some(g) = &self.ground {
            for s in (0..s_count).rev() {
                let (ox, oy) = self.pattern.offset_f32(s);
                let z = g.inv_depth(px + ox, py + oy);
                depth[s] = z.max(0.0);
                if z > 0.0 {
                    ground_mask |= 1 << s;
                    first_ground = s;
                }
            }
        } else {
            depth.fill(0.0);
        }
        let ground = if ground_mask == 0 {
            [0.0; 3]
        } else if let (true, Some(c)) = (ground_mask == full, centre) {
            c
        } else {
            let (ox, oy) = if ground_mask == full {
                (0.5, 0.5)
            } else {
                self.pattern.offset_f32(first_ground)
            };
            let g = self
                .ground
                .as_ref()
                .map_or(0.0, |g| g.inv_depth(px + ox, py + oy));
            self.shade_ground(px + ox, py + oy, g)
        };
        for (s, c) in color.iter_mut().enumerate() {
            *c = if ground_mask & (1 << s) != 0 {
                ground
            } else {
                sky
            };
        }
    }

    /// Environment radiance behind pixel `(x, y)`: from the precomputed texels when given.
    #[inline]
    fn sky(&self, x: usize, y: usize) -> [f32; 3] {
        match self.sky_texels {
            Some(t) => t[y * self.view.width + x],
            None => self
                .env
                .radiance(self.view.ray(x as f32 + 0.5, y as f32 + 0.5)),
        }
    }

    /// Lit ground at pixel-space point `(px, py)`, whose inverse depth `inv_t` is positive.
    #[inline]
    fn shade_ground(&self, px: f32, py: f32, inv_t: f32) -> [f32; 3] {
        let Some(g) = &self.ground else {
            return [0.0; 3];
        };
        let view = &self.view;
        let t = 1.0 / inv_t;
        let d = view.ray(px, py);
        let p = view.eye + d * t;
        // Footprint of one pixel on the plane: ∂P/∂px = t·(∂d − d·∂d.y/d.y).
        // d.y = inv_t · (h − eye.y), so 1/d.y needs no division of its own.
        let inv_dy = t * g.inv_height;
        let dpx = (g.ddx - d * (g.ddx.y * inv_dy)) * t;
        let dpy = (g.ddy - d * (g.ddy.y * inv_dy)) * t;
        // Edge-on the footprint is unbounded: the filter then returns the mean.
        let bound = |v: Vec3| [v.x, v.z].map(|f| if f.abs() < 1e9 { f } else { 1e9 });
        let m = &g.ground.material;
        let albedo = ground_albedo_over_pixel(m, p.x, p.z, bound(dpx), bound(dpy), g.filter);
        lit(
            &g.ground.material,
            albedo,
            p,
            g.normal,
            d,
            self.ambient,
            self.lights,
        )
    }

    fn triangle(
        &self,
        tri: &SetupTri,
        y0: usize,
        rows: usize,
        color: &mut [[f32; 3]],
        depth: &mut [f32],
    ) {
        let s_count = self.pattern.count;
        let width = self.view.width;
        let ya = (tri.bbox[1] as usize).max(y0);
        let yb = (tri.bbox[3] as usize).min(y0 + rows);
        for py in ya..yb {
            for_each_covered_in_row(tri, &self.pattern, py as i32, |px, mask| {
                let base = ((py - y0) * width + px as usize) * s_count;
                let (pxf, pyf) = (px as f32 - tri.ox, py as f32 - tri.oy);
                let mut pass = 0u32;
                let mut first = 0usize;
                for s in (0..s_count).rev() {
                    if mask & (1 << s) != 0 {
                        let (ox, oy) = self.pattern.offset_f32(s);
                        if tri.inv_w.at(pxf + ox, pyf + oy) > depth[base + s] {
                            pass |= 1 << s;
                            first = s;
                        }
                    }
                }
                if pass == 0 {
                    return;
                }
                let (ox, oy) = if mask == self.pattern.full_mask() {
                    (0.5, 0.5)
                } else {
                    self.pattern.offset_f32(first)
                };
                let c = self.shade(tri, px as f32 + ox, py as f32 + oy);
                for s in 0..s_count {
                    if pass & (1 << s) != 0 {
                        let (ox, oy) = self.pattern.offset_f32(s);
                        color[base + s] = c;
                        depth[base + s] = tri.inv_w.at(pxf + ox, pyf + oy);
                    }
                }
            });
        }
    }

    fn shade(&self, tri: &SetupTri, px: f32, py: f32) -> [f32; 3] {
        if tri.tag & EMISSIVE != 0 {
            return self.lights[(tri.tag & !EMISSIVE) as usize].radiance;
        }
        if tri.tag & WATER != 0 {
            return self.shade_water(tri, px, py);
        }
        let (inv_w, a) = tri.interpolate(px, py);
        let d = self.view.ray(px, py);
        let p = self.view.eye + d / inv_w;
        let v = d.normalize_or(self.view.forward);
        let n = Vec3::new(a[0], a[1], a[2]).normalize_or(-v);
        let material = self.materials[tri.tag as usize];
        let footprint = match material.pattern {
            Pattern::Checker { .. } => surface_footprint(&self.view, d, 1.0 / inv_w, n),
            _ => [0.0; 3],
        };
        let albedo = object_albedo(material, p, [a[3], a[4]], footprint);
        lit(material, albedo, p, n, v, self.ambient, self.lights)
    }

    /// A water pixel of the opaque pass.
    #[inline]
    fn shade_water(&self, tri: &SetupTri, px: f32, py: f32) -> [f32; 3] {
        let Some(water) = &self.water else {
            return [0.0; 3];
        };
        let (inv_w, a) = tri.interpolate(px, py);
        let d = self.view.ray(px, py);
        let p = self.view.eye + d / inv_w;
        let v = d.normalize_or(self.view.forward);
        let n = Vec3::new(a[0], a[1], a[2]).normalize_or(Vec3::Y);
        let footprint_m = (p - self.view.eye).length() * self.view.x_per_px;
        water.radiance(p, v, n, footprint_m, self.lights)
    }
}

/// The first run `a..b` of positive values in `z`, if any (NaN is not positive).
fn positive_run(z: &[f32]) -> Option<(usize, usize)> {
    let a = z.iter().position(|&z| z > 0.0)?;
    let b = z[a..]
        .iter()
        .position(|&z| z <= 0.0 || z.is_nan())
        .map_or(z.len(), |k| a + k);
    Some((a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positive_run_is_the_first_run_of_positive_values() {
        assert_eq!(positive_run(&[-1.0, 0.0, 2.0, 3.0, 0.0, 4.0]), Some((2, 4)));
        assert_eq!(positive_run(&[1.0, f32::NAN, 1.0]), Some((0, 1)));
        assert_eq!(positive_run(&[-1.0, 1.0]), Some((1, 2)));
        assert_eq!(positive_run(&[0.0, -0.0, f32::NAN]), None);
    }

    #[test]
    fn ground_span_kernel_matches_the_scalar_ground() {
        use render_scene::{Camera, Ground, Material};
        let camera = Camera::look_at(
            Vec3::new(0.3, 1.3, 3.0),
            Vec3::new(0.0, 0.2, 0.0),
            Vec3::Y,
            60.0,
        );
        let view = camera.view(150, 100);
        let ground = Ground {
            height_m: 0.1,
            material: Material::checker([0.8, 0.7, 0.6], [0.1, 0.2, 0.3], 0.4),
        };
        let g = GroundView::new(&ground, &view).unwrap();
        let lights = [
            Light {
                position: Vec3::new(-1.0, 2.0, 1.0),
                radius_m: 0.1,
                radiance: [50.0, 40.0, 30.0],
                light_lut: None,
            },
            Light {
                position: Vec3::new(2.0, 0.5, -1.0),
                radius_m: 0.3,
                radiance: [5.0; 3],
                light_lut: None,
            },
        ];
        let env = Environment::Uniform([1.0; 3]);
        let bins = Bins::default();
        let ctx = OpaqueCtx {
            view,
            pattern: SamplePattern::new(1),
            env: &env,
            sky_texels: None,
            ground: Some(g),
            ambient: &Irradiance::from_environment(&Environment::Sky(render_scene::Sky::default()))
                .plus_uniform([0.2, 0.3, 0.4]),
            lights: &lights,
            materials: &[],
            tris: &[],
            bins: &bins,
            water: None,
        };
        let mut checked = 0;
        for y in (0..100).step_by(7) {
            for x0 in (0..150).step_by(SPAN) {
                let n = SPAN.min(150 - x0);
                let z: Vec<f32> = (0..n)
                    .map(|i| g.inv_depth((x0 + i) as f32 + 0.5, y as f32 + 0.5))
                    .collect();
                let Some((a, b)) = positive_run(&z) else {
                    continue;
                };
                let mut out = [[0.0; 3]; SPAN];
                ground_span(
                    &ctx.view,
                    ctx.ambient,
                    ctx.lights,
                    &g,
                    y,
                    x0 + a,
                    &mut out[..b - a],
                );
                for (i, got) in out[..b - a].iter().enumerate() {
                    let (cx, cy) = ((x0 + a + i) as f32 + 0.5, y as f32 + 0.5);
                    let want = ctx.shade_ground(cx, cy, g.inv_depth(cx, cy));
                    for k in 0..3 {
                        let tol = 1e-4 * want[k].abs().max(1e-2);
                        assert!(
                            (got[k] - want[k]).abs() <= tol,
                            "({},{y}) channel {k}: {} vs {}",
                            x0 + a + i,
                            got[k],
                            want[k]
                        );
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 500, "only {checked} ground pixels compared");
    }
}

//! The bubble pass: each bubble's triangles, far to near and back faces first, blended over
//! the opaque samples as `dest = dest ⊙ T + R ⊙ reflection + highlights` (seed 000 §4).

use glam::{Vec3, Vec3A};
use render_scene::bubble_order::{far_to_near, is_front_facing, reflection_rate};
use render_scene::camera::View;
use render_scene::highlight::LightSight;
use render_scene::lod::reflection_derivatives;
use render_scene::lut_sampler::LutSampler;
use render_scene::parallax::ground_parallax;
use render_scene::reflection::Reflection;
use render_scene::{FilmField, Light, PartialShading, ReflectionFilter, RenderScene};

use crate::raster::{
    ATTRS, NO_SURFACE, Plane, SamplePattern, SetupTri, append_in_order, clip_vertex,
    for_each_covered_in_row, setup_triangle,
};
use crate::strip::{Bins, STRIP_ROWS};
use rayon::prelude::*;

/// Everything the bubble pass reads.
pub(crate) struct BubbleCtx<'a> {
    pub view: View,
    pub pattern: SamplePattern,
    pub reflectivity: LutSampler<'a>,
    /// `None` means `T = 1 − R`.
    pub transmittance: Option<LutSampler<'a>>,
    pub lights: &'a [Light],
    /// Per light: its highlight table (its own, or the reflectivity).
    pub light_tables: &'a [LutSampler<'a>],
    /// Per bubble (by original index).
    pub reflections: &'a [Reflection<'a>],
    /// Per bubble (by original index): its film field, if it has one.
    pub films: &'a [Option<&'a FilmField>],
    /// How cube maps are read.
    pub filter: ReflectionFilter,
    /// Per bubble (by original index): its dynamic cube map's centre, when reads of it
    /// are corrected for parallax over the ground plane at [`BubbleCtx::ground_height_m`].
    pub parallax_centres: &'a [Vec3],
    /// Height of the ground plane the parallax correction intersects (`None`: no ground,
    /// or the correction is off).
    pub ground_height_m: Option<f32>,
    /// How pixels a triangle covers in part are shaded.
    pub partial: PartialShading,
    pub tris: &'a [SetupTri],
    pub bins: &'a Bins,
}

/// One pixel's shading by the last surface that covered it only in part.
#[derive(Debug, Clone, Copy)]
struct SharedShade {
    surface: u32,
    /// Mesh vertices of the triangle that computed the shading.
    mesh_vertices: [u32; 3],
    /// Samples of the pixel that surface's triangles have covered so far.
    covered: u32,
    t_rgb: [f32; 3],
    add: [f32; 3],
}

impl SharedShade {
    const EMPTY: Self = Self {
        surface: NO_SURFACE,
        mesh_vertices: [0; 3],
        covered: 0,
        t_rgb: [0.0; 3],
        add: [0.0; 3],
    };

    /// Whether `tri`, covering samples `mask`, may take this shading: same surface, a
    /// mesh neighbour of the triangle that computed it (one shared vertex), and none of
    /// the samples already covered. Overlap, or no shared vertex, means another sheet
    /// of the surface (a fold, or its edge) seen in the same pixel.
    ///
    /// Evaluated without short cuts (`&`, `|`): the outcome varies from pixel to pixel
    /// along a mesh's edges, and the branches of `&&` and `any` mispredicted (cachegrind's
    /// branch simulation: 13 k of a `paper` frame's 304 k mispredictions).
    #[inline(always)]
    fn fits(&self, tri: &SetupTri, mask: u32) -> bool {
        let [a, b, c] = tri.mesh_vertices;
        let shares_vertex = self
            .mesh_vertices
            .iter()
            .fold(false, |any, &v| any | (v == a) | (v == b) | (v == c));
        (self.surface == tri.surface) & (self.covered & mask == 0) & shares_vertex
    }
}

thread_local! {
    /// Per-thread [`SharedShade`] of each pixel of the strip being blended.
    static SHARED_SHADES: std::cell::RefCell<Vec<SharedShade>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

impl BubbleCtx<'_> {
    /// Blends every bubble triangle touching strip `strip` over its samples, in order.
    pub fn render_strip(&self, strip: usize, color: &mut [[f32; 3]], depth: &[f32]) {
        let y0 = strip * STRIP_ROWS;
        let rows = color.len() / (self.view.width * self.pattern.count);
        SHARED_SHADES.with_borrow_mut(|shared| {
            shared.clear();
            shared.resize(rows * self.view.width, SharedShade::EMPTY);
            for &t in self.bins.strip(strip) {
                let tri = &self.tris[t as usize];
                // The default 4-sample pattern gets fixed-length sample loops (same arithmetic).
                if self.pattern.count == 4 {
                    self.blend_triangle::<4>(tri, y0, rows, color, depth, shared);
                } else {
                    self.blend_triangle::<0>(tri, y0, rows, color, depth, shared);
                }
            }
        });
    }

    /// Blends one triangle over rows `y0 .. y0 + rows`; `N` is the sample count, or 0 for
    /// the pattern's own.
    ///
    /// A pixel the triangle covers only in part is shaded once per surface: the triangles
    /// of one smooth surface (same [`SetupTri::surface`]) tile it without overlap, so when
    /// this one is a mesh neighbour of the triangle that shaded the pixel and covers
    /// samples disjoint from those already covered, it reuses that shading (from a point
    /// under a pixel away on the same surface, as multisampling already shades every
    /// sample of a pixel at one point). Anything else may be another sheet (a fold) and is
    /// shaded afresh ([`SharedShade::fits`]). On `paper` this saves about a third of the
    /// shadings: most bubble pixels lie on small triangles' edges.
    #[inline(always)]
    fn blend_triangle<const N: usize>(
        &self,
        tri: &SetupTri,
        y0: usize,
        rows: usize,
        color: &mut [[f32; 3]],
        depth: &[f32],
        shared: &mut [SharedShade],
    ) {
        let s_count = if N == 0 { self.pattern.count } else { N };
        let width = self.view.width;
        let full = self.pattern.full_mask();
        // Inverse depth is affine: each sample's differs from the centre's by a constant.
        let mut dz = [0.0f32; 16];
        for (d, &(ox, oy)) in dz.iter_mut().zip(&self.pattern.offsets_px).take(s_count) {
            *d = tri.inv_w.dx * (ox - 0.5) + tri.inv_w.dy * (oy - 0.5);
        }
        let dz = &dz[..s_count];
        let ya = (tri.bbox[1] as usize).max(y0);
        let yb = (tri.bbox[3] as usize).min(y0 + rows);
        let shares = tri.surface != NO_SURFACE && self.partial == PartialShading::PerSurface;
        let mut batch = PixelBatch::EMPTY;
        for py in ya..yb {
            for_each_covered_in_row(tri, &self.pattern, py as i32, |px, mask| {
                let pixel = (py - y0) * width + px as usize;
                let base = pixel * s_count;
                let z = tri
                    .inv_w
                    .at(px as f32 + 0.5 - tri.ox, py as f32 + 0.5 - tri.oy);
                let mut pass = 0u32;
                for (s, (&opaque, &o)) in depth[base..base + s_count].iter().zip(dz).enumerate() {
                    pass |= u32::from(z + o > opaque) << s;
                }
                pass &= mask;
                if pass == 0 {
                    return;
                }
                if mask == full {
                    // Shaded at the centre when the triangle covers the pixel, in lanes.
                    batch.push((px as f32 + 0.5, py as f32 + 0.5), base, pass);
                    if batch.len == LANES {
                        self.blend_batch(tri, &mut batch, &mut color[..]);
                    }
                    return;
                }
                let at = (px as f32, py as f32);
                let (t_rgb, add) =
                    self.shade_partial(tri, at, mask, pass, shares, &mut shared[pixel]);
                blend(&mut color[base..base + s_count], pass, t_rgb, add);
            });
        }
        // Every pixel is blended by each triangle once, so the order within it is free.
        self.blend_batch(tri, &mut batch, color);
    }

    /// Shades the pixels of `batch` in lanes, blends them into `color` and empties it.
    #[inline(always)]
    fn blend_batch(&self, tri: &SetupTri, batch: &mut PixelBatch, color: &mut [[f32; 3]]) {
        let s_count = self.pattern.count;
        let shadings = self.shade_lanes::<LANES>(tri, &batch.at[..batch.len]);
        for ((&base, &pass), (t_rgb, add, _)) in batch
            .base
            .iter()
            .zip(&batch.pass)
            .zip(shadings)
            .take(batch.len)
        {
            blend(&mut color[base..base + s_count], pass, t_rgb, add);
        }
        batch.len = 0;
    }

    /// Shading of a pixel whose top-left corner is `at` and whose samples `mask` the
    /// triangle covers in part (`pass` of them in front of the opaque scene): the shading
    /// `entry` holds when the triangle's surface may share it, else a fresh one at the
    /// first passing sample, which `entry` then keeps for the surface's other triangles.
    #[inline(always)]
    fn shade_partial(
        &self,
        tri: &SetupTri,
        at: (f32, f32),
        mask: u32,
        pass: u32,
        shares: bool,
        entry: &mut SharedShade,
    ) -> ([f32; 3], [f32; 3]) {
        if shares && entry.fits(tri, mask) {
            entry.covered |= mask;
            return (entry.t_rgb, entry.add);
        }
        let (ox, oy) = self.pattern.offset_f32(pass.trailing_zeros() as usize);
        let (t_rgb, add, shareable) = self.shade(tri, at.0 + ox, at.1 + oy);
        *entry = SharedShade {
            // A highlight varies within a pixel: never shared.
            surface: if shareable { tri.surface } else { NO_SURFACE },
            mesh_vertices: tri.mesh_vertices,
            covered: mask,
            t_rgb,
            add,
        };
        (t_rgb, add)
    }

    /// Transmittance and added radiance of the film at pixel-space point `(px, py)`, and
    /// whether they may be shared with the rest of the pixel: [`BubbleCtx::shade_lanes`]
    /// with one lane.
    #[inline]
    fn shade(&self, tri: &SetupTri, px: f32, py: f32) -> Shading {
        let [one] = self.shade_lanes::<1>(tri, &[(px, py)]);
        one
    }

    /// [`BubbleCtx::shade`] at each pixel-space point of `at` (at most `L`; the lanes past
    /// it are left as holes), stage by stage across the lanes.
    ///
    /// Each pixel runs exactly the operations `shade` would, so the results are
    /// bit-identical; only their order across pixels changes. One pixel's shading is a
    /// chain of dependent loads (film field, tables, cube map) longer than the core's
    /// reorder window, so pixels shaded one after the other barely overlap; a stage that
    /// runs for all lanes before the next gives the core independent work to overlap.
    ///
    /// A bubble with a film field reads its thickness and coverage `c` from the field at
    /// the interpolated material direction (attributes 3..6) and blends the film in by
    /// `c`: `T' = 1 − c·(1 − T)`, `add' = c·add`. A hole (`c = 0`) is exactly no film.
    /// Shadings are shareable when no light's highlight reaches within
    /// [`SHARE_MARGIN_PX`] of the point.
    ///
    /// The vector arithmetic runs in `Vec3A` lanes: the same IEEE operations in the same
    /// order as `Vec3`'s (glam sums dot products x, y, then z in both), so results are
    /// bit-identical, in fewer instructions.
    #[inline(always)]
    fn shade_lanes<const L: usize>(&self, tri: &SetupTri, at: &[(f32, f32)]) -> [Shading; L] {
        let at = &at[..at.len().min(L)];
        let mut out = [HOLE; L];
        let mut inv_w = [0.0f32; L];
        let mut attrs = [[0.0f32; ATTRS]; L];
        for ((&(px, py), w), a) in at.iter().zip(&mut inv_w).zip(&mut attrs) {
            (*w, *a) = tri.interpolate(px, py);
        }
        let films = self.film_lanes::<L>(tri, &attrs[..at.len()]);
        let rays = self.ray_lanes::<L>(at, &attrs);
        let mut r_rgb = [[0.0f32; 3]; L];
        let mut t_rgb = [[0.0f32; 3]; L];
        for i in 0..at.len() {
            r_rgb[i] = self.reflectivity.sample(films[i].0, rays[i].cos_theta);
        }
        for i in 0..at.len() {
            t_rgb[i] = match &self.transmittance {
                Some(t) => t.sample(films[i].0, rays[i].cos_theta),
                None => r_rgb[i].map(|r| 1.0 - r),
            };
        }
        let reflection = &self.reflections[tri.tag as usize];
        let footprint = reflection.is_cube() && self.filter == ReflectionFilter::Footprint;
        let mut derivatives = [[Vec3::ZERO; 2]; L];
        let mut points = [Vec3::ZERO; L];
        let mut dirs = [Vec3::ZERO; L];
        for i in 0..at.len() {
            let ray = &rays[i];
            if footprint {
                derivatives[i] = self.reflection_derivatives(tri, ray.d, inv_w[i], attrs[i]);
            }
            let p = self.view.eye + Vec3::from(ray.d / inv_w[i]);
            points[i] = p;
            dirs[i] = self
                .parallax_dir(tri, p, ray.reflected)
                .unwrap_or(ray.reflected);
        }
        let mut env = [[0.0f32; 3]; L];
        for i in 0..at.len() {
            env[i] = reflection.sample(dirs[i], derivatives[i], self.filter);
        }
        for i in 0..at.len() {
            let (thickness_nm, coverage) = films[i];
            // A hole (no film) stays `HOLE`; NaN coverage is not a hole, as in one lane.
            if coverage <= 0.0 {
                continue;
            }
            let (r, e) = (r_rgb[i], env[i]);
            let mut add = [r[0] * e[0], r[1] * e[1], r[2] * e[2]];
            let (p, ray) = (points[i], &rays[i]);
            let shareable = self.add_highlights(
                tri,
                p,
                ray.reflected,
                (thickness_nm, ray.cos_theta),
                &mut add,
            );
            out[i] = if coverage < 1.0 {
                (
                    t_rgb[i].map(|t| 1.0 - coverage * (1.0 - t)),
                    add.map(|a| coverage * a),
                    shareable,
                )
            } else {
                (t_rgb[i], add, shareable)
            };
        }
        out
    }

    /// Per lane: the film's thickness (nm) and coverage at interpolated attributes
    /// `attrs` (the material direction with a film field, else the thickness itself).
    #[inline(always)]
    fn film_lanes<const L: usize>(
        &self,
        tri: &SetupTri,
        attrs: &[[f32; ATTRS]],
    ) -> [(f32, f32); L] {
        let mut films = [(0.0f32, 0.0f32); L];
        match self.films[tri.tag as usize] {
            None => {
                for (f, a) in films.iter_mut().zip(attrs) {
                    *f = (a[3].max(0.0), 1.0);
                }
            }
            Some(field) => {
                for (f, a) in films.iter_mut().zip(attrs) {
                    let film = field.sample(Vec3::new(a[3], a[4], a[5]));
                    *f = (film.thickness_nm, film.coverage);
                }
            }
        }
        films
    }

    /// Per lane: the view ray through pixel-space point `at` and the film's facing
    /// normal there (interpolated attributes 0..3).
    #[inline(always)]
    fn ray_lanes<const L: usize>(
        &self,
        at: &[(f32, f32)],
        attrs: &[[f32; ATTRS]; L],
    ) -> [FilmRay; L] {
        let mut rays = [FilmRay::ZERO; L];
        for ((ray, &(px, py)), a) in rays.iter_mut().zip(at).zip(attrs) {
            let (ax, ay) = self.view.ray_coefficients(px, py);
            let d = Vec3A::from(self.view.forward)
                + Vec3A::from(self.view.right) * ax
                + Vec3A::from(self.view.up) * ay;
            let v = d.normalize_or(self.view.forward.into());
            let mut n = Vec3A::new(a[0], a[1], a[2]).normalize_or(-v);
            let mut c = v.dot(n);
            // Face the film towards the viewer: back faces show the film from inside.
            if c > 0.0 {
                n = -n;
                c = -c;
            }
            *ray = FilmRay {
                d,
                reflected: Vec3::from(v - n * (2.0 * c)),
                cos_theta: (-c).min(1.0),
            };
        }
        rays
    }

    /// Adds every light's highlight reaching film point `p` (seen along a ray reflected
    /// to `reflected`, through a film of the given thickness at that angle's cosine) to
    /// `add`; returns whether none reaches within [`SHARE_MARGIN_PX`]
    /// (the shading may then be shared within the pixel).
    #[inline(always)]
    fn add_highlights(
        &self,
        tri: &SetupTri,
        p: Vec3,
        reflected: Vec3,
        (thickness_nm, cos_theta): (f32, f32),
        add: &mut [f32; 3],
    ) -> bool {
        let mut shareable = true;
        for (light, table) in self.lights.iter().zip(self.light_tables) {
            // Beyond the widened reach the visibility below is exactly 0.
            let sight = LightSight::new(light, p, reflected);
            if !sight.within_reach(light, tri.extra, SHARE_MARGIN_PX) {
                continue;
            }
            shareable = false;
            let vis = sight.visibility(light, reflected, tri.extra);
            if vis > 0.0 {
                let l = table.sample(thickness_nm, cos_theta);
                let gain = light.highlight_gain();
                for k in 0..3 {
                    add[k] += l[k] * gain[k] * vis;
                }
            }
        }
        shareable
    }

    /// The direction bubble `tri.tag` reads its dynamic cube map in for the ray from film
    /// point `p` along `reflected`, when the parallax correction is on and the ray meets
    /// the ground (`parallax::ground_parallax`).
    #[inline]
    fn parallax_dir(&self, tri: &SetupTri, p: Vec3, reflected: Vec3) -> Option<Vec3> {
        let centre = *self.parallax_centres.get(tri.tag as usize)?;
        ground_parallax(centre, p, reflected, self.ground_height_m?)
    }

    /// Change of the unit reflected direction per pixel along x and y at the point with
    /// view ray `d`, inverse depth `inv_w` and interpolated attributes `a`.
    #[inline]
    fn reflection_derivatives(
        &self,
        tri: &SetupTri,
        d: Vec3A,
        inv_w: f32,
        a: [f32; ATTRS],
    ) -> [Vec3; 2] {
        let w = 1.0 / inv_w;
        let n_raw = Vec3A::new(a[0], a[1], a[2]);
        // n = (attr/w) / (1/w), both affine in pixels: ∂n = (∂(attr/w) − n·∂(1/w))·w.
        let along = |pick: fn(&Plane) -> f32| {
            let da = Vec3A::new(
                pick(&tri.attrs[0]),
                pick(&tri.attrs[1]),
                pick(&tri.attrs[2]),
            );
            (da - n_raw * pick(&tri.inv_w)) * w
        };
        let dn_raw = [along(|p| p.dx), along(|p| p.dy)];
        let dd = [
            Vec3A::from(self.view.right) * self.view.x_per_px,
            -Vec3A::from(self.view.up) * self.view.y_per_px,
        ];
        reflection_derivatives(d, dd, n_raw, dn_raw).map(Vec3::from)
    }
}

/// Pixels a triangle covers whole, shaded together ([`BubbleCtx::shade_lanes`]).
const LANES: usize = 8;

/// Whole pixels of one triangle waiting to be shaded: their centres, first sample index
/// and the samples in front of the opaque scene.
struct PixelBatch {
    len: usize,
    at: [(f32, f32); LANES],
    base: [usize; LANES],
    pass: [u32; LANES],
}

impl PixelBatch {
    const EMPTY: Self = Self {
        len: 0,
        at: [(0.0, 0.0); LANES],
        base: [0; LANES],
        pass: [0; LANES],
    };

    /// Adds a pixel; the caller empties a full batch first.
    #[inline(always)]
    fn push(&mut self, at: (f32, f32), base: usize, pass: u32) {
        self.at[self.len] = at;
        self.base[self.len] = base;
        self.pass[self.len] = pass;
        self.len += 1;
    }
}

/// Blends a film of transmittance `t_rgb` adding `add` over the samples `pass` of one
/// pixel's `samples`.
#[inline(always)]
fn blend(samples: &mut [[f32; 3]], pass: u32, t_rgb: [f32; 3], add: [f32; 3]) {
    for (s, c) in samples.iter_mut().enumerate() {
        if pass & (1 << s) != 0 {
            for k in 0..3 {
                c[k] = c[k] * t_rgb[k] + add[k];
            }
        }
    }
}

/// A shading: the film's transmittance, the radiance it adds, and whether it may be
/// shared within its pixel.
type Shading = ([f32; 3], [f32; 3], bool);

/// The shading of a hole in the film: no film at all.
const HOLE: Shading = ([1.0; 3], [0.0; 3], true);

/// One pixel's view ray and what the film's facing normal makes of it.
#[derive(Debug, Clone, Copy)]
struct FilmRay {
    /// The (unnormalised) view ray.
    d: Vec3A,
    /// The unit view ray mirrored in the film.
    reflected: Vec3,
    /// Cosine of the angle of incidence, in [0, 1].
    cos_theta: f32,
}

impl FilmRay {
    const ZERO: Self = Self {
        d: Vec3A::ZERO,
        reflected: Vec3::ZERO,
        cos_theta: 0.0,
    };
}

/// How far (in pixels of reflected-direction turn) a shading may be reused from the
/// point it was computed at: two points of one pixel are at most √2 pixels apart.
const SHARE_MARGIN_PX: f32 = 2.0;

/// Sets up bubble triangles into `out`: bubbles far to near, each bubble's back faces then
/// front faces. Bubbles are set up in parallel into `layers` (kept between frames) and
/// joined in that order, so the result does not depend on the thread count.
pub(crate) fn setup_bubble_tris(
    scene: &RenderScene,
    view: &View,
    out: &mut Vec<SetupTri>,
    layers: &mut Vec<Vec<SetupTri>>,
) {
    let order = far_to_near(&scene.bubbles, view.eye);
    layers.resize_with(order.len(), Vec::new);
    order
        .par_iter()
        .zip(layers.par_iter_mut())
        .for_each(|(&k, layer)| {
            layer.clear();
            setup_bubble(scene, view, k, layer);
        });
    append_in_order(out, &layers[..order.len()]);
}

/// Sets up bubble `k`'s back faces, then its front faces, into `out`.
fn setup_bubble(scene: &RenderScene, view: &View, k: usize, out: &mut Vec<SetupTri>) {
    let bubble = &scene.bubbles[k];
    for front in [false, true] {
        for t in &bubble.triangles {
            if is_front_facing(bubble, *t, view.eye) != front {
                continue;
            }
            let tri = t.map(|i| {
                let i = i as usize;
                let n = bubble.normals[i];
                // With a film field the material direction replaces the thickness.
                let rest = match &bubble.film {
                    Some(film) => film.material_dirs[i].to_array(),
                    None => [bubble.thickness_nm[i], 0.0, 0.0],
                };
                let [a, b, c] = rest;
                clip_vertex(view, bubble.positions[i], [n.x, n.y, n.z, a, b, c])
            });
            let extra = reflection_rate(view, bubble, *t);
            // One surface per bubble and facing: the back layer, then the front.
            let surface = 2 * k as u32 + u32::from(front);
            setup_triangle(view, tri, k as u32, extra, |s| {
                out.push(SetupTri {
                    surface,
                    mesh_vertices: *t,
                    ..s
                });
            });
        }
    }
}

//! The strip passes: background + opaque triangles, and the bubble blend.
//!
//! A strip is `STRIP_ROWS` full image rows; it owns its pixels' samples outright, so strips
//! run in parallel with no shared writes, and each walks its triangles in one fixed order.

use glam::{Vec3, Vec3A};

use crate::camera::View;
use crate::ground::{SPAN, ground_span, span_supported};
use crate::index_f32::index_f32;
use crate::lod::reflection_derivatives;
use crate::lut_sampler::LutSampler;
use crate::raster::{ATTRS, NO_SURFACE, Plane, SamplePattern, SetupTri, for_each_covered_in_row};
use crate::shading::{ground_albedo, lit, object_albedo};
use crate::sky_span::sky_span;
use crate::water_pass::{WATER, WaterShading, shade_water};
use crate::{
    CubeMap, Environment, Ground, Irradiance, Light, Material, PartialShading, Pattern,
    ReflectionFilter, SphereMap,
};

/// Rows per strip (the unit of parallel work).
pub(crate) const STRIP_ROWS: usize = 8;

/// Tag bit marking an emissive light-sphere triangle (low bits: the light's index).
pub(crate) const EMISSIVE: u32 = 1 << 31;

/// Triangle indices per strip, in submission order (a counting sort).
#[derive(Debug, Clone, Default)]
pub(crate) struct Bins {
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl Bins {
    /// Rebuilds the bins of `tris` for `strips` strips.
    pub fn build(&mut self, tris: &[SetupTri], strips: usize) {
        let range = |t: &SetupTri| {
            (
                t.bbox[1] as usize / STRIP_ROWS,
                (t.bbox[3] as usize - 1) / STRIP_ROWS,
            )
        };
        self.starts.clear();
        self.starts.resize(strips + 2, 0);
        for t in tris {
            let (a, b) = range(t);
            for s in a..=b.min(strips - 1) {
                self.starts[s + 2] += 1;
            }
        }
        for s in 2..self.starts.len() {
            self.starts[s] += self.starts[s - 1];
        }
        self.items.clear();
        self.items.resize(self.starts[strips + 1] as usize, 0);
        // starts[s + 1] is now the write cursor of strip s.
        for (i, t) in tris.iter().enumerate() {
            let (a, b) = range(t);
            for s in a..=b.min(strips - 1) {
                let cursor = &mut self.starts[s + 1];
                self.items[*cursor as usize] = i as u32;
                *cursor += 1;
            }
        }
    }

    /// Triangle indices touching strip `s`.
    pub fn strip(&self, s: usize) -> &[u32] {
        &self.items[self.starts[s] as usize..self.starts[s + 1] as usize]
    }
}

/// The ground plane prepared for one view: its inverse depth is affine in pixel coordinates.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GroundView<'a> {
    pub ground: &'a Ground,
    /// `1/t = c + gx·px + gy·py`; the plane is in front where positive.
    pub c: f32,
    pub gx: f32,
    pub gy: f32,
    /// Unit normal facing the eye.
    pub normal: Vec3,
    /// `1 / (height − eye.y)`.
    pub inv_height: f32,
    /// Change of the (unnormalised) view ray per pixel along x and y.
    pub ddx: Vec3,
    pub ddy: Vec3,
}

impl<'a> GroundView<'a> {
    /// `None` when the eye lies in the plane (it is seen edge-on: nothing to draw).
    pub fn new(ground: &'a Ground, view: &View) -> Option<Self> {
        let height = ground.height_m - view.eye.y;
        if height == 0.0 || !height.is_finite() {
            return None;
        }
        let (sx, sy) = (view.x_per_px, view.y_per_px);
        let inv_h = 1.0 / height;
        Some(Self {
            ground,
            c: (view.forward.y - view.tan_half_x * view.right.y + view.tan_half_y * view.up.y)
                * inv_h,
            gx: sx * view.right.y * inv_h,
            gy: -sy * view.up.y * inv_h,
            normal: if height < 0.0 { Vec3::Y } else { -Vec3::Y },
            inv_height: inv_h,
            ddx: view.right * sx,
            ddy: -view.up * sy,
        })
    }

    #[inline]
    pub fn inv_depth(&self, px: f32, py: f32) -> f32 {
        self.c + self.gx * px + self.gy * py
    }
}

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
                    ground_span(self, g, y, x0 + a, &mut centre[a..b]);
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
        let footprint = [dpx.x.abs() + dpy.x.abs(), dpx.z.abs() + dpy.z.abs()];
        let footprint = footprint.map(|f| if f < 1e9 { f } else { 1e9 });
        let albedo = ground_albedo(&g.ground.material, p.x, p.z, footprint);
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
            return shade_water(self, tri, px, py);
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
}

/// World-space extent (metres per axis) that one pixel covers on a surface with normal `n`
/// hit at depth `t` along view ray `d` (forward component 1): the plane's
/// `∂P/∂px = t·(∂d − d·(∂d·n)/(d·n))`, summed over both pixel axes.
#[inline]
fn surface_footprint(view: &View, d: Vec3, t: f32, n: Vec3) -> [f32; 3] {
    let dn = d.dot(n);
    let step = |dd: Vec3| (dd - d * (dd.dot(n) / dn)) * t;
    let (dx, dy) = (
        step(view.right * view.x_per_px),
        step(-view.up * view.y_per_px),
    );
    // Edge-on (d·n → 0) the footprint is unbounded: the filter then returns the mean.
    [
        dx.x.abs() + dy.x.abs(),
        dx.y.abs() + dy.y.abs(),
        dx.z.abs() + dy.z.abs(),
    ]
    .map(|f| if f < 1e6 { f } else { 1e6 })
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

/// Where one bubble's reflections come from.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Reflection<'a> {
    Cube(&'a CubeMap),
    Env(&'a Environment),
    Sphere(&'a SphereMap),
}

impl Reflection<'_> {
    /// Radiance along unit `dir`; cube maps are filtered by `derivatives`, the change of
    /// the direction per pixel along x and y, unless `filter` asks for the single
    /// bilinear tap.
    #[inline]
    fn sample(&self, dir: Vec3, derivatives: [Vec3; 2], filter: ReflectionFilter) -> [f32; 3] {
        let cube: &CubeMap = match *self {
            Self::Cube(c) | Self::Env(Environment::CubeFaces(c)) => c,
            Self::Env(e) => return e.radiance(dir),
            Self::Sphere(s) => return s.sample(dir),
        };
        match filter {
            ReflectionFilter::Footprint => cube.sample_footprint(dir, derivatives),
            ReflectionFilter::Bilinear => cube.sample(dir),
        }
    }

    /// Whether the lookup uses a footprint (so the shader should compute one).
    #[inline]
    fn is_cube(&self) -> bool {
        matches!(self, Self::Cube(_) | Self::Env(Environment::CubeFaces(_)))
    }
}

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
    /// How cube maps are read.
    pub filter: ReflectionFilter,
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
                let (t_rgb, add) = if mask == full {
                    // Shade at the centre when the triangle covers the pixel.
                    let (t_rgb, add, _) = self.shade(tri, px as f32 + 0.5, py as f32 + 0.5);
                    (t_rgb, add)
                } else {
                    let at = (px as f32, py as f32);
                    self.shade_partial(tri, at, mask, pass, shares, &mut shared[pixel])
                };
                for (s, c) in color[base..base + s_count].iter_mut().enumerate() {
                    if pass & (1 << s) != 0 {
                        for k in 0..3 {
                            c[k] = c[k] * t_rgb[k] + add[k];
                        }
                    }
                }
            });
        }
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
    /// whether they may be shared with the rest of the pixel: no light's highlight reaches
    /// within [`SHARE_MARGIN_PX`] of it.
    ///
    /// The vector arithmetic runs in `Vec3A` lanes: the same IEEE operations in the same
    /// order as `Vec3`'s (glam sums dot products x, y, then z in both), so results are
    /// bit-identical, in fewer instructions.
    #[inline]
    fn shade(&self, tri: &SetupTri, px: f32, py: f32) -> ([f32; 3], [f32; 3], bool) {
        let (inv_w, a) = tri.interpolate(px, py);
        let thickness_nm = a[3].max(0.0);
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
        let cos_theta = (-c).min(1.0);
        let r_rgb = self.reflectivity.sample(thickness_nm, cos_theta);
        let t_rgb = match &self.transmittance {
            Some(t) => t.sample(thickness_nm, cos_theta),
            None => r_rgb.map(|r| 1.0 - r),
        };
        let reflected = v - n * (2.0 * c);
        let reflection = &self.reflections[tri.tag as usize];
        let derivatives = if reflection.is_cube() && self.filter == ReflectionFilter::Footprint {
            self.reflection_derivatives(tri, d, inv_w, a)
        } else {
            [Vec3::ZERO; 2]
        };
        let reflected = Vec3::from(reflected);
        let env = reflection.sample(reflected, derivatives, self.filter);
        let mut add = [r_rgb[0] * env[0], r_rgb[1] * env[1], r_rgb[2] * env[2]];
        let mut shareable = true;
        if !self.lights.is_empty() {
            let p = self.view.eye + Vec3::from(d / inv_w);
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
        }
        (t_rgb, add, shareable)
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

/// Width of the highlight filter in pixels: wide enough that the Gaussian's sum over the
/// pixel grid ripples by 2·exp(−2π²σ²) ≈ 0.16 % with the sub-pixel offset.
pub(crate) const HIGHLIGHT_SIGMA_PX: f32 = 0.6;

/// How far (in pixels of reflected-direction turn) a shading may be reused from the
/// point it was computed at: two points of one pixel are at most √2 pixels apart.
const SHARE_MARGIN_PX: f32 = 2.0;

/// Where a light lies from a shaded point, as its highlight ([`LightSight::visibility`]) and
/// the sharing test ([`LightSight::within_reach`]) both need it, computed once per light
/// and point.
struct LightSight {
    to_light: Vec3,
    dist: f32,
    /// Cosine of the angle between the reflected direction and the light's centre.
    cos_gamma: f32,
}

impl LightSight {
    #[inline]
    fn new(light: &Light, p: Vec3, reflected: Vec3) -> Self {
        let to_light = light.position - p;
        let dist = to_light.length();
        Self {
            to_light,
            dist,
            cos_gamma: reflected.dot(to_light) / dist,
        }
    }

    /// Whether the reflected direction passes within the reach of
    /// [`LightSight::visibility`]'s filter, widened by `margin_px` pixels; where it does not,
    /// the visibility is 0. A point inside the light is always within reach.
    ///
    /// asin x ≤ πx/2 bounds the light's angular radius and 1 − cos γ ≤ γ²/2, so this
    /// rejects only rays beyond both the Gaussian's 4 s and the ramp's reach (most rays,
    /// cheaply).
    #[inline]
    fn within_reach(&self, light: &Light, pixel_angle_rad: f32, margin_px: f32) -> bool {
        if self.dist <= light.radius_m {
            return true;
        }
        let w = pixel_angle_rad.max(1e-5);
        let reach = std::f32::consts::PI * (light.radius_m / self.dist) + (2.5 + margin_px) * w;
        1.0 - self.cos_gamma <= 0.5 * reach * reach
    }

    /// Fraction of a pixel's reflected rays (unit `reflected` at its centre) that hit `light`,
    /// given the angle the reflected direction sweeps per pixel, `pixel_angle_rad`.
    ///
    /// A light of angular radius α at angle γ from `reflected` is filtered by a Gaussian of
    /// σ = 0.6 pixel in reflected directions: `vis = α²/(2s²) · exp(−γ²/2s²)` with
    /// `s² = σ² + α²/4` (the disc's own variance), whose integral over directions is the
    /// light's solid angle πα² for every α; and a normalised Gaussian this wide sums to one
    /// over the pixel grid at any sub-pixel offset (within 0.2 %), so a highlight's energy
    /// in the image is the light's power, whatever its radius. Lights wider than 2σ (whose
    /// peak reaches 1) get a one-pixel linear ramp across the disc's rim instead, within
    /// 6 % of the same energy and with a sharp edge.
    #[inline]
    fn visibility(&self, light: &Light, reflected: Vec3, pixel_angle_rad: f32) -> f32 {
        if self.dist <= light.radius_m {
            return 1.0;
        }
        if !self.within_reach(light, pixel_angle_rad, 0.0) {
            return 0.0;
        }
        let w = pixel_angle_rad.max(1e-5);
        let alpha = (light.radius_m / self.dist).asin();
        // atan2 keeps small angles exact where acos(cos γ) would round them to 3e-4 rad.
        let gamma = reflected
            .cross(self.to_light)
            .length()
            .atan2(self.cos_gamma * self.dist);
        let sigma = HIGHLIGHT_SIGMA_PX * w;
        if alpha <= 2.0 * sigma {
            let s2 = sigma * sigma + 0.25 * alpha * alpha;
            alpha * alpha / (2.0 * s2) * (-gamma * gamma / (2.0 * s2)).exp()
        } else {
            ((alpha - gamma) / w + 0.5).clamp(0.0, 1.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::SamplePattern;

    /// The highlight filter from point `p`, as the shader computes it.
    fn light_visibility(light: &Light, p: Vec3, reflected: Vec3, w: f32) -> f32 {
        LightSight::new(light, p, reflected).visibility(light, reflected, w)
    }

    #[test]
    fn light_visibility_is_one_inside_zero_outside_and_half_on_the_rim() {
        let light = Light {
            position: Vec3::new(0.0, 0.0, -10.0),
            radius_m: 0.5,
            radiance: [1.0; 3],
            light_lut: None,
        };
        let w = 0.001;
        assert_eq!(light_visibility(&light, Vec3::ZERO, -Vec3::Z, w), 1.0);
        assert_eq!(light_visibility(&light, Vec3::ZERO, Vec3::X, w), 0.0);
        let alpha = (0.5f32 / 10.0).asin();
        let rim = Vec3::new(alpha.sin(), 0.0, -alpha.cos());
        let v = light_visibility(&light, Vec3::ZERO, rim, w);
        assert!((v - 0.5).abs() < 0.05, "rim visibility {v}");
        // A light far smaller than a pixel: its solid angle times the filter's peak.
        let tiny = Light {
            radius_m: 1e-4,
            ..light
        };
        let (alpha, w) = (1e-5f32, 0.01f32);
        let sigma = HIGHLIGHT_SIGMA_PX * w;
        let v = light_visibility(&tiny, Vec3::ZERO, -Vec3::Z, w);
        let want =
            std::f32::consts::PI * alpha * alpha / (2.0 * std::f32::consts::PI * sigma * sigma);
        assert!((v - want).abs() < 1e-3 * want, "tiny light {v} vs {want}");
        // Inside the light everything is visible.
        assert_eq!(light_visibility(&light, light.position, Vec3::X, w), 1.0);
    }

    #[test]
    fn positive_run_is_the_first_run_of_positive_values() {
        assert_eq!(positive_run(&[-1.0, 0.0, 2.0, 3.0, 0.0, 4.0]), Some((2, 4)));
        assert_eq!(positive_run(&[1.0, f32::NAN, 1.0]), Some((0, 1)));
        assert_eq!(positive_run(&[-1.0, 1.0]), Some((1, 2)));
        assert_eq!(positive_run(&[0.0, -0.0, f32::NAN]), None);
    }

    #[test]
    fn ground_span_kernel_matches_the_scalar_ground() {
        use crate::{Camera, Ground, Material};
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
            ambient: &Irradiance::from_environment(&Environment::Sky(crate::Sky::default()))
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
                ground_span(&ctx, &g, y, x0 + a, &mut out[..b - a]);
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

    #[test]
    fn bins_list_each_triangle_in_every_strip_it_touches_in_order() {
        let tri = |y0: i32, y1: i32| SetupTri {
            bbox: [0, y0, 4, y1],
            ..SetupTri::default()
        };
        let tris = [tri(0, 3), tri(5, 20), tri(8, 9), tri(30, 32)];
        let mut bins = Bins::default();
        bins.build(&tris, 4);
        assert_eq!(bins.strip(0), &[0, 1]);
        assert_eq!(bins.strip(1), &[1, 2]);
        assert_eq!(bins.strip(2), &[1]);
        assert_eq!(bins.strip(3), &[3]);
    }
}

//! Triangle setup and coverage: homogeneous clipping (near plane plus a guard band),
//! fixed-point edge functions with the top-left fill rule, sample patterns, and the
//! screen-space planes that give perspective-correct attributes.

use glam::Vec3;
use rayon::prelude::*;
use render_scene::camera::View;
use render_scene::tessellate::Geometry;

/// Attributes per rasterised vertex: the scene's [`render_scene::tessellate::ATTRS`]
/// (normal x, y, z and texture u, v; bubbles: normal and thickness) and a sixth, so a
/// bubble with a film field carries its material direction in the last three.
pub(crate) const ATTRS: usize = render_scene::tessellate::ATTRS + 1;

/// Sub-pixel precision of snapped vertices: 1/256 pixel.
pub(crate) const SUBPIXEL: i64 = 256;

/// A vertex in clip space: `x`, `y` scaled by the field of view, `w` the view depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ClipVertex {
    pub x: f32,
    pub y: f32,
    pub w: f32,
    pub attrs: [f32; ATTRS],
}

impl ClipVertex {
    fn lerp(&self, o: &ClipVertex, t: f32) -> ClipVertex {
        let mut attrs = [0.0; ATTRS];
        for (k, a) in attrs.iter_mut().enumerate() {
            *a = self.attrs[k] + (o.attrs[k] - self.attrs[k]) * t;
        }
        ClipVertex {
            x: self.x + (o.x - self.x) * t,
            y: self.y + (o.y - self.y) * t,
            w: self.w + (o.w - self.w) * t,
            attrs,
        }
    }
}

/// `value(px, py) = c + dx·(px − ox) + dy·(py − oy)` around the triangle's origin `(ox, oy)`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Plane {
    pub c: f32,
    pub dx: f32,
    pub dy: f32,
}

impl Plane {
    /// The value at offset `(rx, ry)` from the triangle's origin.
    #[inline]
    pub fn at(&self, rx: f32, ry: f32) -> f32 {
        self.c + self.dx * rx + self.dy * ry
    }
}

/// One integer edge function `E(X, Y) = a·X + b·Y + c` in sub-pixel units, bias folded in:
/// a sample is inside the edge iff `E >= 0`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Edge {
    pub a: i64,
    pub b: i64,
    pub c: i64,
}

impl Edge {
    #[inline]
    pub fn at(&self, x: i64, y: i64) -> i64 {
        self.a * x + self.b * y + self.c
    }
}

/// [`SetupTri::surface`] of a triangle that shares its shading with no other.
pub(crate) const NO_SURFACE: u32 = u32::MAX;

/// A triangle ready to rasterise.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct SetupTri {
    pub edges: [Edge; 3],
    /// Pixel bounding box `[x0, y0, x1, y1)`, clipped to the viewport.
    pub bbox: [i32; 4],
    /// Origin of the planes (vertex 0, in pixels).
    pub ox: f32,
    pub oy: f32,
    /// `1/w` (inverse view depth): larger is nearer.
    pub inv_w: Plane,
    /// `attr/w` for each attribute.
    pub attrs: [Plane; ATTRS],
    /// Caller's payload (material, bubble index, ...).
    pub tag: u32,
    /// Caller's extra payload (e.g. the angular size of a pixel in reflected directions).
    pub extra: f32,
    /// Caller's surface id: consecutive triangles with the same `surface` are one smooth
    /// surface (a bubble's front or back layer), whose partial coverages of one pixel may
    /// share a shading (`BubbleCtx`). [`NO_SURFACE`] shares with nothing.
    pub surface: u32,
    /// The surface mesh's vertex indices of this triangle (its pieces after clipping keep
    /// them): triangles that share one are neighbours on the surface.
    pub mesh_vertices: [u32; 3],
}

impl SetupTri {
    /// Perspective-correct attributes at pixel-space point `(px, py)`, with `1/w`.
    #[inline]
    pub fn interpolate(&self, px: f32, py: f32) -> (f32, [f32; ATTRS]) {
        let rx = px - self.ox;
        let ry = py - self.oy;
        // Clamp keeps extrapolated samples (outside the triangle) in front of the eye.
        let inv_w = self.inv_w.at(rx, ry).max(1e-20);
        let w = 1.0 / inv_w;
        let mut out = [0.0; ATTRS];
        for (o, p) in out.iter_mut().zip(&self.attrs) {
            *o = p.at(rx, ry) * w;
        }
        (inv_w, out)
    }
}

/// Sample positions inside a pixel, in 1/256 pixel from its top-left corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SamplePattern {
    pub count: usize,
    pub offsets: [(i64, i64); 16],
    /// The same offsets in pixels.
    pub offsets_px: [(f32, f32); 16],
}

impl SamplePattern {
    /// The pattern for 1, 4, 8, 9 or 16 samples (D3D standard patterns; 9 is a 3 × 3 grid).
    ///
    /// # Panics
    /// Panics on any other count (settings are validated first).
    pub fn new(count: u32) -> SamplePattern {
        // Offsets from the pixel centre in 1/16 pixel.
        let sixteenths: &[(i64, i64)] = match count {
            1 => &[(0, 0)],
            4 => &render_scene::shader_constants::SAMPLE_OFFSETS_4_SIXTEENTHS,
            8 => &[
                (1, -3),
                (-1, 3),
                (5, 1),
                (-3, -5),
                (-5, 5),
                (-7, -1),
                (3, 7),
                (7, -7),
            ],
            16 => &[
                (1, 1),
                (-1, -3),
                (-3, 2),
                (4, -1),
                (-5, -2),
                (2, 5),
                (5, 3),
                (3, -5),
                (-2, 6),
                (0, -7),
                (-4, -6),
                (-6, 4),
                (-8, 0),
                (7, -4),
                (6, 7),
                (-7, -8),
            ],
            9 => &[],
            _ => panic!("unsupported sample count {count}"),
        };
        let mut offsets = [(0, 0); 16];
        if count == 9 {
            for (k, o) in offsets.iter_mut().take(9).enumerate() {
                let grid = |i: usize| (SUBPIXEL * (2 * i as i64 + 1) + 3) / 6;
                *o = (grid(k % 3), grid(k / 3));
            }
        } else {
            for (o, s) in offsets.iter_mut().zip(sixteenths) {
                *o = (
                    SUBPIXEL / 2 + s.0 * SUBPIXEL / 16,
                    SUBPIXEL / 2 + s.1 * SUBPIXEL / 16,
                );
            }
        }
        let s = 1.0 / SUBPIXEL as f32;
        SamplePattern {
            count: count as usize,
            offsets,
            offsets_px: offsets.map(|(x, y)| (x as f32 * s, y as f32 * s)),
        }
    }

    /// Pixel-space offset of sample `s` from the pixel's top-left corner.
    #[inline]
    pub fn offset_f32(&self, s: usize) -> (f32, f32) {
        self.offsets_px[s]
    }

    /// Bit mask with one bit per sample.
    pub fn full_mask(&self) -> u32 {
        if self.count == 32 {
            u32::MAX
        } else {
            (1u32 << self.count) - 1
        }
    }
}

/// Clip-space planes `k·v >= 0` as `(x, y, w, constant)` coefficients: near, then guard band.
fn clip_planes(view: &View) -> [[f32; 4]; 5] {
    // Keep snapped pixel coordinates within ±2^14 px so edge products fit i64 easily.
    let g = (16384.0 / view.width.max(view.height) as f32).max(1.0);
    [
        [0.0, 0.0, 1.0, -view.near_m],
        [1.0, 0.0, g, 0.0],
        [-1.0, 0.0, g, 0.0],
        [0.0, 1.0, g, 0.0],
        [0.0, -1.0, g, 0.0],
    ]
}

#[inline]
fn plane_distance(p: &[f32; 4], v: &ClipVertex) -> f32 {
    p[0] * v.x + p[1] * v.y + p[2] * v.w + p[3]
}

/// Appends `chunks` to `out` one after another, copying in parallel: the result is the
/// serial concatenation whatever the thread count.
pub(crate) fn append_in_order(out: &mut Vec<SetupTri>, chunks: &[Vec<SetupTri>]) {
    // Where each chunk starts in the concatenation; a binary search maps an index back.
    let starts: Vec<usize> = chunks
        .iter()
        .scan(0, |at, c| {
            let start = *at;
            *at += c.len();
            Some(start)
        })
        .collect();
    let total = chunks.iter().map(Vec::len).sum::<usize>();
    out.par_extend((0..total).into_par_iter().map(|i| {
        let k = starts.partition_point(|&s| s <= i) - 1;
        chunks[k][i - starts[k]]
    }));
}

/// Clips a triangle and sets up each resulting triangle, calling `emit` for every one
/// that covers at least one pixel centre row/column of the viewport bounding box.
pub(crate) fn setup_triangle(
    view: &View,
    tri: [ClipVertex; 3],
    tag: u32,
    extra: f32,
    mut emit: impl FnMut(SetupTri),
) {
    let planes = clip_planes(view);
    let inside_all = tri
        .iter()
        .all(|v| planes.iter().all(|p| plane_distance(p, v) >= 0.0));
    if inside_all {
        if let Some(t) = setup_clipped(view, &tri, tag, extra) {
            emit(t);
        }
        return;
    }
    // Sutherland–Hodgman against each plane; 3 + 5 vertices at most.
    let mut poly = [tri[0]; 8];
    let mut n = 3;
    poly[..3].copy_from_slice(&tri);
    let mut next = [tri[0]; 8];
    for p in &planes {
        let mut m = 0;
        for i in 0..n {
            let a = poly[i];
            let b = poly[(i + 1) % n];
            let da = plane_distance(p, &a);
            let db = plane_distance(p, &b);
            if da >= 0.0 {
                next[m] = a;
                m += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                next[m] = a.lerp(&b, da / (da - db));
                m += 1;
            }
        }
        n = m;
        std::mem::swap(&mut poly, &mut next);
        if n < 3 {
            return;
        }
    }
    for k in 1..n - 1 {
        if let Some(t) = setup_clipped(view, &[poly[0], poly[k], poly[k + 1]], tag, extra) {
            emit(t);
        }
    }
}

/// Sets up a triangle already inside the near plane and guard band; `None` if degenerate
/// or off screen.
fn setup_clipped(view: &View, tri: &[ClipVertex; 3], tag: u32, extra: f32) -> Option<SetupTri> {
    let mut fx = [0i64; 3];
    let mut fy = [0i64; 3];
    let mut inv_w = [0f32; 3];
    for (k, v) in tri.iter().enumerate() {
        let (px, py) = view.pixel_of_clip(v.x, v.y, v.w);
        if !(px.is_finite() && py.is_finite()) {
            return None;
        }
        fx[k] = (px * SUBPIXEL as f32).round() as i64;
        fy[k] = (py * SUBPIXEL as f32).round() as i64;
        inv_w[k] = 1.0 / v.w;
    }
    let area = (fx[1] - fx[0]) * (fy[2] - fy[0]) - (fx[2] - fx[0]) * (fy[1] - fy[0]);
    if area == 0 {
        return None;
    }
    // Make the winding positive so every edge function is >= 0 inside.
    let order = if area > 0 { [0, 1, 2] } else { [0, 2, 1] };
    let x = order.map(|k| fx[k]);
    let y = order.map(|k| fy[k]);
    let min_x = x.iter().min().copied().unwrap_or(0);
    let max_x = x.iter().max().copied().unwrap_or(0);
    let min_y = y.iter().min().copied().unwrap_or(0);
    let max_y = y.iter().max().copied().unwrap_or(0);
    let bbox = [
        (min_x.div_euclid(SUBPIXEL) as i32).max(0),
        (min_y.div_euclid(SUBPIXEL) as i32).max(0),
        ((max_x.div_euclid(SUBPIXEL) + 1) as i32).min(view.width as i32),
        ((max_y.div_euclid(SUBPIXEL) + 1) as i32).min(view.height as i32),
    ];
    if bbox[0] >= bbox[2] || bbox[1] >= bbox[3] {
        return None;
    }
    let mut edges = [Edge::default(); 3];
    for (k, e) in edges.iter_mut().enumerate() {
        // Edge k runs from vertex k+1 to k+2, opposite vertex k.
        let (ax, ay) = (x[(k + 1) % 3], y[(k + 1) % 3]);
        let (bx, by) = (x[(k + 2) % 3], y[(k + 2) % 3]);
        let (ex, ey) = (bx - ax, by - ay);
        let top_left = (ey == 0 && ex > 0) || ey < 0;
        // E(P) = ex·(Py − ay) − ey·(Px − ax); strict unless top-left.
        *e = Edge {
            a: -ey,
            b: ex,
            c: ey * ax - ex * ay - i64::from(!top_left),
        };
    }
    let s = 1.0 / SUBPIXEL as f32;
    let ox = x[0] as f32 * s;
    let oy = y[0] as f32 * s;
    let dx1 = (x[1] - x[0]) as f32 * s;
    let dy1 = (y[1] - y[0]) as f32 * s;
    let dx2 = (x[2] - x[0]) as f32 * s;
    let dy2 = (y[2] - y[0]) as f32 * s;
    let inv_area = 1.0 / (dx1 * dy2 - dx2 * dy1);
    let plane = |f: [f32; 3]| {
        let (f1, f2) = (f[1] - f[0], f[2] - f[0]);
        Plane {
            c: f[0],
            dx: (f1 * dy2 - f2 * dy1) * inv_area,
            dy: (f2 * dx1 - f1 * dx2) * inv_area,
        }
    };
    let iw = order.map(|k| inv_w[k]);
    let mut attrs = [Plane::default(); ATTRS];
    for (a, p) in attrs.iter_mut().enumerate() {
        *p = plane(order.map(|k| tri[k].attrs[a] * inv_w[k]));
    }
    Some(SetupTri {
        edges,
        bbox,
        ox,
        oy,
        inv_w: plane(iw),
        attrs,
        tag,
        extra,
        surface: NO_SURFACE,
        mesh_vertices: [0; 3],
    })
}

/// Calls `f(x, mask)` for each pixel of row `py` in `tri`'s bounding box with at least one
/// covered sample; `mask` has bit `s` set when sample `s` is inside.
#[inline]
pub(crate) fn for_each_covered_in_row(
    tri: &SetupTri,
    pattern: &SamplePattern,
    py: i32,
    mut f: impl FnMut(i32, u32),
) {
    let [x0, _, x1, _] = tri.bbox;
    let y = i64::from(py) * SUBPIXEL;
    let x = i64::from(x0) * SUBPIXEL;
    let mut row = tri.edges.map(|e| e.at(x, y));
    let step = tri.edges.map(|e| e.a * SUBPIXEL);
    let sample_offsets = |e: &Edge, s: usize| {
        let (sx, sy) = pattern.offsets[s];
        e.a * sx + e.b * sy
    };
    if pattern.count == 1 {
        let off = tri.edges.map(|e| sample_offsets(&e, 0));
        let (x0, x1) = reachable(x0, x1, &mut row, step, off);
        for px in x0..x1 {
            if (row[0] + off[0]) | (row[1] + off[1]) | (row[2] + off[2]) >= 0 {
                f(px, 1);
            }
            for k in 0..3 {
                row[k] += step[k];
            }
        }
        return;
    }
    let mut offs = [[0i64; 3]; 16];
    for (s, o) in offs.iter_mut().take(pattern.count).enumerate() {
        *o = tri.edges.map(|e| sample_offsets(&e, s));
    }
    // The common 4-sample pattern gets a fixed-length copy so the sample loop unrolls.
    if pattern.count == 4 {
        let offs4: [[i64; 3]; 4] = [offs[0], offs[1], offs[2], offs[3]];
        covered_in_row(x0, x1, row, step, &offs4, f);
    } else {
        covered_in_row(x0, x1, row, step, &offs[..pattern.count], f);
    }
}

/// The multi-sample row walk of [`for_each_covered_in_row`], for sample edge offsets `offs`.
#[inline(always)]
fn covered_in_row(
    x0: i32,
    x1: i32,
    mut row: [i64; 3],
    step: [i64; 3],
    offs: &[[i64; 3]],
    mut f: impl FnMut(i32, u32),
) {
    let mut most_inside = offs[0];
    for o in offs {
        for k in 0..3 {
            most_inside[k] = most_inside[k].max(o[k]);
        }
    }
    let (x0, x1) = reachable(x0, x1, &mut row, step, most_inside);
    for px in x0..x1 {
        let mut mask = 0u32;
        for (s, o) in offs.iter().enumerate() {
            if (row[0] + o[0]) | (row[1] + o[1]) | (row[2] + o[2]) >= 0 {
                mask |= 1 << s;
            }
        }
        if mask != 0 {
            f(px, mask);
        }
        for k in 0..3 {
            row[k] += step[k];
        }
    }
}

/// Narrows the row walk `x0..x1` to the pixels where every edge can hold a sample, and
/// moves `row` (the edge values at `x0`) to the new start.
///
/// `most_inside[k]` is the largest sample offset of edge `k`: a pixel where
/// `row[k] + most_inside[k]` (advanced to it) is negative for some edge has no sample
/// inside. The bounds come from one division per edge in `f64` (exact for edge values
/// below 2⁵³), truncated and widened by a pixel, so they only ever include more pixels
/// than needed; the walk's own test decides each pixel, and the callbacks are the same as
/// for the whole row, without the empty part of a thin triangle's bounding box.
#[inline(always)]
fn reachable(
    x0: i32,
    x1: i32,
    row: &mut [i64; 3],
    step: [i64; 3],
    most_inside: [i64; 3],
) -> (i32, i32) {
    let (mut lo, mut hi) = (0i64, i64::from(x1) - i64::from(x0));
    for k in 0..3 {
        let v = row[k] + most_inside[k];
        // Edge k holds a sample at pixel x0 + i only if v + step·i >= 0.
        let q = (-v as f64 / step[k] as f64) as i64;
        match step[k].signum() {
            1 => lo = lo.max(q.saturating_sub(1)),
            -1 => hi = hi.min(q.saturating_add(2)),
            _ if v < 0 => return (x0, x0),
            _ => {}
        }
    }
    if lo >= hi {
        return (x0, x0);
    }
    for k in 0..3 {
        row[k] += step[k] * lo;
    }
    (x0 + lo as i32, x0 + hi as i32)
}

/// World-space point `p` with attributes `attrs` in `view`'s clip space.
pub(crate) fn clip_vertex(view: &View, p: Vec3, attrs: [f32; ATTRS]) -> ClipVertex {
    let [x, y, w] = view.clip(p);
    ClipVertex { x, y, w, attrs }
}

/// Clips and sets up every triangle of `geometry` for `view`, appending to `out` in order.
pub(crate) fn setup_geometry(geometry: &Geometry, view: &View, out: &mut Vec<SetupTri>) {
    for (t, &tag) in geometry.triangles.iter().zip(&geometry.tags) {
        let tri = t.map(|i| {
            let [a, b, c, d, e] = geometry.attrs[i as usize];
            clip_vertex(view, geometry.positions[i as usize], [a, b, c, d, e, 0.0])
        });
        setup_triangle(view, tri, tag, 0.0, |s| out.push(s));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use render_scene::Camera;

    fn screen_view(w: usize, h: usize) -> View {
        Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 90.0).view(w, h)
    }

    /// A clip vertex that lands on pixel `(px, py)` at depth `w`.
    fn at_pixel(view: &View, px: f32, py: f32, w: f32) -> ClipVertex {
        let x = (2.0 * px / view.width as f32 - 1.0) * w;
        let y = (1.0 - 2.0 * py / view.height as f32) * w;
        ClipVertex {
            x,
            y,
            w,
            attrs: [0.0; ATTRS],
        }
    }

    fn coverage(view: &View, pattern: &SamplePattern, tris: &[[ClipVertex; 3]]) -> Vec<u32> {
        let mut counts = vec![0u32; view.width * view.height * pattern.count];
        for tri in tris {
            setup_triangle(view, *tri, 0, 0.0, |t| {
                for py in t.bbox[1]..t.bbox[3] {
                    for_each_covered_in_row(&t, pattern, py, |px, mask| {
                        for s in 0..pattern.count {
                            if mask & (1 << s) != 0 {
                                counts[(py as usize * view.width + px as usize) * pattern.count
                                    + s] += 1;
                            }
                        }
                    });
                }
            });
        }
        counts
    }

    proptest::proptest! {
        /// The narrowed row walk calls back for exactly the pixels, and with exactly the
        /// masks, that testing every sample of the bounding box against the edges gives;
        /// slivers (thin, long, steep) are where the narrowing cuts most.
        #[test]
        fn row_walk_matches_a_brute_force_test_of_every_sample(
            v in proptest::array::uniform3(proptest::array::uniform2(-4.0f32..36.0)),
            sliver in 0.0f32..1.0,
            samples in proptest::sample::select(vec![1u32, 4, 8, 9, 16]),
        ) {
            let view = screen_view(32, 32);
            let pattern = SamplePattern::new(samples);
            // Pull the third vertex towards the first edge's midpoint to make slivers.
            let mid = [(v[0][0] + v[1][0]) * 0.5, (v[0][1] + v[1][1]) * 0.5];
            let c = [mid[0] + (v[2][0] - mid[0]) * sliver, mid[1] + (v[2][1] - mid[1]) * sliver];
            let tri = [v[0], v[1], c].map(|p| at_pixel(&view, p[0], p[1], 1.0));
            setup_triangle(&view, tri, 0, 0.0, |t| {
                for py in t.bbox[1]..t.bbox[3] {
                    let mut walked = Vec::new();
                    for_each_covered_in_row(&t, &pattern, py, |px, mask| walked.push((px, mask)));
                    let mut brute = Vec::new();
                    for px in t.bbox[0]..t.bbox[2] {
                        let mut mask = 0;
                        for (s, &(sx, sy)) in pattern.offsets[..pattern.count].iter().enumerate() {
                            let (x, y) = (i64::from(px) * SUBPIXEL + sx, i64::from(py) * SUBPIXEL + sy);
                            if t.edges.iter().all(|e| e.at(x, y) >= 0) {
                                mask |= 1 << s;
                            }
                        }
                        if mask != 0 {
                            brute.push((px, mask));
                        }
                    }
                    assert_eq!(walked, brute, "row {}", py);
                }
            });
        }
    }

    #[test]
    fn shared_edges_cover_each_sample_exactly_once() {
        let view = screen_view(16, 16);
        for samples in [1, 4, 9, 16] {
            let pattern = SamplePattern::new(samples);
            // A fan of triangles around an off-grid centre, covering the whole screen.
            let c = at_pixel(&view, 7.3, 8.6, 1.0);
            let ring: Vec<_> = [
                (0.0, 0.0),
                (5.5, 0.0),
                (16.0, 0.0),
                (16.0, 9.0),
                (16.0, 16.0),
                (8.0, 16.0),
                (0.0, 16.0),
                (0.0, 4.0),
            ]
            .iter()
            .map(|&(x, y)| at_pixel(&view, x, y, 1.0))
            .collect();
            let tris: Vec<_> = (0..ring.len())
                .map(|k| [c, ring[k], ring[(k + 1) % ring.len()]])
                .collect();
            let counts = coverage(&view, &pattern, &tris);
            assert!(
                counts.iter().all(|&n| n == 1),
                "{samples} spp: counts {:?}",
                counts.iter().filter(|&&n| n != 1).count()
            );
        }
    }

    #[test]
    fn grid_of_pixel_aligned_squares_covers_each_pixel_once() {
        // Edges through pixel centres exercise the tie-breaking of the top-left rule.
        let view = screen_view(8, 8);
        let pattern = SamplePattern::new(1);
        let mut tris = Vec::new();
        for j in 0..4 {
            for i in 0..4 {
                let p = |dx: f32, dy: f32| {
                    at_pixel(
                        &view,
                        0.5 + 2.0 * (i as f32 + dx),
                        0.5 + 2.0 * (j as f32 + dy),
                        1.0,
                    )
                };
                // Alternate the diagonal and the winding.
                if (i + j) % 2 == 0 {
                    tris.push([p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)]);
                    tris.push([p(0.0, 0.0), p(0.0, 1.0), p(1.0, 1.0)]);
                } else {
                    tris.push([p(1.0, 0.0), p(0.0, 0.0), p(0.0, 1.0)]);
                    tris.push([p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]);
                }
            }
        }
        let counts = coverage(&view, &pattern, &tris);
        // The squares tile [0.5, 8.5)²: every pixel centre (0.5 .. 7.5) lies on some edge or
        // corner, and the top-left rule must give each to exactly one triangle.
        for py in 0..8 {
            for px in 0..8 {
                assert_eq!(counts[py * 8 + px], 1, "pixel ({px},{py})");
            }
        }
    }

    #[test]
    fn near_plane_clipping_keeps_the_visible_part() {
        let view = screen_view(32, 32);
        // A ground-like triangle from behind the camera to far in front.
        let tri = [
            ClipVertex {
                x: -10.0,
                y: -1.0,
                w: -5.0,
                attrs: [1.0; ATTRS],
            },
            ClipVertex {
                x: 10.0,
                y: -1.0,
                w: -5.0,
                attrs: [1.0; ATTRS],
            },
            ClipVertex {
                x: 0.0,
                y: -1.0,
                w: 20.0,
                attrs: [1.0; ATTRS],
            },
        ];
        let mut n = 0;
        let mut min_w = f32::MAX;
        setup_triangle(&view, tri, 0, 0.0, |t| {
            n += 1;
            for py in t.bbox[1]..t.bbox[3] {
                for_each_covered_in_row(&t, &SamplePattern::new(1), py, |px, _| {
                    let (inv_w, a) = t.interpolate(px as f32 + 0.5, py as f32 + 0.5);
                    min_w = min_w.min(1.0 / inv_w);
                    assert!(
                        (a[0] - 1.0).abs() < 1e-4,
                        "constant attribute drifted to {}",
                        a[0]
                    );
                });
            }
        });
        assert!(n >= 1, "clipped triangle vanished");
        assert!(
            min_w >= view.near_m * 0.999,
            "saw depth {min_w} in front of the near plane"
        );
        // Entirely behind the camera: nothing.
        let behind = tri.map(|v| ClipVertex { w: -1.0, ..v });
        setup_triangle(&view, behind, 0, 0.0, |_| {
            panic!("behind-camera triangle emitted")
        });
    }

    #[test]
    fn perspective_correct_interpolation_matches_the_analytic_value() {
        let cam = Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 60.0);
        let view = cam.view(64, 64);
        // A slanted triangle in world space; attribute 0 = world x, attribute 1 = world depth.
        let world = [
            Vec3::new(-1.0, -1.0, -2.0),
            Vec3::new(2.0, -0.5, -8.0),
            Vec3::new(0.0, 1.5, -4.0),
        ];
        let tri = world.map(|p| {
            let [x, y, w] = view.clip(p);
            let mut attrs = [0.0; ATTRS];
            attrs[0] = p.x;
            attrs[1] = -p.z;
            ClipVertex { x, y, w, attrs }
        });
        let mut checked = 0;
        setup_triangle(&view, tri, 0, 0.0, |t| {
            let n = (world[1] - world[0]).cross(world[2] - world[0]);
            for py in t.bbox[1]..t.bbox[3] {
                for_each_covered_in_row(&t, &SamplePattern::new(1), py, |px, _| {
                    let (cx, cy) = (px as f32 + 0.5, py as f32 + 0.5);
                    let (inv_w, a) = t.interpolate(cx, cy);
                    // Analytic: intersect the pixel ray with the triangle's plane.
                    let d = view.ray(cx, cy);
                    let s = n.dot(world[0]) / n.dot(d);
                    let hit = d * s;
                    assert!(
                        (1.0 / inv_w - s).abs() < 1e-3 * s,
                        "depth {} vs {s}",
                        1.0 / inv_w
                    );
                    assert!((a[0] - hit.x).abs() < 1e-3, "x {} vs {}", a[0], hit.x);
                    assert!((a[1] + hit.z).abs() < 1e-3 * s, "z {} vs {}", a[1], -hit.z);
                    checked += 1;
                });
            }
        });
        assert!(checked > 100, "only {checked} pixels checked");
    }

    #[test]
    fn degenerate_triangles_emit_nothing() {
        let view = screen_view(16, 16);
        let p = at_pixel(&view, 3.0, 3.0, 1.0);
        let q = at_pixel(&view, 9.0, 9.0, 1.0);
        let r = at_pixel(&view, 6.0, 6.0, 1.0);
        setup_triangle(&view, [p, p, p], 0, 0.0, |_| panic!("point emitted"));
        setup_triangle(&view, [p, q, r], 0, 0.0, |_| panic!("line emitted"));
        let nan = ClipVertex { x: f32::NAN, ..p };
        setup_triangle(&view, [nan, q, r], 0, 0.0, |_| panic!("NaN emitted"));
    }

    #[test]
    fn sample_patterns_stay_inside_the_pixel_and_are_distinct() {
        for n in [1, 4, 8, 9, 16] {
            let p = SamplePattern::new(n);
            let offs = &p.offsets[..p.count];
            assert!(
                offs.iter()
                    .all(|&(x, y)| (0..SUBPIXEL).contains(&x) && (0..SUBPIXEL).contains(&y)),
                "{n}: {offs:?}"
            );
            for i in 0..offs.len() {
                for j in 0..i {
                    assert_ne!(offs[i], offs[j], "{n} spp repeats a position");
                }
            }
        }
    }
}

//! [`FilmField`]: a bubble film's thickness and coverage over its material sphere, a cube
//! map in [`crate::cubemap::FACE_BASES`] layout, and [`BubbleFilm`]: the field and where
//! each mesh vertex sits on it.
//!
//! Texel `(x, y)` of face `f` (OpenGL order +X, −X, +Y, −Y, +Z, −Z) is stored at
//! `f·n² + y·n + x` and covers the directions `major + s·U + t·V` with
//! `s ∈ [2x/n − 1, 2(x + 1)/n − 1]` (likewise `t` by `y`): the gnomonic cube-sphere grid
//! the film solver steps is this texture as it is, and [`crate::cubemap::face_coordinates`]
//! finds a direction's texel for the film and the environment cube maps alike.
//!
//! A texel with coverage 0 is a hole (burst film) and its thickness is meaningless:
//! [`FilmField::sample`] weighs the four bilinear taps' thicknesses by their coverage, so a
//! hole's rim neither thins nor darkens the film next to it; the coverage itself is the
//! plain bilinear mean.

use std::sync::Arc;

use glam::{Vec3, Vec4};

use crate::RenderError;
use crate::cubemap::{FACE_BASES, MAX_FACE_SIZE, face_coordinates};
use crate::index_f32::index_f32;

/// Largest thickness a film field may hold, in nm: the largest a film table can be baked
/// over ([`lut::config::MAX_THICKNESS_NM`]).
pub const MAX_FILM_THICKNESS_NM: f32 = lut::config::MAX_THICKNESS_NM;

/// A bubble film's thickness and coverage over its material sphere: a cube map in
/// [`crate::cubemap::FACE_BASES`] layout.
///
/// # Guarantees
/// - `1 <= face_size <= `[`MAX_FACE_SIZE`];
/// - `6·n²` thicknesses, each finite and in `[0, MAX_FILM_THICKNESS_NM]`, and `6·n²`
///   coverages, each in `[0, 1]`;
/// - internally each face is also kept with a one-texel border taken from the neighbouring
///   faces (corners: the coverage-weighted mean of the three texels meeting there), so a
///   bilinear sample is continuous across every edge and corner.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmField {
    face_size: usize,
    thickness_nm: Vec<f32>,
    coverage: Vec<f32>,
    /// Six bordered `(n + 2)²` faces of `[thickness, coverage]`.
    bordered: Vec<[f32; 2]>,
}

/// What [`FilmField::sample`] reads at one direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmSample {
    /// Coverage-weighted bilinear thickness in nm (0 where the four taps are all holes).
    pub thickness_nm: f32,
    /// Bilinear coverage in `[0, 1]`: 0 is no film (a hole), 1 whole film.
    pub coverage: f32,
}

/// A bubble's film field and where each mesh vertex sits on it.
#[derive(Debug, Clone, PartialEq)]
pub struct BubbleFilm {
    /// The field (shared: a solver may hand the same field to several frames).
    pub field: Arc<FilmField>,
    /// Per mesh vertex, its material direction (any non-zero length): where on the field
    /// the vertex sits. Interpolated across each triangle and looked up per pixel.
    pub material_dirs: Vec<Vec3>,
}

impl FilmField {
    /// A field of `6·face_size²` texels in the layout the module describes.
    ///
    /// # Errors
    /// [`RenderError::InvalidSetting`] when `face_size` is 0 or above [`MAX_FACE_SIZE`];
    /// [`RenderError::InvalidScene`] when either vector's length is not `6·face_size²`, a
    /// thickness is not finite or outside `[0, MAX_FILM_THICKNESS_NM]`, or a coverage is
    /// outside `[0, 1]` (naming the value and its face and texel).
    pub fn try_new(
        face_size: usize,
        thickness_nm: Vec<f32>,
        coverage: Vec<f32>,
    ) -> Result<Self, RenderError> {
        if !(1..=MAX_FACE_SIZE).contains(&face_size) {
            return Err(RenderError::setting(
                "film face_size",
                face_size,
                "1 ..= 8192 texels",
            ));
        }
        let texels = 6 * face_size * face_size;
        if thickness_nm.len() != texels || coverage.len() != texels {
            return Err(RenderError::scene(
                "film field",
                format!(
                    "{} thicknesses and {} coverages, expected 6·{face_size}² = {texels} each",
                    thickness_nm.len(),
                    coverage.len()
                ),
            ));
        }
        let texel = |i: usize| {
            let n2 = face_size * face_size;
            let (f, r) = (i / n2, i % n2);
            format!(
                "film field, face {f} texel ({}, {})",
                r % face_size,
                r / face_size
            )
        };
        if let Some(i) = thickness_nm
            .iter()
            .position(|h| !(h.is_finite() && (0.0..=MAX_FILM_THICKNESS_NM).contains(h)))
        {
            return Err(RenderError::scene(
                texel(i),
                format!(
                    "thickness {} nm must be finite and in 0 ..= {MAX_FILM_THICKNESS_NM} nm",
                    thickness_nm[i]
                ),
            ));
        }
        if let Some(i) = coverage.iter().position(|c| !(0.0..=1.0).contains(c)) {
            return Err(RenderError::scene(
                texel(i),
                format!("coverage {} must be in 0 ..= 1", coverage[i]),
            ));
        }
        let mut field = Self {
            face_size,
            thickness_nm,
            coverage,
            bordered: Vec::new(),
        };
        field.bordered = field.build_bordered();
        Ok(field)
    }

    /// Edge length of a face in texels.
    pub fn face_size(&self) -> usize {
        self.face_size
    }

    /// Thickness per texel in nm, `face·n² + y·n + x`.
    pub fn thickness_nm(&self) -> &[f32] {
        &self.thickness_nm
    }

    /// Coverage per texel in `[0, 1]`, `face·n² + y·n + x`.
    pub fn coverage(&self) -> &[f32] {
        &self.coverage
    }

    /// The six bordered faces `sample` reads, `[thickness_nm, coverage]` per texel: face
    /// `f`'s bordered texel `(x, y)` (interior texel `(x − 1, y − 1)`, `x, y ∈ [0, n + 1]`)
    /// at `f·(n + 2)² + y·(n + 2) + x`. For a backend that ports [`FilmField::sample`]
    /// (the wgpu backend uploads it as it is).
    pub fn bordered(&self) -> &[[f32; 2]] {
        &self.bordered
    }

    /// Centre direction (unit) of texel `(x, y)` of face `face`:
    /// `normalize(major + s·U + t·V)` with `s = (x + 0.5)/n·2 − 1`, `t = (y + 0.5)/n·2 − 1`.
    ///
    /// # Panics
    /// Panics if `face >= 6`.
    pub fn texel_direction(face_size: usize, face: usize, x: usize, y: usize) -> Vec3 {
        unit_or_raw(raw_direction(
            face_size,
            face,
            x as f32 + 0.5,
            y as f32 + 0.5,
        ))
    }

    /// Bilinear sample at a material direction (any non-zero length; zero reads the
    /// centre of +X), seamless across face edges and corners.
    ///
    /// The thickness is the coverage-weighted mean of the four taps,
    /// `Σ (w c / Σ w c) h` (0 when `Σ w c = 0`), the coverage their plain bilinear mean.
    /// At a texel's centre both are that texel's values exactly.
    #[inline(always)]
    pub fn sample(&self, material_dir: Vec3) -> FilmSample {
        let (face, s, t) = face_coordinates(material_dir);
        let n = index_f32(self.face_size);
        let m = self.face_size + 2;
        let hi = index_f32(m - 1);
        // Interior texel i has its centre at s = (2i + 1)/n − 1 and is stored at i + 1.
        let fx = ((s + 1.0) * 0.5 * n + 0.5).max(0.0).min(hi);
        let fy = ((t + 1.0) * 0.5 * n + 0.5).max(0.0).min(hi);
        // fx, fy are in [0, m − 1] (m ≤ 8194): the i32 conversion is exact.
        let x0 = (fx as i32 as usize).min(m - 2);
        let y0 = (fy as i32 as usize).min(m - 2);
        let tx = fx - index_f32(x0);
        let ty = fy - index_f32(y0);
        let base = face * m * m + y0 * m + x0;
        let quad = &self.bordered[base..base + m + 2];
        let [a, b, c, d] = [quad[0], quad[1], quad[m], quad[m + 1]];
        let w = Vec4::new(
            (1.0 - tx) * (1.0 - ty),
            tx * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * ty,
        );
        let cov = Vec4::new(a[1], b[1], c[1], d[1]);
        let wc = w * cov;
        let sum = wc.x + wc.y + wc.z + wc.w;
        let thickness_nm = if sum > 0.0 {
            // Each weight divided on its own: at a texel's centre it is exactly 1.
            let k = wc / sum;
            k.x * a[0] + k.y * b[0] + k.z * c[0] + k.w * d[0]
        } else {
            0.0
        };
        let top = a[1] + (b[1] - a[1]) * tx;
        let bottom = c[1] + (d[1] - c[1]) * tx;
        FilmSample {
            thickness_nm,
            coverage: (top + (bottom - top) * ty).clamp(0.0, 1.0),
        }
    }

    /// The six faces with a one-texel border: edges from the neighbouring face's nearest
    /// texel along the border texel's direction, corners the coverage-weighted mean of the
    /// three texels meeting at the cube's corner.
    fn build_bordered(&self) -> Vec<[f32; 2]> {
        let n = self.face_size;
        let m = n + 2;
        let at = |f: usize, x: usize, y: usize| {
            let i = f * n * n + y * n + x;
            [self.thickness_nm[i], self.coverage[i]]
        };
        let mut out = vec![[0.0f32; 2]; 6 * m * m];
        for f in 0..6 {
            for y in 0..m {
                for x in 0..m {
                    let inner_x = (1..=n).contains(&x);
                    let inner_y = (1..=n).contains(&y);
                    out[f * m * m + y * m + x] = if inner_x && inner_y {
                        at(f, x - 1, y - 1)
                    } else if inner_x || inner_y {
                        // Border texel (centre at bordered index − 1 + 0.5 texels).
                        let dir = raw_direction(n, f, x as f32 - 0.5, y as f32 - 0.5);
                        let (g, s, t) = face_coordinates(dir);
                        let to_index = |c: f32| (((c + 1.0) * 0.5 * n as f32) as usize).min(n - 1);
                        at(g, to_index(s), to_index(t))
                    } else {
                        continue;
                    };
                }
            }
            // Corners: the face's corner texel and its two bordered neighbours (the two
            // other faces' texels at that cube corner).
            for (cx, cy, dx, dy) in [(0, 0, 1, 1), (m - 1, 0, m - 2, 1), (0, m - 1, 1, m - 2)]
                .into_iter()
                .chain([(m - 1, m - 1, m - 2, m - 2)])
            {
                let three = [(dx, dy), (cx, dy), (dx, cy)].map(|(x, y)| out[f * m * m + y * m + x]);
                let c_sum: f32 = three.iter().map(|v| v[1]).sum();
                let h = if c_sum > 0.0 {
                    three.iter().map(|v| v[0] * v[1]).sum::<f32>() / c_sum
                } else {
                    three.iter().map(|v| v[0]).sum::<f32>() / 3.0
                };
                out[f * m * m + cy * m + cx] = [h, c_sum / 3.0];
            }
        }
        out
    }
}

/// `major + s·U + t·V` at texel coordinates `(x, y)` (texel `i` spans `[i, i + 1]`).
fn raw_direction(face_size: usize, face: usize, x: f32, y: f32) -> Vec3 {
    let n = face_size as f32;
    let s = x / n * 2.0 - 1.0;
    let t = y / n * 2.0 - 1.0;
    let (major, u, v) = FACE_BASES[face];
    major + u * s + v * t
}

fn unit_or_raw(v: Vec3) -> Vec3 {
    v.normalize_or(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_from(n: usize, f: impl Fn(Vec3) -> (f32, f32)) -> FilmField {
        let mut h = Vec::new();
        let mut c = Vec::new();
        for face in 0..6 {
            for y in 0..n {
                for x in 0..n {
                    let (a, b) = f(FilmField::texel_direction(n, face, x, y));
                    h.push(a);
                    c.push(b);
                }
            }
        }
        FilmField::try_new(n, h, c).unwrap()
    }

    /// A pseudo-random value in [0, 1) from an index.
    fn hash01(i: usize) -> f32 {
        let mut x = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0x1234_5678;
        x ^= x >> 29;
        x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x ^= x >> 32;
        (x >> 40) as f32 / (1u64 << 24) as f32
    }

    #[test]
    fn texel_centres_read_the_texel_exactly() {
        for n in [1usize, 2, 8, 64] {
            let count = 6 * n * n;
            let h: Vec<f32> = (0..count).map(|i| 1000.0 * hash01(i)).collect();
            // Some holes, some partial coverage.
            let c: Vec<f32> = (0..count)
                .map(|i| match i % 5 {
                    0 => 0.0,
                    1 => 0.37,
                    _ => 1.0,
                })
                .collect();
            let field = FilmField::try_new(n, h.clone(), c.clone()).unwrap();
            for f in 0..6 {
                for y in 0..n {
                    for x in 0..n {
                        let i = f * n * n + y * n + x;
                        // The unnormalised centre: exact face coordinates for n a power of two.
                        let dir = raw_direction(n, f, x as f32 + 0.5, y as f32 + 0.5);
                        let got = field.sample(dir);
                        assert_eq!(got.coverage, c[i], "n {n} face {f} ({x}, {y})");
                        let want = if c[i] > 0.0 { h[i] } else { 0.0 };
                        if c[i] > 0.0 {
                            assert_eq!(got.thickness_nm, want, "n {n} face {f} ({x}, {y})");
                        }
                        // The unit direction lands within rounding of the centre.
                        let unit = field.sample(FilmField::texel_direction(n, f, x, y));
                        assert!((unit.coverage - c[i]).abs() < 1e-4);
                        if c[i] > 0.0 {
                            assert!(
                                (unit.thickness_nm - h[i]).abs() < 1e-2,
                                "n {n} face {f} ({x}, {y}): {} vs {}",
                                unit.thickness_nm,
                                h[i]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn texel_direction_round_trips_through_face_coordinates() {
        for n in [1usize, 2, 7, 64] {
            for f in 0..6 {
                for y in 0..n {
                    for x in 0..n {
                        let d = FilmField::texel_direction(n, f, x, y);
                        assert!((d.length() - 1.0).abs() < 1e-6);
                        let (g, s, t) = face_coordinates(d);
                        assert_eq!(g, f, "n {n} ({x}, {y})");
                        let to_texel = |c: f32| (c + 1.0) * 0.5 * n as f32 - 0.5;
                        assert!((to_texel(s) - x as f32).abs() < 1e-3, "n {n} f {f} s {s}");
                        assert!((to_texel(t) - y as f32).abs() < 1e-3, "n {n} f {f} t {t}");
                    }
                }
            }
        }
    }

    /// Largest jump of the sampled thickness and coverage between consecutive points of
    /// a fine great-circle arc through `through`, along `tangent`.
    fn largest_step(field: &FilmField, through: Vec3, tangent: Vec3) -> (f32, f32) {
        let steps = 4000;
        let (mut dh, mut dc) = (0.0f32, 0.0f32);
        let mut last: Option<FilmSample> = None;
        for i in 0..=steps {
            let a = (i as f32 / steps as f32 - 0.5) * 0.2;
            let dir = through * a.cos() + tangent * a.sin();
            let s = field.sample(dir);
            if let Some(l) = last {
                dh = dh.max((s.thickness_nm - l.thickness_nm).abs());
                dc = dc.max((s.coverage - l.coverage).abs());
            }
            last = Some(s);
        }
        (dh, dc)
    }

    /// Directions through every edge midpoint, every cube corner and points along the
    /// edges near the corners, each with two crossing tangents.
    fn seam_crossings() -> Vec<(Vec3, Vec3)> {
        let mut out = Vec::new();
        let signs = [-1.0f32, 1.0];
        for &sx in &signs {
            for &sy in &signs {
                for &sz in &signs {
                    let corner = Vec3::new(sx, sy, sz).normalize();
                    for t in [Vec3::X, Vec3::Y, Vec3::Z, Vec3::new(1.0, 2.0, -0.5)] {
                        out.push((corner, (t - corner * t.dot(corner)).normalize()));
                    }
                }
            }
        }
        for axis in 0..3 {
            for &a in &signs {
                for &b in &signs {
                    for along in [0.0f32, 0.5, 0.9, 0.98, -0.95] {
                        let mut p = [0.0f32; 3];
                        p[axis] = along;
                        p[(axis + 1) % 3] = a;
                        p[(axis + 2) % 3] = b;
                        let p = Vec3::from(p).normalize();
                        // Across the edge, and along a diagonal.
                        let mut across = [0.0f32; 3];
                        across[(axis + 1) % 3] = -b;
                        across[(axis + 2) % 3] = a;
                        let mut diag = across;
                        diag[axis] = 0.7;
                        for t in [Vec3::from(across), Vec3::from(diag)] {
                            out.push((p, (t - p * t.dot(p)).normalize()));
                        }
                    }
                }
            }
        }
        out
    }

    #[test]
    fn samples_are_continuous_across_every_edge_and_corner() {
        let n = 16;
        let field = field_from(n, |d| (500.0 + 300.0 * d.x * d.y, 1.0));
        let mut worst = (0.0f32, 0.0f32);
        for (p, t) in seam_crossings() {
            let (dh, dc) = largest_step(&field, p, t);
            worst = (worst.0.max(dh), worst.1.max(dc));
        }
        // The arc steps 5e-5 rad; the field's gradient is at most 300 nm/rad, the
        // bilinear reconstruction's slope across a texel at most a few times that: a
        // seam would jump by a sizeable fraction of a texel's change (~20 nm).
        assert!(worst.0 < 0.1, "thickness jumps by {} nm", worst.0);
        assert_eq!(worst.1, 0.0);
        // And the field is reproduced: within a texel's change of the smooth function.
        for (p, _) in seam_crossings() {
            let want = 500.0 + 300.0 * p.x * p.y;
            let got = field.sample(p).thickness_nm;
            assert!((got - want).abs() < 30.0, "{p}: {got} vs {want}");
        }
    }

    #[test]
    fn coverage_is_continuous_across_seams_and_holes_do_not_thin_their_rim() {
        let n = 16;
        // Coverage varies smoothly; a thickness of 0 where coverage is 0 must not leak.
        let field = field_from(n, |d| {
            let c = (0.5 + 0.5 * d.z).clamp(0.0, 1.0);
            if d.z < -0.3 { (0.0, 0.0) } else { (800.0, c) }
        });
        let mut worst = 0.0f32;
        for (p, t) in seam_crossings() {
            worst = worst.max(largest_step(&field, p, t).1);
        }
        assert!(worst < 1e-2, "coverage jumps by {worst}");
        // Every sample with any coverage reads 800 nm, holes' thickness never blended in.
        for i in 0..2000 {
            let d = Vec3::new(
                hash01(3 * i) - 0.5,
                hash01(3 * i + 1) - 0.5,
                hash01(3 * i + 2) - 0.5,
            );
            let s = field.sample(d);
            if s.coverage > 0.0 {
                assert!((s.thickness_nm - 800.0).abs() < 1e-3, "{d}: {s:?}");
            } else {
                assert_eq!(s.thickness_nm, 0.0);
            }
        }
    }

    #[test]
    fn invalid_fields_are_refused_naming_the_value_and_texel() {
        let n = 3;
        let ok = || (vec![100.0f32; 6 * n * n], vec![1.0f32; 6 * n * n]);
        let err = |r: Result<FilmField, RenderError>| r.unwrap_err().to_string();
        assert!(err(FilmField::try_new(0, vec![], vec![])).contains("face_size"));
        assert!(err(FilmField::try_new(MAX_FACE_SIZE + 1, vec![], vec![])).contains("face_size"));
        let (h, c) = ok();
        assert!(err(FilmField::try_new(n, h[1..].to_vec(), c)).contains("53 thicknesses"));
        let (h, c) = ok();
        assert!(err(FilmField::try_new(n, h, c[1..].to_vec())).contains("53 coverages"));
        // Face 2, texel (1, 2): index 2·9 + 2·3 + 1 = 25.
        for bad in [f32::NAN, f32::INFINITY, -1.0, MAX_FILM_THICKNESS_NM * 2.0] {
            let (mut h, c) = ok();
            h[25] = bad;
            let e = err(FilmField::try_new(n, h, c));
            assert!(e.contains("face 2 texel (1, 2)"), "{e}");
            assert!(e.contains(&format!("thickness {bad} nm")), "{e}");
        }
        for bad in [f32::NAN, -0.1, 1.5] {
            let (h, mut c) = ok();
            c[25] = bad;
            let e = err(FilmField::try_new(n, h, c));
            assert!(e.contains("face 2 texel (1, 2)"), "{e}");
            assert!(e.contains(&format!("coverage {bad}")), "{e}");
        }
        let (h, c) = ok();
        let f = FilmField::try_new(n, h.clone(), c.clone()).unwrap();
        assert_eq!(
            (f.face_size(), f.thickness_nm(), f.coverage()),
            (n, &h[..], &c[..])
        );
    }
}

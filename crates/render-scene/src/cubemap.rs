//! [`CubeMap`]: six square faces with a one-texel border and a mip chain, sampled seamlessly
//! (bilinearly at level 0, or trilinearly by a pixel's footprint).
//!
//! Face layout and orientation follow OpenGL (`GL_TEXTURE_CUBE_MAP_POSITIVE_X` ..): face
//! `f` maps `(s, t) ∈ [−1, 1]²` (s right, t down the image) to `major + s·U + t·V`.
//! Each face is stored as `(N + 2)²` texels: the border ring holds the scene just past the
//! face edge (rendered with a slightly wider frustum, or fetched from the neighbouring face),
//! so a bilinear tap near an edge blends across it without a seam.

use std::path::Path;

use glam::{Vec3, Vec4};

use crate::RenderError;
use crate::index_f32::index_f32;
use crate::lod::{anisotropic_taps, cube_lod};
use crate::texture::{check_texels, read_linear_rgb};

/// Largest accepted face size, in texels.
pub const MAX_FACE_SIZE: usize = 8192;

/// Major axis, `s` axis and `t` axis of each face, in OpenGL order +X, −X, +Y, −Y, +Z, −Z.
pub const FACE_BASES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Z, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::Z, Vec3::NEG_Y),
    (Vec3::Y, Vec3::X, Vec3::Z),
    (Vec3::NEG_Y, Vec3::X, Vec3::NEG_Z),
    (Vec3::Z, Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_X, Vec3::NEG_Y),
];

/// A cube map of linear RGB radiance with bordered faces and a mip chain.
///
/// # Guarantees
/// - `1 <= face_size <= 8192`;
/// - each face holds `(face_size + 2)²` finite, non-negative texels;
/// - levels 1.. halve the face (rounded down) down to 1 texel, each texel the area
///   average of the level above, each border filled from the neighbouring faces.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeMap {
    /// Level 0 (full resolution) first.
    levels: Vec<Level>,
}

/// One mip level: six bordered `(face_size + 2)²` faces.
#[derive(Debug, Clone, PartialEq)]
struct Level {
    face_size: usize,
    texels: Vec<[f32; 3]>,
}

impl CubeMap {
    /// Builds a cube map from six `face_size²` row-major faces (+X, −X, +Y, −Y, +Z, −Z),
    /// filling each border from the neighbouring faces.
    pub fn try_from_faces(
        face_size: usize,
        faces: [Vec<[f32; 3]>; 6],
    ) -> Result<Self, RenderError> {
        check_face_size(face_size)?;
        for (f, face) in faces.iter().enumerate() {
            if face.len() != face_size * face_size {
                return Err(RenderError::scene(
                    format!("cube face {f}"),
                    format!("{} texels, expected {face_size}²", face.len()),
                ));
            }
            check_texels(&format!("cube face {f}"), face, face_size)?;
        }
        let mut cube = Self::black(face_size);
        let m = face_size + 2;
        let top = &mut cube.levels[0];
        for (f, face) in faces.iter().enumerate() {
            for y in 0..face_size {
                let row = top.face_offset(f) + (y + 1) * m + 1;
                top.texels[row..row + face_size]
                    .copy_from_slice(&face[y * face_size..(y + 1) * face_size]);
            }
        }
        top.fill_borders_from_neighbours();
        cube.build_mips();
        Ok(cube)
    }

    /// Loads six square faces of equal size, +X, −X, +Y, −Y, +Z, −Z (PNG as sRGB, EXR linear).
    pub fn load_faces<P: AsRef<Path>>(paths: [P; 6]) -> Result<Self, RenderError> {
        let mut faces: [Vec<[f32; 3]>; 6] = Default::default();
        let mut size = None;
        for (face, path) in faces.iter_mut().zip(&paths) {
            let path = path.as_ref();
            let (w, h, texels) = read_linear_rgb(path)?;
            let bad = |message: String| RenderError::ImageRead {
                path: path.to_path_buf(),
                message,
            };
            if w != h {
                return Err(bad(format!("cube face is {w}x{h}, not square")));
            }
            if *size.get_or_insert(w) != w {
                return Err(bad(format!(
                    "cube face is {w}x{w}, the first face is {0}x{0}",
                    size.unwrap_or(0)
                )));
            }
            *face = texels;
        }
        let size = size.unwrap_or(0);
        Self::try_from_faces(size, faces).map_err(|e| RenderError::ImageRead {
            path: paths[0].as_ref().to_path_buf(),
            message: e.to_string(),
        })
    }

    /// A cube map of `face_size²` faces (borders included) holding `radiance` along each
    /// texel's direction, with its mip chain.
    pub fn from_radiance(
        face_size: usize,
        radiance: impl Fn(Vec3) -> [f32; 3],
    ) -> Result<Self, RenderError> {
        check_face_size(face_size)?;
        let mut cube = Self::black(face_size);
        let top = &mut cube.levels[0];
        let m = face_size + 2;
        for f in 0..6 {
            for y in 0..m {
                for x in 0..m {
                    let dir = top.texel_direction(f, x, y);
                    let off = top.face_offset(f) + y * m + x;
                    top.texels[off] = radiance(dir);
                }
            }
        }
        cube.build_mips();
        Ok(cube)
    }

    /// Edge length of a level-0 face in texels, border excluded.
    pub fn face_size(&self) -> usize {
        self.levels[0].face_size
    }

    /// Number of mip levels, level 0 included (`⌊log2 face_size⌋ + 1`).
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Texels stored for a cube map of `face_size`, every level and border included.
    pub fn stored_texels(face_size: usize) -> usize {
        mip_sizes(face_size).map(|n| 6 * (n + 2) * (n + 2)).sum()
    }

    /// Per texel of a chain of `face_size`, laid out as [`CubeMap::level_texels`] of every
    /// level one after another: the texel [`CubeMap::build_mips`] copies into it, a border
    /// texel's source on the neighbouring face, an interior texel's own index.
    ///
    /// Why a table: at a face's corners the border texel's direction lies as far into
    /// two neighbouring faces, and which one it reads turns on the last bit of its face
    /// coordinates. A GPU's division is not correctly rounded, so the wgpu backend
    /// computing them itself read the other face at some corners (an NVIDIA H200 did,
    /// lavapipe did not); with this table it copies exactly what the CPU copies.
    pub fn border_source_table(face_size: usize) -> Vec<u32> {
        let mut table = Vec::with_capacity(Self::stored_texels(face_size));
        for n in mip_sizes(face_size) {
            let level = Level::black(n);
            let start = table.len();
            table.extend((0..6 * (n + 2) * (n + 2)).map(|i| (start + i) as u32));
            for f in 0..6 {
                for (x, y) in border_ring(n + 2) {
                    let source = level.border_source(f, x, y);
                    table[start + level.bordered_index(f, x, y)] = (start + source) as u32;
                }
            }
        }
        table
    }

    /// Level `level`'s six bordered `(n + 2)²` faces row-major, `n` its face size (the
    /// layout the wgpu backend's mip buffer mirrors).
    ///
    /// # Panics
    /// Panics if `level >= self.levels()`.
    pub fn level_texels(&self, level: usize) -> &[[f32; 3]] {
        let l = &self.levels[level];
        let m = l.face_size + 2;
        &l.texels[..6 * m * m]
    }

    /// Interior texel `(x, y)` of face `face` (0..6 in +X, −X, +Y, −Y, +Z, −Z order).
    ///
    /// # Panics
    /// Panics if `face >= 6` or `x, y >= face_size`.
    pub fn texel(&self, face: usize, x: usize, y: usize) -> [f32; 3] {
        self.levels[0].texel(face, x, y)
    }

    /// Seamless bilinear lookup of level 0 along `dir` (any length; zero reads +X).
    #[inline(always)]
    pub fn sample(&self, dir: Vec3) -> [f32; 3] {
        let (face, s, t) = face_coordinates(dir);
        self.levels[0].bilinear(face, s, t)
    }

    /// Seamless filtered lookup along `dir` for a pixel over which the direction changes
    /// by `derivatives` (per pixel along x and y): trilinear taps spread along the longer
    /// derivative ([`crate::lod::anisotropic_taps`]), all at the level
    /// [`crate::lod::cube_lod`] gives at `dir`, clamped to the chain. A footprint within
    /// level 0 reads one bilinear tap, as [`CubeMap::sample`].
    #[inline]
    pub fn sample_footprint(&self, dir: Vec3, derivatives: [Vec3; 2]) -> [f32; 3] {
        let [a, b] = derivatives;
        let (major, minor) = if a.length_squared() >= b.length_squared() {
            (a, b)
        } else {
            (b, a)
        };
        let (face, s, t) = face_coordinates(dir);
        let major_rad = major.length();
        let n = self.face_size();
        let major_lod = cube_lod(major_rad, n, s, t);
        if major_lod <= 0.0 {
            return self.levels[0].bilinear(face, s, t);
        }
        let last = index_f32(self.levels.len() - 1);
        let (taps, footprint_rad) = anisotropic_taps(major_rad, minor.length());
        if taps == 1 {
            // One tap filters over the major axis itself: its level is the one just computed.
            return rgb(self.trilinear(face, s, t, major_lod.min(last)));
        }
        let lod = cube_lod(footprint_rad, n, s, t).min(last);
        let step = major * dir.length();
        let mut sum = Vec4::ZERO;
        for i in 0..taps {
            let offset = (index_f32(i) + 0.5) / index_f32(taps) - 0.5;
            let (face, s, t) = face_coordinates(dir + step * offset);
            sum += self.trilinear(face, s, t, lod);
        }
        rgb(sum / index_f32(taps))
    }

    /// Seamless trilinear tap at face coordinates `(s, t)` and level `lod` in
    /// `[0, levels − 1]`, in the first three lanes.
    #[inline(always)]
    fn trilinear(&self, face: usize, s: f32, t: f32, lod: f32) -> Vec4 {
        // lod is in [0, last]: the conversion is exact.
        let l0 = lod as i32 as usize;
        let frac = lod - index_f32(l0);
        let (u, v) = ((s + 1.0) * 0.5, (t + 1.0) * 0.5);
        let a = self.levels[l0].bilinear4(face, u, v);
        if frac <= 0.0 || l0 + 1 == self.levels.len() {
            return a;
        }
        let b = self.levels[l0 + 1].bilinear4(face, u, v);
        a + (b - a) * frac
    }

    /// An all-black cube map with its whole chain allocated, the starting point of a
    /// render target.
    pub fn black(face_size: usize) -> Self {
        Self {
            levels: mip_sizes(face_size).map(Level::black).collect(),
        }
    }

    /// Bordered level-0 face `face` as an `(N + 2)²` slice.
    pub fn face(&self, face: usize) -> &[[f32; 3]] {
        let m = self.face_size() + 2;
        &self.levels[0].texels[face * m * m..(face + 1) * m * m]
    }

    /// The six bordered level-0 faces as mutable `(N + 2)²` slices, for rendering into
    /// (then call [`CubeMap::build_mips`]).
    pub fn faces_mut(&mut self) -> std::slice::ChunksExactMut<'_, [f32; 3]> {
        let m = self.face_size() + 2;
        self.levels[0].texels.chunks_exact_mut(m * m)
    }

    /// Rebuilds levels 1.. from level 0: O(level-0 texels).
    pub fn build_mips(&mut self) {
        for k in 1..self.levels.len() {
            let (above, below) = self.levels.split_at_mut(k);
            below[0].downsample_from(&above[k - 1]);
            below[0].fill_borders_from_neighbours();
        }
    }
}

/// The first three lanes.
#[inline(always)]
fn rgb(v: Vec4) -> [f32; 3] {
    [v.x, v.y, v.z]
}

/// Face sizes of the chain: `face_size`, halved (rounded down) until 1.
fn mip_sizes(face_size: usize) -> impl Iterator<Item = usize> {
    std::iter::successors(Some(face_size), |&n| (n > 1).then_some(n / 2))
}

/// The border ring of an `m × m` bordered face: the top and bottom rows whole, then the two
/// columns between them.
fn border_ring(m: usize) -> impl Iterator<Item = (usize, usize)> {
    let rows = [0, m - 1]
        .into_iter()
        .flat_map(move |y| (0..m).map(move |x| (x, y)));
    rows.chain((1..m - 1).flat_map(move |y| [(0, y), (m - 1, y)]))
}

impl Level {
    fn black(face_size: usize) -> Self {
        let m = face_size + 2;
        // One texel past the last face: a 4-lane load of the last texel stays in bounds.
        Self {
            face_size,
            texels: vec![[0.0; 3]; 6 * m * m + 1],
        }
    }

    fn face_offset(&self, face: usize) -> usize {
        let m = self.face_size + 2;
        face * m * m
    }

    fn texel(&self, face: usize, x: usize, y: usize) -> [f32; 3] {
        assert!(
            face < 6 && x < self.face_size && y < self.face_size,
            "texel out of range"
        );
        self.texels[self.face_offset(face) + (y + 1) * (self.face_size + 2) + x + 1]
    }

    /// Bilinear tap at face coordinates `(s, t) ∈ [−1, 1]²`, borders included.
    #[inline(always)]
    fn bilinear(&self, face: usize, s: f32, t: f32) -> [f32; 3] {
        rgb(self.bilinear4(face, (s + 1.0) * 0.5, (t + 1.0) * 0.5))
    }

    /// Bilinear tap at `(u, v) = ((s + 1)/2, (t + 1)/2) ∈ [0, 1]²` in the first three lanes of
    /// a vector. Each lane runs [`crate::texture::bilerp`]'s operations in its order, so the
    /// result is bit-identical to the scalar blend, in a third of the arithmetic.
    #[inline(always)]
    fn bilinear4(&self, face: usize, u: f32, v: f32) -> Vec4 {
        let n = index_f32(self.face_size);
        let m = self.face_size + 2;
        let hi = index_f32(m - 1);
        // Interior texel i has its centre at s = (2i + 1)/N − 1 and is stored at i + 1, so
        // `u·N + 1/2` is in [1/2, N + 1/2]; the bounds only catch NaN (→ 0) and rounding.
        let fx = (u * n + 0.5).max(0.0).min(hi);
        let fy = (v * n + 0.5).max(0.0).min(hi);
        // fx, fy are in [0, m − 1] (m ≤ 8194): i32 conversion is exact and cheaper than usize's.
        let x0 = (fx as i32 as usize).min(m - 2);
        let y0 = (fy as i32 as usize).min(m - 2);
        let tx = fx - index_f32(x0);
        let ty = fy - index_f32(y0);
        let base = self.face_offset(face) + y0 * m + x0;
        // Four floats from each texel: its RGB and the next texel's red, which is ignored
        // (the padding texel keeps the last one in bounds). One bounds check for all four.
        let quad = &self.texels.as_flattened()[3 * base..3 * (base + m + 1) + 4];
        let load = |k: usize| Vec4::from_slice(&quad[k..k + 4]);
        let (a, b, c, d) = (load(0), load(3), load(3 * m), load(3 * m + 3));
        let top = a + (b - a) * tx;
        let bottom = c + (d - c) * tx;
        top + (bottom - top) * ty
    }

    /// Direction through the centre of bordered texel `(x, y)` of face `face`.
    fn texel_direction(&self, face: usize, x: usize, y: usize) -> Vec3 {
        let n = self.face_size as f32;
        let s = (2.0 * x as f32 - 1.0) / n - 1.0;
        let t = (2.0 * y as f32 - 1.0) / n - 1.0;
        let (major, u, v) = FACE_BASES[face];
        major + u * s + v * t
    }

    /// Border texels take the nearest interior texel along their own direction.
    fn fill_borders_from_neighbours(&mut self) {
        // Each border texel reads an interior texel, so the order does not matter.
        for f in 0..6 {
            for (x, y) in border_ring(self.face_size + 2) {
                let dst = self.bordered_index(f, x, y);
                self.texels[dst] = self.texels[self.border_source(f, x, y)];
            }
        }
    }

    /// Index in this level of bordered texel `(x, y)` of face `face`.
    fn bordered_index(&self, face: usize, x: usize, y: usize) -> usize {
        self.face_offset(face) + y * (self.face_size + 2) + x
    }

    /// Index in this level of the interior texel that border texel `(x, y)` of face `face`
    /// copies: the one its own direction falls in on the neighbouring face.
    fn border_source(&self, face: usize, x: usize, y: usize) -> usize {
        let (g, s, t) = face_coordinates(self.texel_direction(face, x, y));
        let to_index =
            |c: f32| (((c + 1.0) * 0.5 * self.face_size as f32) as usize).min(self.face_size - 1);
        self.bordered_index(g, to_index(s) + 1, to_index(t) + 1)
    }

    /// Interior texels as area averages of `above`'s interior (exact 2 × 2 boxes when its
    /// size is even; an odd size spreads each edge texel over two outputs by its overlap).
    fn downsample_from(&mut self, above: &Level) {
        let (m_src, m) = (above.face_size + 2, self.face_size + 2);
        if above.face_size == 2 * self.face_size {
            // Exact 2 × 2 boxes: the common case, without the general weights.
            let n = self.face_size;
            for f in 0..6 {
                let (src, dst) = (above.face_offset(f), self.face_offset(f));
                for y in 0..n {
                    let row = src + (2 * y + 1) * m_src + 1;
                    let (upper, lower) = (
                        &above.texels[row..row + 2 * n],
                        &above.texels[row + m_src..row + m_src + 2 * n],
                    );
                    let out = &mut self.texels[dst + (y + 1) * m + 1..][..n];
                    // Whole rows as slices of equal length: the loop runs without bounds
                    // checks and vectorises; each texel is the same sum as before.
                    for ((o, a), b) in out
                        .iter_mut()
                        .zip(upper.chunks_exact(2))
                        .zip(lower.chunks_exact(2))
                    {
                        *o =
                            std::array::from_fn(|k| (a[0][k] + a[1][k] + b[0][k] + b[1][k]) * 0.25);
                    }
                }
            }
            return;
        }
        let weights = box_weights(above.face_size, self.face_size);
        for f in 0..6 {
            let (src, dst) = (above.face_offset(f), self.face_offset(f));
            for (y, wy) in weights.iter().enumerate() {
                for (x, wx) in weights.iter().enumerate() {
                    let mut sum = [0.0f32; 3];
                    for &(j, vy) in wy {
                        for &(i, vx) in wx {
                            let texel = above.texels[src + (j + 1) * m_src + i + 1];
                            for k in 0..3 {
                                sum[k] += texel[k] * (vx * vy);
                            }
                        }
                    }
                    self.texels[dst + (y + 1) * m + x + 1] = sum;
                }
            }
        }
    }
}

/// Per output texel of `n_out`, the source texels of `n` it overlaps and their weights
/// (overlap over the output texel's width in source texels; they sum to one).
fn box_weights(n: usize, n_out: usize) -> Vec<Vec<(usize, f32)>> {
    let ratio = n as f64 / n_out as f64;
    (0..n_out)
        .map(|i| {
            let (lo, hi) = (i as f64 * ratio, (i + 1) as f64 * ratio);
            (lo.floor() as usize..(hi.ceil() as usize).min(n))
                .map(|j| {
                    let overlap = hi.min((j + 1) as f64) - lo.max(j as f64);
                    (j, (overlap / ratio) as f32)
                })
                .filter(|&(_, w)| w > 0.0)
                .collect()
        })
        .collect()
}

/// Face index and `(s, t) ∈ [−1, 1]²` of a direction (major axis wins; ties go to X, then Y).
#[inline]
pub fn face_coordinates(dir: Vec3) -> (usize, f32, f32) {
    let a = dir.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if dir.x >= 0.0 {
            (0, -dir.z, -dir.y, a.x)
        } else {
            (1, dir.z, -dir.y, a.x)
        }
    } else if a.y >= a.z {
        if dir.y >= 0.0 {
            (2, dir.x, dir.z, a.y)
        } else {
            (3, dir.x, -dir.z, a.y)
        }
    } else if dir.z >= 0.0 {
        (4, dir.x, -dir.y, a.z)
    } else {
        (5, -dir.x, -dir.y, a.z)
    };
    if ma > 0.0 && ma.is_finite() {
        let inv = 1.0 / ma;
        (
            face,
            (sc * inv).clamp(-1.0, 1.0),
            (tc * inv).clamp(-1.0, 1.0),
        )
    } else {
        (0, 0.0, 0.0)
    }
}

fn check_face_size(face_size: usize) -> Result<(), RenderError> {
    if (1..=MAX_FACE_SIZE).contains(&face_size) {
        Ok(())
    } else {
        Err(RenderError::setting(
            "face_size",
            face_size,
            "1 ..= 8192 texels",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Environment;
    use crate::Sky;

    #[test]
    fn face_bases_agree_with_face_coordinates() {
        for (f, (major, u, v)) in FACE_BASES.iter().enumerate() {
            for &(s, t) in &[(0.0, 0.0), (0.5, -0.25), (-0.9, 0.8)] {
                let (g, s2, t2) = face_coordinates(*major + *u * s + *v * t);
                assert_eq!(g, f, "face of ({s},{t})");
                assert!(
                    (s2 - s).abs() < 1e-6 && (t2 - t).abs() < 1e-6,
                    "face {f}: ({s2},{t2}) vs ({s},{t})"
                );
            }
        }
    }

    #[test]
    fn environment_cube_reproduces_a_smooth_environment() {
        let env = Environment::Sky(Sky::default());
        let cube = CubeMap::from_environment(&env, 64).unwrap();
        // Directions across face edges and corners must read the sky within bilinear error.
        for &d in &[
            Vec3::new(1.0, 1.0, 0.3),
            Vec3::new(1.0, 0.999, -1.0),
            Vec3::new(-1.0, 0.2, 1.0),
            Vec3::new(0.3, -1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
        ] {
            let want = env.radiance(d);
            let got = cube.sample(d);
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() < 0.01,
                    "{d}: channel {k} off by {}",
                    got[k] - want[k]
                );
            }
        }
    }

    #[test]
    fn loaded_faces_are_seamless_across_edges() {
        // A linear function of direction: seamless sampling must be continuous across edges.
        let f = |d: Vec3| {
            let d = d.normalize();
            [d.x + 1.0, d.y + 1.0, d.z + 1.0]
        };
        let n = 32;
        let faces: [Vec<[f32; 3]>; 6] = std::array::from_fn(|face| {
            let (major, u, v) = FACE_BASES[face];
            (0..n * n)
                .map(|k| {
                    let s = (2.0 * (k % n) as f32 + 1.0) / n as f32 - 1.0;
                    let t = (2.0 * (k / n) as f32 + 1.0) / n as f32 - 1.0;
                    f(major + u * s + v * t)
                })
                .collect()
        });
        let cube = CubeMap::try_from_faces(n, faces).unwrap();
        // Step across the +X/+Y edge in tiny increments; no jump bigger than the local slope.
        let mut prev = cube.sample(Vec3::new(1.0, 0.98, 0.2));
        for k in 1..=40 {
            let y = 0.98 + 0.001 * k as f32;
            let cur = cube.sample(Vec3::new(1.0, y, 0.2));
            for c in 0..3 {
                assert!(
                    (cur[c] - prev[c]).abs() < 0.02,
                    "jump {} at y {y}",
                    cur[c] - prev[c]
                );
            }
            prev = cur;
        }
    }

    /// Faces of a linear function of direction (+1 so it is non-negative).
    fn linear_faces(n: usize) -> [Vec<[f32; 3]>; 6] {
        std::array::from_fn(|face| {
            let (major, u, v) = FACE_BASES[face];
            (0..n * n)
                .map(|k| {
                    let s = (2.0 * (k % n) as f32 + 1.0) / n as f32 - 1.0;
                    let t = (2.0 * (k / n) as f32 + 1.0) / n as f32 - 1.0;
                    let d = (major + u * s + v * t).normalize();
                    [d.x + 1.0, d.y + 1.0, d.z + 1.0]
                })
                .collect()
        })
    }

    fn face_mean(level: &Level, face: usize) -> [f64; 3] {
        let n = level.face_size;
        let mut sum = [0.0f64; 3];
        for y in 0..n {
            for x in 0..n {
                let t = level.texel(face, x, y);
                for k in 0..3 {
                    sum[k] += f64::from(t[k]) / (n * n) as f64;
                }
            }
        }
        sum
    }

    #[test]
    fn every_level_keeps_each_face_mean_and_halves_down_to_one_texel() {
        for n in [32, 24, 5] {
            let cube = CubeMap::try_from_faces(n, linear_faces(n)).unwrap();
            let sizes: Vec<usize> = cube.levels.iter().map(|l| l.face_size).collect();
            assert_eq!(sizes.last(), Some(&1), "{n}: sizes {sizes:?}");
            assert_eq!(sizes.len(), n.ilog2() as usize + 1, "{n}: sizes {sizes:?}");
            for level in &cube.levels[1..] {
                for f in 0..6 {
                    let (want, got) = (face_mean(&cube.levels[0], f), face_mean(level, f));
                    for k in 0..3 {
                        assert!(
                            (got[k] - want[k]).abs() < 1e-5,
                            "{n}: level of {} face {f} channel {k}: mean off by {}",
                            level.face_size,
                            got[k] - want[k]
                        );
                    }
                }
            }
        }
        // An even size halves by exact 2 × 2 boxes.
        let cube = CubeMap::try_from_faces(8, linear_faces(8)).unwrap();
        let (l0, l1) = (&cube.levels[0], &cube.levels[1]);
        let want: f32 = [(2, 4), (3, 4), (2, 5), (3, 5)]
            .iter()
            .map(|&(x, y)| l0.texel(3, x, y)[1] / 4.0)
            .sum();
        assert!((l1.texel(3, 1, 2)[1] - want).abs() < 1e-6);
        assert_eq!(CubeMap::stored_texels(8), 6 * (100 + 36 + 16 + 9));
    }

    #[test]
    fn border_source_table_indexes_the_chain_as_build_mips_fills_it() {
        for n in [5, 8, 24] {
            let cube = CubeMap::try_from_faces(n, linear_faces(n)).unwrap();
            let table = CubeMap::border_source_table(n);
            assert_eq!(table.len(), CubeMap::stored_texels(n));
            let chain: Vec<[f32; 3]> = (0..cube.levels())
                .flat_map(|l| cube.level_texels(l).iter().copied())
                .collect();
            for (k, &src) in table.iter().enumerate() {
                assert_eq!(chain[k], chain[src as usize], "n {n}: texel {k} from {src}");
            }
        }
    }

    #[test]
    fn every_border_texel_copies_an_interior_texel_of_a_neighbouring_face_next_to_it() {
        let n = 16;
        let table = CubeMap::border_source_table(n);
        let (m, level) = (n + 2, Level::black(n));
        let interior = |k: usize| {
            let (f, r) = (k / (m * m), k % (m * m));
            let (x, y) = (r % m, r / m);
            (f, x, y, (1..=n).contains(&x) && (1..=n).contains(&y))
        };
        let mut corners = 0;
        for (k, &src) in table[..6 * m * m].iter().enumerate() {
            let (f, x, y, inside) = interior(k);
            if inside {
                assert_eq!(src as usize, k, "interior texel {k} is its own");
                continue;
            }
            let (g, sx, sy, source_inside) = interior(src as usize);
            assert!(
                source_inside && g != f,
                "border {f} ({x}, {y}) reads {g} ({sx}, {sy})"
            );
            let (a, b) = (
                level.texel_direction(f, x, y).normalize(),
                level.texel_direction(g, sx, sy).normalize(),
            );
            // A texel spans about 2/n rad at a face's centre; a corner's source is a
            // texel diagonal away.
            assert!(
                a.angle_between(b) < 2.0 / n as f32,
                "border {f} ({x}, {y}) from {g}"
            );
            corners += usize::from((x == 0 || x == m - 1) && (y == 0 || y == m - 1));
        }
        assert_eq!(corners, 24);
    }

    #[test]
    fn box_weights_sum_to_one_and_cover_the_source() {
        for (n, m) in [(8, 4), (5, 2), (3, 1), (7, 3)] {
            let w = box_weights(n, m);
            let mut per_source = vec![0.0f32; n];
            for taps in &w {
                let total: f32 = taps.iter().map(|&(_, v)| v).sum();
                assert!(
                    (total - 1.0).abs() < 1e-6,
                    "{n}→{m}: weights sum to {total}"
                );
                for &(j, v) in taps {
                    per_source[j] += v;
                }
            }
            for (j, &p) in per_source.iter().enumerate() {
                let want = m as f32 / n as f32;
                assert!((p - want).abs() < 1e-6, "{n}→{m}: source {j} weighs {p}");
            }
        }
    }

    #[test]
    fn filtered_lookup_is_seamless_across_edges_at_every_level() {
        let cube = CubeMap::try_from_faces(32, linear_faces(32)).unwrap();
        // Through the 4 × 4 level (0.8 rad reads levels 2-3 of 32²); at 2 × 2 and 1 × 1 each
        // border texel stands for much of a neighbouring face and a seam of 1-2 % remains.
        for footprint in [0.0f32, 0.1, 0.4, 0.8] {
            let derivatives = [Vec3::X * footprint, Vec3::Z * footprint];
            let mut prev = cube.sample_footprint(Vec3::new(1.0, 0.98, 0.2), derivatives);
            for k in 1..=40 {
                let y = 0.98 + 0.001 * k as f32;
                let cur = cube.sample_footprint(Vec3::new(1.0, y, 0.2), derivatives);
                for c in 0..3 {
                    assert!(
                        (cur[c] - prev[c]).abs() < 0.02,
                        "footprint {footprint}: jump {} at y {y}",
                        cur[c] - prev[c]
                    );
                }
                prev = cur;
            }
        }
    }

    #[test]
    fn filtered_lookup_reads_level_zero_for_tiny_footprints_and_the_mean_for_huge_ones() {
        let cube = CubeMap::try_from_faces(16, linear_faces(16)).unwrap();
        let d = Vec3::new(0.3, -0.2, 1.0);
        assert_eq!(cube.sample_footprint(d, [Vec3::ZERO; 2]), cube.sample(d));
        // A footprint wider than the cube reads the one-texel level: at the face's centre,
        // the face's mean.
        let huge = cube.sample_footprint(Vec3::Z, [Vec3::X * 10.0, Vec3::Y * 10.0]);
        let want = face_mean(&cube.levels[0], 4);
        for k in 0..3 {
            assert!(
                (f64::from(huge[k]) - want[k]).abs() < 1e-5,
                "channel {k}: {huge:?} vs {want:?}"
            );
        }
    }

    #[test]
    fn rejects_bad_faces() {
        let ok = || vec![[0.0f32; 3]; 4];
        assert!(CubeMap::try_from_faces(2, [ok(), ok(), ok(), ok(), ok(), vec![]]).is_err());
        let mut bad = ok();
        bad[1][2] = f32::NAN;
        assert!(CubeMap::try_from_faces(2, [ok(), ok(), bad, ok(), ok(), ok()]).is_err());
        assert!(CubeMap::try_from_faces(0, Default::default()).is_err());
        assert!(
            CubeMap::sample(&CubeMap::black(4), Vec3::NAN)
                .iter()
                .all(|c| c.is_finite())
        );
    }
}

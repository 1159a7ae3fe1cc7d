//! [`CubeMap`]: six square faces with a one-texel border, sampled seamlessly and bilinearly.
//!
//! Face layout and orientation follow OpenGL (`GL_TEXTURE_CUBE_MAP_POSITIVE_X` ..): face
//! `f` maps `(s, t) ∈ [−1, 1]²` (s right, t down the image) to `major + s·U + t·V`.
//! Each face is stored as `(N + 2)²` texels: the border ring holds the scene just past the
//! face edge (rendered with a slightly wider frustum, or fetched from the neighbouring face),
//! so a bilinear tap near an edge blends across it without a seam.

use std::path::Path;

use glam::Vec3;

use crate::texture::{bilerp, check_texels, read_linear_rgb};
use crate::{Environment, RenderError};

/// Largest accepted face size, in texels.
pub const MAX_FACE_SIZE: usize = 8192;

/// Major axis, `s` axis and `t` axis of each face, in OpenGL order +X, −X, +Y, −Y, +Z, −Z.
pub(crate) const FACE_BASES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Z, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::Z, Vec3::NEG_Y),
    (Vec3::Y, Vec3::X, Vec3::Z),
    (Vec3::NEG_Y, Vec3::X, Vec3::NEG_Z),
    (Vec3::Z, Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_X, Vec3::NEG_Y),
];

/// A cube map of linear RGB radiance with bordered faces.
///
/// # Guarantees
/// - `1 <= face_size <= 8192`;
/// - each face holds `(face_size + 2)²` finite, non-negative texels.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeMap {
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
        for (f, face) in faces.iter().enumerate() {
            for y in 0..face_size {
                let row = cube.face_offset(f) + (y + 1) * m + 1;
                cube.texels[row..row + face_size]
                    .copy_from_slice(&face[y * face_size..(y + 1) * face_size]);
            }
        }
        cube.fill_borders_from_neighbours();
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

    /// Renders an environment into a cube map of `face_size²` faces (borders included).
    pub fn from_environment(env: &Environment, face_size: usize) -> Result<Self, RenderError> {
        check_face_size(face_size)?;
        let mut cube = Self::black(face_size);
        let m = face_size + 2;
        for f in 0..6 {
            for y in 0..m {
                for x in 0..m {
                    let dir = cube.texel_direction(f, x, y);
                    let off = cube.face_offset(f) + y * m + x;
                    cube.texels[off] = env.radiance(dir);
                }
            }
        }
        Ok(cube)
    }

    /// Edge length of a face in texels, border excluded.
    pub fn face_size(&self) -> usize {
        self.face_size
    }

    /// Interior texel `(x, y)` of face `face` (0..6 in +X, −X, +Y, −Y, +Z, −Z order).
    ///
    /// # Panics
    /// Panics if `face >= 6` or `x, y >= face_size`.
    pub fn texel(&self, face: usize, x: usize, y: usize) -> [f32; 3] {
        assert!(
            face < 6 && x < self.face_size && y < self.face_size,
            "texel out of range"
        );
        self.texels[self.face_offset(face) + (y + 1) * (self.face_size + 2) + x + 1]
    }

    /// Seamless bilinear lookup of the radiance along `dir` (any length; zero reads +X).
    #[inline(always)]
    pub fn sample(&self, dir: Vec3) -> [f32; 3] {
        let (face, s, t) = face_coordinates(dir);
        let n = self.face_size as f32;
        let m = self.face_size + 2;
        // Interior texel i has its centre at s = (2i + 1)/N − 1 and is stored at i + 1.
        let fx = ((s + 1.0) * 0.5 * n + 0.5).clamp(0.0, (m - 1) as f32);
        let fy = ((t + 1.0) * 0.5 * n + 0.5).clamp(0.0, (m - 1) as f32);
        // fx, fy are in [0, m − 1] (m ≤ 8194) or NaN (→ 0 either way): i32 conversion is exact
        // and cheaper than usize's.
        let x0 = (fx as i32 as usize).min(m - 2);
        let y0 = (fy as i32 as usize).min(m - 2);
        let tx = fx - x0 as f32;
        let ty = fy - y0 as f32;
        let base = self.face_offset(face) + y0 * m + x0;
        let a = self.texels[base];
        let b = self.texels[base + 1];
        let c = self.texels[base + m];
        let d = self.texels[base + m + 1];
        bilerp(a, b, c, d, tx, ty)
    }

    /// An all-black cube map, the starting point of a render target.
    pub(crate) fn black(face_size: usize) -> Self {
        let m = face_size + 2;
        Self {
            face_size,
            texels: vec![[0.0; 3]; 6 * m * m],
        }
    }

    /// Bordered face `face` as an `(N + 2)²` slice.
    pub(crate) fn face(&self, face: usize) -> &[[f32; 3]] {
        let m = self.face_size + 2;
        &self.texels[face * m * m..(face + 1) * m * m]
    }

    /// The six bordered faces as mutable `(N + 2)²` slices, for rendering into.
    pub(crate) fn faces_mut(&mut self) -> std::slice::ChunksExactMut<'_, [f32; 3]> {
        let m = self.face_size + 2;
        self.texels.chunks_exact_mut(m * m)
    }

    fn face_offset(&self, face: usize) -> usize {
        let m = self.face_size + 2;
        face * m * m
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
        let m = self.face_size + 2;
        for f in 0..6 {
            for y in 0..m {
                for x in 0..m {
                    if x != 0 && y != 0 && x != m - 1 && y != m - 1 {
                        continue;
                    }
                    let (g, s, t) = face_coordinates(self.texel_direction(f, x, y));
                    let to_index = |c: f32| {
                        (((c + 1.0) * 0.5 * self.face_size as f32) as usize).min(self.face_size - 1)
                    };
                    let value = self.texel(g, to_index(s), to_index(t));
                    let off = self.face_offset(f) + y * m + x;
                    self.texels[off] = value;
                }
            }
        }
    }
}

/// Face index and `(s, t) ∈ [−1, 1]²` of a direction (major axis wins; ties go to X, then Y).
#[inline]
pub(crate) fn face_coordinates(dir: Vec3) -> (usize, f32, f32) {
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

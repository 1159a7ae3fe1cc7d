//! The [`Lut`] table type: storage layout, axes and bilinear sampling.

use std::fmt;

/// Why a [`Lut`] could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum LutError {
    /// Width or height is below 2 (an axis needs both ends) or above 16384.
    BadResolution { width: usize, height: usize },
    /// The thickness range is not finite and positive.
    BadThicknessMax { thickness_max_nm: f32 },
    /// The texel count does not equal width × height.
    TexelCount { expected: usize, got: usize },
    /// A texel holds a NaN or infinite value.
    NonFiniteTexel { column: usize, row: usize },
}

impl fmt::Display for LutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadResolution { width, height } => write!(
                f,
                "resolution {width}x{height} is invalid: each side must be in 2..={MAX_SIDE}"
            ),
            Self::BadThicknessMax { thickness_max_nm } => write!(
                f,
                "thickness range 0..{thickness_max_nm} nm is invalid: the maximum must be finite and > 0"
            ),
            Self::TexelCount { expected, got } => {
                write!(f, "expected {expected} texels, got {got}")
            }
            Self::NonFiniteTexel { column, row } => {
                write!(f, "texel at column {column}, row {row} is not finite")
            }
        }
    }
}

impl std::error::Error for LutError {}

/// Largest accepted side of a table, in texels.
pub const MAX_SIDE: usize = 16384;

/// An RGB table over film thickness (columns) and cosine of the incident angle (rows).
///
/// Column `i` holds thickness `d_i = thickness_max_nm · i / (W − 1)`; row `j`, counted
/// from the top of the image, holds `cos θ_j = j / (H − 1)`. Both axis ends are stored
/// exactly, so a shader maps `d` to `u = (d / d_max · (W − 1) + 0.5) / W`.
///
/// # Guarantees
/// - `2 <= width, height <= 16384`;
/// - `thickness_max_nm` is finite and positive;
/// - every texel is finite.
#[derive(Debug, Clone, PartialEq)]
pub struct Lut {
    width: usize,
    height: usize,
    thickness_max_nm: f32,
    texels: Vec<[f32; 3]>,
}

impl Lut {
    /// Builds a table from row-major texels (row 0 is `cos θ = 0`), checking every guarantee.
    pub fn try_new(
        width: usize,
        height: usize,
        thickness_max_nm: f32,
        texels: Vec<[f32; 3]>,
    ) -> Result<Self, LutError> {
        if !(2..=MAX_SIDE).contains(&width) || !(2..=MAX_SIDE).contains(&height) {
            return Err(LutError::BadResolution { width, height });
        }
        if !(thickness_max_nm.is_finite() && thickness_max_nm > 0.0) {
            return Err(LutError::BadThicknessMax { thickness_max_nm });
        }
        if texels.len() != width * height {
            return Err(LutError::TexelCount {
                expected: width * height,
                got: texels.len(),
            });
        }
        if let Some(k) = texels.iter().position(|t| t.iter().any(|c| !c.is_finite())) {
            return Err(LutError::NonFiniteTexel {
                column: k % width,
                row: k / width,
            });
        }
        Ok(Self {
            width,
            height,
            thickness_max_nm,
            texels,
        })
    }

    /// Builds a table by evaluating `f(thickness_nm, cos_theta)` at every texel.
    pub fn try_from_fn(
        width: usize,
        height: usize,
        thickness_max_nm: f32,
        mut f: impl FnMut(f32, f32) -> [f32; 3],
    ) -> Result<Self, LutError> {
        let texels = if (2..=MAX_SIDE).contains(&width) && (2..=MAX_SIDE).contains(&height) {
            let mut texels = Vec::with_capacity(width * height);
            for j in 0..height {
                let cos_theta = axis_value(j, height, 1.0);
                for i in 0..width {
                    texels.push(f(axis_value(i, width, thickness_max_nm), cos_theta));
                }
            }
            texels
        } else {
            Vec::new()
        };
        Self::try_new(width, height, thickness_max_nm, texels)
    }

    /// Number of columns (thickness samples).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of rows (cos θ samples).
    pub fn height(&self) -> usize {
        self.height
    }

    /// Thickness of the last column, in nm.
    pub fn thickness_max_nm(&self) -> f32 {
        self.thickness_max_nm
    }

    /// Row-major texels, row 0 first (`cos θ = 0`).
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// Thickness held by column `i`, in nm.
    pub fn thickness_nm_at(&self, i: usize) -> f32 {
        axis_value(i, self.width, self.thickness_max_nm)
    }

    /// Cosine of the incident angle held by row `j`.
    pub fn cos_theta_at(&self, j: usize) -> f32 {
        axis_value(j, self.height, 1.0)
    }

    /// The texel at column `i`, row `j`.
    ///
    /// # Panics
    /// Panics if `i >= width` or `j >= height`.
    pub fn texel(&self, i: usize, j: usize) -> [f32; 3] {
        assert!(
            i < self.width && j < self.height,
            "texel ({i}, {j}) out of range"
        );
        self.texels[j * self.width + i]
    }

    /// Bilinear lookup, clamped at the edges and exact at texel centres.
    ///
    /// A NaN coordinate is treated as 0.
    #[inline]
    pub fn sample(&self, thickness_nm: f32, cos_theta: f32) -> [f32; 3] {
        let (i0, i1, tx) = split(thickness_nm / self.thickness_max_nm, self.width);
        let (j0, j1, ty) = split(cos_theta, self.height);
        let row0 = j0 * self.width;
        let row1 = j1 * self.width;
        let top = lerp3(self.texels[row0 + i0], self.texels[row0 + i1], tx);
        let bottom = lerp3(self.texels[row1 + i0], self.texels[row1 + i1], tx);
        lerp3(top, bottom, ty)
    }
}

/// Value held by sample `k` of an axis of `n` samples spanning `0..=max`.
pub(crate) fn axis_value(k: usize, n: usize, max: f32) -> f32 {
    if k + 1 == n {
        max
    } else {
        (f64::from(max) * k as f64 / (n - 1) as f64) as f32
    }
}

/// Splits a normalised coordinate into the two neighbouring samples and the weight of the second.
#[inline]
fn split(t: f32, n: usize) -> (usize, usize, f32) {
    let x = (t * (n - 1) as f32).clamp(0.0, (n - 1) as f32);
    // `clamp` passes NaN through; `as usize` maps NaN to 0, and so does this weight.
    let x = if x.is_nan() { 0.0 } else { x };
    let i0 = (x as usize).min(n - 2);
    (i0, i0 + 1, x - i0 as f32)
}

/// `a + (b − a)·t`, exact at `t = 0` and `t = 1`.
#[inline]
fn lerp3(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    if t == 1.0 {
        return b;
    }
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Lut {
        Lut::try_from_fn(5, 4, 2000.0, |d, c| [d, c, d * c]).unwrap()
    }

    #[test]
    fn exact_at_texel_centres() {
        let lut = ramp();
        for j in 0..lut.height() {
            for i in 0..lut.width() {
                let got = lut.sample(lut.thickness_nm_at(i), lut.cos_theta_at(j));
                assert_eq!(got, lut.texel(i, j), "texel ({i}, {j})");
            }
        }
    }

    #[test]
    fn axis_ends_are_stored_exactly() {
        let lut = ramp();
        assert_eq!(lut.thickness_nm_at(0), 0.0);
        assert_eq!(lut.thickness_nm_at(4), 2000.0);
        assert_eq!(lut.cos_theta_at(3), 1.0);
    }

    #[test]
    fn clamps_outside_the_axes() {
        let lut = ramp();
        assert_eq!(lut.sample(-50.0, -1.0), lut.texel(0, 0));
        assert_eq!(lut.sample(1e9, 7.0), lut.texel(4, 3));
        assert_eq!(lut.sample(f32::NAN, f32::NAN), lut.texel(0, 0));
    }

    #[test]
    fn bilinear_reproduces_a_bilinear_function() {
        let lut = ramp();
        let [d, c, dc] = lut.sample(1234.5, 0.37);
        assert!((d - 1234.5).abs() < 1e-3, "d off by {}", d - 1234.5);
        assert!((c - 0.37).abs() < 1e-6, "c off by {}", c - 0.37);
        assert!(
            (dc - 1234.5 * 0.37).abs() < 1e-2,
            "dc off by {}",
            dc - 1234.5 * 0.37
        );
    }

    #[test]
    fn rejects_bad_construction() {
        assert!(matches!(
            Lut::try_new(1, 4, 1.0, vec![[0.0; 3]; 4]),
            Err(LutError::BadResolution { .. })
        ));
        assert!(matches!(
            Lut::try_new(2, 2, -1.0, vec![[0.0; 3]; 4]),
            Err(LutError::BadThicknessMax { .. })
        ));
        assert!(matches!(
            Lut::try_new(2, 2, 1.0, vec![[0.0; 3]; 3]),
            Err(LutError::TexelCount { .. })
        ));
        let mut texels = vec![[0.0; 3]; 4];
        texels[3][1] = f32::NAN;
        assert_eq!(
            Lut::try_new(2, 2, 1.0, texels),
            Err(LutError::NonFiniteTexel { column: 1, row: 1 })
        );
    }
}

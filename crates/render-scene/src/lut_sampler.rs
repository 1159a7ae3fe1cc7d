//! [`LutSampler`]: [`lut::Lut`]'s bilinear lookup with its scale factors hoisted out of the
//! per-fragment path (no division, inlined into the bubble shader).

use lut::Lut;

use crate::index_f32::index_f32;
use crate::texture::bilerp;

/// A borrowed view of a table, prepared for fast sampling.
#[derive(Debug, Clone, Copy)]
pub struct LutSampler<'a> {
    texels: &'a [[f32; 3]],
    width: usize,
    height: usize,
    /// Columns per nanometre.
    d_scale: f32,
}

impl<'a> LutSampler<'a> {
    /// A sampler reading `lut`.
    pub fn new(lut: &'a Lut) -> Self {
        Self {
            texels: lut.texels(),
            width: lut.width(),
            height: lut.height(),
            d_scale: (lut.width() - 1) as f32 / lut.thickness_max_nm(),
        }
    }

    /// Bilinear lookup clamped at the edges, exact at texel centres; NaN reads as 0.
    #[inline(always)]
    pub fn sample(&self, thickness_nm: f32, cos_theta: f32) -> [f32; 3] {
        let (i0, tx) = split(thickness_nm * self.d_scale, self.width);
        let (j0, ty) = split(cos_theta * index_f32(self.height - 1), self.height);
        let row0 = j0 * self.width + i0;
        let row1 = row0 + self.width;
        let (a, b) = (self.texels[row0], self.texels[row0 + 1]);
        let (c, d) = (self.texels[row1], self.texels[row1 + 1]);
        bilerp(a, b, c, d, tx, ty)
    }
}

/// Lower sample index and weight of the upper one along an axis of `n >= 2` samples.
#[inline(always)]
fn split(x: f32, n: usize) -> (usize, f32) {
    let x = x.clamp(0.0, index_f32(n - 1));
    let x = if x.is_nan() { 0.0 } else { x };
    // x is in [0, n − 1] and n indexes memory, so the cheaper i32 conversion is exact.
    let i0 = (x as i32 as usize).min(n - 2);
    (i0, x - index_f32(i0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agrees_with_lut_sample() {
        let lut = Lut::try_from_fn(17, 9, 1300.0, |d, c| [d.sin(), c * c, d * c * 1e-3]).unwrap();
        let fast = LutSampler::new(&lut);
        for k in 0..500 {
            let d = -50.0 + k as f32 * 2.9;
            let c = (k as f32 * 0.013).fract() * 1.1 - 0.05;
            let (a, b) = (lut.sample(d, c), fast.sample(d, c));
            for ch in 0..3 {
                assert!(
                    (a[ch] - b[ch]).abs() < 1e-5,
                    "({d}, {c}) channel {ch}: {} vs {}",
                    a[ch],
                    b[ch]
                );
            }
        }
        assert_eq!(fast.sample(f32::NAN, f32::NAN), lut.texel(0, 0));
        assert_eq!(fast.sample(0.0, 1.0), lut.texel(0, 8));
    }
}

//! The camera: exposure and white-balance gains, the model's colours as that camera
//! records them (sRGB-encoded), and the estimation of both from the photo.

use crate::error::{InverseError, short};
use crate::model::ColourTable;
use rayon::prelude::*;
use thinfilm::colorspace::srgb_encode;

/// The camera's response: a pixel's linear value is `exposure · gains[c] · m_c`, with `m`
/// the film's white-balanced reflectance (a perfect mirror of the light is `m = 1`).
///
/// # Guarantees
/// Once [`Camera::check`]ed: `exposure` and the gains finite, in [1e-6, 1e6].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Overall scale.
    pub exposure: f64,
    /// Per-channel white-balance error (1 = balanced).
    pub gains: [f64; 3],
}

impl Camera {
    /// Exposure `exposure`, balanced.
    pub fn balanced(exposure: f64) -> Camera {
        Camera {
            exposure,
            gains: [1.0; 3],
        }
    }

    /// Checks the exposure and gains.
    ///
    /// # Errors
    /// The first value that is not finite and within [1e-6, 1e6], by name.
    pub fn check(&self) -> Result<(), InverseError> {
        let ok = |v: f64| v.is_finite() && (1e-6..=1e6).contains(&v);
        if !ok(self.exposure) {
            return Err(InverseError::Setting {
                name: "exposure",
                value: short(self.exposure),
                allowed: "1e-6 to 1e6".into(),
            });
        }
        if let Some(g) = self.gains.iter().find(|g| !ok(**g)) {
            return Err(InverseError::Setting {
                name: "white-balance gain",
                value: short(*g),
                allowed: "1e-6 to 1e6".into(),
            });
        }
        Ok(())
    }

    /// The encoded value this camera records for the model colour `m`.
    pub fn encode(&self, m: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|c| srgb_encode((self.exposure * self.gains[c] * m[c]).max(0.0)))
    }
}

/// The colour table as a camera records it: sRGB-encoded, f32, row-major.
#[derive(Clone, Debug)]
pub struct EncodedTable {
    pub(crate) len: usize,
    pub(crate) rows: usize,
    pub(crate) values: Vec<[f32; 3]>,
}

impl EncodedTable {
    /// Encodes every entry of `table` through `camera`.
    pub fn new(table: &ColourTable, camera: &Camera) -> EncodedTable {
        let values = table
            .values()
            .par_iter()
            .map(|m| camera.encode(m.map(f64::from)).map(|v| v as f32))
            .collect();
        EncodedTable {
            len: table.len(),
            rows: table.rows(),
            values,
        }
    }

    /// Row `r`.
    pub fn row(&self, r: usize) -> &[[f32; 3]] {
        &self.values[r * self.len..(r + 1) * self.len]
    }

    /// Encoded colour at fractional sample `i` (thickness / [`crate::TABLE_STEP_NM`]) and row `r`.
    pub fn sample(&self, i: f64, r: f64) -> [f64; 3] {
        crate::model::sample_bilinear(&self.values, self.len, self.rows, i, r)
    }
}

/// Squared distance between an encoded pixel and a table entry.
#[inline]
pub(crate) fn dist2(p: [f32; 3], t: [f32; 3]) -> f32 {
    let d = [p[0] - t[0], p[1] - t[1], p[2] - t[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// How fast a row's colour moves at sample `i`: the squared colour change per sample
/// squared, over the samples two either side (fewer at the ends).
pub(crate) fn speed2(row: &[[f32; 3]], i: usize) -> f32 {
    let (lo, hi) = (i.saturating_sub(2), (i + 2).min(row.len() - 1));
    let span = (hi - lo).max(1) as f32;
    dist2(row[lo], row[hi]) / (span * span)
}

/// The smallest distance from `p` to a row, sampled every `stride` entries.
pub(crate) fn best_cost(row: &[[f32; 3]], p: [f32; 3], stride: usize) -> f32 {
    row.iter()
        .step_by(stride)
        .fold(f32::INFINITY, |m, t| m.min(dist2(p, *t)))
}

/// A pixel used to estimate the camera: its encoded value and table row.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sample {
    pub(crate) encoded: [f32; 3],
    pub(crate) row: usize,
}

/// Per-pixel cost cap in the estimate, so that background and glints do not steer it.
const COST_CAP: f32 = 3.0 * 0.08 * 0.08;

/// Mean capped distance of the samples to the curve the camera would record.
fn objective(table: &ColourTable, camera: &Camera, samples: &[Sample]) -> f64 {
    let encoded = EncodedTable::new(table, camera);
    let total: f64 = samples
        .par_iter()
        .map(|s| f64::from(best_cost(encoded.row(s.row), s.encoded, 2).min(COST_CAP)))
        .sum();
    total / samples.len().max(1) as f64
}

/// The camera under which the samples lie closest to the model's colour curve: a scan of
/// the exposure, then a pattern search over log exposure and the red and blue gains.
pub(crate) fn estimate(table: &ColourTable, samples: &[Sample], linear_p99: f64) -> Camera {
    let brightest = table
        .values()
        .iter()
        .map(|m| m.iter().fold(0.0f32, |a, b| a.max(*b)))
        .fold(0.0f32, f32::max)
        .max(1e-6);
    let e0 = (linear_p99 / f64::from(brightest)).clamp(1e-5, 1e5);
    let at = |log2: [f64; 3]| Camera {
        exposure: e0 * log2[0].exp2(),
        gains: [log2[1].exp2(), 1.0, log2[2].exp2()],
    };
    let mut best = [0.0; 3];
    let mut best_cost = f64::INFINITY;
    for k in -8..=8 {
        let x = [f64::from(k) / 4.0, 0.0, 0.0];
        let c = objective(table, &at(x), samples);
        if c < best_cost {
            (best, best_cost) = (x, c);
        }
    }
    let mut step = 1.0 / 8.0;
    let mut rounds = 0;
    while step > 1.0 / 512.0 && rounds < 64 {
        rounds += 1;
        let mut improved = false;
        for axis in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut x = best;
                x[axis] += sign * step;
                let c = objective(table, &at(x), samples);
                if c < best_cost {
                    (best, best_cost, improved) = (x, c, true);
                }
            }
        }
        if !improved {
            step /= 2.0;
        }
    }
    at(best)
}

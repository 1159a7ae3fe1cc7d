//! After the orders are fixed: sub-sample thickness, uncertainty, the re-rendered
//! colour, its ΔE2000 from the photo, and the totals.

use crate::camera::{Camera, EncodedTable};
use crate::model::{ColourTable, TABLE_STEP_NM};
use crate::unwrap::{self, Grower, RegionReport};
use crate::{Photo, Settings, Status, Summary, ThicknessMap};
use rayon::prelude::*;
use thinfilm::colorspace::{XYZ_FROM_SRGB, apply};
use thinfilm::{Lab, ciede2000};

/// The tables a fit reads.
pub(crate) struct Tables<'a> {
    /// The model as the camera records it (encoded).
    pub(crate) encoded: &'a EncodedTable,
    /// The model, linear and white-balanced.
    pub(crate) linear: &'a ColourTable,
    /// The camera.
    pub(crate) camera: Camera,
    /// How the camera was found.
    pub(crate) calibration: &'static str,
}

/// One fitted pixel.
#[derive(Clone, Copy, Debug, Default)]
struct Fit {
    /// Thickness as a fractional table sample.
    at: f64,
    /// Squared encoded colour error at the fit.
    cost: f64,
    /// Squared norm of d(encoded colour)/d(thickness), per nm².
    slope2: f64,
}

/// The encoded table's colours on one fractional row, at whole samples.
struct RowView<'a> {
    table: &'a EncodedTable,
    r0: usize,
    r1: usize,
    fr: f32,
}

impl RowView<'_> {
    fn new(table: &EncodedTable, row: f64) -> RowView<'_> {
        let row = row.clamp(0.0, (table.rows - 1) as f64);
        let r0 = row.floor() as usize;
        RowView {
            table,
            r0,
            r1: (r0 + 1).min(table.rows - 1),
            fr: (row - r0 as f64) as f32,
        }
    }

    #[inline]
    fn at(&self, i: usize) -> [f32; 3] {
        let a = self.table.values[self.r0 * self.table.len + i];
        if self.fr == 0.0 {
            return a;
        }
        let b = self.table.values[self.r1 * self.table.len + i];
        [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * self.fr)
    }
}

/// Refines a labelled pixel at sample `i` on fractional row `row`: a descent over whole
/// samples, then the vertex of the parabola through the three nearest.
fn refine(table: &EncodedTable, encoded: [f32; 3], i: usize, row: f64) -> Fit {
    let view = RowView::new(table, row);
    let last = table.len - 1;
    let cost = |i: usize| f64::from(crate::camera::dist2(encoded, view.at(i)));
    let mut i = i.min(last);
    let (mut dm, mut d0, mut dp) = (cost(i.saturating_sub(1)), cost(i), cost((i + 1).min(last)));
    for _ in 0..8 {
        if dm < d0 && dm <= dp && i > 0 {
            i -= 1;
            (dp, d0, dm) = (d0, dm, cost(i.saturating_sub(1)));
        } else if dp < d0 && i < last {
            i += 1;
            (dm, d0, dp) = (d0, dp, cost((i + 1).min(last)));
        } else {
            break;
        }
    }
    let curvature = dm - 2.0 * d0 + dp;
    let delta = if curvature > 0.0 && i > 0 && i < last {
        (0.5 * (dm - dp) / curvature).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    // The parabola's value at its vertex is the cost there.
    let cost_at = if curvature > 0.0 {
        d0 - 0.25 * (dm - dp) * delta
    } else {
        d0
    };
    let (lo, hi) = (i.saturating_sub(1), (i + 1).min(last));
    let (a, b) = (view.at(lo), view.at(hi));
    let span_nm = (hi - lo).max(1) as f64 * TABLE_STEP_NM;
    let slope2 = (0..3)
        .map(|c| (f64::from(b[c] - a[c]) / span_nm).powi(2))
        .sum();
    Fit {
        at: i as f64 + delta,
        cost: cost_at.max(0.0),
        slope2,
    }
}

/// CIELAB of a linear sRGB colour, white the sRGB white, in f32 with a fast cube root:
/// a residual map needs ΔE to a few 1e-5, and the portable f64 cube root made CIELAB
/// the largest cost of a 12 Mpx map. (`tests` checks it against `thinfilm::lab`.)
fn lab_of(linear: [f64; 3]) -> Lab {
    const DELTA: f32 = 6.0 / 29.0;
    let xyz = apply(&XYZ_FROM_SRGB, linear.map(|v| v.clamp(0.0, 1.0)));
    let white = apply(&XYZ_FROM_SRGB, [1.0; 3]);
    let f = |t: f32| {
        if t > DELTA * DELTA * DELTA {
            cbrt_f32(t)
        } else {
            t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
        }
    };
    let [fx, fy, fz] = [0, 1, 2].map(|i| f((xyz[i] / white[i]) as f32));
    Lab {
        l: f64::from(116.0 * fy - 16.0),
        a: f64::from(500.0 * (fx - fy)),
        b: f64::from(200.0 * (fy - fz)),
    }
}

/// Cube root of a positive f32: a bit-level first guess (within 3.5 %) and three Newton
/// steps (1e-3, 1e-6, then f32 rounding).
fn cbrt_f32(t: f32) -> f32 {
    let mut y = f32::from_bits(t.to_bits() / 3 + 0x2A51_4067);
    for _ in 0..3 {
        y -= (y * y * y - t) / (3.0 * y * y);
    }
    y
}

/// The noise level per encoded channel the fits imply: the RMS colour error over the
/// best 95 % of fitted pixels (the rest are glints, edges and outliers).
fn noise_level(mut costs: Vec<f32>) -> f64 {
    if costs.is_empty() {
        return 0.0;
    }
    let keep = ((costs.len() as f64 * 0.95).ceil() as usize).clamp(1, costs.len());
    costs.select_nth_unstable_by(keep - 1, f32::total_cmp);
    let mean = costs[..keep].iter().map(|&c| f64::from(c)).sum::<f64>() / keep as f64;
    (mean / 3.0).sqrt()
}

/// One-sigma thickness uncertainty (nm) of a fit: the colour noise over the colour's
/// rate of change with thickness (Gauss–Newton), with the table's spacing as a floor.
fn uncertainty_nm(slope2: f64, noise: f64, cap_nm: f64) -> f64 {
    let floor = TABLE_STEP_NM / 12f64.sqrt();
    let sigma = if slope2 > 0.0 {
        noise / slope2.sqrt()
    } else {
        cap_nm
    };
    sigma.hypot(floor).min(cap_nm)
}

/// The finished map (its summary still empty).
pub(crate) fn finish_map(
    photo: &Photo,
    settings: &Settings,
    tables: &Tables<'_>,
    cos: &[Option<f32>],
    grower: &Grower<'_>,
    regions: RegionReport,
) -> ThicknessMap {
    let n = photo.len();
    let mut thickness_nm = vec![0.0f32; n];
    let mut slope2 = vec![0.0f32; n];
    let mut residual_de = vec![0.0f32; n];
    let mut rerender = photo.encoded().to_vec();
    let mut status = vec![Status::Excluded; n];
    let mut cost = vec![f32::NAN; n];
    (
        &mut thickness_nm,
        &mut slope2,
        &mut residual_de,
        &mut rerender,
        &mut status,
        &mut cost,
    )
        .into_par_iter()
        .enumerate()
        .for_each(|(p, (h, s2, de, rgb, st, c))| {
            *st = match grower.state[p] {
                unwrap::SATURATED => Status::Saturated,
                unwrap::UNEXPLAINED => Status::Unexplained,
                unwrap::AMBIGUOUS => Status::Ambiguous,
                unwrap::LABELLED => Status::Fitted,
                _ => Status::Excluded,
            };
            if *st != Status::Fitted {
                return;
            }
            let row = tables.linear.row_of(f64::from(cos[p].unwrap_or(1.0)));
            let fit = refine(
                tables.encoded,
                photo.encoded()[p],
                grower.h[p] as usize,
                row,
            );
            let m = tables.linear.sample(fit.at * TABLE_STEP_NM, row);
            let camera = &tables.camera;
            let linear = [0, 1, 2].map(|k| camera.exposure * camera.gains[k] * m[k]);
            let residual = ciede2000(lab_of(photo.linear(p)), lab_of(linear));
            if residual > settings.max_residual_de {
                *st = Status::Unexplained;
                return;
            }
            (*h, *s2, *de, *c) = (
                (fit.at * TABLE_STEP_NM) as f32,
                fit.slope2 as f32,
                residual as f32,
                fit.cost as f32,
            );
            *rgb = camera.encode(m).map(|v| v.clamp(0.0, 1.0) as f32);
        });
    let noise = noise_level(cost.into_iter().filter(|c| !c.is_nan()).collect());
    let cap = tables.linear.len() as f64 * TABLE_STEP_NM;
    let uncertainty_nm: Vec<f32> = slope2
        .par_iter()
        .zip(&status)
        .map(|(&s2, st)| {
            if *st == Status::Fitted {
                uncertainty_nm(f64::from(s2), noise, cap) as f32
            } else {
                0.0
            }
        })
        .collect();
    let fitted = Fitted {
        status: &status,
        thickness_nm: &thickness_nm,
        uncertainty_nm: &uncertainty_nm,
        residual_de: &residual_de,
    };
    let summary = summarise(&fitted, noise, tables, regions);
    ThicknessMap {
        width: photo.width(),
        height: photo.height(),
        thickness_nm,
        uncertainty_nm,
        residual_de,
        rerender,
        status,
        summary,
    }
}

/// The per-pixel results the totals are taken over.
struct Fitted<'a> {
    status: &'a [Status],
    thickness_nm: &'a [f32],
    uncertainty_nm: &'a [f32],
    residual_de: &'a [f32],
}

/// The `q` quantile (nearest rank) of the fitted pixels' values, and their mean.
fn fitted_stats(values: &[f32], status: &[Status], qs: &[f64]) -> (Vec<f64>, f64) {
    let mut v: Vec<f32> = values
        .iter()
        .zip(status)
        .filter(|(_, s)| **s == Status::Fitted)
        .map(|(v, _)| *v)
        .collect();
    if v.is_empty() {
        return (vec![0.0; qs.len()], 0.0);
    }
    let mean = v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    let len = v.len();
    let out = qs
        .iter()
        .map(|q| {
            let rank = ((q * len as f64).ceil() as usize).clamp(1, len);
            f64::from(*v.select_nth_unstable_by(rank - 1, f32::total_cmp).1)
        })
        .collect();
    (out, mean)
}

/// The totals of a finished map.
fn summarise(map: &Fitted<'_>, noise: f64, tables: &Tables<'_>, regions: RegionReport) -> Summary {
    let count = |s: Status| map.status.iter().filter(|&&x| x == s).count();
    let (de, de_mean) = fitted_stats(map.residual_de, map.status, &[0.95, 1.0]);
    let (h, _) = fitted_stats(map.thickness_nm, map.status, &[0.0, 0.5, 1.0]);
    let (sigma, _) = fitted_stats(map.uncertainty_nm, map.status, &[0.5]);
    Summary {
        camera: tables.camera,
        calibration: tables.calibration,
        fitted: count(Status::Fitted),
        saturated: count(Status::Saturated),
        excluded: count(Status::Excluded),
        unexplained: count(Status::Unexplained),
        ambiguous: count(Status::Ambiguous),
        residual_mean_de: de_mean,
        residual_p95_de: de[0],
        residual_max_de: de[1],
        noise_encoded: noise,
        thickness_min_nm: h[0],
        thickness_median_nm: h[1],
        thickness_max_nm: h[2],
        uncertainty_median_nm: sigma[0],
        regions,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_cielab_matches_thinfilms_to_1e_4() {
        let white = apply(&XYZ_FROM_SRGB, [1.0; 3]);
        let mut worst = 0.0f64;
        for k in 0..4096 {
            let rgb = [k % 16, (k / 16) % 16, k / 256].map(|v| (f64::from(v) / 15.0).powi(3));
            let (fast, exact) = (
                lab_of(rgb),
                thinfilm::lab_from_xyz(apply(&XYZ_FROM_SRGB, rgb), white),
            );
            worst = worst
                .max((fast.l - exact.l).abs())
                .max((fast.a - exact.a).abs())
                .max((fast.b - exact.b).abs());
        }
        assert!(worst < 1e-4, "worst CIELAB difference {worst:e}");
    }
}

//! After the orders are fixed: sub-sample thickness, uncertainty, the re-rendered
//! colour, its ΔE2000 from the photo, and the totals.

use crate::camera::{Camera, EncodedTable};
use crate::model::{ColourTable, TABLE_STEP_NM};
use crate::unwrap::{self, Grower, RegionReport};
use crate::{Photo, Settings, Status, Summary, ThicknessMap};
use rayon::prelude::*;
use thinfilm::colorspace::{XYZ_FROM_SRGB, apply};
use thinfilm::{Lab, ciede2000, lab_from_xyz};

/// The tables a fit reads.
pub(crate) struct Tables<'a> {
    /// The model as the camera records it (encoded).
    pub(crate) encoded: &'a EncodedTable,
    /// The model, linear and white-balanced.
    pub(crate) linear: &'a ColourTable,
    /// The camera.
    pub(crate) camera: Camera,
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

/// Refines a labelled pixel at sample `i` on fractional row `row`: a descent on the
/// bilinear table, then the vertex of the parabola through the three nearest samples.
fn refine(table: &EncodedTable, encoded: [f32; 3], i: f64, row: f64) -> Fit {
    let e = encoded.map(f64::from);
    let cost = |i: f64| {
        let t = table.sample(i, row);
        (0..3).map(|c| (e[c] - t[c]).powi(2)).sum::<f64>()
    };
    let last = (table.len - 1) as f64;
    let mut i = i.clamp(0.0, last);
    let (mut dm, mut d0, mut dp) = (cost((i - 1.0).max(0.0)), cost(i), cost((i + 1.0).min(last)));
    for _ in 0..8 {
        if dm < d0 && dm <= dp && i > 0.0 {
            i -= 1.0;
            (dp, d0, dm) = (d0, dm, cost((i - 1.0).max(0.0)));
        } else if dp < d0 && i < last {
            i += 1.0;
            (dm, d0, dp) = (d0, dp, cost((i + 1.0).min(last)));
        } else {
            break;
        }
    }
    let curvature = dm - 2.0 * d0 + dp;
    let delta = if curvature > 0.0 {
        (0.5 * (dm - dp) / curvature).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let at = (i + delta).clamp(0.0, last);
    let (lo, hi) = ((at - 1.0).max(0.0), (at + 1.0).min(last));
    let (a, b) = (table.sample(lo, row), table.sample(hi, row));
    let span_nm = (hi - lo) * TABLE_STEP_NM;
    let slope2 = (0..3).map(|c| ((b[c] - a[c]) / span_nm).powi(2)).sum();
    Fit {
        at,
        cost: cost(at),
        slope2,
    }
}

/// CIELAB of a linear sRGB colour, white the sRGB white.
fn lab_of(linear: [f64; 3]) -> Lab {
    lab_from_xyz(
        apply(&XYZ_FROM_SRGB, linear.map(|v| v.clamp(0.0, 1.0))),
        apply(&XYZ_FROM_SRGB, [1.0; 3]),
    )
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
                f64::from(grower.h[p]),
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
    ThicknessMap {
        width: photo.width(),
        height: photo.height(),
        thickness_nm,
        uncertainty_nm,
        residual_de,
        rerender,
        status,
        summary: Summary::empty(noise),
    }
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

/// Adds the totals to a finished map.
pub(crate) fn with_summary(
    mut map: ThicknessMap,
    _settings: &Settings,
    camera: Camera,
    calibration: &'static str,
    regions: RegionReport,
) -> ThicknessMap {
    let count = |s: Status| map.status.iter().filter(|&&x| x == s).count();
    let (de, de_mean) = fitted_stats(&map.residual_de, &map.status, &[0.95, 1.0]);
    let (h, _) = fitted_stats(&map.thickness_nm, &map.status, &[0.0, 0.5, 1.0]);
    let (sigma, _) = fitted_stats(&map.uncertainty_nm, &map.status, &[0.5]);
    map.summary = Summary {
        camera,
        calibration,
        fitted: count(Status::Fitted),
        saturated: count(Status::Saturated),
        excluded: count(Status::Excluded),
        unexplained: count(Status::Unexplained),
        ambiguous: count(Status::Ambiguous),
        residual_mean_de: de_mean,
        residual_p95_de: de[0],
        residual_max_de: de[1],
        noise_encoded: map.summary.noise_encoded,
        thickness_min_nm: h[0],
        thickness_median_nm: h[1],
        thickness_max_nm: h[2],
        uncertainty_median_nm: sigma[0],
        regions,
    };
    map
}

//! After the orders are fixed: sub-sample thickness, uncertainty, the re-rendered
//! colour and its ΔE2000 from the photo.

use crate::camera::EncodedTable;
use crate::model::TABLE_STEP_NM;
use rayon::prelude::*;
use thinfilm::colorspace::{XYZ_FROM_SRGB, apply, srgb_decode};
use thinfilm::{Lab, ciede2000, lab_from_xyz};

/// One fitted pixel.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Fit {
    /// Thickness (nm).
    pub(crate) thickness_nm: f64,
    /// Squared encoded colour error at the fit.
    pub(crate) cost: f64,
    /// Squared norm of d(encoded colour)/d(thickness), per nm².
    pub(crate) slope2: f64,
    /// The encoded colour the fit predicts.
    pub(crate) rerender: [f64; 3],
    /// ΔE2000 between the photo and `rerender`.
    pub(crate) residual_de: f64,
}

/// Refines a labelled pixel at sample `i` on fractional row `row`: a descent on the
/// bilinear table, then the vertex of the parabola through the three nearest samples.
pub(crate) fn refine(table: &EncodedTable, encoded: [f32; 3], i: f64, row: f64) -> Fit {
    let e = encoded.map(f64::from);
    let cost = |i: f64| {
        let t = table.sample(i, row);
        (0..3).map(|c| (e[c] - t[c]).powi(2)).sum::<f64>()
    };
    let last = (table.len - 1) as f64;
    let mut i = i.clamp(0.0, last);
    for _ in 0..8 {
        let (here, down, up) = (cost(i), cost((i - 1.0).max(0.0)), cost((i + 1.0).min(last)));
        if down < here && down <= up && i > 0.0 {
            i -= 1.0;
        } else if up < here && i < last {
            i += 1.0;
        } else {
            break;
        }
    }
    let (d0, dm, dp) = (cost(i), cost((i - 1.0).max(0.0)), cost((i + 1.0).min(last)));
    let curvature = dm - 2.0 * d0 + dp;
    let delta = if curvature > 0.0 {
        (0.5 * (dm - dp) / curvature).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let at = (i + delta).clamp(0.0, last);
    let rerender = table.sample(at, row);
    let (lo, hi) = ((at - 1.0).max(0.0), (at + 1.0).min(last));
    let (a, b) = (table.sample(lo, row), table.sample(hi, row));
    let span_nm = (hi - lo) * TABLE_STEP_NM;
    let slope2 = (0..3).map(|c| ((b[c] - a[c]) / span_nm).powi(2)).sum();
    Fit {
        thickness_nm: at * TABLE_STEP_NM,
        cost: cost(at),
        slope2,
        rerender,
        residual_de: delta_e(e, rerender),
    }
}

/// ΔE2000 between two sRGB-encoded colours (clamped to [0, 1]), white the sRGB white.
pub(crate) fn delta_e(a: [f64; 3], b: [f64; 3]) -> f64 {
    ciede2000(lab_of(a), lab_of(b))
}

fn lab_of(encoded: [f64; 3]) -> Lab {
    let linear = encoded.map(|v| srgb_decode(v.clamp(0.0, 1.0)));
    lab_from_xyz(
        apply(&XYZ_FROM_SRGB, linear),
        apply(&XYZ_FROM_SRGB, [1.0; 3]),
    )
}

/// The noise level per encoded channel the fits imply: the RMS colour error over the
/// best 95 % of fitted pixels (the rest are glints, edges and outliers).
pub(crate) fn noise_level(fits: &[Fit]) -> f64 {
    let mut costs: Vec<f64> = fits.par_iter().map(|f| f.cost).collect();
    if costs.is_empty() {
        return 0.0;
    }
    let keep = ((costs.len() as f64 * 0.95).ceil() as usize).clamp(1, costs.len());
    costs.select_nth_unstable_by(keep - 1, f64::total_cmp);
    let mean = costs[..keep].iter().sum::<f64>() / keep as f64;
    (mean / 3.0).sqrt()
}

/// One-sigma thickness uncertainty (nm) of a fit: the colour noise over the colour's
/// rate of change with thickness (Gauss–Newton), with the table's spacing as a floor.
pub(crate) fn uncertainty_nm(fit: &Fit, noise: f64, cap_nm: f64) -> f64 {
    let floor = TABLE_STEP_NM / 12f64.sqrt();
    let sigma = if fit.slope2 > 0.0 {
        noise / fit.slope2.sqrt()
    } else {
        cap_nm
    };
    sigma.hypot(floor).min(cap_nm)
}

//! The f64 row kernel of [`crate::stack_grid::StackGrid`] for lossless stacks seen without
//! evanescence (every medium real, every `q = n cos θ` real and positive at the row's
//! angle): the characteristic-matrix product with its real structure kept, so a layer
//! costs a few multiplications and a point one division per polarisation (Rouard's
//! recursion, [`super::stack_f64`], divides at every layer). The sine and cosine are
//! tabulated once per distinct layer phase; then each block of [`LANES`] wavelengths
//! goes through every layer in registers and leaves as `R` and `T`. Vectorised by LLVM
//! over the lanes (AVX2 picked at run time; no FMA contraction, so bit-identical to the
//! portable build).
//!
//! A layer of admittance `y` and phase `δ` has the characteristic matrix
//! `[[cos δ, i sin δ / y], [i y sin δ, cos δ]]` (Macleod, *Thin-Film Optical Filters*,
//! §2.2). Folding from the substrate, `(B, C) = M₁ ⋯ M_L (1, y_sub)`, then
//! `r = (y₀B − C) / (y₀B + C)` and `T = 4 y₀ y_sub / |y₀B + C|²`. The denominator is
//! never small: energy conservation gives `|y₀B + C|² ≥ 4 y₀ y_sub`, so unlike the
//! recursion this path has no pole to repair.

use super::trig_f64::{MAX_ARG, sin_cos};

/// A lossless layer at one angle: `β = 2π d q` (its phase is `β / λ`) and its admittance
/// per polarisation solved (`q` for s, `q / n²` for p).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RealLayer {
    /// `2π d q` in nm.
    pub beta_nm: f64,
    /// The admittance for each polarisation.
    pub y: [f64; 2],
}

/// Wavelengths per block: one AVX2 register of f64.
const LANES: usize = 4;

/// One distinct layer phase over a row (padded to whole blocks): `sin δ` and `cos δ`.
#[derive(Clone, Debug, Default)]
struct Phase {
    beta_nm: f64,
    sin: Vec<f64>,
    cos: Vec<f64>,
}

/// Scratch for one row: each distinct layer phase, and which one each layer uses.
#[derive(Clone, Debug, Default)]
pub(crate) struct RealRow {
    phases: Vec<Phase>,
    layers: Vec<RealLayer>,
    inv_y: Vec<[f64; 2]>,
    layer_phase: Vec<usize>,
    inv_padded: Vec<f64>,
}

/// What one row's fold reads: the layers back to front, their phases, the end media.
struct Fold<'a> {
    layers: &'a [RealLayer],
    /// `1 / y` of each layer, per polarisation (a division per block would cost more than
    /// the block's multiplications).
    inv_y: &'a [[f64; 2]],
    layer_phase: &'a [usize],
    phases: &'a [Phase],
    y_incident: [f64; 2],
    y_substrate: [f64; 2],
}

impl RealRow {
    /// `R` and `T` of the stack at each `1/λ` of `inv_wavelength_nm` into `r` and `t` (as
    /// long), for the first polarisation (`both` false) or the mean of both. `layers` run
    /// back to front; admittances are `[first, second]` polarisation.
    ///
    /// # Panics
    /// If `r` or `t` is not as long as `inv_wavelength_nm`.
    pub(crate) fn fill(
        &mut self,
        inv_wavelength_nm: &[f64],
        layers: impl IntoIterator<Item = RealLayer>,
        y_ends: [[f64; 2]; 2],
        both: bool,
        r: &mut [f64],
        t: &mut [f64],
    ) {
        assert!(r.len() == inv_wavelength_nm.len() && t.len() == r.len());
        self.layers.clear();
        self.layers.extend(layers);
        self.inv_y.clear();
        (self.inv_y).extend(self.layers.iter().map(|l| l.y.map(|y| 1.0 / y)));
        self.tabulate_phases(inv_wavelength_nm);
        let fold = Fold {
            layers: &self.layers,
            inv_y: &self.inv_y,
            layer_phase: &self.layer_phase,
            phases: &self.phases,
            y_incident: y_ends[0],
            y_substrate: y_ends[1],
        };
        fill_row(&fold, both, r, t);
    }

    /// `sin δ` and `cos δ` once per distinct `β`, over the row padded to whole blocks:
    /// periodic and symmetric stacks (Bragg mirrors, `HLH` filters) repeat a few layers,
    /// and the sine and cosine are most of a layer's cost.
    fn tabulate_phases(&mut self, inv_wavelength_nm: &[f64]) {
        let padded = inv_wavelength_nm.len().div_ceil(LANES) * LANES;
        self.inv_padded.clear();
        self.inv_padded.extend_from_slice(inv_wavelength_nm);
        self.inv_padded.resize(padded, 0.0);
        let largest = inv_wavelength_nm.iter().fold(0.0f64, |m, &x| m.max(x));
        self.layer_phase.clear();
        let mut count = 0;
        for layer in &self.layers {
            let known = self.phases[..count]
                .iter()
                .position(|p| p.beta_nm == layer.beta_nm);
            if let Some(k) = known {
                self.layer_phase.push(k);
                continue;
            }
            if count == self.phases.len() {
                self.phases.push(Phase::default());
            }
            let phase = &mut self.phases[count];
            self.layer_phase.push(count);
            count += 1;
            phase.beta_nm = layer.beta_nm;
            phase.sin.resize(padded, 0.0);
            phase.cos.resize(padded, 0.0);
            let (sin, cos) = (&mut phase.sin[..padded], &mut phase.cos[..padded]);
            if layer.beta_nm.abs() * largest <= MAX_ARG {
                sin_cos_row(&self.inv_padded, layer.beta_nm, sin, cos);
            } else {
                let rows = sin.iter_mut().zip(cos.iter_mut()).zip(&self.inv_padded);
                for ((s, c), &inv) in rows {
                    (*s, *c) = (layer.beta_nm * inv).sin_cos();
                }
            }
        }
        self.phases.truncate(count);
    }
}

/// `sin(β/λ)` and `cos(β/λ)` over a row, by the polynomial kernel (within its range).
fn sin_cos_row(inv: &[f64], beta_nm: f64, sin: &mut [f64], cos: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { sin_cos_row_avx2(inv, beta_nm, sin, cos) };
        return;
    }
    sin_cos_row_body(inv, beta_nm, sin, cos);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn sin_cos_row_avx2(inv: &[f64], beta_nm: f64, sin: &mut [f64], cos: &mut [f64]) {
    sin_cos_row_body(inv, beta_nm, sin, cos);
}

#[inline(always)]
fn sin_cos_row_body(inv: &[f64], beta_nm: f64, sin: &mut [f64], cos: &mut [f64]) {
    let n = inv.len();
    let (sin, cos) = (&mut sin[..n], &mut cos[..n]);
    for i in 0..n {
        (sin[i], cos[i]) = sin_cos(beta_nm * inv[i]);
    }
}

fn fill_row(fold: &Fold, both: bool, r: &mut [f64], t: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { fill_row_avx2(fold, both, r, t) };
        return;
    }
    fill_row_dispatch(fold, both, r, t);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn fill_row_avx2(fold: &Fold, both: bool, r: &mut [f64], t: &mut [f64]) {
    fill_row_dispatch(fold, both, r, t);
}

/// One loop per polarisation count, so that neither branches inside.
#[inline(always)]
fn fill_row_dispatch(fold: &Fold, both: bool, r: &mut [f64], t: &mut [f64]) {
    if both {
        fill_row_body::<2>(fold, r, t);
    } else {
        fill_row_body::<1>(fold, r, t);
    }
}

/// Every block of the row; the last, partial one is computed whole (the tables are
/// padded) and written in part.
#[inline(always)]
fn fill_row_body<const P: usize>(fold: &Fold, r: &mut [f64], t: &mut [f64]) {
    let n = r.len();
    for start in (0..n).step_by(LANES) {
        let (rv, tv) = block::<P>(fold, start);
        let end = (start + LANES).min(n);
        r[start..end].copy_from_slice(&rv[..end - start]);
        t[start..end].copy_from_slice(&tv[..end - start]);
    }
}

/// One block of wavelengths through every layer: `(B, C) ← M (B, C)` with
/// `M = [[cos δ, i sin δ / y], [i y sin δ, cos δ]]`, then `R` and `T` (the mean over the
/// first `P` polarisations).
#[inline(always)]
fn block<const P: usize>(fold: &Fold, start: usize) -> ([f64; LANES], [f64; LANES]) {
    let mut b_re = [[1.0; LANES]; P];
    let mut b_im = [[0.0; LANES]; P];
    let mut c_re: [[f64; LANES]; P] = std::array::from_fn(|k| [fold.y_substrate[k]; LANES]);
    let mut c_im = [[0.0; LANES]; P];
    let layers = fold.layers.iter().zip(fold.inv_y);
    for ((layer, inv_y), &phase) in layers.zip(fold.layer_phase) {
        let phase = &fold.phases[phase];
        let (sin, cos) = (
            &phase.sin[start..start + LANES],
            &phase.cos[start..start + LANES],
        );
        for k in 0..P {
            let (y, inv_y) = (layer.y[k], inv_y[k]);
            for l in 0..LANES {
                let (s_over_y, y_s) = (sin[l] * inv_y, sin[l] * y);
                let (br, bi, cr, ci) = (b_re[k][l], b_im[k][l], c_re[k][l], c_im[k][l]);
                b_re[k][l] = cos[l] * br - s_over_y * ci;
                b_im[k][l] = cos[l] * bi + s_over_y * cr;
                c_re[k][l] = cos[l] * cr - y_s * bi;
                c_im[k][l] = cos[l] * ci + y_s * br;
            }
        }
    }
    let weight = 1.0 / P as f64;
    let (mut r, mut t) = ([0.0; LANES], [0.0; LANES]);
    for k in 0..P {
        let y0 = fold.y_incident[k];
        let t_num = 4.0 * y0 * fold.y_substrate[k] * weight;
        for l in 0..LANES {
            let (p_re, p_im) = (y0 * b_re[k][l], y0 * b_im[k][l]);
            let (num_re, num_im) = (p_re - c_re[k][l], p_im - c_im[k][l]);
            let (den_re, den_im) = (p_re + c_re[k][l], p_im + c_im[k][l]);
            let inv = 1.0 / (den_re * den_re + den_im * den_im);
            r[l] += weight * (num_re * num_re + num_im * num_im) * inv;
            t[l] += t_num * inv;
        }
    }
    (r, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_portable_fold_is_bit_identical_to_the_dispatched_one() {
        let layers =
            [(1.38, 100.0), (2.1, 60.0), (1.38, 100.0), (1.7, 3e7)].map(|(n, d): (f64, f64)| {
                RealLayer {
                    beta_nm: std::f64::consts::TAU * d * n,
                    y: [n, 1.0 / n],
                }
            });
        let inv: Vec<f64> = (360..=837).map(|w| 1.0 / f64::from(w)).collect();
        for both in [false, true] {
            let mut row = RealRow::default();
            let (mut r, mut t) = (vec![0.0; inv.len()], vec![0.0; inv.len()]);
            row.fill(
                &inv,
                layers,
                [[1.0, 1.0], [1.52, 1.0 / 1.52]],
                both,
                &mut r,
                &mut t,
            );
            let fold = Fold {
                layers: &row.layers,
                inv_y: &row.inv_y,
                layer_phase: &row.layer_phase,
                phases: &row.phases,
                y_incident: [1.0, 1.0],
                y_substrate: [1.52, 1.0 / 1.52],
            };
            let (mut r2, mut t2) = (vec![0.0; inv.len()], vec![0.0; inv.len()]);
            fill_row_dispatch(&fold, both, &mut r2, &mut t2);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&r), bits(&r2));
            assert_eq!(bits(&t), bits(&t2));
            assert!(r.iter().zip(&t).all(|(r, t)| (r + t - 1.0).abs() < 1e-12));
        }
    }
}

//! The f64 row kernel of [`crate::stack_grid::StackGrid`]: one angle's wavelengths for a
//! coherent stack of constant indices, folded from the substrate by Rouard's recursion,
//! autovectorised (4 lanes with AVX2, picked at run time; no FMA contraction, so
//! bit-identical to the portable build).
//!
//! Each layer `j`, seen through the interface in front of it (coefficients `r`, `t`), maps
//! the amplitudes `Γ`, `τ` of everything behind it to
//! `Γ' = (r + Γ φ²) / (1 + r Γ φ²)` and `τ' = t τ φ / (1 + r Γ φ²)` (of which only `|τ|²`
//! is kept), with `φ = e^{iδ}`,
//! `δ = β_j / λ` and `Im δ ≥ 0`, so `|φ| ≤ 1` and nothing grows: the sum of every order of
//! reflection inside the layer. The interface coefficients depend on the angle only, so a
//! point costs one `e^{iδ}` per layer (shared by s and p) and a complex division per layer
//! and polarisation.

use super::trig_f64::{MAX_ARG, sin_cos};
use num_complex::Complex64;

/// One interface's amplitude coefficients for one polarisation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Coeffs {
    /// Reflection, `(y_front − y_back) / (y_front + y_back)`.
    pub r: Complex64,
    /// Transmission, `2 y_front / (y_front + y_back)`.
    pub t: Complex64,
}

/// A layer at one angle: `β = 2π d q` (its phase is `β / λ`), and the interface in front
/// of it for each polarisation solved.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LayerTerms {
    /// `2π d q` in nm (complex where the layer absorbs or is evanescent).
    pub beta_nm: Complex64,
    /// The front interface's coefficients, per polarisation.
    pub front: [Coeffs; 2],
}

/// One polarisation's running state over a row, structure of arrays: `Γ` and `|τ|²`.
#[derive(Clone, Debug, Default)]
pub(crate) struct Amplitudes {
    /// `Re Γ`.
    pub g_re: Vec<f64>,
    /// `Im Γ`.
    pub g_im: Vec<f64>,
    /// `|τ|²`: the transmittance needs only the modulus, which a layer scales by
    /// `|t|² |φ|² / |1 + r Γ φ²|²`.
    pub t_norm: Vec<f64>,
}

impl Amplitudes {
    fn start(&mut self, len: usize, exit: Coeffs) {
        for (v, x) in [
            (&mut self.g_re, exit.r.re),
            (&mut self.g_im, exit.r.im),
            (&mut self.t_norm, exit.t.norm_sqr()),
        ] {
            v.clear();
            v.resize(len, x);
        }
    }
}

/// Scratch for one row: the layer phase factor and both polarisations' amplitudes.
#[derive(Clone, Debug, Default)]
pub(crate) struct Row {
    /// `φ² = e^{2iδ}` over the row, and `|φ|²`.
    sq_re: Vec<f64>,
    sq_im: Vec<f64>,
    phi_norm: Vec<f64>,
    /// The amplitudes of the polarisations solved, after [`Row::fold`].
    pub amps: [Amplitudes; 2],
}

impl Row {
    /// `Γ` and `|τ|²` of the whole stack at each `1/λ` of `inv_wavelength_nm`, for the
    /// first `pols` polarisations (1 or 2): `exit` is the last interface, `layers` run
    /// back to front (the order the recursion meets them).
    pub(crate) fn fold(
        &mut self,
        inv_wavelength_nm: &[f64],
        exit: [Coeffs; 2],
        layers: &[LayerTerms],
        pols: usize,
    ) {
        let n = inv_wavelength_nm.len();
        for (amps, &exit) in self.amps.iter_mut().zip(&exit).take(pols) {
            amps.start(n, exit);
        }
        for v in [&mut self.sq_re, &mut self.sq_im, &mut self.phi_norm] {
            v.resize(n, 0.0);
        }
        let largest = inv_wavelength_nm.iter().fold(0.0f64, |m, &x| m.max(x));
        for layer in layers {
            self.phase(inv_wavelength_nm, largest, layer.beta_nm);
            let front = layer.front.map(Front::new);
            let phi = (&self.sq_re[..], &self.sq_im[..], &self.phi_norm[..]);
            if pols == 2 {
                let [s, p] = &mut self.amps;
                through_layer_both(phi, front, s, p);
            } else {
                through_layer(phi, front[0], &mut self.amps[0]);
            }
        }
    }

    /// `φ² = e^{2iβ/λ}` and `|φ|²` over the row (only these enter the recursion): the
    /// vector sine and cosine for a lossless layer within their range (`|φ|² = 1`), libm's
    /// with the decay `e^{−2 Im δ}` otherwise.
    fn phase(&mut self, inv_wavelength_nm: &[f64], largest: f64, beta_nm: Complex64) {
        let twice = 2.0 * beta_nm;
        if twice.im == 0.0 && twice.re.abs() * largest <= MAX_ARG {
            phase_lossless(
                inv_wavelength_nm,
                twice.re,
                &mut self.sq_re,
                &mut self.sq_im,
            );
            self.phi_norm.fill(1.0);
            return;
        }
        let sq = self.sq_re.iter_mut().zip(self.sq_im.iter_mut());
        for (((re, im), norm), &inv) in sq.zip(self.phi_norm.iter_mut()).zip(inv_wavelength_nm) {
            let delta2 = twice * inv;
            let (sin, cos) = delta2.re.sin_cos();
            let decay2 = (-delta2.im).exp();
            (*re, *im, *norm) = (decay2 * cos, decay2 * sin, decay2);
        }
    }
}

/// An interface's terms as the kernel uses them: `r`, and `|t|²`.
#[derive(Clone, Copy)]
struct Front {
    r_re: f64,
    r_im: f64,
    t_norm: f64,
}

impl Front {
    fn new(c: Coeffs) -> Front {
        Front {
            r_re: c.r.re,
            r_im: c.r.im,
            t_norm: c.t.norm_sqr(),
        }
    }
}

fn phase_lossless(inv: &[f64], beta_nm: f64, re: &mut [f64], im: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { phase_lossless_avx2(inv, beta_nm, re, im) };
        return;
    }
    phase_lossless_body(inv, beta_nm, re, im);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn phase_lossless_avx2(inv: &[f64], beta_nm: f64, re: &mut [f64], im: &mut [f64]) {
    phase_lossless_body(inv, beta_nm, re, im);
}

#[inline(always)]
fn phase_lossless_body(inv: &[f64], beta_nm: f64, re: &mut [f64], im: &mut [f64]) {
    let n = inv.len();
    let (re, im) = (&mut re[..n], &mut im[..n]);
    for i in 0..n {
        let (sin, cos) = sin_cos(beta_nm * inv[i]);
        re[i] = cos;
        im[i] = sin;
    }
}

fn through_layer(phi: (&[f64], &[f64], &[f64]), front: Front, amps: &mut Amplitudes) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { through_layer_avx2(phi, front, amps) };
        return;
    }
    through_layer_body(phi, front, amps);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn through_layer_avx2(phi: (&[f64], &[f64], &[f64]), front: Front, amps: &mut Amplitudes) {
    through_layer_body(phi, front, amps);
}

#[inline(always)]
fn through_layer_body(phi: (&[f64], &[f64], &[f64]), front: Front, amps: &mut Amplitudes) {
    let n = phi.0.len();
    let (sq_re, sq_im, phi_norm) = (&phi.0[..n], &phi.1[..n], &phi.2[..n]);
    let (g_re, g_im) = (&mut amps.g_re[..n], &mut amps.g_im[..n]);
    let t_norm = &mut amps.t_norm[..n];
    for i in 0..n {
        let sq = (sq_re[i], sq_im[i], phi_norm[i]);
        (g_re[i], g_im[i], t_norm[i]) = step(front, sq, g_re[i], g_im[i], t_norm[i]);
    }
}

/// Both polarisations in one pass: they share the phase's loads and `φ²`.
fn through_layer_both(
    phi: (&[f64], &[f64], &[f64]),
    front: [Front; 2],
    s: &mut Amplitudes,
    p: &mut Amplitudes,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { through_layer_both_avx2(phi, front, s, p) };
        return;
    }
    through_layer_both_body(phi, front, s, p);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn through_layer_both_avx2(
    phi: (&[f64], &[f64], &[f64]),
    front: [Front; 2],
    s: &mut Amplitudes,
    p: &mut Amplitudes,
) {
    through_layer_both_body(phi, front, s, p);
}

#[inline(always)]
fn through_layer_both_body(
    phi: (&[f64], &[f64], &[f64]),
    front: [Front; 2],
    s: &mut Amplitudes,
    p: &mut Amplitudes,
) {
    let n = phi.0.len();
    let (sq_re, sq_im, phi_norm) = (&phi.0[..n], &phi.1[..n], &phi.2[..n]);
    let (sg_re, sg_im, st) = (&mut s.g_re[..n], &mut s.g_im[..n], &mut s.t_norm[..n]);
    let (pg_re, pg_im, pt) = (&mut p.g_re[..n], &mut p.g_im[..n], &mut p.t_norm[..n]);
    for i in 0..n {
        let sq = (sq_re[i], sq_im[i], phi_norm[i]);
        (sg_re[i], sg_im[i], st[i]) = step(front[0], sq, sg_re[i], sg_im[i], st[i]);
        (pg_re[i], pg_im[i], pt[i]) = step(front[1], sq, pg_re[i], pg_im[i], pt[i]);
    }
}

/// The smallest `|1 + rΓφ²|²` the recursion trusts: a layer amplifies the rounding of what
/// is behind it by up to `1 / |1 + rΓφ²|²`, here 100.
const MIN_DEN_NORM: f64 = 1e-2;

/// `r + Γφ²` and `1 + rΓφ²` with `|1 + rΓφ²|²`: one layer's numerator and denominator.
#[derive(Clone, Copy)]
struct Bounce {
    num_re: f64,
    num_im: f64,
    den_re: f64,
    den_im: f64,
    den_norm: f64,
}

#[inline(always)]
fn bounce(front: Front, sq: (f64, f64, f64), g_re: f64, g_im: f64) -> Bounce {
    let (sq_re, sq_im, _) = sq;
    let x_re = g_re * sq_re - g_im * sq_im;
    let x_im = g_re * sq_im + g_im * sq_re;
    let den_re = 1.0 + (front.r_re * x_re - front.r_im * x_im);
    let den_im = front.r_re * x_im + front.r_im * x_re;
    Bounce {
        num_re: front.r_re + x_re,
        num_im: front.r_im + x_im,
        den_re,
        den_im,
        den_norm: den_re * den_re + den_im * den_im,
    }
}

/// One layer for one point, given `1 / |1 + rΓφ²|²`: `Γ' = (r + Γφ²) / (1 + rΓφ²)`,
/// `|τ'|² = |t|² |τ|² |φ|² / |1 + rΓφ²|²`.
#[inline(always)]
fn apply(front: Front, b: Bounce, inv_norm: f64, phi_norm: f64, t_norm: f64) -> (f64, f64, f64) {
    // Near a pole (a guided mode of the layers behind) Γ carries a relative error of
    // ε / |den|, which the layers in front can turn into an absolute one: such points
    // are poisoned, so that the caller takes them by the transfer matrix instead.
    let poison = if b.den_norm < MIN_DEN_NORM {
        f64::NAN
    } else {
        0.0
    };
    // num / den = num · conj(den) / |den|².
    let g_re = (b.num_re * b.den_re + b.num_im * b.den_im) * inv_norm + poison;
    let g_im = (b.num_im * b.den_re - b.num_re * b.den_im) * inv_norm;
    (g_re, g_im, front.t_norm * t_norm * phi_norm * inv_norm)
}

/// One layer for one point of one polarisation.
#[inline(always)]
fn step(front: Front, sq: (f64, f64, f64), g_re: f64, g_im: f64, t_norm: f64) -> (f64, f64, f64) {
    let b = bounce(front, sq, g_re, g_im);
    apply(front, b, 1.0 / b.den_norm, sq.2, t_norm)
}

//! General N-layer transfer-matrix method (characteristic matrices), s and p, complex
//! indices allowed: multilayer stacks (Hirayama et al.) and the independent cross-check
//! of the single-film Airy sum.
//!
//! Each layer maps the tangential fields at its back face to its front face by
//! `[[cos δ, −i sin δ / y], [−i y sin δ, cos δ]]` (for the `e^{−iωt}` convention),
//! with `δ = 2π q d / λ`, `q = n cos θ` and the layer's admittance `y = q` for s
//! and `y = q / n² = cos θ / n` for p (the p case works with `H_y` as its field, so no
//! admittance is ever infinite and grazing incidence stays finite). `sin δ / y` is
//! written as `(2π d / λ)(q / y) sinc δ`, finite even at a layer's critical angle where
//! `q = 0`.

use crate::dispersion::{CONSTANT_RANGE_NM, check_in_range};
use crate::fresnel::{self, Amplitudes, OpticsError, Response};
use crate::incidence::Incidence;
use crate::index::IndexModel;
use num_complex::Complex64;

mod incoherent;

/// One homogeneous layer of a stack.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// The layer's index model: real or complex `n + iκ` (`κ ≥ 0` absorbs), possibly dispersive.
    pub index: IndexModel,
    /// Physical thickness in nm.
    pub thickness_nm: f64,
    /// `false` for an incoherent layer (thick compared with the light's coherence length,
    /// such as a substrate slide): intensities add across it instead of amplitudes.
    pub coherent: bool,
}

impl Layer {
    /// A layer of any index model (a real or complex constant, a dispersion model, a table).
    pub fn new(index: impl Into<IndexModel>, thickness_nm: f64) -> Layer {
        Layer {
            index: index.into(),
            thickness_nm,
            coherent: true,
        }
    }

    /// An incoherent layer (see [`Layer::coherent`]): its multiple reflections add in
    /// intensity, as in Byrnes' `inc_tmm`; only its absorption depends on its thickness.
    pub fn incoherent(index: impl Into<IndexModel>, thickness_nm: f64) -> Layer {
        Layer {
            coherent: false,
            ..Layer::new(index, thickness_nm)
        }
    }

    /// A lossless layer of constant real index `n`.
    pub fn lossless(n: f64, thickness_nm: f64) -> Layer {
        Layer::new(n, thickness_nm)
    }
}

/// A stack: a lossless incident medium, layers in the order light meets them, a substrate.
#[derive(Clone, Debug, PartialEq)]
pub struct Stack {
    /// Real index of the incident medium.
    pub n_incident: f64,
    /// The layers, front to back.
    pub layers: Vec<Layer>,
    /// Index model of the semi-infinite substrate.
    pub n_substrate: IndexModel,
}

#[derive(Clone, Copy, PartialEq)]
enum Polarisation {
    S,
    P,
}

/// The indices of every medium at one wavelength.
struct Media {
    n0: f64,
    layers: Vec<(Complex64, f64)>,
    n_sub: Complex64,
    /// Positions in `layers` of the incoherent layers, front to back.
    incoherent: Vec<usize>,
}

impl Stack {
    /// A validated stack.
    ///
    /// # Guarantees
    /// `n_incident` is finite and `> 0`; every layer's and the substrate's model passes
    /// [`IndexModel::validate`] (complex indices finite with `Re > 0`, `Im ≥ 0`); every
    /// thickness is finite and `≥ 0`.
    pub fn new(
        n_incident: f64,
        layers: Vec<Layer>,
        n_substrate: impl Into<IndexModel>,
    ) -> Result<Stack, OpticsError> {
        let stack = Stack {
            n_incident,
            layers,
            n_substrate: n_substrate.into(),
        };
        stack.validate().map(|()| stack)
    }

    /// Checks a stack built from its fields, with the guarantees of [`Stack::new`].
    pub fn validate(&self) -> Result<(), OpticsError> {
        fresnel::check_real_index("n_incident", self.n_incident)?;
        self.n_substrate.validate()?;
        for layer in &self.layers {
            layer.index.validate()?;
            fresnel::check_thickness(layer.thickness_nm)?;
        }
        Ok(())
    }

    /// The wavelengths (nm) every medium's model covers: the intersection of their ranges
    /// (the incident medium, a constant, covers [`CONSTANT_RANGE_NM`]). `lo > hi` if empty.
    pub fn range_nm(&self) -> [f64; 2] {
        self.layers
            .iter()
            .map(|layer| layer.index.range_nm())
            .chain([self.n_substrate.range_nm()])
            .fold(CONSTANT_RANGE_NM, |[lo, hi], [a, b]| [lo.max(a), hi.min(b)])
    }

    /// Amplitude coefficients at `wavelength_nm` and `cos_theta_incident` ∈ [0, 1].
    pub fn try_amplitudes(
        &self,
        wavelength_nm: f64,
        cos_theta_incident: f64,
    ) -> Result<Amplitudes, OpticsError> {
        fresnel::check_cos("cos_theta_incident", cos_theta_incident)?;
        self.try_amplitudes_at(wavelength_nm, Incidence::try_from_cos(cos_theta_incident)?)
    }

    /// Amplitude coefficients at `wavelength_nm` in the direction `incidence`.
    ///
    /// Exact for any thickness: a layer's growing and decaying exponentials are factored
    /// out, so a thick absorbing or evanescent layer gives `t → 0`, never an overflow.
    pub fn try_amplitudes_at(
        &self,
        wavelength_nm: f64,
        incidence: Incidence,
    ) -> Result<Amplitudes, OpticsError> {
        let media = self.media(wavelength_nm)?;
        if let Some(&k) = media.incoherent.first() {
            return Err(OpticsError::Incoherent { layer: k + 1 });
        }
        if incidence.cos() == 0.0 {
            let (r_s, r_p, t) = if media.all_equal() {
                (0.0, 0.0, 1.0)
            } else {
                (-1.0, 1.0, 0.0)
            };
            return Ok(Amplitudes {
                r_s: r_s.into(),
                r_p: r_p.into(),
                t_s: t.into(),
                t_p: t.into(),
            });
        }
        let [s, h] = media.solve_both(wavelength_nm, incidence);
        // The p solve works with H_y: its r has the opposite sign and its t is scaled by
        // n_sub/n_0 relative to the electric-field convention of `fresnel`.
        Ok(Amplitudes {
            r_s: s.r,
            r_p: -h.r,
            t_s: s.t,
            t_p: h.t * media.n0 / media.n_sub,
        })
    }

    /// Intensity reflectance and transmittance at `wavelength_nm` and `cos_theta_incident`.
    pub fn try_response(
        &self,
        wavelength_nm: f64,
        cos_theta_incident: f64,
    ) -> Result<Response, OpticsError> {
        fresnel::check_cos("cos_theta_incident", cos_theta_incident)?;
        self.try_response_at(wavelength_nm, Incidence::try_from_cos(cos_theta_incident)?)
    }

    /// Intensity reflectance and transmittance at `wavelength_nm` in the direction
    /// `incidence`, exact for any thickness (see [`Stack::try_amplitudes_at`]).
    pub fn try_response_at(
        &self,
        wavelength_nm: f64,
        incidence: Incidence,
    ) -> Result<Response, OpticsError> {
        let media = self.media(wavelength_nm)?;
        if incidence.cos() == 0.0 {
            return Ok(Response::grazing(media.all_equal()));
        }
        if !media.incoherent.is_empty() {
            return Ok(media.incoherent_response(wavelength_nm, incidence));
        }
        let [s, p] = media.solve_both(wavelength_nm, incidence);
        Ok(Response {
            r_s: s.r.norm_sqr(),
            r_p: p.r.norm_sqr(),
            t_s: s.transmittance,
            t_p: p.transmittance,
        })
    }

    /// [`Stack::try_response`] for known-good arguments.
    ///
    /// # Panics
    /// If the stack is invalid (see [`Stack::new`]), `wavelength_nm` is not finite and
    /// positive or outside a medium's range, or `cos_theta_incident` is not in [0, 1].
    pub fn response(&self, wavelength_nm: f64, cos_theta_incident: f64) -> Response {
        self.try_response(wavelength_nm, cos_theta_incident)
            .unwrap_or_else(|err| panic!("{err}"))
    }

    fn media(&self, wavelength_nm: f64) -> Result<Media, OpticsError> {
        self.validate()?;
        fresnel::check_wavelength(wavelength_nm)?;
        check_in_range(
            "incident medium's constant index",
            CONSTANT_RANGE_NM,
            wavelength_nm,
        )?;
        let checked = |model: &IndexModel, what: &'static str| {
            let n = model.try_n_at(wavelength_nm)?;
            fresnel::check_complex_index(what, n).map(|()| n)
        };
        let layers = self
            .layers
            .iter()
            .map(|layer| Ok((checked(&layer.index, "layer index")?, layer.thickness_nm)))
            .collect::<Result<_, OpticsError>>()?;
        let incoherent = (self.layers.iter().enumerate())
            .filter_map(|(k, layer)| (!layer.coherent).then_some(k))
            .collect();
        Ok(Media {
            n0: self.n_incident,
            layers,
            n_sub: checked(&self.n_substrate, "n_substrate")?,
            incoherent,
        })
    }
}

/// One polarisation's solution, in the field of its solve (`E_y` for s, `H_y` for p).
struct Solution {
    r: Complex64,
    t: Complex64,
    transmittance: f64,
}

impl Media {
    fn all_equal(&self) -> bool {
        let n0 = Complex64::new(self.n0, 0.0);
        self.n_sub == n0 && self.layers.iter().all(|&(n, _)| n == n0)
    }

    /// `[s, p]`; requires `incidence.cos() > 0`.
    fn solve_both(&self, wavelength_nm: f64, incidence: Incidence) -> [Solution; 2] {
        let block = Block {
            entry: Complex64::new(self.n0, 0.0),
            layers: &self.layers,
            reversed: false,
            exit: self.n_sub,
        };
        block.solve_pols(
            [Polarisation::S, Polarisation::P],
            self.n0,
            wavelength_nm,
            incidence,
        )
    }
}

/// Coherent layers between two semi-infinite media: the whole stack, or (with incoherent
/// layers) the run of coherent layers between two incoherent media.
struct Block<'a> {
    /// The medium light arrives from (complex when it is an absorbing incoherent layer).
    entry: Complex64,
    /// The coherent layers, front to back as stored.
    layers: &'a [(Complex64, f64)],
    /// Light meets `layers` back to front (the block seen from its exit side).
    reversed: bool,
    /// The medium light leaves into.
    exit: Complex64,
}

impl Block<'_> {
    /// Requires `incidence.cos() > 0`; `n0` is the real incident medium of the whole stack
    /// (its `n0 sin θ` is the same in every medium, Snell).
    ///
    /// `[B, C] = M_1 ⋯ M_N [1, y_sub]` is carried as `e^{L} [B', C']` with `[B', C']` of
    /// modulus ≤ 1: each layer's matrix is applied divided by `e^{Im δ}` (its largest
    /// possible growth) and the product renormalised, the scales summed into `L`. Then
    /// `r` is scale-free, `t = 2 y0 e^{−L} / (y0 B' + C')` and `T` carries `e^{−2L}`.
    /// From an absorbing entry medium `T = |t|² Re y_sub / Re y0`: Byrnes' power ratio
    /// for incoherent media, the flux of the forward wave alone.
    fn solve(
        &self,
        pol: Polarisation,
        n0: f64,
        wavelength_nm: f64,
        incidence: Incidence,
    ) -> Solution {
        let [solution] = self.solve_pols([pol], n0, wavelength_nm, incidence);
        solution
    }

    /// [`Block::solve`] for several polarisations at once: each layer's normal index,
    /// phase and trigonometry, the costly part, are computed once for all of them.
    fn solve_pols<const N: usize>(
        &self,
        pols: [Polarisation; N],
        n0: f64,
        wavelength_nm: f64,
        incidence: Incidence,
    ) -> [Solution; N] {
        let k_per_nm = std::f64::consts::TAU / wavelength_nm;
        let admittance = |pol: Polarisation, n: Complex64, q: Complex64| match pol {
            Polarisation::S => q,
            Polarisation::P => q / (n * n),
        };
        let q_entry = incidence.normal_index(n0, self.entry);
        let q_exit = incidence.normal_index(n0, self.exit);
        let y0 = pols.map(|pol| admittance(pol, self.entry, q_entry));
        let y_sub = pols.map(|pol| admittance(pol, self.exit, q_exit));
        let mut field = y_sub.map(|y| (Complex64::new(1.0, 0.0), y));
        let mut log_scale = [0.0; N];
        // The matrices multiply from the exit side towards the entry side.
        let count = self.layers.len();
        for step in 0..count {
            let at = if self.reversed {
                step
            } else {
                count - 1 - step
            };
            let (n, thickness_nm) = self.layers[at];
            let q = incidence.normal_index(n0, n);
            let delta = k_per_nm * thickness_nm * q;
            let (cos_d, sin_d, sinc_d) = scaled_trig(delta);
            for k in 0..N {
                let pol = pols[k];
                let y = admittance(pol, n, q);
                let q_over_y = match pol {
                    Polarisation::S => Complex64::new(1.0, 0.0),
                    Polarisation::P => n * n,
                };
                let sin_over_y = k_per_nm * thickness_nm * q_over_y * sinc_d;
                let minus_i = Complex64::new(0.0, -1.0);
                let f = field[k];
                let next = (
                    cos_d * f.0 + minus_i * sin_over_y * f.1,
                    minus_i * y * sin_d * f.0 + cos_d * f.1,
                );
                let size = next.0.norm().max(next.1.norm());
                if size > 0.0 && size.is_finite() {
                    field[k] = (next.0 / size, next.1 / size);
                    log_scale[k] += delta.im + size.ln();
                } else {
                    field[k] = next;
                    log_scale[k] += delta.im;
                }
            }
        }
        std::array::from_fn(|k| {
            let (y0, y_sub) = (y0[k], y_sub[k]);
            let (b, c) = field[k];
            let den = y0 * b + c;
            let shrink = (-log_scale[k]).exp();
            let transmittance = if y0.im == 0.0 {
                // Divided factor by factor: |den|² alone underflows a hair from grazing.
                4.0 * (y0.re / den.norm()) * (y_sub.re / den.norm()) * shrink * shrink
            } else if y0.re > 0.0 {
                let ratio = y0.norm() / den.norm() * shrink;
                4.0 * ratio * ratio * (y_sub.re / y0.re)
            } else {
                // An evanescent entry medium carries no power towards the block.
                0.0
            };
            Solution {
                r: divide(y0 * b - c, den),
                t: divide(2.0 * y0, den) * shrink,
                transmittance,
            }
        })
    }
}

/// `(cos δ, sin δ, sin δ / δ)`, each times `e^{−Im δ}` so that none overflows however large
/// `Im δ ≥ 0` is: `e^{−Im δ} cos δ = (e^{i Re δ − 2 Im δ} + e^{−i Re δ}) / 2`.
fn scaled_trig(delta: Complex64) -> (Complex64, Complex64, Complex64) {
    // One sine and cosine for both waves (libm's are exactly odd and even in their angle).
    let (sin_re, cos_re) = delta.re.sin_cos();
    let grow = (-2.0 * delta.im).exp();
    let forward = Complex64::new(grow * cos_re, grow * sin_re);
    let backward = Complex64::new(cos_re, -sin_re);
    let cos_d = 0.5 * (forward + backward);
    let sin_d = Complex64::new(0.0, -0.5) * (forward - backward);
    let sinc_d = if delta.norm_sqr() < 1e-8 {
        sinc(delta) * (-delta.im).exp()
    } else {
        sin_d / delta
    };
    (cos_d, sin_d, sinc_d)
}

/// `a / b`, scaled first so that `|b|²` cannot underflow (num-complex divides by `|b|²`).
fn divide(a: Complex64, b: Complex64) -> Complex64 {
    let scale = b.re.abs().max(b.im.abs());
    if scale > 0.0 && scale.is_finite() {
        (a / scale) / (b / scale)
    } else {
        a / b
    }
}

/// `sin z / z` for complex `z`, by its series near 0 where the quotient loses accuracy.
fn sinc(z: Complex64) -> Complex64 {
    if z.norm_sqr() < 1e-8 {
        let z2 = z * z;
        1.0 - z2 / 6.0 + z2 * z2 / 120.0
    } else {
        z.sin() / z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sinc_series_meets_quotient_at_the_switch() {
        for z in [
            Complex64::new(1e-4, 0.0),
            Complex64::new(0.0, 1e-4),
            Complex64::new(7e-5, 7e-5),
        ] {
            let quotient = z.sin() / z;
            let series = sinc(z * 0.999_999);
            assert!((quotient - series).norm() < 1e-12, "{quotient} vs {series}");
        }
    }

    #[test]
    fn empty_stack_is_one_interface() {
        let stack = Stack::new(1.0, vec![], Complex64::new(1.5, 0.1)).unwrap();
        let surface = fresnel::Interface::new(1.0, Complex64::new(1.5, 0.1)).unwrap();
        for cos in [1.0, 0.7, 0.2, 0.01] {
            let a = stack.try_amplitudes(550.0, cos).unwrap();
            let b = surface.try_amplitudes(cos).unwrap();
            for (x, y) in [
                (a.r_s, b.r_s),
                (a.r_p, b.r_p),
                (a.t_s, b.t_s),
                (a.t_p, b.t_p),
            ] {
                assert!((x - y).norm() < 1e-14, "cos {cos}: {x} vs {y}");
            }
        }
    }
}

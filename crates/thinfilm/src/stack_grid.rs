//! Coherent multilayer stacks on a grid of angle × wavelength, exact in f64: every
//! interface's coefficients are computed once per angle, then each (angle, wavelength)
//! point is folded through the layers on a vectorised kernel of [`crate::batch`].
//!
//! At an angle where every medium is real and no layer is evanescent (the common case:
//! dielectric coatings), the kernel multiplies the layers' real-structured characteristic
//! matrices: one sine and cosine per distinct layer phase and one division per point and
//! polarisation. Other stacks of constant indices (absorbing, or evanescent at that angle)
//! take Rouard's recursion, one `e^{iδ}` per layer and a complex division per layer and
//! polarisation, except at grazing incidence. Any other stack or point, and any point where
//! the recursion meets a pole (a guided mode of a lossless sub-stack hit exactly), takes
//! the transfer matrix of [`Stack::try_response_at`], so every point is exact. All agree
//! to 1e-13 (the test `optics_stack_grid`).
//!
//! ```
//! use thinfilm::grid::Polarisation;
//! use thinfilm::stack_grid::StackGrid;
//! use thinfilm::tmm::{Layer, Stack};
//! let layers = vec![Layer::lossless(1.38, 100.0), Layer::lossless(2.1, 60.0)];
//! let stack = Stack::new(1.0, layers, 1.52).unwrap();
//! let grid = StackGrid::try_new(&stack, &[0.0, 45.0], &[450.0, 550.0, 650.0]).unwrap();
//! let (mut r, mut t) = (vec![0.0; 6], vec![0.0; 6]);
//! grid.try_fill(Polarisation::Unpolarised, &mut r, &mut t).unwrap();
//! assert!(r.iter().zip(&t).all(|(r, t)| (r + t - 1.0).abs() < 1e-14));
//! ```

use crate::batch::stack_f64::{Amplitudes, Coeffs, LayerTerms, Row};
use crate::batch::stack_real_f64::{RealLayer, RealRow};
use crate::dispersion::check_in_range;
use crate::fresnel::{self, OpticsError, check_len};
use crate::grid::Polarisation;
use crate::incidence::Incidence;
use crate::tmm::Stack;
use num_complex::Complex64;

/// One angle's terms for a kernel, or the general path.
#[derive(Clone, Debug)]
enum AngleRow {
    /// Every medium real and seen without evanescence: the real characteristic matrices.
    Real {
        /// The layers, back to front.
        layers: Vec<RealLayer>,
        /// The incident medium's and the substrate's admittances, for s and p.
        y_incident: [f64; 2],
        y_substrate: [f64; 2],
    },
    /// Constant indices, all coherent, `cos θ > 0`.
    Folded {
        /// The direction, for points the recursion cannot take.
        incidence: Incidence,
        /// The last interface (last layer, or the incident medium, to the substrate).
        exit: [Coeffs; 2],
        /// The layers, back to front.
        layers: Vec<LayerTerms>,
        /// `Re y_substrate / y_incident` for s and p: `T = ratio · |τ|²`.
        power_ratio: [f64; 2],
    },
    /// Every point by the transfer matrix.
    General(Incidence),
}

thread_local! {
    // Each thread keeps its kernels' scratch: a span takes about 0.1 ms, and allocating
    // its rows cost a tenth of that.
    static REAL_ROW: std::cell::RefCell<RealRow> = std::cell::RefCell::default();
    static ROUARD_ROW: std::cell::RefCell<Row> = std::cell::RefCell::default();
}

/// A stack's interface terms over angle × wavelength, ready to fill `R` and `T`.
#[derive(Clone, Debug)]
pub struct StackGrid {
    stack: Stack,
    wavelength_nm: Vec<f64>,
    inv_wavelength_nm: Vec<f64>,
    rows: Vec<AngleRow>,
}

impl StackGrid {
    /// The grid of `angle_deg` (each in [0, 90]) × `wavelength_nm` for `stack`.
    ///
    /// # Errors
    /// An [`OpticsError`] naming the first bad stack value, angle or wavelength (outside
    /// the range of a medium's model).
    pub fn try_new(
        stack: &Stack,
        angle_deg: &[f64],
        wavelength_nm: &[f64],
    ) -> Result<StackGrid, OpticsError> {
        stack.validate()?;
        let range = stack.range_nm();
        for &wavelength in wavelength_nm {
            fresnel::check_wavelength(wavelength)?;
            check_in_range("stack's index models", range, wavelength)?;
        }
        let media = constant_media(stack);
        let rows = angle_deg
            .iter()
            .map(|&angle| {
                let incidence = Incidence::try_from_angle_deg(angle)?;
                Ok(match &media {
                    Some(media) if incidence.cos() > 0.0 => {
                        let q = normal_indices(stack, media, incidence);
                        real(stack, media, &q)
                            .unwrap_or_else(|| folded(stack, media, &q, incidence))
                    }
                    _ => AngleRow::General(incidence),
                })
            })
            .collect::<Result<_, OpticsError>>()?;
        Ok(StackGrid {
            stack: stack.clone(),
            wavelength_nm: wavelength_nm.to_vec(),
            inv_wavelength_nm: wavelength_nm.iter().map(|w| 1.0 / w).collect(),
            rows,
        })
    }

    /// Number of angles: rows of [`StackGrid::try_fill`]'s angle-major output.
    pub fn angles(&self) -> usize {
        self.rows.len()
    }

    /// Number of wavelengths: the length of one row.
    pub fn wavelengths(&self) -> usize {
        self.wavelength_nm.len()
    }

    /// Number of (angle, wavelength) points.
    pub fn len(&self) -> usize {
        self.angles() * self.wavelengths()
    }

    /// Whether the grid has no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// `R` and `T` at every point, angle-major, into `r` and `t` (each
    /// [`StackGrid::len`] long).
    ///
    /// # Errors
    /// `r` or `t` of the wrong length.
    pub fn try_fill(
        &self,
        pol: Polarisation,
        r: &mut [f64],
        t: &mut [f64],
    ) -> Result<(), OpticsError> {
        check_len("r", r.len(), self.len())?;
        check_len("t", t.len(), self.len())?;
        let width = self.wavelengths().max(1);
        let rows = r.chunks_mut(width).zip(t.chunks_mut(width));
        for (angle, (r, t)) in rows.enumerate() {
            self.try_fill_row(angle, pol, r, t)?;
        }
        Ok(())
    }

    /// `R` and `T` at angle `angle`'s wavelengths (rows are independent: fill them in
    /// parallel).
    ///
    /// # Errors
    /// `angle` beyond the grid, or `r` or `t` not [`StackGrid::wavelengths`] long.
    pub fn try_fill_row(
        &self,
        angle: usize,
        pol: Polarisation,
        r: &mut [f64],
        t: &mut [f64],
    ) -> Result<(), OpticsError> {
        check_len("r", r.len(), self.wavelengths())?;
        self.try_fill_span(angle, 0, pol, r, t)
    }

    /// `R` and `T` at angle `angle` for the wavelengths `first..first + r.len()` (spans are
    /// independent too: split long rows to share them between threads).
    ///
    /// # Errors
    /// `angle` or the span beyond the grid, or `t` not as long as `r`.
    pub fn try_fill_span(
        &self,
        angle: usize,
        first: usize,
        pol: Polarisation,
        r: &mut [f64],
        t: &mut [f64],
    ) -> Result<(), OpticsError> {
        check_len("t", t.len(), r.len())?;
        let row = self.rows.get(angle).ok_or(OpticsError::Length {
            what: "angle row",
            len: angle,
            expected: self.angles(),
        })?;
        let span = first
            .checked_add(r.len())
            .filter(|&end| end <= self.wavelengths())
            .map(|end| first..end)
            .ok_or(OpticsError::Length {
                what: "wavelengths from first",
                len: first.saturating_add(r.len()),
                expected: self.wavelengths(),
            })?;
        let wavelengths = &self.wavelength_nm[span.clone()];
        let (lead, pols) = match pol {
            Polarisation::P => (1, 1),
            Polarisation::S => (0, 1),
            Polarisation::Unpolarised => (0, 2),
        };
        match row {
            AngleRow::Real {
                layers,
                y_incident,
                y_substrate,
            } => {
                let pick = |y: [f64; 2]| [y[lead], y[1 - lead]];
                let layers = layers.iter().map(|l| RealLayer { y: pick(l.y), ..*l });
                let ends = [pick(*y_incident), pick(*y_substrate)];
                let inv = &self.inv_wavelength_nm[span];
                REAL_ROW.with_borrow_mut(|row| row.fill(inv, layers, ends, pols == 2, r, t));
                Ok(())
            }
            AngleRow::Folded {
                incidence,
                exit,
                layers,
                power_ratio,
            } => {
                let pick = |k: [Coeffs; 2]| [k[lead], k[1 - lead]];
                let layers: Vec<_> = (layers.iter())
                    .map(|l| LayerTerms {
                        front: pick(l.front),
                        ..*l
                    })
                    .collect();
                let ratio = [power_ratio[lead], power_ratio[1 - lead]];
                ROUARD_ROW.with_borrow_mut(|kernel| {
                    kernel.fold(&self.inv_wavelength_nm[span], pick(*exit), &layers, pols);
                    write_row(kernel, ratio, pols, r, t);
                });
                self.repair_poles(wavelengths, *incidence, pol, r, t)
            }
            AngleRow::General(incidence) => {
                for (k, &wavelength) in wavelengths.iter().enumerate() {
                    (r[k], t[k]) = self.exact_at(wavelength, *incidence, pol)?;
                }
                Ok(())
            }
        }
    }

    /// Points the recursion could not evaluate (a pole of a sub-stack), by the matrix.
    fn repair_poles(
        &self,
        wavelengths: &[f64],
        incidence: Incidence,
        pol: Polarisation,
        r: &mut [f64],
        t: &mut [f64],
    ) -> Result<(), OpticsError> {
        for (k, &wavelength) in wavelengths.iter().enumerate() {
            if !(r[k].is_finite() && t[k].is_finite()) {
                (r[k], t[k]) = self.exact_at(wavelength, incidence, pol)?;
            }
        }
        Ok(())
    }

    fn exact_at(
        &self,
        wavelength_nm: f64,
        incidence: Incidence,
        pol: Polarisation,
    ) -> Result<(f64, f64), OpticsError> {
        let resp = self.stack.try_response_at(wavelength_nm, incidence)?;
        Ok(match pol {
            Polarisation::S => (resp.r_s, resp.t_s),
            Polarisation::P => (resp.r_p, resp.t_p),
            Polarisation::Unpolarised => (resp.r(), resp.t()),
        })
    }
}

/// `R = |Γ|²`, `T = ratio · |τ|²`, one polarisation or the mean of two.
fn write_row(kernel: &Row, ratio: [f64; 2], pols: usize, r: &mut [f64], t: &mut [f64]) {
    let reflect = |a: &Amplitudes, k: usize| a.g_re[k] * a.g_re[k] + a.g_im[k] * a.g_im[k];
    let transmit = |a: &Amplitudes, k: usize, ratio: f64| ratio * a.t_norm[k];
    let [first, second] = &kernel.amps;
    for k in 0..r.len() {
        if pols == 1 {
            (r[k], t[k]) = (reflect(first, k), transmit(first, k, ratio[0]));
        } else {
            r[k] = 0.5 * (reflect(first, k) + reflect(second, k));
            t[k] = 0.5 * (transmit(first, k, ratio[0]) + transmit(second, k, ratio[1]));
        }
    }
}

/// Every medium's index, front to back, when all are constant and every layer coherent.
fn constant_media(stack: &Stack) -> Option<Vec<Complex64>> {
    let mut media = vec![Complex64::from(stack.n_incident)];
    for layer in &stack.layers {
        if !layer.coherent {
            return None;
        }
        media.push(layer.index.as_constant()?);
    }
    media.push(stack.n_substrate.as_constant()?);
    Some(media)
}

/// Each medium's `q = n cos θ` at `incidence`, front to back.
fn normal_indices(stack: &Stack, media: &[Complex64], incidence: Incidence) -> Vec<Complex64> {
    (media.iter())
        .map(|&n| incidence.normal_index(stack.n_incident, n))
        .collect()
}

/// A medium's admittances for s and p: `q` and `q / n²` (the p solve works with `H_y`).
fn admittances(n: Complex64, q: Complex64) -> [Complex64; 2] {
    [q, q / (n * n)]
}

/// The real kernel's terms at one angle, when every medium is real and every
/// `q = n cos θ` (`q`, front to back) real and positive there (no absorption, no
/// evanescence).
fn real(stack: &Stack, media: &[Complex64], q: &[Complex64]) -> Option<AngleRow> {
    if !(media.iter().zip(q)).all(|(n, q)| n.im == 0.0 && q.im == 0.0 && q.re > 0.0) {
        return None;
    }
    // `admittances` in real arithmetic.
    let y = |m: usize| [q[m].re, q[m].re / (media[m].re * media[m].re)];
    let last = media.len() - 1;
    let layers = (1..last)
        .rev()
        .map(|m| RealLayer {
            beta_nm: std::f64::consts::TAU * stack.layers[m - 1].thickness_nm * q[m].re,
            y: y(m),
        })
        .collect();
    Some(AngleRow::Real {
        layers,
        y_incident: y(0),
        y_substrate: y(last),
    })
}

/// The kernel's terms at one angle with `cos θ > 0`, where the media have the normal
/// indices `q`.
fn folded(stack: &Stack, media: &[Complex64], q: &[Complex64], incidence: Incidence) -> AngleRow {
    let y = |m: usize| admittances(media[m], q[m]);
    let interface = |m: usize| {
        let (front, back) = (y(m), y(m + 1));
        [0, 1].map(|p| Coeffs {
            r: (front[p] - back[p]) / (front[p] + back[p]),
            t: 2.0 * front[p] / (front[p] + back[p]),
        })
    };
    let last = media.len() - 1;
    let layers = (1..last)
        .rev()
        .map(|m| LayerTerms {
            beta_nm: std::f64::consts::TAU * stack.layers[m - 1].thickness_nm * q[m],
            front: interface(m - 1),
        })
        .collect();
    let (y0, y_sub) = (y(0), y(last));
    AngleRow::Folded {
        incidence,
        exit: interface(last - 1),
        layers,
        power_ratio: [0, 1].map(|p| y_sub[p].re / y0[p].re),
    }
}

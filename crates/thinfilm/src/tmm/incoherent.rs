//! Stacks with incoherent layers: the coherent runs between them are solved in amplitude
//! (both ways), then intensities are added across each incoherent layer, as in Byrnes'
//! `inc_tmm` (arXiv:1603.02720, section 5).
//!
//! The stack is cut at its incoherent layers into media `M_0` (the incident medium),
//! `M_1 … M_k` (the incoherent layers) and `M_{k+1}` (the substrate), with a coherent
//! block `B_j` (possibly empty: a bare interface) between `M_j` and `M_{j+1}`. Each block
//! has power coefficients `R_f, T_f` from the front and `R_b, T_b` from the back. Light in
//! `M_j` loses `P_j = exp(−4π d_j Im(n_j cos θ_j) / λ)` of its power per pass. Seen from
//! inside `M_j` at its front face, everything behind it reflects `R'_j` and transmits
//! `T'_j` into the substrate; folding from the back,
//!
//! `R' ← R_f + T_f T_b P² R' / (1 − R_b P² R')`, `T' ← T_f P T' / (1 − R_b P² R')`,
//!
//! the geometric series of the bounces inside `M_j`, summed in intensity. This is the
//! product of Byrnes' 2×2 intensity matrices written as a continued fraction: it never
//! divides by `P` or `T_f`, so an opaque layer (`P` underflowing to 0) or an evanescent one
//! gives its limit, never a NaN.

use num_complex::Complex64;

use super::{Block, Media, Polarisation};
use crate::fresnel::Response;
use crate::incidence::Incidence;

/// Power reflectance and transmittance of one polarisation.
#[derive(Clone, Copy)]
struct Power {
    r: f64,
    t: f64,
}

impl Media {
    /// `R` and `T` for each polarisation; requires `incidence.cos() > 0` and at least one
    /// incoherent layer.
    pub(super) fn incoherent_response(&self, wavelength_nm: f64, incidence: Incidence) -> Response {
        let s = self.incoherent_power(Polarisation::S, wavelength_nm, incidence);
        let p = self.incoherent_power(Polarisation::P, wavelength_nm, incidence);
        Response {
            r_s: s.r,
            r_p: p.r,
            t_s: s.t,
            t_p: p.t,
        }
    }

    fn incoherent_power(
        &self,
        pol: Polarisation,
        wavelength_nm: f64,
        incidence: Incidence,
    ) -> Power {
        let k_per_nm = std::f64::consts::TAU / wavelength_nm;
        // Media M_0 … M_{k+1} and the blocks between them, as ranges of `self.layers`.
        let mut media = vec![Complex64::new(self.n0, 0.0)];
        let mut blocks = Vec::with_capacity(self.incoherent.len() + 1);
        let mut start = 0;
        for &k in &self.incoherent {
            media.push(self.layers[k].0);
            blocks.push(start..k);
            start = k + 1;
        }
        media.push(self.n_sub);
        blocks.push(start..self.layers.len());

        let solve = |j: usize, backwards: bool| {
            let (entry, exit) = if backwards {
                (media[j + 1], media[j])
            } else {
                (media[j], media[j + 1])
            };
            let block = Block {
                entry,
                layers: &self.layers[blocks[j].clone()],
                reversed: backwards,
                exit,
            };
            let sol = block.solve(pol, self.n0, wavelength_nm, incidence);
            Power {
                r: sol.r.norm_sqr(),
                t: sol.transmittance,
            }
        };

        let last = blocks.len() - 1;
        let mut behind = solve(last, false);
        for j in (0..last).rev() {
            // M_{j+1} is the incoherent layer between blocks j and j + 1.
            let (n, thickness_nm) = self.layers[self.incoherent[j]];
            let q = incidence.normal_index(self.n0, n);
            let pass = (-2.0 * k_per_nm * thickness_nm * q.im).exp();
            let front = solve(j, false);
            let back = solve(j, true);
            let returned = pass * pass * behind.r;
            let feed = front.t * back.t;
            let bounces = 1.0 - back.r * returned;
            behind = if feed > 0.0 && bounces > 0.0 {
                Power {
                    r: front.r + feed * returned / bounces,
                    t: front.t * pass * behind.t / bounces,
                }
            } else {
                // Nothing enters M_{j+1} (an opaque block, or an evanescent M_{j+1}):
                // `front.t > 0` implies `back.t > 0`, so no transmitted power is lost here.
                Power { r: front.r, t: 0.0 }
            };
        }
        behind
    }
}

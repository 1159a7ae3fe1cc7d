//! Cell means: a film's colour that stays exact at grazing incidence.
//!
//! Towards grazing incidence each face of a film reflects almost everything, and the
//! film's transmission fringes become lines far narrower than any sampling step: at 89°
//! the lines of a 2 µm soap film are about 1 nm wide, at 89.9° 0.05 nm. Point samples of
//! R(λ) hit or miss them by chance (3–6 ΔE2000 at a 5 nm step).
//!
//! Per polarisation a symmetric lossless film transmits
//! `T(φ) = A · (1 − r²) / (1 − 2r cos 2πφ + r²)` with `r = ρ²`, `A = (1 − r)/(1 + r)`
//! and φ the round-trip phase in periods. Its integral has a closed form,
//! `∫ T dφ = A (φ + θ(φ)/π)` with the bounded, 1-periodic
//! `θ(φ) = atan2((1 − A) sin πφ cos πφ, A cos² πφ + sin² πφ)`, so the mean of R over a
//! wavelength cell, taking φ linear in λ across it, is exact however sharp the lines:
//! `mean R = 1 − A − A (θ(φ_lo) − θ(φ_hi)) / (π (φ_lo − φ_hi))`.
//!
//! A [`SpectralIntegrator`] on an even grid turns into cells around its nodes
//! ([`CellWeights`]): the node values the interpolating weights expect are rebuilt from
//! the cell means to fourth order, `R_k ≈ (−R̄_{k−1} + 26 R̄_k − R̄_{k+1}) / 24`, so smooth
//! spectra keep the accuracy of the node quadrature while each narrow line keeps its exact
//! area. Cells are used only where they are needed ([`cell_threshold_nm`]): they cost
//! about three point samples each.

use num_complex::Complex64;

use crate::airy::ThinFilm;
use crate::dispersion::RefractiveIndex;
use crate::fresnel::Response;
use crate::incidence::Incidence;
use crate::integrate::SpectralIntegrator;

/// Cells are used once the film's sharpest feature, the half-width of its s-polarised
/// transmission lines at the shortest cell wavelength, is narrower than this many cell
/// widths.
pub const SHARPNESS_CELLS: f64 = 0.7;

/// Smallest phase change across a cell (in periods) for which cell means are used: below
/// it the difference of `θ` at the two edges would cancel in f32 (and R is smooth there).
pub const MIN_CELL_PERIODS: f64 = 1e-3;

/// Below this `cos² θ_t` inside the film (near its critical angle) cells are not used.
pub const MIN_COS2_IN_FILM: f64 = 1e-4;

/// A [`SpectralIntegrator`] rewritten over cells: `XYZ = Σ_c weights[c] · mean_c(R) +
/// Σ_l line_weights[l] · R(line_nm[l])`.
///
/// # Guarantees
/// `edges_nm` has one more entry than `centres_nm` and `weights`, is strictly increasing,
/// and `edges_nm[c] <= centres_nm[c] <= edges_nm[c + 1]`; `line_nm` and `line_weights`
/// have the same length. For `R ≡ 1` the sums give the integrator's white.
#[derive(Clone, Debug, PartialEq)]
pub struct CellWeights {
    /// Cell edges, nm.
    pub edges_nm: Vec<f64>,
    /// The node each cell was built around, nm (where its index is taken).
    pub centres_nm: Vec<f64>,
    /// XYZ weight of each cell's mean reflectance.
    pub weights: Vec<[f64; 3]>,
    /// Emission lines, nm: sampled at their wavelength.
    pub line_nm: Vec<f64>,
    /// XYZ weight of each line.
    pub line_weights: Vec<[f64; 3]>,
}

impl CellWeights {
    /// Cells around the nodes `first_nm + k · spacing_nm` (`k < node_weights.len()`, the
    /// end cells halved to stay inside the grid), with node-value weights `node_weights`.
    /// Leading and trailing cells of zero weight are dropped.
    pub(crate) fn from_grid(
        first_nm: f64,
        spacing_nm: f64,
        node_weights: &[[f64; 3]],
        lines: Vec<(f64, [f64; 3])>,
    ) -> CellWeights {
        let k = node_weights.len();
        let mut weights = vec![[0.0; 3]; k];
        for (node, w) in node_weights.iter().enumerate() {
            let stencil: &[(usize, f64)] = if node == 0 || node + 1 == k {
                &[(node, 1.0)]
            } else {
                &[
                    (node - 1, -1.0 / 24.0),
                    (node, 26.0 / 24.0),
                    (node + 1, -1.0 / 24.0),
                ]
            };
            for &(cell, c) in stencil {
                (0..3).for_each(|i| weights[cell][i] += c * w[i]);
            }
        }
        let node_nm = |i: usize| first_nm + spacing_nm * i as f64;
        let last_nm = node_nm(k - 1);
        let edge_nm = |i: usize| match i {
            0 => first_nm,
            i if i == k => last_nm,
            i => node_nm(i) - 0.5 * spacing_nm,
        };
        let nonzero = |w: &[f64; 3]| w.iter().any(|&c| c != 0.0);
        let start = weights.iter().position(nonzero).unwrap_or(k);
        let end = weights.iter().rposition(nonzero).map_or(start, |i| i + 1);
        let (line_nm, line_weights) = lines.into_iter().unzip();
        CellWeights {
            edges_nm: (start..=end.max(start)).map(edge_nm).collect(),
            centres_nm: (start..end).map(node_nm).collect(),
            weights: weights[start..end].to_vec(),
            line_nm,
            line_weights,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Whether there are no cells (a pure line spectrum).
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// The widest cell, nm (0 without cells).
    pub fn spacing_nm(&self) -> f64 {
        self.edges_nm
            .windows(2)
            .map(|e| e[1] - e[0])
            .fold(0.0, f64::max)
    }
}

/// The thickness (nm) from which cell means are used for the symmetric film
/// `n_outside | n_film | n_outside` seen at `cos_theta_outside`; `None` where they never
/// are. Thinner films are point-sampled.
///
/// Cells are used for `d >= threshold`, where the threshold is the larger of
/// * the thickness at which the s-polarised lines' half-width at the shortest cell
///   wavelength, `γ · λ² / (2 n cos θ_t d)` nm with `γ = −ln ρ_s² / 2π` periods, falls
///   below [`SHARPNESS_CELLS`] cell widths, and
/// * the thickness at which the thinnest cell spans [`MIN_CELL_PERIODS`] of phase.
///
/// `None` also at exactly grazing incidence (R ≡ 1), where the film and the outside are the
/// same, and near or beyond the film's critical angle.
pub fn cell_threshold_nm(
    cells: &CellWeights,
    n_outside: f64,
    n_film: &RefractiveIndex,
    cos_theta_outside: f64,
) -> Option<f64> {
    if cells.is_empty() || !(cos_theta_outside > 0.0 && cos_theta_outside <= 1.0) {
        return None;
    }
    let sin2 = 1.0 - cos_theta_outside * cos_theta_outside;
    let n_cos_t = |wavelength_nm: f64| {
        let n = n_film.n_at(wavelength_nm);
        let cos2_t = 1.0 - (n_outside / n).powi(2) * sin2;
        (cos2_t >= MIN_COS2_IN_FILM).then(|| n * cos2_t.sqrt())
    };
    let mut min_periods_per_nm = f64::INFINITY;
    for e in cells.edges_nm.windows(2) {
        let q_lo = 2.0 * n_cos_t(e[0])? / e[0];
        let q_hi = 2.0 * n_cos_t(e[1])? / e[1];
        min_periods_per_nm = min_periods_per_nm.min((q_lo - q_hi).abs());
    }
    let shortest_nm = cells.edges_nm[0];
    let inside = n_cos_t(shortest_nm)?;
    let outside = n_outside * cos_theta_outside;
    let rho = (outside - inside) / (outside + inside);
    if rho == 0.0 {
        return None;
    }
    let half_width_periods = -(rho * rho).ln() / std::f64::consts::TAU;
    let sharp_nm = half_width_periods * shortest_nm * shortest_nm
        / (2.0 * inside * SHARPNESS_CELLS * cells.spacing_nm());
    let resolved_nm = MIN_CELL_PERIODS / min_periods_per_nm;
    Some(sharp_nm.max(resolved_nm))
}

/// `(A, 1 − A)` for one interface of amplitude reflectance `ρ = (x − y)/(x + y)`:
/// `A = (1 − ρ²)/(1 + ρ²)`, from `1 − ρ² = 4xy/(x + y)²` so it keeps its precision near
/// total reflection.
pub fn line_area(x: f64, y: f64) -> (f64, f64) {
    let inv = 1.0 / (x + y);
    let t = 4.0 * x * y * inv * inv;
    let a = t / (2.0 - t);
    (a, 1.0 - a)
}

/// `θ(φ)` of the module doc for the phase `periods`, given `(A, 1 − A)`.
fn theta(periods: f64, (a, one_minus_a): (f64, f64)) -> f64 {
    let x = std::f64::consts::PI * (periods - periods.round());
    let (s, c) = x.sin_cos();
    (one_minus_a * s * c).atan2(a * c * c + s * s)
}

/// Mean unpolarised reflectance of `n_outside | n_film | n_outside`, `thickness_nm` thick,
/// over the cell `[lo_nm, hi_nm]` built around `centre_nm`, at `cos_theta_outside`.
/// Inputs as for [`cell_threshold_nm`] returning `Some(t)` with `thickness_nm >= t`.
pub fn cell_mean_reflectance(
    n_outside: f64,
    n_film: &RefractiveIndex,
    cos_theta_outside: f64,
    [lo_nm, centre_nm, hi_nm]: [f64; 3],
    thickness_nm: f64,
) -> f64 {
    let sin2 = 1.0 - cos_theta_outside * cos_theta_outside;
    let n_cos_t = |wavelength_nm: f64| {
        let n = n_film.n_at(wavelength_nm);
        (n, (n * n - n_outside * n_outside * sin2).max(0.0).sqrt())
    };
    let phase = |wavelength_nm: f64| 2.0 * n_cos_t(wavelength_nm).1 / wavelength_nm;
    let (q_lo, q_hi) = (phase(lo_nm), phase(hi_nm));
    let span = std::f64::consts::PI * (q_lo - q_hi) * thickness_nm;
    let (n, inside) = n_cos_t(centre_nm);
    let cos1 = inside / n;
    let outside_s = n_outside * cos_theta_outside;
    let polarisations = [
        line_area(outside_s, inside),
        line_area(n_outside * cos1, n * cos_theta_outside),
    ];
    let mean_r = |area: (f64, f64)| {
        let dtheta = theta(q_lo * thickness_nm, area) - theta(q_hi * thickness_nm, area);
        area.1 - area.0 * dtheta / span
    };
    0.5 * polarisations.iter().map(|&a| mean_r(a)).sum::<f64>()
}

impl SpectralIntegrator {
    /// XYZ of the light a film reflects at `cos_theta_outside`, exact at grazing incidence:
    /// for a symmetric lossless film thicker than [`cell_threshold_nm`] the reflectance is
    /// integrated over cells ([`crate::cells`]); otherwise (and for any other film) it is
    /// sampled at [`SpectralIntegrator::wavelengths_nm`] as [`SpectralIntegrator::xyz`] does.
    ///
    /// # Panics
    /// Where [`ThinFilm::response`] panics.
    pub fn film_xyz(&self, film: &ThinFilm, cos_theta_outside: f64) -> [f64; 3] {
        let incidence =
            Incidence::try_from_cos(cos_theta_outside).unwrap_or_else(|err| panic!("{err}"));
        self.film_xyz_at(film, incidence)
    }

    /// [`SpectralIntegrator::film_xyz`] in the direction `incidence` (given by its angle or
    /// sin θ, the point samples stay exact however near grazing).
    ///
    /// # Panics
    /// Where [`ThinFilm::try_response_at`] fails.
    pub fn film_xyz_at(&self, film: &ThinFilm, incidence: Incidence) -> [f64; 3] {
        match self.cell_use(film, incidence.cos()) {
            Some(cells) => cells_xyz(cells, film, incidence.cos()),
            None => self.xyz(|w| response_at(film, w, incidence).r()),
        }
    }

    /// XYZ of the light a film transmits, with the same method as
    /// [`SpectralIntegrator::film_xyz`] (for cells, the white minus the reflection: the
    /// film is lossless).
    ///
    /// # Panics
    /// Where [`ThinFilm::response`] panics.
    pub fn film_transmitted_xyz(&self, film: &ThinFilm, cos_theta_outside: f64) -> [f64; 3] {
        match self.cell_use(film, cos_theta_outside) {
            Some(cells) => {
                let r = cells_xyz(cells, film, cos_theta_outside);
                let white = self.white_xyz();
                std::array::from_fn(|c| white[c] - r[c])
            }
            None => self.xyz(|w| film.response(w, cos_theta_outside).t()),
        }
    }

    /// The cells, where `film` at `cos_theta_outside` is integrated over them.
    fn cell_use(&self, film: &ThinFilm, cos_theta_outside: f64) -> Option<&CellWeights> {
        let cells = self.cells()?;
        let symmetric = film.n_substrate == Complex64::new(film.n_outside, 0.0);
        let threshold = cell_threshold_nm(cells, film.n_outside, &film.n_film, cos_theta_outside);
        (symmetric && threshold.is_some_and(|t| film.thickness_nm >= t)).then_some(cells)
    }
}

fn response_at(film: &ThinFilm, wavelength_nm: f64, incidence: Incidence) -> Response {
    film.try_response_at(wavelength_nm, incidence)
        .unwrap_or_else(|err| panic!("{err}"))
}

fn cells_xyz(cells: &CellWeights, film: &ThinFilm, cos_theta_outside: f64) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    for (c, w) in cells.weights.iter().enumerate() {
        let cell = [
            cells.edges_nm[c],
            cells.centres_nm[c],
            cells.edges_nm[c + 1],
        ];
        let r = cell_mean_reflectance(
            film.n_outside,
            &film.n_film,
            cos_theta_outside,
            cell,
            film.thickness_nm,
        );
        (0..3).for_each(|i| xyz[i] += w[i] * r);
    }
    for (&line_nm, w) in cells.line_nm.iter().zip(&cells.line_weights) {
        let r = film.response(line_nm, cos_theta_outside).r();
        (0..3).for_each(|i| xyz[i] += w[i] * r);
    }
    xyz
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_far_narrower_than_a_fringe_means_the_point_value() {
        let film = ThinFilm::soap(500.0);
        for cos in [1.0, 0.5, 0.05] {
            let mean = cell_mean_reflectance(
                1.0,
                &RefractiveIndex::SOAP,
                cos,
                [549.99, 550.0, 550.01],
                500.0,
            );
            let point = film.response(550.0, cos).r();
            assert!((mean - point).abs() < 1e-7, "cos {cos}: {mean} vs {point}");
        }
    }

    #[test]
    fn a_cell_over_whole_fringes_means_the_fringe_average() {
        // Over exactly one period of φ the mean transmission is A, so mean R = 1 − A.
        let (n, cos, d) = (1.33f64, 0.02f64, 3000.0);
        let n_cos_t = (n * n - (1.0 - cos * cos)).sqrt();
        let lo = 500.0;
        let q_lo = 2.0 * n_cos_t / lo;
        let hi = 2.0 * n_cos_t * d / (q_lo * d - 1.0);
        let mean = cell_mean_reflectance(1.0, &RefractiveIndex::SOAP, cos, [lo, lo, hi], d);
        let (a_s, _) = line_area(cos, n_cos_t);
        let (a_p, _) = line_area(n_cos_t / n, n * cos);
        let want = 1.0 - 0.5 * (a_s + a_p);
        assert!((mean - want).abs() < 1e-9, "{mean} vs {want}");
    }
}

//! RGB → spectrum by Smits (1999), "An RGB-to-spectrum conversion for reflectances",
//! sampled on the reference's wavelength grid, with a linear correction that makes the
//! round trip back to linear RGB exact.
//!
//! Smits' seven basis spectra were fitted for an equal-energy white; here they multiply
//! the scene's reference illuminant, so the uplift of (1, 1, 1) is that illuminant's
//! white. The remaining round-trip error of the coloured bases (a few per cent) is removed
//! by adding `Σ_c δ_c B_c(λ)`, `δ = rgb − project(smits(rgb))`, with `B` the red, green
//! and blue bases mixed so that `project(B_c)` is the unit vector `e_c`. The RGB the scene
//! author wrote is then exactly the colour the reference sees where nothing intervenes.

use thinfilm::colorspace::invert;

/// Centres of Smits' ten bins over 380–720 nm.
const BIN_CENTRES_NM: [f64; 10] = [
    380.0,
    417.777_778,
    455.555_556,
    493.333_333,
    531.111_111,
    568.888_889,
    606.666_667,
    644.444_444,
    682.222_222,
    720.0,
];

/// Smits' Table 1: white, cyan, magenta, yellow, red, green, blue.
const BASES: [[f64; 10]; 7] = [
    [
        1.0000, 1.0000, 0.9999, 0.9993, 0.9992, 0.9998, 1.0000, 1.0000, 1.0000, 1.0000,
    ],
    [
        0.9710, 0.9426, 1.0007, 1.0007, 1.0007, 1.0007, 0.1564, 0.0000, 0.0000, 0.0000,
    ],
    [
        1.0000, 1.0000, 0.9685, 0.2229, 0.0000, 0.0458, 0.8369, 1.0000, 1.0000, 0.9959,
    ],
    [
        0.0001, 0.0000, 0.1088, 0.6651, 1.0000, 1.0000, 0.9996, 0.9586, 0.9685, 0.9840,
    ],
    [
        0.1012, 0.0515, 0.0000, 0.0000, 0.0000, 0.0000, 0.8325, 1.0149, 1.0149, 1.0149,
    ],
    [
        0.0000, 0.0000, 0.0273, 0.7937, 1.0000, 0.9418, 0.1719, 0.0000, 0.0000, 0.0025,
    ],
    [
        1.0000, 1.0000, 0.8916, 0.3323, 0.0000, 0.0000, 0.0003, 0.0369, 0.0483, 0.0496,
    ],
];

const WHITE: usize = 0;
const CYAN: usize = 1;
const MAGENTA: usize = 2;
const YELLOW: usize = 3;
const RED: usize = 4;
const GREEN: usize = 5;
const BLUE: usize = 6;

/// Smits' bases and the correction bases, sampled on one wavelength grid.
#[derive(Debug, Clone)]
pub(crate) struct Uplift {
    /// `bases[b][k]`: basis `b` at grid wavelength `k` (linear between bin centres, held
    /// constant beyond the ends).
    bases: [Vec<f64>; 7],
    /// `correction[c][k]`: the spectrum whose projection is the unit RGB vector `e_c`.
    correction: [Vec<f64>; 3],
    /// Linear RGB per wavelength of a unit spectral factor (the projection).
    project: Vec<[f64; 3]>,
}

impl Uplift {
    /// Samples the bases at `wavelength_nm`; `project[k]` is the linear RGB a unit factor
    /// at wavelength `k` adds.
    pub fn new(wavelength_nm: &[f64], project: &[[f64; 3]]) -> Uplift {
        let bases = std::array::from_fn(|b| {
            wavelength_nm
                .iter()
                .map(|&w| sample_bins(&BASES[b], w))
                .collect::<Vec<f64>>()
        });
        let mut uplift = Uplift {
            bases,
            correction: [vec![], vec![], vec![]],
            project: project.to_vec(),
        };
        // Columns: the projections of the red, green and blue bases.
        let prims = [RED, GREEN, BLUE].map(|b| uplift.rgb_of(&uplift.bases[b]));
        let p = [0, 1, 2].map(|row| [0, 1, 2].map(|col| prims[col][row]));
        let p_inv = invert(p);
        uplift.correction = std::array::from_fn(|c| {
            (0..wavelength_nm.len())
                .map(|k| (0..3).map(|j| uplift.bases[RED + j][k] * p_inv[j][c]).sum())
                .collect()
        });
        uplift
    }

    /// Linear RGB of spectral factor `s` (one value per grid wavelength).
    pub fn rgb_of(&self, s: &[f64]) -> [f64; 3] {
        let mut rgb = [0.0; 3];
        for (w, v) in self.project.iter().zip(s) {
            for c in 0..3 {
                rgb[c] += w[c] * v;
            }
        }
        rgb
    }

    /// Writes the spectral factor of linear RGB `rgb` (non-negative) into `out`.
    ///
    /// # Panics
    /// Panics if `out` is shorter than the grid.
    pub fn spectrum(&self, rgb: [f32; 3], out: &mut [f64]) {
        let [r, g, b] = rgb.map(f64::from);
        let out = &mut out[..self.project.len()];
        out.fill(0.0);
        let terms = smits_terms(r, g, b);
        for (basis, weight) in terms {
            if weight != 0.0 {
                for (o, v) in out.iter_mut().zip(&self.bases[basis]) {
                    *o += weight * v;
                }
            }
        }
        let got = self.rgb_of(out);
        for c in 0..3 {
            let delta = [r, g, b][c] - got[c];
            for (o, v) in out.iter_mut().zip(&self.correction[c]) {
                *o += delta * v;
            }
        }
    }
}

/// Smits' decomposition: white up to the smallest channel, then a secondary and a primary.
fn smits_terms(r: f64, g: f64, b: f64) -> [(usize, f64); 3] {
    if r <= g && r <= b {
        if g <= b {
            [(WHITE, r), (CYAN, g - r), (BLUE, b - g)]
        } else {
            [(WHITE, r), (CYAN, b - r), (GREEN, g - b)]
        }
    } else if g <= r && g <= b {
        if r <= b {
            [(WHITE, g), (MAGENTA, r - g), (BLUE, b - r)]
        } else {
            [(WHITE, g), (MAGENTA, b - g), (RED, r - b)]
        }
    } else if r <= g {
        [(WHITE, b), (YELLOW, r - b), (GREEN, g - r)]
    } else {
        [(WHITE, b), (YELLOW, g - b), (RED, r - g)]
    }
}

/// Linear interpolation between bin centres, constant beyond the ends.
fn sample_bins(bins: &[f64; 10], wavelength_nm: f64) -> f64 {
    if wavelength_nm <= BIN_CENTRES_NM[0] {
        return bins[0];
    }
    for i in 0..9 {
        let (a, b) = (BIN_CENTRES_NM[i], BIN_CENTRES_NM[i + 1]);
        if wavelength_nm <= b {
            let t = (wavelength_nm - a) / (b - a);
            return bins[i] * (1.0 - t) + bins[i + 1] * t;
        }
    }
    bins[9]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::Grid;
    use thinfilm::{Illuminant, Observer};

    fn d65_grid() -> Grid {
        Grid::try_new(Observer::Cie1931, &Illuminant::D65.spectrum(), 10.0).unwrap()
    }

    #[test]
    fn round_trip_is_exact_and_smits_alone_is_not() {
        let grid = d65_grid();
        let up = Uplift::new(&grid.wavelength_nm, &grid.reference_rgb);
        let mut s = vec![0.0; grid.len()];
        let mut worst_smits: f64 = 0.0;
        for rgb in [
            [1.0, 1.0, 1.0],
            [0.9, 0.1, 0.2],
            [0.05, 0.7, 0.3],
            [0.2, 0.3, 0.95],
            [3.0, 2.0, 0.5],
        ] {
            up.spectrum(rgb, &mut s);
            let back = up.rgb_of(&s);
            for c in 0..3 {
                let d = back[c] - f64::from(rgb[c]);
                assert!(d.abs() < 1e-9, "{rgb:?} channel {c} off by {d}");
            }
            // Without the correction Smits is off by up to a few per cent.
            let mut plain = vec![0.0; grid.len()];
            for (basis, w) in smits_terms(rgb[0].into(), rgb[1].into(), rgb[2].into()) {
                for (o, v) in plain.iter_mut().zip(&up.bases[basis]) {
                    *o += w * v;
                }
            }
            let back = up.rgb_of(&plain);
            for c in 0..3 {
                worst_smits = worst_smits.max((back[c] - f64::from(rgb[c])).abs());
            }
        }
        assert!(worst_smits > 1e-3, "plain Smits error {worst_smits}");
    }

    #[test]
    fn white_uplifts_to_a_flat_spectrum() {
        let grid = d65_grid();
        let up = Uplift::new(&grid.wavelength_nm, &grid.reference_rgb);
        let mut s = vec![0.0; grid.len()];
        up.spectrum([0.5; 3], &mut s);
        for (k, v) in s.iter().enumerate() {
            assert!((v - 0.5).abs() < 2e-3, "wavelength {k}: {v}");
        }
    }
}

//! Cell means: the f32 kernel against the f64 path of `SpectralIntegrator::film_xyz`, and
//! where each is used. Their accuracy against a fine integration of the spectrum is tested
//! in `crates/lut/tests/grazing_accuracy.rs`.

use proptest::prelude::*;
use thinfilm::airy::ThinFilm;
use thinfilm::batch::{CellSpectrum, try_weighted_cell_row};
use thinfilm::cells::{CellWeights, cell_threshold_nm};
use thinfilm::cmf::Observer;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::fresnel::OpticsError;
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::SpectralIntegrator;

fn d65(step_nm: f64) -> SpectralIntegrator {
    SpectralIntegrator::new(Observer::Cie1931, &Illuminant::D65.spectrum(), step_nm)
        .expect("valid integrator")
}

/// The kernel's inputs for `cells` under `index`, XYZ weights in f32.
struct KernelCells {
    n_edge: Vec<f64>,
    n_cell: Vec<f64>,
    weights: Vec<[f32; 3]>,
}

impl KernelCells {
    fn new(cells: &CellWeights, index: &RefractiveIndex) -> Self {
        KernelCells {
            n_edge: cells.edges_nm.iter().map(|&w| index.n_at(w)).collect(),
            n_cell: cells.centres_nm.iter().map(|&w| index.n_at(w)).collect(),
            weights: cells.weights.iter().map(|w| w.map(|c| c as f32)).collect(),
        }
    }

    fn spectrum<'a>(&'a self, cells: &'a CellWeights) -> CellSpectrum<'a> {
        CellSpectrum {
            edge_nm: &cells.edges_nm,
            n_film_edge: &self.n_edge,
            n_film_cell: &self.n_cell,
            weights: &self.weights,
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn f32_cell_kernel_matches_the_f64_cell_means(
        water in any::<bool>(),
        cos in prop_oneof![1e-4..0.02f64, 0.02..0.3f64],
        fractions in prop::collection::vec(0.0..1.0f64, 1..12),
    ) {
        let index = if water { RefractiveIndex::Water } else { RefractiveIndex::SOAP };
        let integrator = d65(5.0);
        let cells = integrator.cells().expect("an even grid");
        let cos = f64::from(cos as f32);
        let start = cell_threshold_nm(cells, 1.0, &index, cos).expect("cells at grazing");
        prop_assume!(start < 4000.0);
        let thickness: Vec<f32> = fractions
            .iter()
            .map(|f| (start + f * (4000.0 - start)) as f32)
            .map(|d| if f64::from(d) < start { f32::from_bits(d.to_bits() + 1) } else { d })
            .collect();
        let kernel = KernelCells::new(cells, &index);
        let mut out = vec![[0.0f32; 3]; thickness.len()];
        try_weighted_cell_row(1.0, cos as f32, &kernel.spectrum(cells), &thickness, &mut out)
            .expect("valid row");
        for (d, got) in thickness.iter().zip(&out) {
            let film = ThinFilm::symmetric(1.0, index, f64::from(*d));
            let want = integrator.film_xyz(&film, cos);
            for c in 0..3 {
                let diff = f64::from(got[c]) - want[c];
                prop_assert!(
                    diff.abs() < 3e-5,
                    "cos {cos} d {d} channel {c}: {} vs {}, off by {diff:e}", got[c], want[c]
                );
            }
        }
    }
}

#[test]
fn cells_start_only_where_the_lines_get_narrow() {
    let integrator = d65(5.0);
    let cells = integrator.cells().expect("an even grid");
    let threshold = |cos: f64| cell_threshold_nm(cells, 1.0, &RefractiveIndex::SOAP, cos);
    // Head-on the lines are as broad as the fringes: only films past 8 µm (whose fringes
    // are a few nm apart) need cells.
    assert!(
        threshold(1.0).is_some_and(|t| t > 8000.0),
        "{:?}",
        threshold(1.0)
    );
    // The threshold falls monotonically towards grazing.
    let t: Vec<f64> = [0.5, 0.2, 0.05, 0.01, 0.001]
        .iter()
        .map(|&c| threshold(c).expect("finite"))
        .collect();
    assert!(t.windows(2).all(|w| w[1] < w[0]), "{t:?}");
    assert!(t[3] < 1000.0, "{t:?}");
    // Exactly grazing, R ≡ 1: nothing to refine; nor for an index-matched film.
    assert_eq!(threshold(0.0), None);
    let matched = cell_threshold_nm(cells, 1.33, &RefractiveIndex::SOAP, 0.1);
    assert!(matched.is_none_or(|t| t > 1e5), "{matched:?}");
}

#[test]
fn film_xyz_is_xyz_where_cells_are_not_used() {
    let integrator = d65(5.0);
    for (d, cos) in [(300.0, 1.0), (1500.0, 0.6), (3000.0, 0.4)] {
        let film = ThinFilm::soap(d);
        let plain = integrator.xyz(|w| film.response(w, cos).r());
        assert_eq!(integrator.film_xyz(&film, cos), plain, "d {d} cos {cos}");
    }
}

#[test]
fn cell_row_rejects_bad_inputs_naming_them() {
    let integrator = d65(5.0);
    let cells = integrator.cells().expect("an even grid");
    let kernel = KernelCells::new(cells, &RefractiveIndex::SOAP);
    let spectrum = kernel.spectrum(cells);
    let mut out = [[7.0f32; 3]; 2];
    let run = |cos: f32, d: [f32; 2], out: &mut [[f32; 3]; 2]| {
        try_weighted_cell_row(1.0, cos, &spectrum, &d, out)
    };
    assert!(matches!(
        run(0.0, [1000.0, 2000.0], &mut out),
        Err(OpticsError::Cosine { value, .. }) if value == 0.0
    ));
    assert!(matches!(
        run(0.01, [1000.0, 0.0], &mut out),
        Err(OpticsError::Thickness { thickness_nm }) if thickness_nm == 0.0
    ));
    assert!(matches!(
        run(0.01, [f32::NAN, 1.0], &mut out),
        Err(OpticsError::Thickness { .. })
    ));
    assert_eq!(out, [[7.0; 3]; 2], "untouched on error");
    let short = CellSpectrum {
        n_film_cell: &kernel.n_cell[1..],
        ..spectrum
    };
    let err = try_weighted_cell_row(1.0, 0.01, &short, &[1000.0], &mut [[0.0; 3]]).unwrap_err();
    assert!(err.to_string().contains("n_film_cell"), "{err}");
    // A film thinner than the outside, beyond its critical angle.
    let n_low = vec![1.0; kernel.n_edge.len()];
    let thin = CellSpectrum {
        n_film_edge: &n_low,
        ..spectrum
    };
    let err = try_weighted_cell_row(1.2, 0.3, &thin, &[1000.0], &mut [[0.0; 3]]).unwrap_err();
    assert!(err.to_string().contains("critical angle"), "{err}");
}

#[test]
fn cell_weights_reproduce_the_node_quadrature_for_smooth_spectra() {
    // Broad fringes: the cell form and the node form of the same integrator agree to the
    // fourth order in the step (without the (−1, 26, −1)/24 rebuild of node values from
    // cell means they would differ by the box filter's (ωh)²/24: 6.5e-5 instead of 3.9e-6).
    let integrator = d65(5.0);
    let cells = integrator.cells().expect("an even grid");
    let mut worst = 0.0f64;
    for (d, cos) in [(150.0, 1.0), (400.0, 0.7), (800.0, 0.9), (1200.0, 1.0)] {
        let film = ThinFilm::soap(d);
        let nodes = integrator.xyz(|w| film.response(w, cos).r());
        let mut xyz = [0.0; 3];
        for (c, w) in cells.weights.iter().enumerate() {
            let cell = [
                cells.edges_nm[c],
                cells.centres_nm[c],
                cells.edges_nm[c + 1],
            ];
            let r =
                thinfilm::cells::cell_mean_reflectance(1.0, &RefractiveIndex::SOAP, cos, cell, d);
            (0..3).for_each(|k| xyz[k] += w[k] * r);
        }
        for k in 0..3 {
            worst = worst.max((xyz[k] - nodes[k]).abs());
        }
    }
    assert!(worst < 1.5e-5, "cell and node forms differ by {worst:e}");
}

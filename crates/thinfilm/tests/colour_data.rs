//! The embedded CIE tables against published facts about them.

use thinfilm::cmf::Observer;
use thinfilm::illuminant::{Illuminant, illuminant_a};
use thinfilm::integrate::SpectralIntegrator;
use thinfilm::spectrum::Spectrum;

/// Asserts |actual − expected| ≤ tol, printing the difference.
fn assert_close(actual: f64, expected: f64, tol: f64, what: &str) {
    let diff = (actual - expected).abs();
    assert!(
        diff <= tol,
        "{what}: got {actual}, expected {expected}, |diff| = {diff:e} > {tol:e}"
    );
}

/// Chromaticity xy of an illuminant by the CIE 1 nm summation.
fn chromaticity(observer: Observer, illuminant: &Spectrum) -> [f64; 2] {
    let xyz = SpectralIntegrator::new(observer, illuminant, 1.0)
        .unwrap()
        .white_xyz();
    let sum = xyz[0] + xyz[1] + xyz[2];
    [xyz[0] / sum, xyz[1] / sum]
}

#[test]
fn cie1931_y_bar_peaks_at_one_at_555_nm() {
    let table = Observer::Cie1931.table_1nm();
    let (peak_index, peak) = table
        .iter()
        .enumerate()
        .max_by(|a, b| a.1[1].total_cmp(&b.1[1]))
        .unwrap();
    assert_eq!(peak_index, 195, "ȳ peak is at 555 nm");
    assert_eq!(peak[1], 1.0);
    assert_eq!(Observer::Cie1931.cmf(555.0)[1], 1.0);
}

#[test]
fn cmf_integrals_are_equal_for_equal_energy_white() {
    // CIE 015: the CMFs are normalised so that equal-energy white has x = y = 1/3.
    // The normalisation was made on the original 5 nm, 380–780 nm table, where the
    // three sums agree to 1e-5; the extended 1 nm, 360–830 nm tables (interpolated
    // and extrapolated by the CIE) agree to 3.3e-4 (1931) and 1.1e-4 (1964). The
    // 1931 ȳ sum at 1 nm is 106.857 (pbrt's CIE_Y_integral).
    for (observer, y_sum, tol_1nm, tol_5nm) in [
        (Observer::Cie1931, 106.856_895, 4e-4, 2e-5),
        (Observer::Cie1964, 116.661_877, 1.5e-4, 1.5e-4),
    ] {
        let table = observer.table_1nm();
        let sum_1nm: Vec<f64> = (0..3).map(|c| table.iter().map(|r| r[c]).sum()).collect();
        let sum_5nm: Vec<f64> = (0..3)
            .map(|c| table[20..=420].iter().step_by(5).map(|r| 5.0 * r[c]).sum())
            .collect();
        assert_close(sum_1nm[1], y_sum, 1e-4, "Σȳ at 1 nm");
        for c in [0, 2] {
            assert_close(sum_1nm[c] / sum_1nm[1], 1.0, tol_1nm, "1 nm Σx̄/Σȳ or Σz̄/Σȳ");
            assert_close(sum_5nm[c] / sum_5nm[1], 1.0, tol_5nm, "5 nm Σx̄/Σȳ or Σz̄/Σȳ");
        }
    }
}

#[test]
fn cmfs_are_non_negative_and_span_360_to_830_nm() {
    for observer in Observer::ALL {
        let table = observer.table_1nm();
        assert_eq!(table.len(), 471);
        assert!(table.iter().flatten().all(|&v| v >= 0.0));
        assert!(observer.cmf(Observer::MIN_NM)[2] > 0.0);
    }
}

#[test]
fn cie1964_y_bar_peaks_at_one_near_557_nm() {
    let table = Observer::Cie1964.table_1nm();
    let peak = table.iter().map(|r| r[1]).fold(0.0, f64::max);
    let index = table.iter().position(|r| r[1] == peak).unwrap();
    assert_close(peak, 1.0, 1e-3, "ȳ₁₀ peak");
    assert!(
        (555..=558).contains(&(360 + index)),
        "ȳ₁₀ peak at {} nm",
        360 + index
    );
}

#[test]
fn illuminant_chromaticities_match_published_values_1931() {
    // CIE 015:2018 Table 9.1 / 10.3 (five-decimal values as computed by CIE from
    // the same tables; F-series from the 5 nm tables).
    let cases = [
        (Illuminant::D65, [0.31271, 0.32902]),
        (Illuminant::D50, [0.34567, 0.35850]),
        (Illuminant::A, [0.44757, 0.40745]),
        (Illuminant::E, [1.0 / 3.0, 1.0 / 3.0]),
        (Illuminant::F2, [0.37208, 0.37529]),
        (Illuminant::F11, [0.38052, 0.37713]),
    ];
    for (illuminant, expected) in cases {
        let xy = chromaticity(Observer::Cie1931, &illuminant.spectrum());
        for c in 0..2 {
            assert_close(xy[c], expected[c], 1e-4, illuminant.name());
        }
    }
}

#[test]
fn illuminant_chromaticities_match_published_values_1964() {
    // CIE 015:2018, 10° observer.
    let cases = [
        (Illuminant::D65, [0.31382, 0.33100]),
        (Illuminant::D50, [0.34773, 0.35952]),
        (Illuminant::A, [0.45117, 0.40594]),
        (Illuminant::E, [1.0 / 3.0, 1.0 / 3.0]),
        (Illuminant::F2, [0.37925, 0.36733]),
        (Illuminant::F11, [0.38541, 0.37123]),
    ];
    for (illuminant, expected) in cases {
        let xy = chromaticity(Observer::Cie1964, &illuminant.spectrum());
        for c in 0..2 {
            assert_close(xy[c], expected[c], 1e-4, illuminant.name());
        }
    }
}

#[test]
fn d65_white_matches_the_srgb_white_point() {
    let xy = chromaticity(Observer::Cie1931, &Illuminant::D65.spectrum());
    assert_close(xy[0], 0.3127, 1e-4, "D65 x");
    assert_close(xy[1], 0.3290, 1e-4, "D65 y");
}

#[test]
fn illuminant_a_closed_form_matches_the_cie_table() {
    let table = Spectrum::from_csv_str(include_str!("../data/illuminant_a.csv")).unwrap();
    assert_close(illuminant_a(560.0), 100.0, 1e-12, "A at 560 nm");
    for (&w, &v) in table.wavelengths_nm().iter().zip(table.values()) {
        // The CIE table is the formula rounded to six significant figures.
        assert_close(illuminant_a(w), v, 5e-6 * v, &format!("A at {w} nm"));
        assert_close(
            Illuminant::A.spectrum().value_at(w),
            v,
            5e-6 * v,
            "A spectrum",
        );
    }
}

#[test]
fn d_series_tables_are_normalised_to_100_at_560_nm() {
    for illuminant in [Illuminant::D65, Illuminant::D50] {
        assert_close(
            illuminant.spectrum().value_at(560.0),
            100.0,
            1e-9,
            illuminant.name(),
        );
    }
}

#[test]
fn sodium_lamp_is_the_two_d_lines_two_to_one() {
    let sodium = Illuminant::Sodium.spectrum();
    assert!(sodium.wavelengths_nm().is_empty());
    let lines = sodium.lines();
    assert_eq!(lines.len(), 2);
    assert_close(lines[0].0, 589.0, 0.01, "D2");
    assert_close(lines[1].0, 589.6, 0.01, "D1");
    assert_close(lines[0].1 / lines[1].1, 2.0, 1e-12, "D2:D1");
    // A line source's white is the CMF at the lines: nearly spectral yellow.
    let xy = chromaticity(Observer::Cie1931, &sodium);
    let cmf = Observer::Cie1931.cmf(589.2);
    let sum: f64 = cmf.iter().sum();
    assert_close(xy[0], cmf[0] / sum, 1e-3, "sodium x");
    assert_close(xy[1], cmf[1] / sum, 1e-3, "sodium y");
}

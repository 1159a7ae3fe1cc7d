//! Spectrum parsing and interpolation properties.

use proptest::prelude::*;
use thinfilm::spectrum::{Spectrum, SpectrumError};

proptest! {
    #[test]
    fn csv_parsing_never_panics(text in "\\PC{0,200}") {
        let _ = Spectrum::from_csv_str(&text);
    }

    #[test]
    fn csv_rows_with_junk_never_panic(rows in proptest::collection::vec("[0-9eE.+-]{0,6},[0-9a-z.+-]{0,6}", 0..8)) {
        let text = format!("wavelength_nm,value\n{}", rows.join("\n"));
        match Spectrum::from_csv_str(&text) {
            Ok(s) => prop_assert!(s.values().iter().all(|v| v.is_finite() && *v >= 0.0)),
            Err(SpectrumError::Csv { line, .. }) => prop_assert!(line >= 1 && line <= rows.len() + 1),
            Err(other) => prop_assert!(false, "unexpected error kind {other:?}"),
        }
    }

    #[test]
    fn value_at_stays_between_neighbouring_samples(
        values in proptest::collection::vec(0.0f64..100.0, 2..20),
        t in 0.0f64..1.0,
    ) {
        let wavelength_nm: Vec<f64> = (0..values.len()).map(|i| 400.0 + 7.0 * i as f64).collect();
        let s = Spectrum::try_from_samples(wavelength_nm.clone(), values.clone()).unwrap();
        let w = 400.0 + t * 7.0 * (values.len() - 1) as f64;
        let i = (((w - 400.0) / 7.0).floor() as usize).min(values.len() - 2);
        let (lo, hi) = (values[i].min(values[i + 1]), values[i].max(values[i + 1]));
        let v = s.value_at(w);
        prop_assert!(v >= lo - 1e-12 && v <= hi + 1e-12, "{v} not in [{lo}, {hi}]");
        for (&w, &v) in wavelength_nm.iter().zip(&values) {
            prop_assert_eq!(s.value_at(w), v);
        }
    }
}

#[test]
fn missing_file_error_names_the_path() {
    let path = std::path::Path::new("/definitely/not/here/spectrum.csv");
    let e = Spectrum::from_csv_path(path).unwrap_err();
    assert!(matches!(e, SpectrumError::Io { .. }));
    assert!(
        e.to_string().contains("/definitely/not/here/spectrum.csv"),
        "{e}"
    );
}

#[test]
fn csv_accepts_crlf_and_scientific_notation() {
    let s = Spectrum::from_csv_str("wavelength_nm,value\r\n4.0e2,1e-3\r\n410,2.5E1\r\n").unwrap();
    assert_eq!(s.wavelengths_nm(), &[400.0, 410.0]);
    assert_eq!(s.values(), &[1e-3, 25.0]);
}

#[test]
fn scaled_and_lined_spectra_keep_their_shape() {
    let s = Spectrum::try_from_samples(vec![400.0, 500.0], vec![1.0, 2.0]).unwrap();
    let scaled = s.clone().try_scaled(3.0).unwrap();
    assert_eq!(scaled.value_at(450.0), 4.5);
    assert!(s.clone().try_scaled(f64::NAN).is_err());
    let lined = s.try_with_lines(vec![(546.1, 5.0), (435.8, 2.0)]).unwrap();
    assert_eq!(lined.lines(), &[(435.8, 2.0), (546.1, 5.0)]);
    assert_eq!(lined.value_at(450.0), 1.5);
}

//! The colour table (f32 batch kernel, 2 nm spectral spacing, bilinear) against the exact
//! path (complex Airy amplitudes, cell-mean integration), and the camera's encoding.

use film_inverse::{Camera, ColourTable, FilmModel};
use thinfilm::{Illuminant, Observer, RefractiveIndex};

#[test]
fn the_table_matches_the_exact_airy_colours_to_1e_4() {
    let model = FilmModel::soap(&Illuminant::F11.spectrum());
    let table = ColourTable::build(&model, 0.3, 1.0, 64);
    let mut worst = 0.0f64;
    for h in (0..1500).step_by(7) {
        for cos in [0.3, 0.55, 0.8, 1.0] {
            let row = table.row_of(cos);
            if (row - row.round()).abs() > 1e-9 {
                continue;
            }
            let a = table.sample(f64::from(h), row);
            let b = model.rgb_exact(f64::from(h), cos);
            worst = worst.max((0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max));
        }
    }
    assert!(worst < 1e-4, "worst channel difference {worst:e}");
}

#[test]
fn a_perfect_mirror_is_white_and_black_film_is_dark() {
    let model = FilmModel::soap(&Illuminant::A.spectrum());
    let zero = model.rgb_exact(0.0, 1.0);
    assert!(zero.iter().all(|v| v.abs() < 1e-12), "{zero:?}");
    // A quarter-wave film reflects about 4ρ/(1+ρ)² ≈ 0.078 of every colour near 550 nm.
    let quarter = model.rgb_exact(550.0 / (4.0 * 1.33), 1.0);
    assert!((quarter[1] - 0.078).abs() < 0.01, "{quarter:?}");
    let white = Camera::balanced(1.0).encode([1.0; 3]);
    assert!(white.iter().all(|v| (v - 1.0).abs() < 1e-12), "{white:?}");
}

#[test]
fn models_out_of_range_are_refused_by_name() {
    let d65 = Illuminant::D65.spectrum();
    let soap = RefractiveIndex::SOAP;
    let err = FilmModel::try_new(1.0, soap, &d65, Observer::Cie1931, 1e308).unwrap_err();
    assert!(err.to_string().contains("thickness_max_nm 1e308"), "{err}");
    let err = FilmModel::try_new(1e-300, soap, &d65, Observer::Cie1931, 1500.0).unwrap_err();
    assert!(err.to_string().contains("n_outside 1e-300"), "{err}");
    let low = RefractiveIndex::constant(1.2).unwrap();
    let err = FilmModel::try_new(1.33, low, &d65, Observer::Cie1931, 1500.0).unwrap_err();
    assert!(
        err.to_string().contains("must lie above n_outside"),
        "{err}"
    );
}

//! Helpers shared by the optics test files.
#![allow(dead_code)]

use num_complex::Complex64;
use thinfilm::airy::ThinFilm;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::tmm::{Layer, Stack};

/// Asserts `|actual − expected| ≤ tol`, printing both values and the difference.
#[track_caller]
pub fn assert_close(label: &str, actual: f64, expected: f64, tol: f64) {
    let diff = (actual - expected).abs();
    assert!(
        diff <= tol,
        "{label}: actual {actual} vs expected {expected}, |diff| = {diff:e} > tol {tol:e}"
    );
}

/// Asserts two complex numbers agree to `tol` in modulus of the difference.
#[track_caller]
pub fn assert_close_c(label: &str, actual: Complex64, expected: Complex64, tol: f64) {
    let diff = (actual - expected).norm();
    assert!(
        diff <= tol,
        "{label}: actual {actual} vs expected {expected}, |diff| = {diff:e} > tol {tol:e}"
    );
}

/// A film with constant real indices.
pub fn film(n_outside: f64, n_film: f64, n_substrate: Complex64, thickness_nm: f64) -> ThinFilm {
    ThinFilm {
        n_outside,
        n_film: RefractiveIndex::Constant(n_film),
        n_substrate,
        thickness_nm,
    }
}

/// The same film as a one-layer transfer-matrix stack.
pub fn as_stack(film: &ThinFilm, wavelength_nm: f64) -> Stack {
    Stack {
        n_incident: film.n_outside,
        layers: vec![Layer::lossless(
            film.n_film.n_at(wavelength_nm),
            film.thickness_nm,
        )],
        n_substrate: film.n_substrate.into(),
    }
}

/// Real complex number.
pub fn re(x: f64) -> Complex64 {
    Complex64::new(x, 0.0)
}

/// SplitMix64: a small seeded generator, so the trials are the same on every run.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

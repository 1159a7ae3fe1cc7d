//! Exact spectral thin-film optics and CIE colour.
//!
//! `thinfilm` knows nothing of meshes or rendering: it turns a film description
//! (indices, thickness, angle, wavelength) into reflectance and transmittance, and
//! spectra into colour.
//!
//! It depends on nothing but `num-complex`, so it can be added alone:
//!
//! ```
//! use thinfilm::{Illuminant, Observer, SpectralIntegrator, ThinFilm, DEFAULT_STEP_NM};
//! use thinfilm::colorspace::{SRGB_FROM_XYZ, apply, hex, srgb8_from_linear};
//!
//! let film = ThinFilm::soap(300.0); // air | 1.33 | air, 300 nm thick
//! let d65 = SpectralIntegrator::new(Observer::Cie1931, &Illuminant::D65.spectrum(), DEFAULT_STEP_NM).unwrap();
//! let xyz = d65.xyz(|wavelength_nm| film.response(wavelength_nm, 1.0).r()); // head-on
//! let rgb = apply(&SRGB_FROM_XYZ, xyz);
//! println!("reflected colour {}", hex(srgb8_from_linear(rgb)));
//! assert!(xyz[1] > 0.0 && xyz[1] < 0.2);
//! ```
//!
//! Optics: [`fresnel`], [`airy`] (exact single film), [`tmm`] (N-layer stacks, exact for
//! any thickness), [`dispersion`] (real models, each with its wavelength range), [`index`]
//! (complex and tabulated n,k models), [`incidence`] (angle or sin θ, exact at grazing),
//! the exact film grid [`grid`] and the f32 fast path [`batch`]. Colour, split pbrt-style:
//! [`spectrum`], [`cmf`], [`illuminant`], [`integrate`] (with [`cells`], exact at grazing
//! incidence), [`colorspace`], [`lab`].

pub mod airy;
pub mod batch;
pub mod dispersion;
pub mod fit;
pub mod fresnel;
pub mod graded;
pub mod grid;
pub mod incidence;
pub mod index;
pub mod stack_grid;
pub mod tmm;

pub mod cells;
pub mod cmf;
pub mod colorspace;
pub mod illuminant;
pub mod integrate;
pub mod lab;
pub mod spectrum;

pub use airy::{Response, ThinFilm};
pub use dispersion::RefractiveIndex;
pub use fresnel::{Interface, OpticsError};
pub use incidence::Incidence;
pub use index::{IndexModel, NkTable};
pub use num_complex::Complex64;
pub use tmm::{Layer, Stack};

pub use cmf::Observer;
pub use illuminant::{Illuminant, UnknownIlluminant};
pub use integrate::{DEFAULT_STEP_NM, IntegrateError, Quadrature, SpectralIntegrator};
pub use lab::{Lab, ciede2000, lab_from_xyz};
pub use spectrum::{Spectrum, SpectrumError};

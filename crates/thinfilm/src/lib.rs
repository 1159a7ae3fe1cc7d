//! Exact spectral thin-film optics and CIE colour.
//!
//! `thinfilm` knows nothing of meshes or rendering: it turns a film description
//! (indices, thickness, angle, wavelength) into reflectance and transmittance, and
//! spectra into colour.

pub mod airy;
pub mod batch;
pub mod dispersion;
pub mod fresnel;
pub mod tmm;

pub mod cmf;
pub mod colorspace;
pub mod illuminant;
pub mod integrate;
pub mod lab;
pub mod spectrum;

pub use airy::{Response, ThinFilm};
pub use dispersion::RefractiveIndex;
pub use fresnel::OpticsError;

pub use cmf::Observer;
pub use illuminant::{Illuminant, UnknownIlluminant};
pub use integrate::{DEFAULT_STEP_NM, IntegrateError, Quadrature, SpectralIntegrator};
pub use lab::{Lab, ciede2000, lab_from_xyz};
pub use spectrum::{Spectrum, SpectrumError};

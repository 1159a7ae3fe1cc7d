//! [`Material`]: an opaque surface's albedo [`Pattern`] and specular lobe.

use crate::environment::check_rgb;
use crate::{RenderError, Texture};

/// How a surface's albedo varies over it.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    /// One albedo everywhere.
    Solid([f32; 3]),
    /// A checkerboard of cubes `scale_m` wide (squares on the ground, box-filtered there).
    Checker {
        /// Albedo of the cell holding the origin.
        a: [f32; 3],
        /// Albedo of its neighbours.
        b: [f32; 3],
        /// Edge length of one cell in metres.
        scale_m: f32,
    },
    /// An image: on the ground one repeat spans `scale_m` metres along X and Z; objects use
    /// their mesh UVs and ignore `scale_m`.
    Textured {
        /// The albedo image (linear).
        texture: Texture,
        /// Size of one repeat on the ground, in metres.
        scale_m: f32,
    },
}

/// An opaque surface: Lambert diffuse plus normalised Blinn-Phong specular.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Diffuse albedo.
    pub pattern: Pattern,
    /// Specular reflectance per channel (0 for a matte surface).
    pub specular: [f32; 3],
    /// Blinn-Phong exponent.
    pub shininess: f32,
}

impl Material {
    /// A matte surface of one albedo.
    pub fn matte(albedo: [f32; 3]) -> Material {
        Material {
            pattern: Pattern::Solid(albedo),
            specular: [0.0; 3],
            shininess: 1.0,
        }
    }

    /// A matte checkerboard.
    pub fn checker(a: [f32; 3], b: [f32; 3], scale_m: f32) -> Material {
        Material {
            pattern: Pattern::Checker { a, b, scale_m },
            specular: [0.0; 3],
            shininess: 1.0,
        }
    }

    /// Checks the material's numbers, naming it `what` in the error.
    pub fn validate(&self, what: &str) -> Result<(), RenderError> {
        check_rgb(&format!("{what} specular"), self.specular)?;
        if !(self.shininess.is_finite() && self.shininess >= 0.0) {
            return Err(RenderError::scene(
                what,
                format!("shininess {} must be finite and >= 0", self.shininess),
            ));
        }
        match &self.pattern {
            Pattern::Solid(c) => check_rgb(&format!("{what} albedo"), *c),
            Pattern::Checker { a, b, scale_m } => {
                check_rgb(&format!("{what} checker a"), *a)?;
                check_rgb(&format!("{what} checker b"), *b)?;
                check_scale(what, *scale_m)
            }
            Pattern::Textured { scale_m, .. } => check_scale(what, *scale_m),
        }
    }
}

fn check_scale(what: &str, scale_m: f32) -> Result<(), RenderError> {
    if scale_m.is_finite() && scale_m > 0.0 {
        Ok(())
    } else {
        Err(RenderError::scene(
            what,
            format!("pattern scale {scale_m} m must be finite and > 0"),
        ))
    }
}

//! [`LutMeta`] and the `lut.json` document that describes a saved set.

use serde::{Deserialize, Serialize};

/// Version of the `lut.json` layout; [`crate::LutSet::load`] refuses any other.
pub const FORMAT_VERSION: u32 = 1;

/// Value of the `format` field of every `lut.json`.
pub const FORMAT_NAME: &str = "bubbles-lut";

/// Colour space of every texture.
pub const COLOR_SPACE: &str =
    "linear sRGB (ITU-R BT.709 primaries, D65 white), no transfer function";

/// What a baked set was made from: enough to reproduce it and to interpret its texels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LutMeta {
    /// Thickness held by the last column, in nm (the first holds 0).
    pub thickness_max_nm: f32,
    /// Refractive index of the medium on both sides of the film (air: 1).
    pub n_outside: f64,
    /// The film's refractive-index model, as configured.
    pub film_index: String,
    /// The film index at every integration wavelength, as `[wavelength_nm, n]`.
    pub film_index_samples: Vec<[f64; 2]>,
    /// CIE standard observer of the colour matching functions.
    pub observer: String,
    /// Spacing of the integration wavelengths, in nm.
    pub step_nm: f64,
    /// The white light that the reflectivity and transmittance tables are normalised to.
    pub reference_illuminant: String,
    /// Colour space of the texels.
    pub color_space: String,
}

/// The whole `lut.json` file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LutDocument {
    pub format: String,
    pub format_version: u32,
    pub width: usize,
    pub height: usize,
    pub axes: Axes,
    pub meta: LutMeta,
    pub textures: Vec<TextureEntry>,
}

/// Both texture axes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Axes {
    pub u: Axis,
    pub v: Axis,
}

/// One axis: what it holds and the exact texel ↔ value ↔ texture-coordinate mapping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Axis {
    pub quantity: String,
    pub min: f64,
    pub max: f64,
    pub samples: usize,
    pub texel: String,
    pub texture_coordinate: String,
}

/// One texture and its files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TextureEntry {
    /// File stem: `reflectivity`, `transmittance` or `light_<name>`.
    pub name: String,
    /// What the texels mean.
    pub quantity: String,
    /// The light's name, for light-source textures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light: Option<String>,
    /// FNV-1a 64 of the f32 texels (little-endian bits, row-major, RGB), 16 hex digits.
    pub texels_fnv1a64: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exr: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub png16: Option<Png16Entry>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub png8_preview: Option<String>,
}

/// A 16-bit PNG twin and how to decode its codes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Png16Entry {
    pub file: String,
    /// `value = offset + scale · code / 65535`.
    pub offset: f32,
    /// See `offset`.
    pub scale: f32,
    /// FNV-1a 64 of the 16-bit codes (little-endian, row-major, RGB).
    pub codes_fnv1a64: String,
}

impl Axes {
    /// The axes of a `width × height` table reaching `thickness_max_nm`.
    pub fn new(width: usize, height: usize, thickness_max_nm: f32) -> Self {
        Self {
            u: Axis {
                quantity: "film thickness d, nm".into(),
                min: 0.0,
                max: f64::from(thickness_max_nm),
                samples: width,
                texel: "column i (0 = left) holds d_i = max * i / (samples - 1)".into(),
                texture_coordinate: "u = (d / max * (samples - 1) + 0.5) / samples".into(),
            },
            v: Axis {
                quantity: "cosine of the incident angle in the outside medium, cos theta".into(),
                min: 0.0,
                max: 1.0,
                samples: height,
                texel: "row j (0 = top of the image) holds cos_theta_j = j / (samples - 1)".into(),
                texture_coordinate:
                    "v = (cos_theta * (samples - 1) + 0.5) / samples, v = 0 at the top row".into(),
            },
        }
    }
}

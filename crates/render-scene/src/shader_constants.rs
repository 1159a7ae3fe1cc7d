//! Every CPU-defined constant a shader sees, listed once under the name the WGSL declares
//! it with. The GPU backend injects these lists into its shaders instead of retyping a
//! number, so a change here reaches both backends in the same build.

use crate::frame::{
    ACES_FROM_SRGB, ACES_INPUT_MAX, SRGB_FROM_ACES, SRGB_GAMMA, SRGB_LINEAR_MAX, SRGB_LINEAR_SLOPE,
    SRGB_OFFSET, SRGB_SCALE,
};
use crate::highlight::HIGHLIGHT_SIGMA_PX;
use crate::lod::{LOD_BIAS, MAX_ANISOTROPY, MIN_FOOTPRINT_TEXELS};
use crate::shading::{FLAT_FOOTPRINT_CELLS, GROUND_HALF_OFFSET_PX};
use crate::water::FRESNEL_STEPS;

pub use crate::cubemap::FACE_BASES;
pub use crate::frame::{ACES_DENOMINATOR, ACES_NUMERATOR};

/// Tag bit marking an emissive light-sphere triangle (low bits: the light's index).
pub const EMISSIVE: u32 = 1 << 31;

/// Tag bit marking a water triangle in the opaque pass.
pub const WATER: u32 = 1 << 30;

/// The 4-sample pattern (D3D's and Vulkan's standard one): each sample's offset from the
/// pixel centre in 1/16 pixel, y down, in sample order. The CPU rasteriser samples there,
/// and the GPU's water shades a partly covered pixel at its first covered one as the CPU
/// does.
pub const SAMPLE_OFFSETS_4_SIXTEENTHS: [(i64, i64); 4] = [(-2, -6), (6, -2), (-6, 2), (2, 6)];

/// The tone curve's 3×3 matrices (rows), by WGSL name.
pub const TONE_MATRICES: [(&str, [[f32; 3]; 3]); 2] = [
    ("ACES_FROM_SRGB", ACES_FROM_SRGB),
    ("SRGB_FROM_ACES", SRGB_FROM_ACES),
];

/// The tone curve's and the sRGB encoding's scalars, by WGSL name.
pub const TONE_SCALARS: [(&str, f32); 6] = [
    ("ACES_INPUT_MAX", ACES_INPUT_MAX),
    ("SRGB_LINEAR_MAX", SRGB_LINEAR_MAX),
    ("SRGB_LINEAR_SLOPE", SRGB_LINEAR_SLOPE),
    ("SRGB_SCALE", SRGB_SCALE),
    ("SRGB_OFFSET", SRGB_OFFSET),
    ("SRGB_GAMMA", SRGB_GAMMA),
];

/// The scene shading's f32 constants (highlight filter, checker filter, cube-map LOD), by
/// WGSL name.
pub const SCENE_SCALARS: [(&str, f32); 5] = [
    ("HIGHLIGHT_SIGMA_PX", HIGHLIGHT_SIGMA_PX),
    ("FLAT_FOOTPRINT_CELLS", FLAT_FOOTPRINT_CELLS),
    ("GROUND_HALF_OFFSET_PX", GROUND_HALF_OFFSET_PX),
    ("LOD_BIAS", LOD_BIAS),
    ("MIN_FOOTPRINT_TEXELS", MIN_FOOTPRINT_TEXELS),
];

/// The scene shading's integer constants (tag bits, anisotropic tap limit, the water's
/// Fresnel table intervals), by WGSL name.
pub const SCENE_WORDS: [(&str, u32); 4] = [
    ("EMISSIVE", EMISSIVE),
    ("WATER", WATER),
    ("MAX_ANISOTROPY", MAX_ANISOTROPY as u32),
    ("FRESNEL_STEPS", FRESNEL_STEPS as u32),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tag_bits_are_distinct_single_bits() {
        assert_eq!(EMISSIVE.count_ones(), 1);
        assert_eq!(WATER.count_ones(), 1);
        assert_eq!(EMISSIVE & WATER, 0);
    }

    #[test]
    fn every_name_is_listed_once() {
        let mut names: Vec<&str> = TONE_MATRICES.iter().map(|(n, _)| *n).collect();
        names.extend(TONE_SCALARS.iter().map(|(n, _)| *n));
        names.extend(SCENE_SCALARS.iter().map(|(n, _)| *n));
        names.extend(SCENE_WORDS.iter().map(|(n, _)| *n));
        let count = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), count, "a constant is listed twice");
    }
}

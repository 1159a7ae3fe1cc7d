//! WGSL sources with the constants the CPU backend defines injected, so that the two
//! backends share one source of truth: a shader names `{{SHARED_CONSTANTS}}` where the
//! generated block goes.

use super::scene_data::{
    ENV_SKY, ENV_UNIFORM, NO_TABLE, PATTERN_CHECKER, PATTERN_SOLID, REFLECTION_CUBE,
    REFLECTION_CUBE_BILINEAR, REFLECTION_ENVIRONMENT,
};
use crate::cubemap::FACE_BASES;
use crate::frame::{
    ACES_DENOMINATOR, ACES_FROM_SRGB, ACES_INPUT_MAX, ACES_NUMERATOR, SRGB_FROM_ACES, SRGB_GAMMA,
    SRGB_LINEAR_MAX, SRGB_LINEAR_SLOPE, SRGB_OFFSET, SRGB_SCALE,
};
use crate::lod::{LOD_BIAS, MAX_ANISOTROPY, MIN_FOOTPRINT_TEXELS};

/// The marker a WGSL source puts where the shared constants go.
const MARKER: &str = "{{SHARED_CONSTANTS}}";

/// `source` with the shared constants block in place of its marker.
///
/// # Panics
/// Panics if `source` lacks the marker (a programming error in a shader of this crate).
pub(super) fn with_shared_constants(source: &str) -> String {
    assert!(source.contains(MARKER), "shader has no {MARKER} marker");
    source.replace(MARKER, &shared_constants())
}

/// The WGSL declarations of every constant the CPU backend shares with the shaders.
pub(super) fn shared_constants() -> String {
    let mut out = String::from("// Generated from raster's Rust constants: do not edit.\n");
    for (name, rows) in [
        ("ACES_FROM_SRGB", ACES_FROM_SRGB),
        ("SRGB_FROM_ACES", SRGB_FROM_ACES),
    ] {
        for (k, row) in rows.iter().enumerate() {
            out += &format!("const {name}_ROW{k} = {};\n", vec3(row));
        }
    }
    out += &format!(
        "const ACES_NUMERATOR = vec2<f32>({}, {});\n",
        float(ACES_NUMERATOR[0]),
        float(ACES_NUMERATOR[1])
    );
    out += &format!("const ACES_DENOMINATOR = {};\n", vec3(&ACES_DENOMINATOR));
    for (name, value) in [
        ("ACES_INPUT_MAX", ACES_INPUT_MAX),
        ("SRGB_LINEAR_MAX", SRGB_LINEAR_MAX),
        ("SRGB_LINEAR_SLOPE", SRGB_LINEAR_SLOPE),
        ("SRGB_SCALE", SRGB_SCALE),
        ("SRGB_OFFSET", SRGB_OFFSET),
        ("SRGB_GAMMA", SRGB_GAMMA),
    ] {
        out += &format!("const {name}: f32 = {};\n", float(value));
    }
    out + &scene_constants()
}

/// The scene passes' constants: the CPU's highlight filter width and emissive tag bit, and
/// the encodings `scene_data` packs the uniforms with.
fn scene_constants() -> String {
    let mut out = String::new();
    for (name, value) in [
        ("HIGHLIGHT_SIGMA_PX", crate::passes::HIGHLIGHT_SIGMA_PX),
        ("PI", std::f32::consts::PI),
        ("PATTERN_SOLID", PATTERN_SOLID),
        ("PATTERN_CHECKER", PATTERN_CHECKER),
        ("FLAT_FOOTPRINT_CELLS", crate::shading::FLAT_FOOTPRINT_CELLS),
        ("LOD_BIAS", LOD_BIAS),
        ("MIN_FOOTPRINT_TEXELS", MIN_FOOTPRINT_TEXELS),
    ] {
        out += &format!("const {name}: f32 = {};\n", float(value));
    }
    for (name, value) in [
        ("EMISSIVE", crate::passes::EMISSIVE),
        ("ENV_SKY", ENV_SKY),
        ("ENV_UNIFORM", ENV_UNIFORM),
        ("REFLECTION_CUBE", REFLECTION_CUBE),
        ("REFLECTION_ENVIRONMENT", REFLECTION_ENVIRONMENT),
        ("REFLECTION_CUBE_BILINEAR", REFLECTION_CUBE_BILINEAR),
        ("NO_TABLE", NO_TABLE),
        ("MAX_ANISOTROPY", MAX_ANISOTROPY as u32),
    ] {
        out += &format!("const {name}: u32 = {value}u;\n");
    }
    // cubemap.rs `FACE_BASES`: major, s and t axes of each face.
    for (name, pick) in [("FACE_MAJOR", 0usize), ("FACE_S", 1), ("FACE_T", 2)] {
        let axes: Vec<String> = FACE_BASES
            .iter()
            .map(|b| vec3(&[b.0, b.1, b.2][pick].to_array()))
            .collect();
        out += &format!("const {name} = array<vec3<f32>, 6>({});\n", axes.join(", "));
    }
    out
}

fn vec3(v: &[f32; 3]) -> String {
    format!(
        "vec3<f32>({}, {}, {})",
        float(v[0]),
        float(v[1]),
        float(v[2])
    )
}

/// An f32 as a WGSL literal that parses back to the same value (Rust's shortest round trip).
fn float(x: f32) -> String {
    let text = format!("{x:?}");
    if text.contains(['.', 'e']) {
        text
    } else {
        format!("{text}.0")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_literals_round_trip() {
        for x in [ACES_NUMERATOR[1], 1e6, 12.92, -0.53108, 0.0] {
            let text = float(x);
            assert_eq!(text.parse::<f32>().unwrap(), x, "{text}");
            assert!(text.contains(['.', 'e']), "{text} is not a float literal");
        }
    }
}

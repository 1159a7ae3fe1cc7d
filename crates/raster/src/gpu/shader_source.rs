//! WGSL sources with the constants the CPU backend defines injected, so that the two
//! backends share one source of truth: a shader names `{{SHARED_CONSTANTS}}` where the
//! generated block goes.

// Without the `wgpu` feature only the naga layout test uses this module.
#![cfg_attr(not(feature = "wgpu"), allow(dead_code))]

use super::scene_data::{
    ENV_CUBE, ENV_EQUIRECT, ENV_SKY, ENV_UNIFORM, NO_TABLE, PATTERN_CHECKER, PATTERN_SOLID,
    PATTERN_TEXTURED, REFLECTION_CUBE, REFLECTION_CUBE_BILINEAR, REFLECTION_ENV_CUBE,
    REFLECTION_ENV_CUBE_BILINEAR, REFLECTION_ENVIRONMENT, REFLECTION_SPHERE_MAP,
};
use super::water_data::{
    WATER_REFLECTION_CUBE, WATER_REFLECTION_ENVIRONMENT, WATER_REFLECTION_SPHERE_MAP,
};
use render_scene::shader_constants::{
    ACES_DENOMINATOR, ACES_NUMERATOR, FACE_BASES, SAMPLE_OFFSETS_4_SIXTEENTHS, SCENE_SCALARS,
    SCENE_WORDS, TONE_MATRICES, TONE_SCALARS,
};

/// The scene shader (`scene.wgsl`) with the shared constants in place.
pub(super) fn scene_wgsl() -> String {
    with_shared_constants(include_str!("scene.wgsl"))
}

/// The tone-map shader: the tone curves (`tone_curve.wgsl`) with the shared constants in
/// place, then the read-back pass (`tonemap.wgsl`).
pub(super) fn tonemap_wgsl() -> String {
    with_tone_curve(include_str!("tonemap.wgsl"))
}

/// The window's present shader: the tone curves, then `present.wgsl`.
pub(super) fn present_wgsl() -> String {
    with_tone_curve(include_str!("present.wgsl"))
}

/// `pass` after the tone curves, so two passes share one port of `Frame::to_srgb8`.
fn with_tone_curve(pass: &str) -> String {
    with_shared_constants(include_str!("tone_curve.wgsl")) + pass
}

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
    let mut out = String::from(
        "// Generated from render_scene::shader_constants and scene_data: do not edit.\n",
    );
    for (name, rows) in TONE_MATRICES {
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
    for (name, value) in TONE_SCALARS {
        out += &format!("const {name}: f32 = {};\n", float(value));
    }
    out + &scene_constants()
}

/// The scene passes' constants: the CPU's (`render_scene::shader_constants`) and the
/// encodings `scene_data` packs the uniforms with.
fn scene_constants() -> String {
    let mut out = String::new();
    let packing_scalars = [
        ("PI", std::f32::consts::PI),
        ("PATTERN_SOLID", PATTERN_SOLID),
        ("PATTERN_CHECKER", PATTERN_CHECKER),
        ("PATTERN_TEXTURED", PATTERN_TEXTURED),
    ];
    for (name, value) in SCENE_SCALARS.into_iter().chain(packing_scalars) {
        out += &format!("const {name}: f32 = {};\n", float(value));
    }
    let packing_words = [
        ("ENV_SKY", ENV_SKY),
        ("ENV_UNIFORM", ENV_UNIFORM),
        ("ENV_EQUIRECT", ENV_EQUIRECT),
        ("ENV_CUBE", ENV_CUBE),
        ("REFLECTION_CUBE", REFLECTION_CUBE),
        ("REFLECTION_ENVIRONMENT", REFLECTION_ENVIRONMENT),
        ("REFLECTION_CUBE_BILINEAR", REFLECTION_CUBE_BILINEAR),
        ("REFLECTION_ENV_CUBE", REFLECTION_ENV_CUBE),
        ("REFLECTION_ENV_CUBE_BILINEAR", REFLECTION_ENV_CUBE_BILINEAR),
        ("REFLECTION_SPHERE_MAP", REFLECTION_SPHERE_MAP),
        ("NO_TABLE", NO_TABLE),
        ("WATER_REFLECTION_CUBE", WATER_REFLECTION_CUBE),
        ("WATER_REFLECTION_ENVIRONMENT", WATER_REFLECTION_ENVIRONMENT),
        ("WATER_REFLECTION_SPHERE_MAP", WATER_REFLECTION_SPHERE_MAP),
    ];
    for (name, value) in SCENE_WORDS.into_iter().chain(packing_words) {
        out += &format!("const {name}: u32 = {value}u;\n");
    }
    // The 4-sample pattern's offsets from the pixel centre, in pixels.
    let offsets: Vec<String> = SAMPLE_OFFSETS_4_SIXTEENTHS
        .iter()
        .map(|&(x, y)| {
            let px = |s: i64| float(s as f32 / 16.0);
            format!("vec2<f32>({}, {})", px(x), px(y))
        })
        .collect();
    out += &format!(
        "const SAMPLE_OFFSETS_4 = array<vec2<f32>, 4>({});\n",
        offsets.join(", ")
    );
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

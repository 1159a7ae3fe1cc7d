// The tone curves and sRGB encoding, exactly as raster's `Frame::to_srgb8`: exposure is
// applied by the caller, then the curve, then the sRGB curve. Shared by the read-back
// pass (`tonemap.wgsl`) and the window's present pass (`present.wgsl`), which are
// generated with this text in front of them (`shader_source`).

{{SHARED_CONSTANTS}}

const CURVE_CLAMP: u32 = 0u;
const CURVE_REINHARD: u32 = 1u;
const CURVE_ACES: u32 = 2u;

fn mul_rows(r0: vec3<f32>, r1: vec3<f32>, r2: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(r0, v), dot(r1, v), dot(r2, v));
}

fn aces_fitted(rgb: vec3<f32>) -> vec3<f32> {
    let c = min(rgb, vec3<f32>(ACES_INPUT_MAX));
    let v = mul_rows(ACES_FROM_SRGB_ROW0, ACES_FROM_SRGB_ROW1, ACES_FROM_SRGB_ROW2, c);
    let a = v * (v + ACES_NUMERATOR.x) - ACES_NUMERATOR.y;
    let b = v * (ACES_DENOMINATOR.x * v + ACES_DENOMINATOR.y) + ACES_DENOMINATOR.z;
    let out = mul_rows(SRGB_FROM_ACES_ROW0, SRGB_FROM_ACES_ROW1, SRGB_FROM_ACES_ROW2, a / b);
    return clamp(out, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn tone_map(rgb_in: vec3<f32>, curve: u32) -> vec3<f32> {
    let rgb = max(rgb_in, vec3<f32>(0.0));
    switch curve {
        case CURVE_CLAMP: { return min(rgb, vec3<f32>(1.0)); }
        // Large inputs go straight to 1, as the CPU's infinity does, without relying on
        // the shader's handling of infinities.
        case CURVE_REINHARD: {
            return select(rgb / (vec3<f32>(1.0) + rgb), vec3<f32>(1.0), rgb > vec3<f32>(3.0e38));
        }
        default: { return aces_fitted(rgb); }
    }
}

fn encode_srgb(c_in: vec3<f32>) -> vec3<f32> {
    let c = clamp(c_in, vec3<f32>(0.0), vec3<f32>(1.0));
    let curve = SRGB_SCALE * pow(c, vec3<f32>(1.0 / SRGB_GAMMA)) - SRGB_OFFSET;
    return select(curve, c * SRGB_LINEAR_SLOPE, c <= vec3<f32>(SRGB_LINEAR_MAX));
}

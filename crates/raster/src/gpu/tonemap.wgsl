// Tone mapping and sRGB encoding of the linear HDR frame into 8-bit texels for read-back,
// exactly as raster's `Frame::to_srgb8`: exposure, tone curve (`tone_curve.wgsl`, in front
// of this text), sRGB curve, round half up to 8 bits.

struct Params {
    scale: f32,
    curve: u32,
    width: u32,
    height: u32,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var ldr: texture_storage_2d<rgba8uint, write>;
@group(0) @binding(2) var<uniform> params: Params;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) {
        return;
    }
    let rgb = textureLoad(hdr, vec2<i32>(id.xy), 0).rgb * params.scale;
    let encoded = encode_srgb(tone_map(rgb, params.curve));
    let bytes = vec3<u32>(min(floor(encoded * 255.0 + 0.5), vec3<f32>(255.0)));
    textureStore(ldr, vec2<i32>(id.xy), vec4<u32>(bytes, 255u));
}

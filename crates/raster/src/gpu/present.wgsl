// The window's present pass: the resolved HDR frame, tone-mapped (`tone_curve.wgsl`, in
// front of this text) and upscaled nearest-neighbour exactly as the CPU viewer's
// `tone_map_into` and `upscale`, straight into the surface texture; then the overlay, a
// small premultiplied-alpha RGBA texture, blended over it.

struct Present {
    scale: f32,
    curve: u32,
    // 1: write sRGB-encoded values (a UNORM surface); 0: linear (an sRGB surface encodes).
    encode: u32,
    pad: u32,
    // The HDR frame's size and the surface's, in pixels.
    source: vec2<u32>,
    target_size: vec2<u32>,
    // The overlay's top-left corner and size on the surface, in pixels.
    overlay_origin: vec2<u32>,
    overlay_size: vec2<u32>,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var overlay: texture_2d<f32>;
@group(0) @binding(2) var<uniform> present: Present;

// One triangle that covers the surface.
@vertex
fn vs_frame(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

// view/pixels.rs `upscale`: source texel (x · iw / w, y · ih / h) in integers.
@fragment
fn fs_frame(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<u32>(at.xy);
    let texel = min(px * present.source / present.target_size, present.source - 1u);
    let rgb = textureLoad(hdr, vec2<i32>(texel), 0).rgb * present.scale;
    let mapped = tone_map(rgb, present.curve);
    let out = select(mapped, encode_srgb(mapped), present.encode == 1u);
    return vec4<f32>(out, 1.0);
}

// Two triangles over the overlay's rectangle.
@vertex
fn vs_overlay(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32(i == 1u || i == 2u || i == 4u), f32(i >= 2u && i != 3u));
    let px = vec2<f32>(present.overlay_origin) + corner * vec2<f32>(present.overlay_size);
    let ndc = px / vec2<f32>(present.target_size) * 2.0 - 1.0;
    return vec4<f32>(ndc.x, -ndc.y, 0.0, 1.0);
}

@fragment
fn fs_overlay(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let texel = vec2<u32>(at.xy) - present.overlay_origin;
    return textureLoad(overlay, vec2<i32>(min(texel, present.overlay_size - 1u)), 0);
}

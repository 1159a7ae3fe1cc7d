// The frame's passes in WGSL, each a port of the CPU backend (the specification):
// background sky (passes.rs `OpaqueCtx::sky`), ground plane (`shade_ground`), opaque
// objects and light spheres (`OpaqueCtx::shade`, shading.rs `lit`), and the bubble film
// (`BubbleCtx::shade`, `LightSight::visibility`, film_field.rs `FilmField::sample` for a
// bubble with a film field). Constants shared with Rust are injected below.

{{SHARED_CONSTANTS}}

// One view: the camera fitted to a pixel grid (camera.rs `View`) and the ground plane's
// per-view constants (passes.rs `GroundView`).
struct View {
    eye: vec4<f32>,
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // tan_half_x, tan_half_y, x_per_px, y_per_px
    tan_half_per_px: vec4<f32>,
    // width, height, near_m, 1 when the ground's checker is filtered over half pixels
    size_near: vec4<f32>,
    // c, gx, gy, inv_height: 1/t = c + gx·px + gy·py
    ground: vec4<f32>,
    // ddx.xyz, normal.y
    ground_ddx: vec4<f32>,
    // ddy.xyz, 1 when the ground is drawn in this view
    ground_ddy: vec4<f32>,
}

struct Scene {
    sh: array<vec4<f32>, 9>,
    env_kind: u32,
    light_count: u32,
    reflection: u32,
    transmittance_table: u32,
    zenith: vec4<f32>,
    horizon: vec4<f32>,
    nadir: vec4<f32>,
    // sun direction (unit), cos of its angular radius
    sun_dir: vec4<f32>,
    // sun radiance, 1 when the sun is on
    sun_rgb: vec4<f32>,
    uniform_rgb: vec4<f32>,
    ground_material: u32,
    ground_height_m: f32,
    cube_face_size: u32,
    reflectivity_table: u32,
    // 1 when dynamic cube maps are read corrected for the ground's parallax (parallax.rs)
    ground_parallax: u32,
    // the main view's sample count (`fs_water` shades where the CPU does)
    frame_samples: u32,
    // The environment image in `images`: first texel, width, height of an equirect; first
    // texel, face size of cube faces (scene_data.rs `Atlas`).
    env_image: vec4<u32>,
    // The sphere map in `images`: first texel, width, height; then its map_from_world by
    // rows (spheremap.rs `SphereMap`).
    sphere_image: vec4<u32>,
    sphere_from_world: array<vec4<f32>, 3>,
}

struct Material {
    // albedo a, checker scale in metres
    a: vec4<f32>,
    // albedo b, shininess
    b: vec4<f32>,
    // specular rgb, pattern kind
    specular: vec4<f32>,
    // a textured material's image in `images`: first texel, width, height (its repeat on
    // the ground is `a.w` metres)
    image: vec4<u32>,
}

struct Light {
    // position, radius in metres
    position: vec4<f32>,
    // radiance, index of its highlight table
    radiance: vec4<f32>,
    // highlight gain (`Light::highlight_gain`)
    gain: vec4<f32>,
}

// A table's place in the stacked LUT texture: first row, width, height, columns per nm.
struct LutInfo {
    row0: f32,
    width: f32,
    height: f32,
    d_scale: f32,
}

@group(0) @binding(0) var<uniform> view: View;
@group(1) @binding(0) var<uniform> scene: Scene;
@group(1) @binding(1) var<storage, read> materials: array<Material>;
@group(1) @binding(2) var<storage, read> lights: array<Light>;
// The image atlas: every image the scene reads (the environment's), row-major one after
// another, linear texel i at (i mod width, i div width), RGB (scene_data.rs `Atlas`).
@group(1) @binding(3) var images: texture_2d<f32>;
@group(2) @binding(0) var luts: texture_2d<f32>;
@group(2) @binding(1) var<storage, read> lut_info: array<LutInfo>;
@group(2) @binding(2) var cubes: texture_2d_array<f32>;
// Every bubble's cube mip chain, laid out as cubemap.rs `CubeMap`'s levels: per bubble,
// per level (level 0 first), six bordered (n + 2)² faces of packed RGB (see `cube_mips`).
@group(2) @binding(3) var<storage, read> cube_mips: array<f32>;
// Every film field's six bordered (n + 2)² faces of [thickness_nm, coverage], laid out as
// film_field.rs `FilmField::bordered`, one field after another; linear texel i sits at
// (i mod width, i div width) (scene_data.rs `film_fields`).
@group(2) @binding(4) var film_texels: texture_2d<f32>;

// ---- shared functions ------------------------------------------------------------------

// camera.rs `View::ray`: unnormalised ray through pixel-space point `pix` (forward part 1).
fn view_ray(pix: vec2<f32>) -> vec3<f32> {
    let ax = pix.x * view.tan_half_per_px.z - view.tan_half_per_px.x;
    let ay = view.tan_half_per_px.y - pix.y * view.tan_half_per_px.w;
    return view.forward.xyz + view.right.xyz * ax + view.up.xyz * ay;
}

// camera.rs `View::clip` as clip coordinates whose depth z/w = near/w is the CPU's
// inverse depth scaled by near: larger is nearer, and w < near falls behind the far plane.
fn clip_of(p: vec3<f32>) -> vec4<f32> {
    let rel = p - view.eye.xyz;
    return vec4<f32>(
        dot(rel, view.right.xyz) / view.tan_half_per_px.x,
        dot(rel, view.up.xyz) / view.tan_half_per_px.y,
        view.size_near.z,
        dot(rel, view.forward.xyz),
    );
}

fn normalize_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let len2 = dot(v, v);
    if (len2 > 0.0 && len2 < 3.0e38) {
        return v * inverseSqrt(len2);
    }
    return fallback;
}

fn lerp3(a: vec3<f32>, b: vec3<f32>, t: f32) -> vec3<f32> {
    return a * (1.0 - t) + b * t;
}

// environment.rs `Sky::radiance` and `Environment::radiance`.
fn env_radiance(dir: vec3<f32>) -> vec3<f32> {
    if (scene.env_kind == ENV_UNIFORM) {
        return scene.uniform_rgb.xyz;
    }
    if (scene.env_kind == ENV_EQUIRECT) {
        return equirect_sample(scene.env_image, dir);
    }
    if (scene.env_kind == ENV_CUBE) {
        return env_cube_sample(scene.env_image.x, scene.env_image.y, dir);
    }
    let d = normalize_or(dir, vec3<f32>(0.0, 1.0, 0.0));
    var out: vec3<f32>;
    if (d.y >= 0.0) {
        let s = 1.0 - d.y;
        out = lerp3(scene.zenith.xyz, scene.horizon.xyz, s * s * s);
    } else {
        out = lerp3(scene.horizon.xyz, scene.nadir.xyz, min(-d.y * 10.0, 1.0));
    }
    if (scene.sun_rgb.w > 0.0 && dot(d, scene.sun_dir.xyz) >= scene.sun_dir.w) {
        out += scene.sun_rgb.xyz;
    }
    return out;
}

// ---- images: environment maps and textures ---------------------------------------------

// Linear texel `i` of the image atlas.
fn image_texel(i: u32) -> vec3<f32> {
    let width = textureDimensions(images).x;
    return textureLoad(images, vec2<u32>(i % width, i / width), 0).xyz;
}

// A texel pair on one axis and the second one's weight (texture.rs `split_repeat`,
// `split_clamp`).
struct Split {
    i0: u32,
    i1: u32,
    t: f32,
}

// texture.rs `split_repeat`: the axis of `n` texels repeats (texel centres at (i + 0.5)/n).
fn split_repeat(u: f32, n: u32) -> Split {
    var x = u * f32(n) - 0.5;
    // Not finite (NaN or infinite) reads as 0.
    if (!(abs(x) < 3.0e38)) {
        x = 0.0;
    }
    let f = floor(x);
    var i0: u32;
    if (abs(f) < 2147483520.0) {
        let q = i32(f) % i32(n);
        i0 = u32(select(q, q + i32(n), q < 0));
    } else {
        let nf = f32(n);
        i0 = u32(clamp(f - nf * floor(f / nf), 0.0, nf - 1.0));
    }
    return Split(i0, select(i0 + 1u, 0u, i0 + 1u == n), x - f);
}

// texture.rs `split_clamp`: the axis of `n` texels is clamped to its edges.
fn split_clamp(u: f32, n: u32) -> Split {
    var x = clamp(u * f32(n) - 0.5, 0.0, f32(n - 1u));
    if (x != x) {
        x = 0.0;
    }
    let i0 = u32(x);
    return Split(i0, min(i0 + 1u, n - 1u), x - f32(i0));
}

// texture.rs `Texture::bilinear` and `bilerp` of the image whose first texel is `first`
// and which is `width` texels wide.
fn image_bilinear(first: u32, width: u32, sx: Split, sy: Split) -> vec3<f32> {
    let a = image_texel(first + sy.i0 * width + sx.i0);
    let b = image_texel(first + sy.i0 * width + sx.i1);
    let c = image_texel(first + sy.i1 * width + sx.i0);
    let d = image_texel(first + sy.i1 * width + sx.i1);
    let top = a + (b - a) * sx.t;
    let bottom = c + (d - c) * sx.t;
    return top + (bottom - top) * sy.t;
}

// texture.rs `Texture::sample_equirect` of the image `img` = (first texel, width, height):
// u = 0.5 + atan2(x, −z)/2π, v = acos(y)/π.
fn equirect_sample(img: vec4<u32>, dir: vec3<f32>) -> vec3<f32> {
    let len = length(dir);
    var y = 1.0;
    if (len > 0.0) {
        y = clamp(dir.y / len, -1.0, 1.0);
    }
    let u = 0.5 + atan2(dir.x, -dir.z) * (0.5 / PI);
    let v = acos(y) * (1.0 / PI);
    return image_bilinear(img.x, img.y, split_repeat(u, img.y), split_clamp(v, img.z));
}

// texture.rs `Texture::sample_repeat` of the image `img` = (first texel, width, height).
fn image_repeat(img: vec4<u32>, u: f32, v: f32) -> vec3<f32> {
    return image_bilinear(img.x, img.y, split_repeat(u, img.y), split_repeat(v, img.z));
}

// texture.rs `Texture::sample_clamp` of the image `img` = (first texel, width, height).
fn image_clamp(img: vec4<u32>, u: f32, v: f32) -> vec3<f32> {
    return image_bilinear(img.x, img.y, split_clamp(u, img.y), split_clamp(v, img.z));
}

// spheremap.rs `SphereMap::sample`: the mirror ball's image at the reflected direction
// `dir` (any length) turned into map space: u = r.x/m + ½, v = ½ − r.y/m,
// m = 2·√(r.x² + r.y² + (r.z + 1)²).
fn sphere_map_sample(dir: vec3<f32>) -> vec3<f32> {
    let rows = scene.sphere_from_world;
    let q = vec3<f32>(dot(rows[0].xyz, dir), dot(rows[1].xyz, dir), dot(rows[2].xyz, dir));
    let r = normalize_or(q, vec3<f32>(0.0, 0.0, 1.0));
    let m = 2.0 * sqrt(r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0));
    // At r = −Z every rim point is the answer: the rim's right-hand side, as the CPU.
    var uv = vec2<f32>(1.0, 0.5);
    if (m > 1e-6) {
        uv = vec2<f32>(r.x / m + 0.5, 0.5 - r.y / m);
    }
    return image_clamp(scene.sphere_image, uv.x, uv.y);
}

// cubemap.rs `CubeMap::sample` of cube faces stored in the atlas: level 0's six bordered
// (n + 2)² faces from texel `first`, n = `size`; `cube_level_bilinear`'s arithmetic.
fn env_cube_sample(first: u32, size: u32, dir: vec3<f32>) -> vec3<f32> {
    let fst = face_coordinates(dir);
    let at = bordered_bilinear(fst, f32(size));
    let tx = at.z;
    let ty = at.w;
    let mu = size + 2u;
    let i = first + (u32(fst.x) * mu + u32(at.y)) * mu + u32(at.x);
    let a = image_texel(i);
    let b = image_texel(i + 1u);
    let c = image_texel(i + mu);
    let d = image_texel(i + mu + 1u);
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
    return top + (bottom - top) * ty;
}

// reflection.rs `Reflection::sample` of `Reflection::Env` and `Reflection::Sphere`: the
// environment's cube faces through their mip chain (chain 0 of `cube_mips`), filtered as
// a dynamic cube map is, the sphere map, or the environment itself.
fn static_reflection(dir: vec3<f32>, derivatives: array<vec3<f32>, 2>) -> vec3<f32> {
    if (scene.reflection == REFLECTION_ENV_CUBE) {
        return cube_footprint(0u, dir, derivatives[0], derivatives[1]);
    }
    if (scene.reflection == REFLECTION_ENV_CUBE_BILINEAR) {
        return cube_sample(0u, dir);
    }
    if (scene.reflection == REFLECTION_SPHERE_MAP) {
        return sphere_map_sample(dir);
    }
    return env_radiance(dir);
}

// irradiance.rs `Irradiance::diffuse`.
fn sh_diffuse(n_in: vec3<f32>) -> vec3<f32> {
    let n = normalize_or(n_in, vec3<f32>(0.0, 1.0, 0.0));
    let x = n.x;
    let y = n.y;
    let z = n.z;
    var out = scene.sh[0].xyz;
    out += scene.sh[1].xyz * y;
    out += scene.sh[2].xyz * z;
    out += scene.sh[3].xyz * x;
    out += scene.sh[4].xyz * (x * y);
    out += scene.sh[5].xyz * (y * z);
    out += scene.sh[6].xyz * (3.0 * z * z - 1.0);
    out += scene.sh[7].xyz * (x * z);
    out += scene.sh[8].xyz * (x * x - y * y);
    return max(out, vec3<f32>(0.0));
}

// shading.rs `lit`: Lambert from the SH irradiance and the lights, normalised Blinn-Phong.
fn lit(m: Material, albedo: vec3<f32>, p: vec3<f32>, n_in: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    var n = n_in;
    if (dot(n, v) > 0.0) {
        n = -n;
    }
    var out = albedo * sh_diffuse(n);
    let has_specular = any(m.specular.xyz != vec3<f32>(0.0));
    let shininess = m.b.w;
    let spec_norm = (shininess + 8.0) / 8.0;
    for (var i = 0u; i < scene.light_count; i++) {
        let light = lights[i];
        let to_light = light.position.xyz - p;
        let dist2 = dot(to_light, to_light);
        if (dist2 <= 0.0) {
            continue;
        }
        let l = to_light * inverseSqrt(dist2);
        let n_dot_l = dot(n, l);
        if (n_dot_l <= 0.0) {
            continue;
        }
        let r = light.position.w;
        let solid = min(r * r / dist2, 1.0) * n_dot_l;
        var weight = albedo * solid;
        if (has_specular) {
            let h = normalize_or(l - normalize_or(v, vec3<f32>(0.0)), vec3<f32>(0.0));
            let s = spec_norm * pow(max(dot(n, h), 0.0), shininess) * solid;
            weight += m.specular.xyz * s;
        }
        out += weight * light.radiance.xyz;
    }
    return out;
}

// shading.rs `filtered_square`: the ±1 square wave of unit cells box-filtered over `w`.
fn filtered_square(x: f32, footprint: f32) -> f32 {
    let w = footprint + 1e-3;
    let lo = (x - 0.5 * w) * 0.5;
    let hi = (x + 0.5 * w) * 0.5;
    return 2.0 * (abs(lo - floor(lo) - 0.5) - abs(hi - floor(hi) - 0.5)) / w;
}

// shading.rs `filtered_checker`.
fn filtered_checker(p: vec2<f32>, footprint: vec2<f32>) -> f32 {
    return 0.5 - 0.5 * filtered_square(p.x, footprint.x) * filtered_square(p.y, footprint.y);
}

// passes.rs `surface_footprint`: metres per axis one pixel covers on a surface with normal
// `n` hit at depth `t` along view ray `d` (forward component 1).
fn surface_footprint(d: vec3<f32>, t: f32, n: vec3<f32>) -> vec3<f32> {
    let dn = dot(d, n);
    let ddx = view.right.xyz * view.tan_half_per_px.z;
    let ddy = -view.up.xyz * view.tan_half_per_px.w;
    let dx = (ddx - d * (dot(ddx, n) / dn)) * t;
    let dy = (ddy - d * (dot(ddy, n) / dn)) * t;
    let f = abs(dx) + abs(dy);
    return select(vec3<f32>(1e6), f, f < vec3<f32>(1e6));
}

// shading.rs `object_albedo` (solid, the 3-D checker box-filtered over `footprint`, an
// image at the mesh's `uv`).
fn object_albedo(m: Material, p: vec3<f32>, uv: vec2<f32>, footprint: vec3<f32>) -> vec3<f32> {
    if (m.specular.w == PATTERN_TEXTURED) {
        return image_repeat(m.image, uv.x, uv.y);
    }
    if (m.specular.w != PATTERN_CHECKER) {
        return m.a.xyz;
    }
    let q = p / m.a.w;
    let f = min(footprint / m.a.w, vec3<f32>(1e6));
    var i = 1.0;
    for (var k = 0; k < 3; k++) {
        let x = clamp(q[k], -1e6, 1e6);
        if (f[k] < FLAT_FOOTPRINT_CELLS) {
            i *= 1.0 - 2.0 * (floor(x) - 2.0 * floor(x * 0.5));
        } else {
            i *= filtered_square(x, f[k]);
        }
    }
    return lerp3(m.a.xyz, m.b.xyz, 0.5 - 0.5 * i);
}

// ---- sky ---------------------------------------------------------------------------------

struct FullScreen {
    @builtin(position) position: vec4<f32>,
    // Pixel-space point, at a covered sample where the pixel is only partly covered (as
    // the CPU shades a partly covered pixel at a covered sample).
    @location(0) @interpolate(perspective, centroid) pix: vec2<f32>,
}

fn full_screen_corner(k: u32) -> vec2<f32> {
    return vec2<f32>(select(-1.0, 3.0, k == 1u), select(-1.0, 3.0, k == 2u));
}

fn pixel_of_ndc(ndc: vec2<f32>) -> vec2<f32> {
    return vec2<f32>((ndc.x + 1.0) * 0.5 * view.size_near.x, (1.0 - ndc.y) * 0.5 * view.size_near.y);
}

@vertex
fn vs_sky(@builtin(vertex_index) k: u32) -> FullScreen {
    let ndc = full_screen_corner(k);
    return FullScreen(vec4<f32>(ndc, 0.0, 1.0), pixel_of_ndc(ndc));
}

@fragment
fn fs_sky(in: FullScreen) -> @location(0) vec4<f32> {
    // The CPU fills every sample of a pixel with the sky along its centre's ray.
    return vec4<f32>(env_radiance(view_ray(in.position.xy)), 1.0);
}

// ---- ground ------------------------------------------------------------------------------

fn ground_inv_depth(pix: vec2<f32>) -> f32 {
    return view.ground.x + view.ground.y * pix.x + view.ground.z * pix.y;
}

// The plane's visible polygon, clipped on the CPU (`scene_data::ground_triangles`) to
// where its inverse depth is positive, with depth near/t at each vertex: depth is affine in
// pixel space, so the rasteriser interpolates it exactly.
@vertex
fn vs_ground(@location(0) ndc_depth: vec3<f32>) -> FullScreen {
    return FullScreen(vec4<f32>(ndc_depth, 1.0), pixel_of_ndc(ndc_depth.xy));
}

@fragment
fn fs_ground(in: FullScreen) -> @location(0) vec4<f32> {
    // The CPU shades the ground once per pixel (`background_pixel`), at the centre where
    // the plane covers every sample: so does this where the plane covers the whole pixel
    // (its inverse depth, affine in pixel space, positive at all four corners), also
    // along the internal edges of the clipped polygon, where each triangle's centroid
    // would fall elsewhere (visible where an image is minified). Elsewhere (the horizon)
    // at the covered samples' centroid.
    var pix = in.pix;
    let corner_margin = 0.5 * (abs(view.ground.y) + abs(view.ground.z));
    if (ground_inv_depth(in.position.xy) - corner_margin > 0.0) {
        pix = in.position.xy;
    }
    let inv_t = max(ground_inv_depth(pix), 1e-30);
    let t = 1.0 / inv_t;
    let d = view_ray(pix);
    let p = view.eye.xyz + d * t;
    // passes.rs `shade_ground`: footprint of one pixel on the plane.
    let inv_dy = t * view.ground.w;
    let ddx = view.ground_ddx.xyz;
    let ddy = view.ground_ddy.xyz;
    let dpx = (ddx - d * (ddx.y * inv_dy)) * t;
    let dpy = (ddy - d * (ddy.y * inv_dy)) * t;
    // Edge-on the footprint is unbounded: the filter then returns the mean.
    let ax = clamp(vec2<f32>(dpx.x, dpx.z), vec2<f32>(-1e9), vec2<f32>(1e9));
    let ay = clamp(vec2<f32>(dpy.x, dpy.z), vec2<f32>(-1e9), vec2<f32>(1e9));
    let m = materials[scene.ground_material];
    var albedo = m.a.xyz;
    if (m.specular.w == PATTERN_CHECKER) {
        // shading.rs `ground_albedo_over_pixel`: two half-pixel boxes (`ground_halves`)
        // along the longer of the pixel's sides on the plane, or one box.
        let inv = 1.0 / m.a.w;
        let c = vec2<f32>(p.x, p.z);
        var w = filtered_checker(c * inv, (abs(ax) + abs(ay)) * inv);
        if (view.size_near.w != 0.0) {
            let long_x = dot(ax, ax) >= dot(ay, ay);
            let major = select(ay, ax, long_x);
            let minor = select(ax, ay, long_x);
            let o = GROUND_HALF_OFFSET_PX * major;
            let f = (0.5 * abs(major) + abs(minor)) * inv;
            w = 0.5 * (filtered_checker((c - o) * inv, f) + filtered_checker((c + o) * inv, f));
        }
        albedo = lerp3(m.a.xyz, m.b.xyz, w);
    }
    // shading.rs `ground_albedo` of an image: one repeat per `scale_m` along x and z.
    if (m.specular.w == PATTERN_TEXTURED) {
        albedo = image_repeat(m.image, p.x / m.a.w, p.z / m.a.w);
    }
    let normal = vec3<f32>(0.0, view.ground_ddx.w, 0.0);
    return vec4<f32>(lit(m, albedo, p, normal, d), 1.0);
}

// ---- opaque objects and light spheres ----------------------------------------------------

struct ObjectIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tag: u32,
    @location(3) uv: vec2<f32>,
}

struct ObjectOut {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) world: vec3<f32>,
    @location(1) @interpolate(perspective, centroid) normal: vec3<f32>,
    @location(2) @interpolate(flat) tag: u32,
    @location(3) @interpolate(perspective, centroid) uv: vec2<f32>,
}

@vertex
fn vs_object(in: ObjectIn) -> ObjectOut {
    return ObjectOut(clip_of(in.position), in.position, in.normal, in.tag, in.uv);
}

@fragment
fn fs_object(in: ObjectOut) -> @location(0) vec4<f32> {
    if ((in.tag & EMISSIVE) != 0u) {
        return vec4<f32>(lights[in.tag & ~EMISSIVE].radiance.xyz, 1.0);
    }
    let v = normalize_or(in.world - view.eye.xyz, view.forward.xyz);
    let n = normalize_or(in.normal, -v);
    let m = materials[in.tag];
    // The view ray with forward component 1 and the depth along it, as the CPU's `d`, `t`.
    let rel = in.world - view.eye.xyz;
    let t = dot(rel, view.forward.xyz);
    let footprint = surface_footprint(rel / t, t, n);
    let albedo = object_albedo(m, in.world, in.uv, footprint);
    return vec4<f32>(lit(m, albedo, in.world, n, v), 1.0);
}

// ---- water -------------------------------------------------------------------------------
//
// water_shading.rs `WaterShading::radiance`, drawn by the opaque pass for the triangles
// tagged WATER (raster passes/opaque.rs `OpaqueCtx::shade_water`).

struct Water {
    // absorption per metre (rgb), refractive index
    absorption_ior: vec4<f32>,
    // water.rs `WaterSurface::floor_height_m`
    floor_height_m: f32,
    // the floor's entry in `materials`
    floor_material: u32,
    // WATER_REFLECTION_CUBE, WATER_REFLECTION_ENVIRONMENT or WATER_REFLECTION_SPHERE_MAP
    reflection: u32,
    // face size of `water_cube` (dynamic cube maps only)
    cube_face_size: u32,
    // the camera's eye_from_world by rows (sphere-map reflections)
    eye_from_world: array<vec4<f32>, 3>,
}

// Bindings 3.. of group 3: the cube mip passes hold 0..2 of that group in this module.
@group(3) @binding(3) var<uniform> water: Water;
// water.rs `FresnelTable` samples: from air (table 0), then from water (table 1), each
// FRESNEL_STEPS + 1 values of R at cos θ = i / FRESNEL_STEPS.
@group(3) @binding(4) var<storage, read> fresnel: array<f32>;
// The cube map seen from the eye mirrored in the rest plane: six bordered (n + 2)² faces
// (raster passes/water.rs `WaterPass::render_cube`), level 0 only.
@group(3) @binding(5) var water_cube: texture_2d_array<f32>;

// water.rs `FresnelTable::reflectance` of table `table`.
fn fresnel_reflectance(table: u32, cos_theta: f32) -> f32 {
    var c = 0.0;
    if (cos_theta >= 0.0) {
        c = min(cos_theta, 1.0);
    }
    let x = c * f32(FRESNEL_STEPS);
    let i = min(u32(x), FRESNEL_STEPS - 1u);
    let t = x - f32(i);
    let k = table * (FRESNEL_STEPS + 1u) + i;
    return fresnel[k] + (fresnel[k + 1u] - fresnel[k]) * t;
}

// water.rs `refract`: the refracted direction in xyz, w = 1; w = 0 under total internal
// reflection.
fn refract_or_none(incident: vec3<f32>, normal: vec3<f32>, eta: f32) -> vec4<f32> {
    let cos_i = -dot(incident, normal);
    let sin2_t = eta * eta * max(1.0 - cos_i * cos_i, 0.0);
    if (sin2_t >= 1.0) {
        return vec4<f32>(0.0);
    }
    let cos_t = sqrt(1.0 - sin2_t);
    return vec4<f32>(incident * eta + normal * (eta * cos_i - cos_t), 1.0);
}

// shading.rs `ground_albedo`: the material's pattern repeating along x and z, a checker
// box-filtered over `footprint` metres, an image point-sampled.
fn ground_albedo(m: Material, x: f32, z: f32, footprint: vec2<f32>) -> vec3<f32> {
    if (m.specular.w == PATTERN_CHECKER) {
        let inv = 1.0 / m.a.w;
        let t = filtered_checker(vec2<f32>(x * inv, z * inv), footprint * inv);
        return lerp3(m.a.xyz, m.b.xyz, t);
    }
    if (m.specular.w == PATTERN_TEXTURED) {
        return image_repeat(m.image, x / m.a.w, z / m.a.w);
    }
    return m.a.xyz;
}

// water_shading.rs `WaterShading::floor_radiance` with `floor_hit`: the lit floor seen
// from `p` along `dir` through the water, dimmed by Beer–Lambert absorption over the path;
// black when the ray does not go down to the floor.
fn water_floor(p: vec3<f32>, dir: vec3<f32>, footprint_m: f32) -> vec3<f32> {
    if (!(dir.y < 0.0) || !all(abs(dir) < vec3<f32>(3.0e38))) {
        return vec3<f32>(0.0);
    }
    let path_m = max((water.floor_height_m - p.y) / dir.y, 0.0);
    let q = p + dir * path_m;
    let m = materials[water.floor_material];
    let albedo = ground_albedo(m, q.x, q.z, vec2<f32>(footprint_m));
    let floor = lit(m, albedo, q, vec3<f32>(0.0, 1.0, 0.0), dir);
    return floor * exp(-water.absorption_ior.xyz * path_m);
}

// cubemap.rs `CubeMap::sample` of the water's cube map: one bilinear tap of level 0.
fn water_cube_sample(dir: vec3<f32>) -> vec3<f32> {
    let fst = face_coordinates(dir);
    let at = bordered_bilinear(fst, f32(water.cube_face_size));
    let face = i32(fst.x);
    let x = i32(at.x);
    let y = i32(at.y);
    let a = textureLoad(water_cube, vec2<i32>(x, y), face, 0).xyz;
    let b = textureLoad(water_cube, vec2<i32>(x + 1, y), face, 0).xyz;
    let c = textureLoad(water_cube, vec2<i32>(x, y + 1), face, 0).xyz;
    let d = textureLoad(water_cube, vec2<i32>(x + 1, y + 1), face, 0).xyz;
    let top = a + (b - a) * at.z;
    let bottom = c + (d - c) * at.z;
    return top + (bottom - top) * at.w;
}

// water.rs `sphere_map_uv`: seed 002's texture coordinates of view-space direction `r`.
fn sphere_map_uv(r_view: vec3<f32>) -> vec2<f32> {
    let r = normalize_or(r_view, vec3<f32>(0.0));
    return clamp((r.xy + vec2<f32>(1.0)) * 0.5, vec2<f32>(0.0), vec2<f32>(1.0));
}

// water.rs `sphere_map_direction`: the view-space direction a seed 002 coordinate stands
// for, on the far side (z ≤ 0); outside the unit disc, the rim.
fn sphere_map_direction(uv: vec2<f32>) -> vec3<f32> {
    let xy = 2.0 * uv - vec2<f32>(1.0);
    let r2 = dot(xy, xy);
    if (r2 >= 1.0) {
        return normalize_or(vec3<f32>(xy, 0.0), vec3<f32>(0.0, 0.0, -1.0));
    }
    return vec3<f32>(xy, -sqrt(1.0 - r2));
}

// water_shading.rs `WaterReflection::sample`: radiance reflected along unit `dir`.
fn water_reflection(dir: vec3<f32>) -> vec3<f32> {
    if (water.reflection == WATER_REFLECTION_CUBE) {
        return water_cube_sample(dir);
    }
    if (water.reflection == WATER_REFLECTION_SPHERE_MAP) {
        let rows = water.eye_from_world;
        let e = vec3<f32>(dot(rows[0].xyz, dir), dot(rows[1].xyz, dir), dot(rows[2].xyz, dir));
        let back = sphere_map_direction(sphere_map_uv(e));
        // eye_from_world transposed: the rows' combination.
        let world = rows[0].xyz * back.x + rows[1].xyz * back.y + rows[2].xyz * back.z;
        return sphere_map_sample(world);
    }
    return env_radiance(dir);
}

// water_shading.rs `WaterShading::radiance`: the exact Fresnel blend of the reflected
// scene and the floor refracted through the water, at `p` with unit normal `n` (up) seen
// along unit `v`; `footprint_m` is a pixel's width there.
fn water_radiance(p: vec3<f32>, v: vec3<f32>, n: vec3<f32>, footprint_m: f32) -> vec3<f32> {
    let ior = water.absorption_ior.w;
    let c = dot(v, n);
    var r: f32;
    var reflected: vec3<f32>;
    var transmitted = vec3<f32>(0.0);
    if (c <= 0.0) {
        // From the air: reflect the scene, refract onto the floor.
        r = fresnel_reflectance(0u, -c);
        let t = refract_or_none(v, n, 1.0 / ior);
        if (t.w > 0.0) {
            transmitted = water_floor(p, t.xyz, footprint_m);
        }
        reflected = water_reflection(v - n * (2.0 * c));
    } else {
        // From under the water: reflect the floor, refract the scene above; total
        // internal reflection reflects everything.
        let m = -n;
        let t = refract_or_none(v, m, ior);
        reflected = water_floor(p, v - m * (2.0 * dot(v, m)), footprint_m);
        r = 1.0;
        if (t.w > 0.0) {
            r = fresnel_reflectance(1u, c);
            transmitted = water_reflection(t.xyz);
        }
    }
    return r * reflected + (1.0 - r) * transmitted;
}

// The water's position and normal at the pixel centre, perspective-correct (whether the
// centre is covered or not). Times 1/w they are affine in screen space, so their
// differences between neighbouring pixels give them anywhere in the pixel exactly, as
// raster.rs `SetupTri::interpolate` does. (Screen-linear varyings would be affine too, but
// a triangle clipped at the near plane gets them wrong on lavapipe.)
struct WaterOut {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(perspective, center) world: vec3<f32>,
    @location(1) @interpolate(perspective, center) normal: vec3<f32>,
}

@vertex
fn vs_water(in: ObjectIn) -> WaterOut {
    return WaterOut(clip_of(in.position), in.position, in.normal);
}

// Where passes/opaque.rs `OpaqueCtx::triangle` shades a pixel whose samples `covered` the
// triangle covers, as an offset from the pixel centre: the centre when it covers them all,
// else its first covered sample (the 4-sample pattern is the CPU's, injected; with 2, 8 or
// 16 samples, the centre).
fn water_shading_offset(covered: u32) -> vec2<f32> {
    let full = (1u << scene.frame_samples) - 1u;
    if (scene.frame_samples != 4u || (covered & full) == full) {
        return vec2<f32>(0.0);
    }
    return SAMPLE_OFFSETS_4[min(firstTrailingBit(covered & full), 3u)];
}

// passes/opaque.rs `OpaqueCtx::shade_water`: a water pixel of the opaque pass.
@fragment
fn fs_water(in: WaterOut, @builtin(sample_mask) covered: u32) -> @location(0) vec4<f32> {
    // Derivatives need uniform control flow, so they come first.
    let centre_inv_w = 1.0 / dot(in.world - view.eye.xyz, view.forward.xyz);
    let world_over_w = in.world * centre_inv_w;
    let normal_over_w = in.normal * centre_inv_w;
    let dw = array<vec3<f32>, 2>(dpdxFine(world_over_w), dpdyFine(world_over_w));
    let dn = array<vec3<f32>, 2>(dpdxFine(normal_over_w), dpdyFine(normal_over_w));
    let di = vec2<f32>(dpdxFine(centre_inv_w), dpdyFine(centre_inv_w));
    let o = water_shading_offset(covered);
    let inv_w = max(centre_inv_w + di.x * o.x + di.y * o.y, 1e-20);
    let world = (world_over_w + dw[0] * o.x + dw[1] * o.y) / inv_w;
    let normal = (normal_over_w + dn[0] * o.x + dn[1] * o.y) / inv_w;
    let rel = world - view.eye.xyz;
    let v = normalize_or(rel, view.forward.xyz);
    let n = normalize_or(normal, vec3<f32>(0.0, 1.0, 0.0));
    let footprint_m = length(rel) * view.tan_half_per_px.z;
    return vec4<f32>(water_radiance(world, v, n, footprint_m), 1.0);
}

// ---- bubbles -----------------------------------------------------------------------------

struct BubbleIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) thickness_nm: f32,
    // renderer.rs `reflection_rate` of the vertex's triangle
    @location(3) pixel_angle_rad: f32,
    @location(4) bubble: u32,
    // where the vertex sits on its bubble's film field (zero without one)
    @location(5) material_dir: vec3<f32>,
    // the bubble's film field: first texel in `film_texels`, face size (0: no field)
    @location(6) film: vec2<u32>,
    // the bubble's centre, where its cube map is rendered from
    @location(7) centre: vec3<f32>,
}

struct BubbleOut {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) world: vec3<f32>,
    @location(1) @interpolate(perspective, centroid) normal: vec3<f32>,
    @location(2) @interpolate(perspective, centroid) thickness_nm: f32,
    @location(3) @interpolate(flat) pixel_angle_rad: f32,
    @location(4) @interpolate(flat) bubble: u32,
    // normal/w and 1/w interpolated affinely in screen space: their differences between
    // neighbouring pixels are exactly the CPU's plane derivatives (`SetupTri::attrs`,
    // `inv_w`), from which the normal's derivative follows as on the CPU.
    @location(5) @interpolate(linear, center) normal_over_w: vec3<f32>,
    @location(6) @interpolate(linear, center) inv_w: f32,
    // raster.rs attributes 3..6 of a bubble with a film field: perspective-correct
    @location(7) @interpolate(perspective, centroid) material_dir: vec3<f32>,
    @location(8) @interpolate(flat) film: vec2<u32>,
    @location(9) @interpolate(flat) centre: vec3<f32>,
}

@vertex
fn vs_bubble(in: BubbleIn) -> BubbleOut {
    let clip = clip_of(in.position);
    return BubbleOut(clip, in.position, in.normal, in.thickness_nm, in.pixel_angle_rad,
        in.bubble, in.normal / clip.w, 1.0 / clip.w, in.material_dir, in.film, in.centre);
}

// lut_sampler.rs `split`: lower sample index and the upper one's weight on an axis of n.
fn lut_split(x_in: f32, n: f32) -> vec2<f32> {
    var x = clamp(x_in, 0.0, n - 1.0);
    if (x != x) {
        x = 0.0;
    }
    let i0 = min(floor(x), n - 2.0);
    return vec2<f32>(i0, x - i0);
}

// lut_sampler.rs `LutSampler::sample` (= `Lut::sample`): texel (i, j) of a table holds
// d = d_max·i/(W−1), cos θ = j/(H−1), so the lookup scales to texel units and blends the
// four texels with textureLoad, in `bilerp`'s operation order. No sampler is involved:
// a sampler's normalised uv would put texel centres at (i + 0.5)/W instead.
fn lut_sample(table: u32, thickness_nm: f32, cos_theta: f32) -> vec3<f32> {
    let info = lut_info[table];
    let sx = lut_split(thickness_nm * info.d_scale, info.width);
    let sy = lut_split(cos_theta * (info.height - 1.0), info.height);
    let x0 = i32(sx.x);
    let y0 = i32(info.row0 + sy.x);
    let a = textureLoad(luts, vec2<i32>(x0, y0), 0).xyz;
    let b = textureLoad(luts, vec2<i32>(x0 + 1, y0), 0).xyz;
    let c = textureLoad(luts, vec2<i32>(x0, y0 + 1), 0).xyz;
    let d = textureLoad(luts, vec2<i32>(x0 + 1, y0 + 1), 0).xyz;
    let top = a + (b - a) * sx.y;
    let bottom = c + (d - c) * sx.y;
    return top + (bottom - top) * sy.y;
}

// cubemap.rs `face_coordinates`: face index and (s, t) in [−1, 1]².
fn face_coordinates(dir: vec3<f32>) -> vec3<f32> {
    let a = abs(dir);
    var face: f32;
    var sc: f32;
    var tc: f32;
    var ma: f32;
    if (a.x >= a.y && a.x >= a.z) {
        if (dir.x >= 0.0) {
            face = 0.0; sc = -dir.z; tc = -dir.y;
        } else {
            face = 1.0; sc = dir.z; tc = -dir.y;
        }
        ma = a.x;
    } else if (a.y >= a.z) {
        if (dir.y >= 0.0) {
            face = 2.0; sc = dir.x; tc = dir.z;
        } else {
            face = 3.0; sc = dir.x; tc = -dir.z;
        }
        ma = a.y;
    } else {
        if (dir.z >= 0.0) {
            face = 4.0; sc = dir.x; tc = -dir.y;
        } else {
            face = 5.0; sc = -dir.x; tc = -dir.y;
        }
        ma = a.z;
    }
    if (ma > 0.0 && ma < 3.0e38) {
        let inv = 1.0 / ma;
        return vec3<f32>(face, clamp(sc * inv, -1.0, 1.0), clamp(tc * inv, -1.0, 1.0));
    }
    return vec3<f32>(0.0);
}

// Face size of level `level` of the chain: the face halved (rounded down) `level` times.
fn mip_size(level: u32) -> u32 {
    return scene.cube_face_size >> level;
}

// cubemap.rs `CubeMap::levels`: ⌊log2 N⌋ + 1.
fn mip_levels() -> u32 {
    return firstLeadingBit(scene.cube_face_size) + 1u;
}

// Floats from the start of a bubble's chain to level `level`.
fn mip_offset(level: u32) -> u32 {
    var off = 0u;
    for (var k = 0u; k < level; k++) {
        let m = mip_size(k) + 2u;
        off += 18u * m * m;
    }
    return off;
}

// Float index of bordered texel (x, y) of face `face`, level `level`, bubble `bubble`.
fn mip_index(bubble: u32, level: u32, face: u32, x: u32, y: u32) -> u32 {
    let m = mip_size(level) + 2u;
    return bubble * mip_offset(mip_levels()) + mip_offset(level) + 3u * ((face * m + y) * m + x);
}

fn mip_texel(i: u32) -> vec3<f32> {
    return vec3<f32>(cube_mips[i], cube_mips[i + 1u], cube_mips[i + 2u]);
}

// cubemap.rs `Level::bilinear`'s texel position on a bordered face of `n` interior texels
// at face coordinates `fst`: the lower texel's column and row (borders counted) and the
// bilinear weights, as (x0, y0, tx, ty).
fn bordered_bilinear(fst: vec3<f32>, n: f32) -> vec4<f32> {
    let m = n + 2.0;
    let fx = clamp((fst.y + 1.0) * 0.5 * n + 0.5, 0.0, m - 1.0);
    let fy = clamp((fst.z + 1.0) * 0.5 * n + 0.5, 0.0, m - 1.0);
    let x0 = min(floor(fx), m - 2.0);
    let y0 = min(floor(fy), m - 2.0);
    return vec4<f32>(x0, y0, fx - x0, fy - y0);
}

// cubemap.rs `Level::bilinear`: seamless bilinear tap of one level at (s, t), borders
// included.
fn cube_level_bilinear(bubble: u32, level: u32, fst: vec3<f32>) -> vec3<f32> {
    let n = f32(mip_size(level));
    let at = bordered_bilinear(fst, n);
    let tx = at.z;
    let ty = at.w;
    let i = mip_index(bubble, level, u32(fst.x), u32(at.x), u32(at.y));
    let row = 3u * u32(n + 2.0);
    let a = mip_texel(i);
    let b = mip_texel(i + 3u);
    let c = mip_texel(i + row);
    let d = mip_texel(i + row + 3u);
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
    return top + (bottom - top) * ty;
}

// cubemap.rs `CubeMap::sample`: one bilinear tap of level 0 (the CPU's bilinear mode).
fn cube_sample(bubble: u32, dir: vec3<f32>) -> vec3<f32> {
    return cube_level_bilinear(bubble, 0u, face_coordinates(dir));
}

// lod.rs `cube_lod`.
fn cube_lod(footprint_rad: f32, s: f32, t: f32) -> f32 {
    let q = 1.0 + s * s + t * t;
    let q34 = sqrt(q) * sqrt(sqrt(q));
    let texels = footprint_rad * f32(scene.cube_face_size) * 0.5 * q34;
    if (texels > MIN_FOOTPRINT_TEXELS) {
        return max(log2(texels) + LOD_BIAS, 0.0);
    }
    return 0.0;
}

// cubemap.rs `CubeMap::trilinear`: the seamless trilinear tap at face coordinates `fst`
// and level `lod` in [0, levels − 1].
fn cube_trilinear(bubble: u32, fst: vec3<f32>, lod: f32) -> vec3<f32> {
    let last = mip_levels() - 1u;
    let l0 = u32(lod);
    let frac = lod - f32(l0);
    let a = cube_level_bilinear(bubble, l0, fst);
    if (frac <= 0.0 || l0 == last) {
        return a;
    }
    let b = cube_level_bilinear(bubble, l0 + 1u, fst);
    return a + (b - a) * frac;
}

// cubemap.rs `CubeMap::sample_footprint` with lod.rs `anisotropic_taps`: one level-0
// bilinear tap while the longer derivative's footprint stays within level 0; else the
// axis ratio rounded (1 ..= MAX_ANISOTROPY) trilinear taps spread along the longer
// derivative, all at the level of the footprint at `dir` (one tap: the longer axis's).
fn cube_footprint(bubble: u32, dir: vec3<f32>, da: vec3<f32>, db: vec3<f32>) -> vec3<f32> {
    var major = da;
    var minor = db;
    if (dot(da, da) < dot(db, db)) {
        major = db;
        minor = da;
    }
    let fst = face_coordinates(dir);
    let major_rad = length(major);
    let major_lod = cube_lod(major_rad, fst.y, fst.z);
    if (major_lod <= 0.0) {
        return cube_level_bilinear(bubble, 0u, fst);
    }
    let last = f32(mip_levels() - 1u);
    let minor_rad = length(minor);
    // Rounded, at least 1 (NaN → 1), at most MAX_ANISOTROPY.
    let ratio = major_rad / max(minor_rad, 1e-12);
    var taps = 1u;
    if (ratio + 0.5 >= 2.0) {
        taps = u32(min(ratio + 0.5, f32(MAX_ANISOTROPY)));
    }
    if (taps == 1u) {
        return cube_trilinear(bubble, fst, min(major_lod, last));
    }
    let footprint = max(major_rad / f32(taps), minor_rad);
    let lod = min(cube_lod(footprint, fst.y, fst.z), last);
    let step = major * length(dir);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < taps; i++) {
        let offset = (f32(i) + 0.5) / f32(taps) - 0.5;
        sum += cube_trilinear(bubble, face_coordinates(dir + step * offset), lod);
    }
    return sum / f32(taps);
}

// lod.rs `reflection_derivatives`: change per pixel of the unit reflected direction, from
// the view ray `d`, its change per pixel `dd`, the interpolated normal and its change.
fn reflection_derivatives(d: vec3<f32>, dd: array<vec3<f32>, 2>, n_raw: vec3<f32>,
    dn_raw: array<vec3<f32>, 2>) -> array<vec3<f32>, 2> {
    let d_len = length(d);
    let n_len = length(n_raw);
    let v = d / d_len;
    let n_hat = n_raw / n_len;
    let sign = select(1.0, -1.0, dot(v, n_hat) > 0.0);
    let n = n_hat * sign;
    let c = dot(v, n);
    var out: array<vec3<f32>, 2>;
    for (var k = 0; k < 2; k++) {
        let dv = (dd[k] - v * dot(v, dd[k])) / d_len;
        let dn = (dn_raw[k] - n_hat * dot(n_hat, dn_raw[k])) * (sign / n_len);
        let dc = dot(dv, n) + dot(v, dn);
        let dr = dv - (n * dc + dn * c) * 2.0;
        let finite = all(abs(dr) < vec3<f32>(3.0e38));
        out[k] = select(vec3<f32>(0.0), dr, finite);
    }
    return out;
}

// passes.rs `Reflection::sample`: footprint-filtered, or one bilinear tap in the CPU's
// bilinear mode. Every cube lookup of the backend goes through here.
fn reflection(bubble: u32, dir: vec3<f32>, derivatives: array<vec3<f32>, 2>) -> vec3<f32> {
    if (scene.reflection == REFLECTION_CUBE) {
        return cube_footprint(bubble, dir, derivatives[0], derivatives[1]);
    }
    if (scene.reflection == REFLECTION_CUBE_BILINEAR) {
        return cube_sample(bubble, dir);
    }
    return static_reflection(dir, derivatives);
}

// parallax.rs `ground_parallax`: the direction from `centre` to where the ray from film
// point `p` along unit `dir` meets the ground `y = height_m`; `dir` itself when it does
// not, or when `p` and `centre` are on opposite sides of the plane.
fn ground_parallax(centre: vec3<f32>, p: vec3<f32>, dir: vec3<f32>, height_m: f32) -> vec3<f32> {
    let above = p.y - height_m;
    if (!(dir.y * above < 0.0 && (centre.y - height_m) * above > 0.0)) {
        return dir;
    }
    let to_hit = p - dir * (above / dir.y) - centre;
    let len = length(to_hit);
    if (!(len > 0.0 && len < 3.0e38)) {
        return dir;
    }
    return to_hit / len;
}

// passes.rs `LightSight::visibility`: the highlight filter (see its documentation).
fn light_visibility(light: Light, p: vec3<f32>, reflected: vec3<f32>, pixel_angle_rad: f32) -> f32 {
    let to_light = light.position.xyz - p;
    let dist = length(to_light);
    let radius = light.position.w;
    if (dist <= radius) {
        return 1.0;
    }
    let cos_gamma = dot(reflected, to_light) / dist;
    let sin_alpha = radius / dist;
    let w = max(pixel_angle_rad, 1e-5);
    let reach = PI * sin_alpha + 2.5 * w;
    if (1.0 - cos_gamma > 0.5 * reach * reach) {
        return 0.0;
    }
    let alpha = asin(sin_alpha);
    let gamma = atan2(length(cross(reflected, to_light)), cos_gamma * dist);
    let sigma = HIGHLIGHT_SIGMA_PX * w;
    if (alpha <= 2.0 * sigma) {
        let s2 = sigma * sigma + 0.25 * alpha * alpha;
        return alpha * alpha / (2.0 * s2) * exp(-gamma * gamma / (2.0 * s2));
    }
    return clamp((alpha - gamma) / w + 0.5, 0.0, 1.0);
}

// Linear texel `i` of the film texture: [thickness_nm, coverage].
fn film_texel(i: u32) -> vec2<f32> {
    let width = textureDimensions(film_texels).x;
    return textureLoad(film_texels, vec2<u32>(i % width, i / width), 0).xy;
}

// film_field.rs `FilmField::sample`: (thickness_nm, coverage) at material direction
// `dir`, the coverage-weighted bilinear thickness Σ (w c / Σ w c) h (0 when Σ w c = 0) and
// the plain bilinear coverage, from the bordered faces (seamless across edges) of the
// field whose first texel is `film.x` and face size `film.y`.
fn film_sample(film: vec2<u32>, dir: vec3<f32>) -> vec2<f32> {
    let fst = face_coordinates(dir);
    let n = f32(film.y);
    let m = film.y + 2u;
    let hi = f32(m - 1u);
    // Interior texel i has its centre at s = (2i + 1)/n − 1 and is stored at i + 1.
    let fx = min(max((fst.y + 1.0) * 0.5 * n + 0.5, 0.0), hi);
    let fy = min(max((fst.z + 1.0) * 0.5 * n + 0.5, 0.0), hi);
    let x0 = min(u32(fx), m - 2u);
    let y0 = min(u32(fy), m - 2u);
    let tx = fx - f32(x0);
    let ty = fy - f32(y0);
    let base = film.x + (u32(fst.x) * m + y0) * m + x0;
    let a = film_texel(base);
    let b = film_texel(base + 1u);
    let c = film_texel(base + m);
    let d = film_texel(base + m + 1u);
    let w = vec4<f32>((1.0 - tx) * (1.0 - ty), tx * (1.0 - ty), (1.0 - tx) * ty, tx * ty);
    let wc = w * vec4<f32>(a.y, b.y, c.y, d.y);
    let sum = wc.x + wc.y + wc.z + wc.w;
    var thickness_nm = 0.0;
    if (sum > 0.0) {
        // Each weight divided on its own: at a texel's centre it is exactly 1.
        let k = wc / sum;
        thickness_nm = k.x * a.x + k.y * b.x + k.z * c.x + k.w * d.x;
    }
    let top = a.y + (b.y - a.y) * tx;
    let bottom = c.y + (d.y - c.y) * tx;
    return vec2<f32>(thickness_nm, clamp(top + (bottom - top) * ty, 0.0, 1.0));
}

// The film as passes.rs `BubbleCtx::shade` sees it from the viewer, with its coverage
// (1 without a film field; 0 is a hole: no film at all).
struct Film {
    v: vec3<f32>,
    n: vec3<f32>,
    c: f32,
    cos_theta: f32,
    thickness_nm: f32,
    coverage: f32,
}

fn film_of(in: BubbleOut) -> Film {
    let v = normalize_or(in.world - view.eye.xyz, view.forward.xyz);
    var n = normalize_or(in.normal, -v);
    var c = dot(v, n);
    // Face the film towards the viewer: back faces show the film from inside.
    if (c > 0.0) {
        n = -n;
        c = -c;
    }
    var thickness_nm = max(in.thickness_nm, 0.0);
    var coverage = 1.0;
    if (in.film.y != 0u) {
        // With a film field the field's thickness replaces the vertex thickness.
        let s = film_sample(in.film, in.material_dir);
        thickness_nm = s.x;
        coverage = s.y;
    }
    return Film(v, n, c, min(-c, 1.0), thickness_nm, coverage);
}

fn film_reflectivity(f: Film) -> vec3<f32> {
    return lut_sample(scene.reflectivity_table, f.thickness_nm, f.cos_theta);
}

// The multiplicative pass, blended (Zero, OneMinusSrc): dest ← dest · T.
@fragment
fn fs_bubble_transmit(in: BubbleOut) -> @location(0) vec4<f32> {
    let f = film_of(in);
    if (f.coverage <= 0.0) {
        // A hole: T = 1, the destination stays as it is.
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    var t = vec3<f32>(1.0) - film_reflectivity(f);
    if (scene.transmittance_table != NO_TABLE) {
        t = lut_sample(scene.transmittance_table, f.thickness_nm, f.cos_theta);
    }
    // Blended by coverage: 1 − T' = c·(1 − T) (exactly 1 − T at c = 1).
    return vec4<f32>((vec3<f32>(1.0) - t) * f.coverage, 1.0);
}

// The additive pass, blended (One, One): dest ← dest + R ⊙ env(reflect) + highlights.
@fragment
fn fs_bubble_add(in: BubbleOut) -> @location(0) vec4<f32> {
    // passes.rs `BubbleCtx::reflection_derivatives`: ∂n = (∂(n/w) − n·∂(1/w))·w. Derivatives
    // need uniform control flow, so they come first.
    let w = 1.0 / in.inv_w;
    let n_centre = in.normal_over_w * w;
    let dn_raw = array<vec3<f32>, 2>(
        (dpdxFine(in.normal_over_w) - n_centre * dpdxFine(in.inv_w)) * w,
        (dpdyFine(in.normal_over_w) - n_centre * dpdyFine(in.inv_w)) * w);
    let f = film_of(in);
    if (f.coverage <= 0.0) {
        // A hole adds nothing.
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let r = film_reflectivity(f);
    let reflected = f.v - f.n * (2.0 * f.c);
    let rel = in.world - view.eye.xyz;
    let dd = array<vec3<f32>, 2>(view.right.xyz * view.tan_half_per_px.z,
        -view.up.xyz * view.tan_half_per_px.w);
    let derivatives = reflection_derivatives(rel / dot(rel, view.forward.xyz), dd, in.normal,
        dn_raw);
    var dir = reflected;
    if (scene.ground_parallax != 0u) {
        dir = ground_parallax(in.centre, in.world, reflected, scene.ground_height_m);
    }
    var add = r * reflection(in.bubble, dir, derivatives);
    for (var i = 0u; i < scene.light_count; i++) {
        let light = lights[i];
        let vis = light_visibility(light, in.world, reflected, in.pixel_angle_rad);
        if (vis > 0.0) {
            let l = lut_sample(u32(light.radiance.w), f.thickness_nm, f.cos_theta);
            add += l * light.gain.xyz * vis;
        }
    }
    // Blended by coverage: add' = c·add.
    return vec4<f32>(add * f.coverage, 1.0);
}

// ---- cube mip chain ------------------------------------------------------------------------
//
// cubemap.rs `CubeMap::build_mips` on the faces the GPU rendered: level 0 copied from the
// face texture (borders included, as rendered), then per level the box filter of
// `Level::downsample_from` and the border refill of `Level::fill_borders_from_neighbours`.
// Each is one dispatch over (x, y, bubble·6 + face); the level's parameters are a uniform.

struct MipStep {
    // level written, face size of the level read, face size of the level written, 0
    level_sizes: vec4<u32>,
}

@group(3) @binding(0) var faces_in: texture_2d_array<f32>;
@group(3) @binding(1) var<storage, read_write> mips_out: array<f32>;
@group(3) @binding(2) var<uniform> mip_step: MipStep;

fn mip_out_index(layer: u32, level: u32, x: u32, y: u32) -> u32 {
    return mip_index(layer / 6u, level, layer % 6u, x, y);
}

fn store_mip(i: u32, c: vec3<f32>) {
    mips_out[i] = c.x;
    mips_out[i + 1u] = c.y;
    mips_out[i + 2u] = c.z;
}

fn load_mip(i: u32) -> vec3<f32> {
    return vec3<f32>(mips_out[i], mips_out[i + 1u], mips_out[i + 2u]);
}

@compute @workgroup_size(8, 8, 1)
fn cs_mip_copy(@builtin(global_invocation_id) id: vec3<u32>) {
    let m = scene.cube_face_size + 2u;
    if (id.x >= m || id.y >= m) {
        return;
    }
    let c = textureLoad(faces_in, vec2<i32>(id.xy), i32(id.z), 0).xyz;
    store_mip(mip_out_index(id.z, 0u, id.x, id.y), c);
}

// cubemap.rs `box_weights` of output texel `i`: the first source texel, its count and
// per source texel `j` the overlap over the output's width (`box_weight`).
fn box_span(i: u32, n: u32, n_out: u32) -> vec2<u32> {
    let ratio = f32(n) / f32(n_out);
    let lo = f32(i) * ratio;
    let hi = f32(i + 1u) * ratio;
    return vec2<u32>(u32(floor(lo)), min(u32(ceil(hi)), n));
}

fn box_weight(i: u32, j: u32, n: u32, n_out: u32) -> f32 {
    let ratio = f32(n) / f32(n_out);
    let lo = f32(i) * ratio;
    let hi = f32(i + 1u) * ratio;
    return max(min(hi, f32(j + 1u)) - max(lo, f32(j)), 0.0) / ratio;
}

@compute @workgroup_size(8, 8, 1)
fn cs_mip_downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = mip_step.level_sizes.x;
    let n = mip_step.level_sizes.y;
    let n_out = mip_step.level_sizes.z;
    if (id.x >= n_out || id.y >= n_out) {
        return;
    }
    let sy = box_span(id.y, n, n_out);
    let sx = box_span(id.x, n, n_out);
    var sum = vec3<f32>(0.0);
    for (var j = sy.x; j < sy.y; j++) {
        let vy = box_weight(id.y, j, n, n_out);
        for (var i = sx.x; i < sx.y; i++) {
            let vx = box_weight(id.x, i, n, n_out);
            sum += load_mip(mip_out_index(id.z, level - 1u, i + 1u, j + 1u)) * (vx * vy);
        }
    }
    store_mip(mip_out_index(id.z, level, id.x + 1u, id.y + 1u), sum);
}

// render-scene `CubeMap::border_source_table`, one chain's worth: per texel of the chain
// the texel it copies (a border texel's source on the neighbouring face). Taken from the
// CPU rather than computed here: at a face's corners the choice of face turns on the
// last bit of the coordinates, and a GPU's division is not correctly rounded.
@group(3) @binding(6) var<storage, read> mip_border_source: array<u32>;

@compute @workgroup_size(8, 8, 1)
fn cs_mip_borders(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = mip_step.level_sizes.x;
    let n = mip_step.level_sizes.z;
    let m = n + 2u;
    if (id.x >= m || id.y >= m) {
        return;
    }
    if (id.x != 0u && id.y != 0u && id.x != m - 1u && id.y != m - 1u) {
        return;
    }
    let i = mip_out_index(id.z, level, id.x, id.y);
    let chain = (id.z / 6u) * mip_offset(mip_levels());
    let source = mip_border_source[(i - chain) / 3u];
    store_mip(i, load_mip(chain + 3u * source));
}

// The frame's passes in WGSL, each a port of the CPU backend (the specification):
// background sky (passes.rs `OpaqueCtx::sky`), ground plane (`shade_ground`), opaque
// objects and light spheres (`OpaqueCtx::shade`, shading.rs `lit`), and the bubble film
// (`BubbleCtx::shade`, `light_visibility`). Constants shared with Rust are injected below.

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
    // width, height, near_m, 0
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
}

struct Material {
    // albedo a, checker scale in metres
    a: vec4<f32>,
    // albedo b, shininess
    b: vec4<f32>,
    // specular rgb, pattern kind
    specular: vec4<f32>,
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
@group(2) @binding(0) var luts: texture_2d<f32>;
@group(2) @binding(1) var<storage, read> lut_info: array<LutInfo>;
@group(2) @binding(2) var cubes: texture_2d_array<f32>;

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

// shading.rs `object_albedo` (solid, and the 3-D checker box-filtered over `footprint`).
fn object_albedo(m: Material, p: vec3<f32>, footprint: vec3<f32>) -> vec3<f32> {
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
    let inv_t = max(ground_inv_depth(in.pix), 1e-30);
    let t = 1.0 / inv_t;
    let d = view_ray(in.pix);
    let p = view.eye.xyz + d * t;
    // passes.rs `shade_ground`: footprint of one pixel on the plane.
    let inv_dy = t * view.ground.w;
    let ddx = view.ground_ddx.xyz;
    let ddy = view.ground_ddy.xyz;
    let dpx = (ddx - d * (ddx.y * inv_dy)) * t;
    let dpy = (ddy - d * (ddy.y * inv_dy)) * t;
    let footprint = min(vec2<f32>(abs(dpx.x) + abs(dpy.x), abs(dpx.z) + abs(dpy.z)), vec2<f32>(1e9));
    let m = materials[scene.ground_material];
    var albedo = m.a.xyz;
    if (m.specular.w == PATTERN_CHECKER) {
        let inv = 1.0 / m.a.w;
        let w = filtered_checker(vec2<f32>(p.x * inv, p.z * inv), footprint * inv);
        albedo = lerp3(m.a.xyz, m.b.xyz, w);
    }
    let normal = vec3<f32>(0.0, view.ground_ddx.w, 0.0);
    return vec4<f32>(lit(m, albedo, p, normal, d), 1.0);
}

// ---- opaque objects and light spheres ----------------------------------------------------

struct ObjectIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tag: u32,
}

struct ObjectOut {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) world: vec3<f32>,
    @location(1) @interpolate(perspective, centroid) normal: vec3<f32>,
    @location(2) @interpolate(flat) tag: u32,
}

@vertex
fn vs_object(in: ObjectIn) -> ObjectOut {
    return ObjectOut(clip_of(in.position), in.position, in.normal, in.tag);
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
    return vec4<f32>(lit(m, object_albedo(m, in.world, footprint), in.world, n, v), 1.0);
}

// ---- bubbles -----------------------------------------------------------------------------

struct BubbleIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) thickness_nm: f32,
    // renderer.rs `reflection_rate` of the vertex's triangle
    @location(3) pixel_angle_rad: f32,
    @location(4) bubble: u32,
}

struct BubbleOut {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) world: vec3<f32>,
    @location(1) @interpolate(perspective, centroid) normal: vec3<f32>,
    @location(2) @interpolate(perspective, centroid) thickness_nm: f32,
    @location(3) @interpolate(flat) pixel_angle_rad: f32,
    @location(4) @interpolate(flat) bubble: u32,
}

@vertex
fn vs_bubble(in: BubbleIn) -> BubbleOut {
    return BubbleOut(clip_of(in.position), in.position, in.normal, in.thickness_nm,
        in.pixel_angle_rad, in.bubble);
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

// cubemap.rs `CubeMap::sample`: seamless bilinear lookup in bubble `bubble`'s bordered
// faces (layers 6·bubble .. 6·bubble + 5, each (N + 2)² texels). Every cube lookup of the
// backend goes through this one function.
fn cube_sample(bubble: u32, dir: vec3<f32>) -> vec3<f32> {
    let fst = face_coordinates(dir);
    let n = f32(scene.cube_face_size);
    let m = n + 2.0;
    let fx = clamp((fst.y + 1.0) * 0.5 * n + 0.5, 0.0, m - 1.0);
    let fy = clamp((fst.z + 1.0) * 0.5 * n + 0.5, 0.0, m - 1.0);
    let x0 = min(floor(fx), m - 2.0);
    let y0 = min(floor(fy), m - 2.0);
    let tx = fx - x0;
    let ty = fy - y0;
    let layer = i32(bubble * 6u + u32(fst.x));
    let xy = vec2<i32>(i32(x0), i32(y0));
    let a = textureLoad(cubes, xy, layer, 0).xyz;
    let b = textureLoad(cubes, xy + vec2<i32>(1, 0), layer, 0).xyz;
    let c = textureLoad(cubes, xy + vec2<i32>(0, 1), layer, 0).xyz;
    let d = textureLoad(cubes, xy + vec2<i32>(1, 1), layer, 0).xyz;
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
    return top + (bottom - top) * ty;
}

fn reflection(bubble: u32, dir: vec3<f32>) -> vec3<f32> {
    if (scene.reflection == REFLECTION_CUBE) {
        return cube_sample(bubble, dir);
    }
    return env_radiance(dir);
}

// passes.rs `light_visibility`: the highlight filter (see its documentation).
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

// The film as passes.rs `BubbleCtx::shade` sees it from the viewer.
struct Film {
    v: vec3<f32>,
    n: vec3<f32>,
    c: f32,
    cos_theta: f32,
    thickness_nm: f32,
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
    return Film(v, n, c, min(-c, 1.0), max(in.thickness_nm, 0.0));
}

fn film_reflectivity(f: Film) -> vec3<f32> {
    return lut_sample(scene.reflectivity_table, f.thickness_nm, f.cos_theta);
}

// The multiplicative pass, blended (Zero, OneMinusSrc): dest ← dest · T.
@fragment
fn fs_bubble_transmit(in: BubbleOut) -> @location(0) vec4<f32> {
    let f = film_of(in);
    var t = vec3<f32>(1.0) - film_reflectivity(f);
    if (scene.transmittance_table != NO_TABLE) {
        t = lut_sample(scene.transmittance_table, f.thickness_nm, f.cos_theta);
    }
    return vec4<f32>(vec3<f32>(1.0) - t, 1.0);
}

// The additive pass, blended (One, One): dest ← dest + R ⊙ env(reflect) + highlights.
@fragment
fn fs_bubble_add(in: BubbleOut) -> @location(0) vec4<f32> {
    let f = film_of(in);
    let r = film_reflectivity(f);
    let reflected = f.v - f.n * (2.0 * f.c);
    var add = r * reflection(in.bubble, reflected);
    for (var i = 0u; i < scene.light_count; i++) {
        let light = lights[i];
        let vis = light_visibility(light, in.world, reflected, in.pixel_angle_rad);
        if (vis > 0.0) {
            let l = lut_sample(u32(light.radiance.w), f.thickness_nm, f.cos_theta);
            add += l * light.gain.xyz * vis;
        }
    }
    return vec4<f32>(add, 1.0);
}

//! The scene as the shaders read it: uniform and storage buffer bytes laid out as the
//! structs of `scene.wgsl`, vertex streams, and the stacked LUT texture. Pure CPU code.

// Without the `wgpu` feature only the naga layout test uses this module.
#![cfg_attr(not(feature = "wgpu"), allow(dead_code))]

use glam::{Mat3, Vec3};

use super::GpuError;
use super::bytes::Bytes;
use super::water_data::WaterData;
use render_scene::bubble_order::{far_to_near, is_front_facing, reflection_rate};
use render_scene::camera::View;
use render_scene::ground_view::{GroundFilter, GroundView};
use render_scene::parallax::proxy_ground_height_m;
use render_scene::tessellate::{Geometry, tessellate};
use render_scene::{
    Environment, FilmTables, Light, Material, Pattern, ReflectionFilter, ReflectionMode,
    ReflectionParallax, RenderScene, RenderSettings, Sky,
};

/// `Material.specular.w` of a solid albedo.
pub(super) const PATTERN_SOLID: f32 = 0.0;
/// `Material.specular.w` of a checkerboard.
pub(super) const PATTERN_CHECKER: f32 = 1.0;
/// `Material.specular.w` of an image (`Material.image` in the image atlas).
pub(super) const PATTERN_TEXTURED: f32 = 2.0;
/// `Scene.env_kind` of a procedural sky.
pub(super) const ENV_SKY: u32 = 0;
/// `Scene.env_kind` of a uniform environment.
pub(super) const ENV_UNIFORM: u32 = 1;
/// `Scene.env_kind` of an equirect (latitude-longitude) image in the image atlas.
pub(super) const ENV_EQUIRECT: u32 = 2;
/// `Scene.env_kind` of six cube faces (level 0, bordered) in the image atlas.
pub(super) const ENV_CUBE: u32 = 3;
/// `Scene.reflection` of dynamic cube maps.
pub(super) const REFLECTION_CUBE: u32 = 0;
/// `Scene.reflection` of the static environment.
pub(super) const REFLECTION_ENVIRONMENT: u32 = 1;
/// `Scene.reflection` of dynamic cube maps read with one bilinear tap
/// ([`ReflectionFilter::Bilinear`]).
pub(super) const REFLECTION_CUBE_BILINEAR: u32 = 2;
/// `Scene.reflection` of the static environment when it is cube faces: their mip chain is
/// chain 0 of `cube_mips`, read with the footprint filter.
pub(super) const REFLECTION_ENV_CUBE: u32 = 3;
/// [`REFLECTION_ENV_CUBE`] read with one bilinear tap ([`ReflectionFilter::Bilinear`]).
pub(super) const REFLECTION_ENV_CUBE_BILINEAR: u32 = 4;
/// `Scene.reflection` of a sphere map (`Scene.sphere_image` in the image atlas).
pub(super) const REFLECTION_SPHERE_MAP: u32 = 5;
/// `Scene.transmittance_table` when `T = 1 − R`.
pub(super) const NO_TABLE: u32 = u32::MAX;

/// Bytes of the WGSL `View` struct.
pub(super) const VIEW_BYTES: u64 = 9 * 16;
/// Bytes of one object vertex: position, normal, tag, texture uv.
pub(super) const OBJECT_VERTEX_BYTES: u64 = 36;
/// Bytes of one bubble vertex: position, normal, thickness, pixel angle, bubble index,
/// material direction (zero without a film field), the bubble's film field as (first
/// texel in the film texture, face size; face size 0: no field), and the bubble's centre
/// (where its cube map is rendered from).
pub(super) const BUBBLE_VERTEX_BYTES: u64 = 68;

/// How bubbles read their dynamic cube maps: the renderer's choices.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct CubeReads {
    /// Footprint-filtered or one bilinear tap.
    pub filter: ReflectionFilter,
    /// Corrected for the ground's parallax, or from the centre.
    pub parallax: ReflectionParallax,
}

/// The WGSL `View` of `view`, with the ground plane's constants when it is drawn.
pub(super) fn view_bytes(view: &View, ground: Option<&GroundView<'_>>) -> Vec<u8> {
    let mut b = Bytes::default();
    for axis in [view.eye, view.forward, view.right, view.up] {
        b.vec4(axis.to_array(), 0.0);
    }
    b.vec4(
        [view.tan_half_x, view.tan_half_y, view.x_per_px],
        view.y_per_px,
    );
    // Its last lane: 1 when the ground's checker is filtered over half pixels.
    let halves = ground.is_some_and(|g| g.filter == GroundFilter::Halves);
    b.vec4(
        [view.width as f32, view.height as f32, view.near_m],
        f32::from(u8::from(halves)),
    );
    match ground {
        Some(g) => {
            b.vec4([g.c, g.gx, g.gy], g.inv_height);
            b.vec4(g.ddx.to_array(), g.normal.y);
            b.vec4(g.ddy.to_array(), 1.0);
        }
        None => {
            b.vec4([0.0; 3], 0.0)
                .vec4([0.0; 3], 0.0)
                .vec4([0.0; 3], 0.0);
        }
    }
    debug_assert_eq!(b.0.len() as u64, VIEW_BYTES);
    b.0
}

/// The ground plane's visible part of `view` as a triangle list of `(ndc x, ndc y, depth)`:
/// the screen rectangle clipped, in pixel space, to where the plane's inverse depth `1/t`
/// lies in `(0, 1/near]` (the CPU's per-sample test `1/t > 0`), with depth `near/t`.
///
/// Clipping here rather than by the GPU's depth clip gives every internal edge of the
/// polygon the same two vertices in both triangles, so coverage stays watertight.
pub(super) fn ground_triangles(view: &View, g: &GroundView<'_>) -> Vec<[f32; 3]> {
    let (w, h) = (view.width as f32, view.height as f32);
    let inv_depth = |p: [f32; 2]| g.inv_depth(p[0], p[1]);
    let mut poly = vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]];
    poly = clip(&poly, inv_depth);
    poly = clip(&poly, |p| 1.0 / view.near_m - inv_depth(p));
    let vertex = |p: [f32; 2]| {
        let z = (view.near_m * inv_depth(p)).clamp(0.0, 1.0);
        [2.0 * p[0] / w - 1.0, 1.0 - 2.0 * p[1] / h, z]
    };
    let mut out = Vec::new();
    for k in 1..poly.len().saturating_sub(1) {
        out.extend([vertex(poly[0]), vertex(poly[k]), vertex(poly[k + 1])]);
    }
    out
}

/// The convex polygon `poly` cut to where the affine `f` is ≥ 0 (Sutherland–Hodgman).
fn clip(poly: &[[f32; 2]], f: impl Fn([f32; 2]) -> f32) -> Vec<[f32; 2]> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (k, &a) in poly.iter().enumerate() {
        let b = poly[(k + 1) % poly.len()];
        let (fa, fb) = (f(a), f(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            let t = fa / (fa - fb);
            out.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
        }
    }
    out
}

/// Everything of a frame that the shaders read, packed.
#[derive(Debug, Default)]
pub(super) struct SceneData {
    /// The WGSL `Scene` uniform.
    pub scene: Vec<u8>,
    /// `array<Material>`: the objects' materials, then the ground's, then the water
    /// floor's.
    pub materials: Vec<u8>,
    /// `array<Light>`.
    pub lights: Vec<u8>,
    /// Object triangles (three vertices each), then the light spheres'.
    pub objects: Vec<u8>,
    /// Vertices of the objects alone (what cube faces draw).
    pub object_vertices: u32,
    /// Vertices of objects and light spheres.
    pub all_vertices: u32,
    /// Bubble triangles in drawing order.
    pub bubbles: Vec<u8>,
    /// Vertex ranges of the bubble draws, in order: far to near, back faces then front.
    pub bubble_draws: Vec<std::ops::Range<u32>>,
    /// Per bubble: its film field as (first texel, face size), `(0, 0)` without one (for
    /// the bubble vertices of other views, [`bubble_vertices`]).
    pub film_places: Vec<[u32; 2]>,
    /// The water surface, when the scene has one.
    pub water: Option<WaterData>,
    /// The LUT texture: `(width, height, Rgba32Float texels)`.
    pub luts: LutTexture,
    /// `array<LutInfo>`.
    pub lut_info: Vec<u8>,
    /// The film texture: every distinct film field's bordered faces
    /// (`FilmField::bordered`, `[thickness_nm, coverage]` as Rg32Float), one after
    /// another, texel `i` at `(i mod width, i div width)`.
    pub films: FilmTexture,
    /// The image atlas (`Atlas`): the environment's image or cube faces, the sphere map,
    /// the materials' images, as Rgba32Float.
    pub images: LutTexture,
    /// The environment cube faces' whole mip chain as f32 RGB in `CubeMap`'s level layout
    /// (what `cube_mips` holds per bubble) when the static environment reflects in the
    /// bubbles; empty otherwise.
    pub env_chain: Vec<u8>,
}

/// Why the wgpu backend cannot draw `what` on this device (an adapter limit, named).
fn unsupported(what: impl Into<String>) -> GpuError {
    GpuError::Unsupported(what.into())
}

impl SceneData {
    /// Packs `scene` for the main view `view` (bubbles sorted and split by side for its eye),
    /// rendered with `frame_samples` samples a pixel.
    pub(super) fn new(
        scene: &RenderScene,
        tables: &FilmTables,
        settings: &RenderSettings,
        (view, frame_samples): (&View, u32),
        max_texture_side: u32,
        reads: CubeReads,
    ) -> Result<SceneData, GpuError> {
        let mut objects = Geometry::default();
        let mut light_spheres = Geometry::default();
        let mut materials = tessellate(scene, &mut objects, &mut light_spheres);
        let ground_material = materials.len() as u32;
        if let Some(g) = &scene.ground {
            materials.push(&g.material);
        }
        let water = scene.water.as_ref().map(|w| {
            materials.push(&w.floor);
            WaterData::new(w, scene, &settings.reflection, materials.len() as u32 - 1)
        });
        let mut object_bytes = Bytes::default();
        push_geometry(&mut object_bytes, &objects);
        let object_vertices = (object_bytes.0.len() as u64 / OBJECT_VERTEX_BYTES) as u32;
        if settings.draw_lights {
            push_geometry(&mut object_bytes, &light_spheres);
        }
        let all_vertices = (object_bytes.0.len() as u64 / OBJECT_VERTEX_BYTES) as u32;
        let (films, film_places) = film_fields(scene, max_texture_side)?;
        let (bubbles, bubble_draws) = bubble_vertices(scene, view, &film_places);
        let (luts, lut_info, first_light) = stack_tables(tables, max_texture_side)?;
        // A light without a table of its own uses the reflectivity (table 0).
        let light_tables: Vec<u32> = scene
            .lights
            .iter()
            .map(|l| l.light_lut.map_or(0, |i| first_light + i as u32))
            .collect();
        let mut atlas = Atlas::default();
        let env_image = match &scene.environment {
            Environment::Equirect(t) => atlas.push(t.texels(), t.width(), t.height()),
            Environment::CubeFaces(c) => atlas.push(c.level_texels(0), c.face_size(), 0),
            Environment::Sky(_) | Environment::Uniform(_) => [0; 4],
        };
        let sphere = match &settings.reflection {
            ReflectionMode::SphereMap(map) => {
                let t = map.texture();
                let image = atlas.push(t.texels(), t.width(), t.height());
                Some((image, map.map_from_world()))
            }
            _ => None,
        };
        // The static environment's cube faces are read as a bubble's cube map is, from
        // `cube_mips` (chain 0): `face_size` is then theirs.
        let env_cube = match (&settings.reflection, &scene.environment) {
            (ReflectionMode::StaticEnvironment, Environment::CubeFaces(c)) => Some(c),
            _ => None,
        };
        let face_size = match (&settings.reflection, env_cube) {
            (ReflectionMode::DynamicCubeMap { face_size }, _) => *face_size as u32,
            (_, Some(c)) => c.face_size() as u32,
            _ => 0,
        };
        let material_bytes = material_bytes(&materials, &mut atlas);
        let env_chain: Vec<u8> = env_cube.map_or(Vec::new(), |c| {
            (0..c.levels())
                .flat_map(|level| c.level_texels(level))
                .flatten()
                .flat_map(|x| x.to_le_bytes())
                .collect()
        });
        Ok(SceneData {
            scene: scene_bytes(
                scene,
                &settings.reflection,
                reads,
                [face_size, ground_material, frame_samples],
                env_image,
                sphere,
                tables,
            ),
            materials: material_bytes,
            lights: light_bytes(&scene.lights, &light_tables),
            objects: object_bytes.0,
            object_vertices,
            all_vertices,
            bubbles,
            bubble_draws,
            film_places,
            water,
            luts,
            lut_info,
            films,
            images: atlas.finish(max_texture_side)?,
            env_chain,
        })
    }
}

/// Images as `scene.wgsl` reads them (`images`): each image's texels row-major, one image
/// after another, linear texel `i` at `(i mod width, i div width)` of one Rgba32Float
/// texture (rows of at most the device's side, the last row padded).
#[derive(Debug, Default)]
struct Atlas {
    texels: Bytes,
}

impl Atlas {
    /// Appends `texels`; returns the WGSL descriptor `(first texel, a, b, 0)`.
    fn push(&mut self, texels: &[[f32; 3]], a: usize, b: usize) -> [u32; 4] {
        let first = self.texels.0.len() / 16;
        for t in texels {
            self.texels.vec4(*t, 1.0);
        }
        // `finish` refuses an atlas past the device's side² (< 2³²) texels.
        [first as u32, a as u32, b as u32, 0]
    }

    /// The texture `(width, height, texels)`.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`], naming the texel count and the limit, when the atlas
    /// would be taller than `max_side`.
    fn finish(mut self, max_side: u32) -> Result<LutTexture, GpuError> {
        let count = (self.texels.0.len() / 16).max(1);
        let width = count.min(max_side as usize);
        let height = count.div_ceil(width);
        if height > max_side as usize {
            return Err(unsupported(format!(
                "images of {count} texels (the environment's and the textures': their \
                 texture holds at most {max_side} × {max_side} texels on this device)"
            )));
        }
        self.texels.0.resize(16 * width * height, 0);
        Ok((width as u32, height as u32, self.texels.0))
    }
}

fn scene_bytes(
    scene: &RenderScene,
    reflection: &ReflectionMode,
    reads: CubeReads,
    [face_size, ground_material, frame_samples]: [u32; 3],
    env_image: [u32; 4],
    sphere: Option<([u32; 4], Mat3)>,
    tables: &FilmTables,
) -> Vec<u8> {
    let mut b = Bytes::default();
    let ambient = scene.irradiance.plus_uniform(scene.ambient_rgb);
    for c in ambient.coeffs() {
        b.vec4(*c, 0.0);
    }
    let (env_kind, sky, uniform) = match &scene.environment {
        Environment::Uniform(rgb) => (ENV_UNIFORM, Sky::default(), *rgb),
        Environment::Sky(sky) => (ENV_SKY, *sky, [0.0; 3]),
        Environment::Equirect(_) => (ENV_EQUIRECT, Sky::default(), [0.0; 3]),
        Environment::CubeFaces(_) => (ENV_CUBE, Sky::default(), [0.0; 3]),
    };
    let env_cube = matches!(scene.environment, Environment::CubeFaces(_));
    b.u32(env_kind).u32(scene.lights.len() as u32);
    b.u32(match (reflection, reads.filter) {
        (ReflectionMode::DynamicCubeMap { .. }, ReflectionFilter::Footprint) => REFLECTION_CUBE,
        (ReflectionMode::DynamicCubeMap { .. }, ReflectionFilter::Bilinear) => {
            REFLECTION_CUBE_BILINEAR
        }
        (ReflectionMode::StaticEnvironment, ReflectionFilter::Footprint) if env_cube => {
            REFLECTION_ENV_CUBE
        }
        (ReflectionMode::StaticEnvironment, ReflectionFilter::Bilinear) if env_cube => {
            REFLECTION_ENV_CUBE_BILINEAR
        }
        (ReflectionMode::SphereMap(_), _) => REFLECTION_SPHERE_MAP,
        _ => REFLECTION_ENVIRONMENT,
    });
    // Table 0 is the reflectivity, 1 the transmittance when there is one.
    b.u32(if tables.transmittance.is_some() {
        1
    } else {
        NO_TABLE
    });
    b.vec4(sky.zenith_rgb, 0.0)
        .vec4(sky.horizon_rgb, 0.0)
        .vec4(sky.nadir_rgb, 0.0);
    let sun = sky.sun_direction.normalize_or(Vec3::Y);
    // The same f32 expression as `Sky::radiance`'s threshold.
    b.vec4(sun.to_array(), sky.sun_radius_deg.to_radians().cos());
    let sun_on = sky.sun_rgb != [0.0; 3];
    b.vec4(sky.sun_rgb, if sun_on { 1.0 } else { 0.0 });
    b.vec4(uniform, 0.0);
    let height = scene.ground.as_ref().map_or(0.0, |g| g.height_m);
    b.u32(ground_material).f32(height).u32(face_size).u32(0);
    // On exactly where the CPU corrects (renderer.rs `ground_height_m`).
    let parallax = proxy_ground_height_m(reads.parallax, reflection, scene).is_some();
    // The main view's sample count (the water's shading point in a partly covered pixel).
    b.u32(u32::from(parallax)).u32(frame_samples).u32(0).u32(0);
    // The environment image: (first texel, width, height) of an equirect, (first texel,
    // face size) of cube faces.
    for w in env_image {
        b.u32(w);
    }
    // The sphere map: its image (first texel, width, height), then the rows of its
    // `map_from_world`.
    let (image, map_from_world) = sphere.unwrap_or(([0; 4], Mat3::IDENTITY));
    for w in image {
        b.u32(w);
    }
    for row in 0..3 {
        b.vec4(map_from_world.row(row).to_array(), 0.0);
    }
    b.0
}

/// The WGSL `array<Material>`; a textured material's image goes into `atlas`.
fn material_bytes(materials: &[&Material], atlas: &mut Atlas) -> Vec<u8> {
    let mut b = Bytes::default();
    for m in materials {
        let mut image = [0; 4];
        let (a, bb, scale, kind) = match &m.pattern {
            Pattern::Checker { a, b, scale_m } => (*a, *b, *scale_m, PATTERN_CHECKER),
            Pattern::Solid(c) => (*c, *c, 1.0, PATTERN_SOLID),
            Pattern::Textured { texture, scale_m } => {
                image = atlas.push(texture.texels(), texture.width(), texture.height());
                ([0.0; 3], [0.0; 3], *scale_m, PATTERN_TEXTURED)
            }
        };
        b.vec4(a, scale)
            .vec4(bb, m.shininess)
            .vec4(m.specular, kind);
        for w in image {
            b.u32(w);
        }
    }
    if materials.is_empty() {
        b.vec4([0.0; 3], 1.0)
            .vec4([0.0; 3], 1.0)
            .vec4([0.0; 3], 0.0)
            .vec4([0.0; 3], 0.0);
    }
    b.0
}

fn light_bytes(lights: &[Light], tables: &[u32]) -> Vec<u8> {
    let mut b = Bytes::default();
    for (l, &table) in lights.iter().zip(tables) {
        b.vec4(l.position.to_array(), l.radius_m)
            .vec4(l.radiance, table as f32)
            .vec4(l.highlight_gain(), 0.0);
    }
    if lights.is_empty() {
        b.vec4([0.0; 3], 0.0)
            .vec4([0.0; 3], 0.0)
            .vec4([0.0; 3], 0.0);
    }
    b.0
}

/// Appends `g`'s triangles as three vertices each (position, normal, tag, uv).
fn push_geometry(b: &mut Bytes, g: &Geometry) {
    for (t, &tag) in g.triangles.iter().zip(&g.tags) {
        for i in t.map(|i| i as usize) {
            let p = g.positions[i];
            let a = g.attrs[i];
            b.f32(p.x).f32(p.y).f32(p.z);
            b.f32(a[0]).f32(a[1]).f32(a[2]);
            b.u32(tag);
            b.f32(a[3]).f32(a[4]);
        }
    }
}

/// Bubble vertices in the CPU's drawing order (renderer.rs `setup_bubbles`): bubbles far
/// to near, each bubble's back faces then its front faces; one draw range per side.
///
/// `films[k]` is bubble `k`'s film field as (first texel, face size), `(0, 0)` without one.
pub(super) fn bubble_vertices(
    scene: &RenderScene,
    view: &View,
    films: &[[u32; 2]],
) -> (Vec<u8>, Vec<std::ops::Range<u32>>) {
    let mut b = Bytes::default();
    let mut draws = Vec::new();
    let mut start = 0u32;
    let centres: Vec<Vec3> = scene.bubbles.iter().map(|b| b.center()).collect();
    for k in far_to_near(&scene.bubbles, view.eye) {
        let bubble = &scene.bubbles[k];
        for front in [false, true] {
            for t in &bubble.triangles {
                if is_front_facing(bubble, *t, view.eye) != front {
                    continue;
                }
                let rate = reflection_rate(view, bubble, *t);
                for i in t.map(|i| i as usize) {
                    let (p, n) = (bubble.positions[i], bubble.normals[i]);
                    b.f32(p.x).f32(p.y).f32(p.z).f32(n.x).f32(n.y).f32(n.z);
                    b.f32(bubble.thickness_nm[i]).f32(rate).u32(k as u32);
                    // The CPU's attributes 3..6 (`setup_bubble_tris`): where the vertex
                    // sits on the film field, interpolated and looked up per pixel.
                    let m = bubble
                        .film
                        .as_ref()
                        .map_or(Vec3::ZERO, |f| f.material_dirs[i]);
                    b.f32(m.x).f32(m.y).f32(m.z);
                    b.u32(films[k][0]).u32(films[k][1]);
                    let c = centres[k];
                    b.f32(c.x).f32(c.y).f32(c.z);
                }
            }
            let end = (b.0.len() as u64 / BUBBLE_VERTEX_BYTES) as u32;
            if end > start {
                draws.push(start..end);
            }
            start = end;
        }
    }
    (b.0, draws)
}

/// A data texture `(width, height, texels)`.
pub(super) type FilmTexture = (u32, u32, Vec<u8>);

/// The film fields as `scene.wgsl` reads them: the film texture (every distinct field's
/// bordered faces, a field two bubbles share stored once, rows of at most `max_side`
/// texels, the last row padded) and per bubble its field's (first texel, face size), `(0,
/// 0)` without one.
///
/// # Errors
/// [`GpuError::Unsupported`], naming the film fields, when the texture would be taller
/// than `max_side`.
fn film_fields(
    scene: &RenderScene,
    max_side: u32,
) -> Result<(FilmTexture, Vec<[u32; 2]>), GpuError> {
    let too_large = |texels: usize| {
        unsupported(format!(
            "film fields of {texels} texels (their texture's rows hold {max_side}, at most \
             {max_side} rows on this device)"
        ))
    };
    let mut texels = Bytes::default();
    let mut stored: Vec<(*const render_scene::FilmField, u32)> = Vec::new();
    let mut places = Vec::with_capacity(scene.bubbles.len());
    for bubble in &scene.bubbles {
        let Some(film) = &bubble.film else {
            places.push([0, 0]);
            continue;
        };
        let key = std::sync::Arc::as_ptr(&film.field);
        let offset = match stored.iter().find(|(p, _)| *p == key) {
            Some(&(_, offset)) => offset,
            None => {
                let offset = texels.0.len() / 8;
                let offset = u32::try_from(offset).map_err(|_| too_large(offset))?;
                for &[h, c] in film.field.bordered() {
                    texels.f32(h).f32(c);
                }
                stored.push((key, offset));
                offset
            }
        };
        places.push([offset, film.field.face_size() as u32]);
    }
    let count = (texels.0.len() / 8).max(1);
    let width = count.min(max_side as usize);
    let height = count.div_ceil(width);
    if height > max_side as usize {
        return Err(too_large(count));
    }
    texels.0.resize(8 * width * height, 0);
    Ok(((width as u32, height as u32, texels.0), places))
}

/// The stacked LUT texture `(width, height, texels)`.
type LutTexture = (u32, u32, Vec<u8>);

/// The tables stacked in rows of one Rgba32Float texture (reflectivity, transmittance if
/// any, then the light tables), their `LutInfo`s, and the index of the first light table.
fn stack_tables(
    tables: &FilmTables,
    max_side: u32,
) -> Result<(LutTexture, Vec<u8>, u32), GpuError> {
    let mut list = vec![&tables.reflectivity];
    list.extend(tables.transmittance.as_ref());
    let first_light = list.len() as u32;
    list.extend(&tables.lights);
    let width = list.iter().map(|t| t.width()).max().unwrap_or(2);
    let height: usize = list.iter().map(|t| t.height()).sum();
    if width > max_side as usize || height > max_side as usize {
        return Err(GpuError::TooLarge {
            size: (width as u32, height as u32),
            max_side,
        });
    }
    let mut texels = Bytes::default();
    let mut info = Bytes::default();
    let mut row0 = 0usize;
    for t in &list {
        for row in t.texels().chunks_exact(t.width()) {
            for c in row {
                texels.vec4(*c, 1.0);
            }
            for _ in t.width()..width {
                texels.vec4([0.0; 3], 0.0);
            }
        }
        // The same f32 expression as `LutSampler::new`'s `d_scale`.
        let d_scale = (t.width() - 1) as f32 / t.thickness_max_nm();
        info.f32(row0 as f32)
            .f32(t.width() as f32)
            .f32(t.height() as f32)
            .f32(d_scale);
        row0 += t.height();
    }
    Ok(((width as u32, height as u32, texels.0), info.0, first_light))
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use render_scene::{BubbleFilm, BubbleMesh, Camera, FilmField, Ground, Texture, Vec3};

    use super::*;

    fn words(bytes: &[u8]) -> Vec<u32> {
        bytes
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes(w.try_into().unwrap()))
            .collect()
    }

    fn floats(bytes: &[u8]) -> Vec<f32> {
        words(bytes).into_iter().map(f32::from_bits).collect()
    }

    #[test]
    fn film_fields_are_packed_once_each_with_every_vertex_material_direction() {
        let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 40.0);
        let mut scene = RenderScene::new(camera, Environment::Uniform([1.0; 3]));
        let settings = RenderSettings::default();
        let plain = BubbleMesh {
            positions: vec![Vec3::X, Vec3::Y, Vec3::Z],
            normals: vec![Vec3::X, Vec3::Y, Vec3::Z],
            thickness_nm: vec![500.0; 3],
            triangles: vec![[0, 1, 2]],
            film: None,
        };
        let (h, c): (Vec<f32>, Vec<f32>) = (0..24).map(|i| (10.0 * i as f32, 0.5)).unzip();
        let shared = Arc::new(FilmField::try_new(2, h, c).unwrap());
        let other = Arc::new(FilmField::try_new(1, vec![700.0; 6], vec![1.0; 6]).unwrap());
        let dirs = vec![
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::NEG_Y,
            Vec3::new(0.0, 0.0, -5.0),
        ];
        let film = |field: &Arc<FilmField>| {
            Some(BubbleFilm {
                field: field.clone(),
                material_dirs: dirs.clone(),
            })
        };
        scene.bubbles = vec![plain.clone(); 4];
        scene.bubbles[1].film = film(&shared);
        scene.bubbles[2].film = film(&other);
        scene.bubbles[3].film = film(&shared);
        let tables = FilmTables::from_reflectivity(
            render_scene::Lut::try_from_fn(4, 4, 1000.0, |_, _| [0.1; 3]).unwrap(),
        );
        let view = scene.camera.view(16, 16);
        // Rows of at most 50 texels: 6·4² + 6·3² = 150 texels, three rows.
        let data = SceneData::new(
            &scene,
            &tables,
            &settings,
            (&view, 1),
            50,
            CubeReads::default(),
        )
        .unwrap();
        let (width, height, bytes) = &data.films;
        assert_eq!((*width, *height), (50, 3));
        let want: Vec<f32> = shared
            .bordered()
            .iter()
            .chain(other.bordered())
            .flatten()
            .copied()
            .collect();
        assert_eq!(floats(bytes), want);
        // Bubble 0 none; 1 and 3 share the first field (6·4² texels); 2 after it. Every
        // vertex carries its material direction (zero without a field) and its field.
        let first = 6 * 4 * 4;
        let places = [[0, 0], [0, 2], [first, 1], [0, 2]];
        let vertices = words(&data.bubbles);
        let stride = (BUBBLE_VERTEX_BYTES / 4) as usize;
        assert_eq!(vertices.len() % stride, 0);
        let mut seen = [0usize; 4];
        for v in vertices.chunks_exact(stride) {
            let k = v[8] as usize;
            seen[k] += 1;
            let m = Vec3::new(
                f32::from_bits(v[9]),
                f32::from_bits(v[10]),
                f32::from_bits(v[11]),
            );
            if k == 0 {
                assert_eq!(m, Vec3::ZERO);
            } else {
                assert!(dirs.contains(&m), "bubble {k}: {m}");
            }
            assert_eq!([v[12], v[13]], places[k], "bubble {k}");
        }
        assert_eq!(seen, [3; 4]);
        // Too tall for the device: named, never drawn otherwise.
        let err = SceneData::new(
            &scene,
            &tables,
            &settings,
            (&view, 1),
            10,
            CubeReads::default(),
        )
        .unwrap_err();
        assert!(matches!(err, GpuError::Unsupported(_)), "{err:?}");
        assert!(
            err.to_string().contains("film fields of 150 texels"),
            "{err}"
        );
    }

    #[test]
    fn images_go_into_the_atlas_named_by_the_environment_and_their_materials() {
        let camera = Camera::look_at(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO, Vec3::Y, 40.0);
        let env = Texture::try_new(3, 1, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0; 3]]);
        let mut scene = RenderScene::new(camera, Environment::Equirect(env.unwrap()));
        let texture = Texture::try_new(1, 2, vec![[10.0; 3], [11.0; 3]]).unwrap();
        scene.ground = Some(Ground {
            height_m: 0.0,
            material: Material {
                pattern: Pattern::Textured {
                    texture,
                    scale_m: 0.5,
                },
                specular: [0.0; 3],
                shininess: 1.0,
            },
        });
        let lut = render_scene::Lut::try_from_fn(2, 2, 1000.0, |_, _| [0.1; 3]).unwrap();
        let tables = FilmTables::from_reflectivity(lut);
        let settings = RenderSettings::default();
        let view = scene.camera.view(16, 16);
        let pack = |max_side| {
            SceneData::new(
                &scene,
                &tables,
                &settings,
                (&view, 1),
                max_side,
                CubeReads::default(),
            )
        };
        let data = pack(3).unwrap();
        // Rows of 3 texels: the environment's three, the ground's two, one of padding.
        let (width, height, bytes) = &data.images;
        assert_eq!((*width, *height), (3, 2));
        let want = [
            [1.0, 2.0, 3.0, 1.0],
            [4.0, 5.0, 6.0, 1.0],
            [7.0, 7.0, 7.0, 1.0],
            [10.0, 10.0, 10.0, 1.0],
            [11.0, 11.0, 11.0, 1.0],
            [0.0; 4],
        ];
        assert_eq!(floats(bytes), want.concat());
        // Scene.env_image after 9 + 6 vec4s and 12 words: first texel 0, 3 × 1.
        assert_eq!(words(&data.scene)[72..76], [0, 3, 1, 0]);
        // The ground, the only material: textured, 0.5 m a repeat, image at texel 3, 1 × 2.
        let m = words(&data.materials);
        assert_eq!(f32::from_bits(m[11]), PATTERN_TEXTURED);
        assert_eq!(f32::from_bits(m[3]), 0.5);
        assert_eq!(m[12..16], [3, 1, 2, 0]);
        // Rows of 2: three rows, more than the device's 2: named, never drawn otherwise.
        let err = pack(2).unwrap_err();
        assert!(err.to_string().contains("images of 5 texels"), "{err}");
    }

    #[test]
    fn a_scene_without_film_fields_packs_one_unused_texel() {
        let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0);
        let scene = RenderScene::new(camera, Environment::Uniform([1.0; 3]));
        let ((w, h, texels), places) = film_fields(&scene, 8192).unwrap();
        assert_eq!((w, h, floats(&texels)), (1, 1, vec![0.0, 0.0]));
        assert!(places.is_empty());
    }
}

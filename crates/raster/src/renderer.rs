//! [`Renderer`]: runs the passes of a frame and keeps their buffers between frames.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use crate::lut_sampler::LutSampler;
use glam::Vec3;
use rayon::prelude::*;

use crate::camera::View;
use crate::cubemap::FACE_BASES;
use crate::passes::{Bins, BubbleCtx, EMISSIVE, GroundView, OpaqueCtx, Reflection, STRIP_ROWS};
use crate::raster::{ATTRS, ClipVertex, SamplePattern, SetupTri, setup_triangle};
use crate::water_pass::{WaterPass, setup_water};
use crate::{
    BubbleMesh, CubeMap, Environment, FilmTables, Frame, Material, Object, PartialShading,
    ReflectionFilter, ReflectionMode, RenderError, RenderScene, RenderSettings, TriMesh,
};

/// Slices and stacks of a tessellated [`Object::Sphere`].
const SPHERE_SEGMENTS: (usize, usize) = (48, 24);
/// Slices and stacks of a drawn light sphere.
const LIGHT_SEGMENTS: (usize, usize) = (16, 8);

/// World-space opaque triangles with a material tag each.
#[derive(Debug, Clone, Default)]
pub(crate) struct Geometry {
    pub positions: Vec<Vec3>,
    /// Per vertex: normal x, y, z and texture u, v.
    pub attrs: Vec<[f32; ATTRS]>,
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle: the material index, or [`EMISSIVE`] with a light's index.
    pub tags: Vec<u32>,
}

impl Geometry {
    fn clear(&mut self) {
        self.positions.clear();
        self.attrs.clear();
        self.triangles.clear();
        self.tags.clear();
    }

    fn push(&mut self, mesh: &TriMesh, tag: u32) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&mesh.positions);
        for (k, n) in mesh.normals.iter().enumerate() {
            let uv = mesh.uvs.get(k).copied().unwrap_or([0.0; 2]);
            self.attrs.push([n.x, n.y, n.z, uv[0], uv[1]]);
        }
        for t in &mesh.triangles {
            self.triangles.push(t.map(|i| i + base));
            self.tags.push(tag);
        }
    }

    /// Clips and sets up every triangle for `view`, appending to `out` in order.
    fn setup(&self, view: &View, out: &mut Vec<SetupTri>) {
        for (t, &tag) in self.triangles.iter().zip(&self.tags) {
            let tri =
                t.map(|i| clip_vertex(view, self.positions[i as usize], self.attrs[i as usize]));
            setup_triangle(view, tri, tag, 0.0, |s| out.push(s));
        }
    }
}

fn clip_vertex(view: &View, p: Vec3, attrs: [f32; ATTRS]) -> ClipVertex {
    let [x, y, w] = view.clip(p);
    ClipVertex { x, y, w, attrs }
}

/// Per cube face: its triangles and depth buffer, reused across frames.
#[derive(Debug, Clone, Default)]
struct FaceScratch {
    tris: Vec<SetupTri>,
    bins: Bins,
    depth: Vec<f32>,
}

/// Renders [`RenderScene`]s, reusing every buffer from one frame to the next.
///
/// Output is bit-identical at any rayon thread count: strips of rows own their pixels and
/// walk their triangles in a fixed order. Run it inside `ThreadPool::install` to choose
/// the pool.
#[derive(Debug, Default)]
pub struct Renderer {
    frame: Frame,
    cube_maps: Vec<CubeMap>,
    faces: Vec<FaceScratch>,
    objects: Geometry,
    light_spheres: Geometry,
    opaque_tris: Vec<SetupTri>,
    opaque_bins: Bins,
    bubble_tris: Vec<SetupTri>,
    bubble_bins: Bins,
    /// The environment rendered into cube faces, reused while the environment is unchanged
    /// (kept only for the cheap-to-compare procedural kinds).
    env_cube: Option<(Environment, CubeMap)>,
    water: WaterPass,
    filter: ReflectionFilter,
    partial: PartialShading,
}

impl Renderer {
    /// A renderer with empty buffers (they grow on the first frame).
    pub fn new() -> Renderer {
        Renderer::default()
    }

    /// Chooses how bubbles read cube maps from the next frame on (default: filtered by the
    /// footprint; bilinear is the unfiltered lookup, kept to measure the filter against).
    pub fn set_reflection_filter(&mut self, filter: ReflectionFilter) {
        self.filter = filter;
    }

    /// Chooses how bubble pixels covered in part by a triangle are shaded from the next
    /// frame on (default: once per surface; per triangle is kept to measure it against).
    pub fn set_partial_shading(&mut self, partial: PartialShading) {
        self.partial = partial;
    }

    /// The last rendered frame.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// The dynamic cube map rendered for bubble `index` in the last frame, if any.
    pub fn cube_map(&self, index: usize) -> Option<&CubeMap> {
        self.cube_maps.get(index)
    }

    /// The water's reflection cube map (seen from the eye mirrored in its rest plane)
    /// rendered in the last frame, if any.
    pub fn water_cube_map(&self) -> Option<&CubeMap> {
        self.water.cube()
    }

    /// Renders one frame: opaque scene, per-bubble cube maps, sorted bubble blend, resolve.
    pub fn render(
        &mut self,
        scene: &RenderScene,
        tables: &FilmTables,
        settings: &RenderSettings,
    ) -> Result<&Frame, RenderError> {
        settings.validate()?;
        scene.validate(tables)?;
        let start = Instant::now();
        let view = scene.camera.view(settings.width, settings.height);
        let pattern = SamplePattern::new(settings.samples);
        let materials = self.tessellate(scene);
        let strips = settings.height.div_ceil(STRIP_ROWS);

        self.opaque_tris.clear();
        self.objects.setup(&view, &mut self.opaque_tris);
        if settings.draw_lights {
            self.light_spheres.setup(&view, &mut self.opaque_tris);
        }
        if let Some(w) = &scene.water {
            setup_water(w, &view, &mut self.opaque_tris);
        }
        self.opaque_bins.build(&self.opaque_tris, strips);
        self.setup_bubbles(scene, &view);
        self.bubble_bins.build(&self.bubble_tris, strips);
        let setup_s = start.elapsed().as_secs_f64();

        let t = Instant::now();
        if let ReflectionMode::DynamicCubeMap { face_size } = settings.reflection {
            self.render_cube_maps(scene, &materials, face_size);
        }
        let mut cube_maps_s = t.elapsed().as_secs_f64();
        if let Some(w) = &scene.water {
            self.water.prepare_tables(w.ior);
        }

        let t = Instant::now();
        let ambient = scene.irradiance.plus_uniform(scene.ambient_rgb);
        let ground = scene
            .ground
            .as_ref()
            .and_then(|g| GroundView::new(g, &view));
        let mut opaque = OpaqueCtx {
            view,
            pattern,
            env: &scene.environment,
            sky_texels: None,
            ground,
            ambient: &ambient,
            lights: &scene.lights,
            materials: &materials,
            tris: &self.opaque_tris,
            bins: &self.opaque_bins,
            water: None,
        };
        let reflections: Vec<Reflection<'_>> = (0..scene.bubbles.len())
            .map(|b| match &settings.reflection {
                ReflectionMode::DynamicCubeMap { .. } => Reflection::Cube(&self.cube_maps[b]),
                ReflectionMode::StaticEnvironment => Reflection::Env(&scene.environment),
                ReflectionMode::SphereMap(map) => Reflection::Sphere(map),
            })
            .collect();
        let light_tables: Vec<LutSampler<'_>> = scene
            .lights
            .iter()
            .map(|l| {
                LutSampler::new(
                    l.light_lut
                        .map_or(&tables.reflectivity, |i| &tables.lights[i]),
                )
            })
            .collect();
        let bubbles = BubbleCtx {
            view,
            pattern,
            reflectivity: LutSampler::new(&tables.reflectivity),
            transmittance: tables.transmittance.as_ref().map(LutSampler::new),
            lights: &scene.lights,
            light_tables: &light_tables,
            reflections: &reflections,
            filter: self.filter,
            partial: self.partial,
            tris: &self.bubble_tris,
            bins: &self.bubble_bins,
        };
        if scene.water.is_some() {
            let t = Instant::now();
            if let ReflectionMode::DynamicCubeMap { face_size } = settings.reflection {
                let env_cube = self.env_cube.as_ref().map(|(_, c)| c);
                let (objects, lights) = (&self.objects, &self.light_spheres);
                let setup = |v: &View, out: &mut Vec<SetupTri>| {
                    objects.setup(v, out);
                    if settings.draw_lights {
                        lights.setup(v, out);
                    }
                };
                let pass = &mut self.water;
                pass.render_cube(scene, face_size, &opaque, &bubbles, env_cube, &setup);
            }
            cube_maps_s += t.elapsed().as_secs_f64();
        }
        let water_pass = &self.water;
        opaque.water = scene
            .water
            .as_ref()
            .map(|w| water_pass.shading(w, scene, settings));
        let (w, h) = (settings.width, settings.height);
        self.frame.width = w;
        self.frame.height = h;
        self.frame.rgb.resize(w * h, [0.0; 3]);
        let phase_ns = [(); 3].map(|_| AtomicU64::new(0));
        // Each strip runs opaque → bubbles → resolve on a per-thread sample buffer, so its
        // samples stay in cache and never travel to memory.
        self.frame
            .rgb
            .par_chunks_mut(STRIP_ROWS * w)
            .enumerate()
            .for_each(|(s, out)| {
                STRIP_SCRATCH.with_borrow_mut(|(color, depth)| {
                    let n = out.len() * pattern.count;
                    color.resize(n, [0.0; 3]);
                    depth.resize(n, 0.0);
                    let (color, depth) = (&mut color[..n], &mut depth[..n]);
                    let t0 = Instant::now();
                    opaque.render_strip(s, color, depth);
                    let t1 = Instant::now();
                    bubbles.render_strip(s, color, depth);
                    let t2 = Instant::now();
                    resolve(out, color, pattern.count);
                    let t3 = Instant::now();
                    for (acc, d) in phase_ns.iter().zip([t1 - t0, t2 - t1, t3 - t2]) {
                        acc.fetch_add(d.as_nanos() as u64, Ordering::Relaxed);
                    }
                });
            });
        // Apportion the fused pass's wall time by each phase's share of the CPU time.
        let wall_s = t.elapsed().as_secs_f64();
        let cpu = phase_ns.map(|a| a.into_inner() as f64);
        let total: f64 = cpu.iter().sum::<f64>().max(1.0);
        let [opaque_s, bubbles_s, resolve_s] = cpu.map(|c| wall_s * c / total);
        self.frame.timings = crate::FrameTimings {
            setup_s,
            cube_maps_s,
            opaque_s,
            bubbles_s,
            resolve_s,
        };
        Ok(&self.frame)
    }

    /// Fills the world-space object and light-sphere geometry; returns the material table.
    fn tessellate<'s>(&mut self, scene: &'s RenderScene) -> Vec<&'s Material> {
        tessellate(scene, &mut self.objects, &mut self.light_spheres)
    }

    /// Sets up bubble triangles: bubbles far to near, each bubble's back faces then front faces.
    fn setup_bubbles(&mut self, scene: &RenderScene, view: &View) {
        self.bubble_tris.clear();
        setup_bubble_tris(scene, view, &mut self.bubble_tris);
    }

    /// Renders each bubble's six cube faces (the scene without bubbles or light spheres).
    fn render_cube_maps(&mut self, scene: &RenderScene, materials: &[&Material], face_size: usize) {
        let n = scene.bubbles.len();
        self.cube_maps.truncate(n);
        for c in &mut self.cube_maps {
            if c.face_size() != face_size {
                *c = CubeMap::black(face_size);
            }
        }
        self.cube_maps.resize_with(n, || CubeMap::black(face_size));
        self.faces.resize_with(6 * n, FaceScratch::default);
        self.update_env_cube(&scene.environment, face_size);
        let env_cube = self.env_cube.as_ref().map(|(_, c)| c);
        let m = face_size + 2;
        let centers: Vec<Vec3> = scene.bubbles.iter().map(BubbleMesh::center).collect();
        let ambient = scene.irradiance.plus_uniform(scene.ambient_rgb);
        let objects = &self.objects;
        let jobs: Vec<_> = self
            .cube_maps
            .iter_mut()
            .flat_map(|c| c.faces_mut())
            .zip(self.faces.iter_mut())
            .enumerate()
            .collect();
        jobs.into_par_iter().for_each(|(j, (texels, scratch))| {
            let (major, s_axis, t_axis) = FACE_BASES[j % 6];
            let wide = m as f32 / face_size as f32;
            let view = View::new(
                centers[j / 6],
                [major, s_axis, -t_axis],
                (wide, wide),
                (m, m),
                scene.camera.near_m(),
            );
            scratch.tris.clear();
            objects.setup(&view, &mut scratch.tris);
            let strips = m.div_ceil(STRIP_ROWS);
            scratch.bins.build(&scratch.tris, strips);
            scratch.depth.resize(m * m, 0.0);
            let ctx = OpaqueCtx {
                view,
                pattern: SamplePattern::new(1),
                env: &scene.environment,
                sky_texels: env_cube.map(|c| c.face(j % 6)),
                ground: scene
                    .ground
                    .as_ref()
                    .and_then(|g| GroundView::new(g, &view)),
                ambient: &ambient,
                lights: &scene.lights,
                materials,
                tris: &scratch.tris,
                bins: &scratch.bins,
                water: None,
            };
            let rows = STRIP_ROWS * m;
            // Strips of a face run in parallel too: twelve faces alone balance poorly.
            texels
                .par_chunks_mut(rows)
                .zip(scratch.depth.par_chunks_mut(rows))
                .enumerate()
                .for_each(|(s, (color, depth))| ctx.render_strip(s, color, depth));
        });
        self.cube_maps.par_iter_mut().for_each(CubeMap::build_mips);
    }

    /// Caches the environment's cube faces when it is procedural (cheap to compare);
    /// their texel directions are the same for every bubble, so they can be copied.
    fn update_env_cube(&mut self, env: &Environment, face_size: usize) {
        if !matches!(env, Environment::Sky(_) | Environment::Uniform(_)) {
            self.env_cube = None;
            return;
        }
        let fresh = self
            .env_cube
            .as_ref()
            .is_some_and(|(e, c)| e == env && c.face_size() == face_size);
        if !fresh {
            self.env_cube = CubeMap::from_environment(env, face_size)
                .ok()
                .map(|c| (env.clone(), c));
        }
    }
}

/// Sets up bubble triangles: bubbles far to near, each bubble's back faces then front faces.
pub(crate) fn setup_bubble_tris(scene: &RenderScene, view: &View, out: &mut Vec<SetupTri>) {
    for k in far_to_near(&scene.bubbles, view.eye) {
        let bubble = &scene.bubbles[k];
        for front in [false, true] {
            for t in &bubble.triangles {
                if is_front_facing(bubble, *t, view.eye) == front {
                    let tri = t.map(|i| {
                        let i = i as usize;
                        let n = bubble.normals[i];
                        clip_vertex(
                            view,
                            bubble.positions[i],
                            [n.x, n.y, n.z, bubble.thickness_nm[i], 0.0],
                        )
                    });
                    let extra = reflection_rate(view, bubble, *t);
                    // One surface per bubble and facing: the back layer, then the front.
                    let surface = 2 * k as u32 + u32::from(front);
                    setup_triangle(view, tri, k as u32, extra, |s| {
                        out.push(SetupTri {
                            surface,
                            mesh_vertices: *t,
                            ..s
                        });
                    });
                }
            }
        }
    }
}

thread_local! {
    /// Per-thread sample colour and depth of the strip being rendered, reused across frames.
    static STRIP_SCRATCH: std::cell::RefCell<(Vec<[f32; 3]>, Vec<f32>)> =
        const { std::cell::RefCell::new((Vec::new(), Vec::new())) };
}

/// Averages each pixel's samples (in sample order, so the sum is deterministic).
fn resolve(out: &mut [[f32; 3]], color: &[[f32; 3]], samples: usize) {
    let scale = 1.0 / samples as f32;
    for (o, px) in out.iter_mut().zip(color.chunks_exact(samples)) {
        let mut sum = [0.0f32; 3];
        for c in px {
            for k in 0..3 {
                sum[k] += c[k];
            }
        }
        *o = sum.map(|s| s * scale);
    }
}

/// Fills `objects` and `light_spheres` with the scene's world-space triangles (both
/// backends draw these same triangles); returns the material table `objects`' tags index.
pub(crate) fn tessellate<'s>(
    scene: &'s RenderScene,
    objects: &mut Geometry,
    light_spheres: &mut Geometry,
) -> Vec<&'s Material> {
    objects.clear();
    light_spheres.clear();
    let mut materials = Vec::with_capacity(scene.objects.len());
    for (k, object) in scene.objects.iter().enumerate() {
        materials.push(object.material());
        let tag = k as u32;
        match object {
            Object::Sphere {
                center, radius_m, ..
            } => {
                let (s, r) = SPHERE_SEGMENTS;
                objects.push(&TriMesh::uv_sphere(*center, *radius_m, s, r), tag);
            }
            Object::Box {
                center,
                half_extents_m,
                ..
            } => objects.push(&TriMesh::cuboid(*center, *half_extents_m), tag),
            Object::Mesh { mesh, .. } => objects.push(mesh, tag),
        }
    }
    for (k, light) in scene.lights.iter().enumerate() {
        let (s, r) = LIGHT_SEGMENTS;
        let mesh = TriMesh::uv_sphere(light.position, light.radius_m, s, r);
        light_spheres.push(&mesh, EMISSIVE | k as u32);
    }
    materials
}

/// Bubble indices in drawing order, far to near, by the power distance `|c − e|² − r²` of
/// each bubble's sphere (centre `c`, `r²` the mean squared vertex distance from it) to the
/// eye `e`: for non-overlapping spheres, a sphere in front of another along any ray has
/// the smaller power distance, whatever their sizes (the centre distance alone is not).
pub(crate) fn far_to_near(bubbles: &[BubbleMesh], eye: Vec3) -> Vec<usize> {
    let mut order: Vec<(f64, usize)> = bubbles
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let c = b.center().as_dvec3();
            let r2 = b
                .positions
                .iter()
                .map(|p| (p.as_dvec3() - c).length_squared())
                .sum::<f64>()
                / b.positions.len().max(1) as f64;
            ((c - eye.as_dvec3()).length_squared() - r2, k)
        })
        .collect();
    // Stable, far first; NaN-free because the scene was validated.
    order.sort_by(|a, b| b.0.total_cmp(&a.0));
    order.into_iter().map(|(_, k)| k).collect()
}

/// Whether triangle `t` faces the eye, its outward side taken from the vertex normals
/// (so the mesh's winding does not matter).
pub(crate) fn is_front_facing(bubble: &BubbleMesh, t: [u32; 3], eye: Vec3) -> bool {
    let [a, b, c] = t.map(|i| bubble.positions[i as usize]);
    let geometric = (b - a).cross(c - a);
    let normals: Vec3 = t.iter().map(|&i| bubble.normals[i as usize]).sum();
    let outward = if geometric.dot(normals) < 0.0 {
        -geometric
    } else {
        geometric
    };
    outward.dot(eye - a) > 0.0
}

/// Angle swept by the reflected direction per pixel across triangle `t` (radians), for
/// anti-aliasing light highlights; clamped to `[1e-4, 0.5]`.
pub(crate) fn reflection_rate(view: &View, bubble: &BubbleMesh, t: [u32; 3]) -> f32 {
    let mut reflected = [Vec3::ZERO; 3];
    let mut pixels = [(0.0f32, 0.0f32); 3];
    for (k, &i) in t.iter().enumerate() {
        let p = bubble.positions[i as usize];
        let [x, y, w] = view.clip(p);
        if w <= view.near_m {
            return 0.5;
        }
        pixels[k] = view.pixel_of_clip(x, y, w);
        let v = (p - view.eye).normalize_or_zero();
        let mut n = bubble.normals[i as usize].normalize_or_zero();
        if v.dot(n) > 0.0 {
            n = -n;
        }
        reflected[k] = v - n * (2.0 * v.dot(n));
    }
    let mut rate = 1e-4f32;
    for k in 0..3 {
        let j = (k + 1) % 3;
        let (dx, dy) = (pixels[j].0 - pixels[k].0, pixels[j].1 - pixels[k].1);
        let len_px = (dx * dx + dy * dy).sqrt();
        if len_px > 1e-3 {
            rate = rate.max((reflected[j] - reflected[k]).length() / len_px);
        }
    }
    if rate.is_finite() { rate.min(0.5) } else { 0.5 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// An icosahedron inscribed in the sphere: its vertex mean is the centre exactly.
    fn icosahedron(center: Vec3, radius_m: f32) -> BubbleMesh {
        let phi = (1.0 + 5f32.sqrt()) / 2.0;
        let mut positions = Vec::new();
        for (a, b) in [(1.0, phi), (-1.0, phi), (1.0, -phi), (-1.0, -phi)] {
            for v in [
                Vec3::new(0.0, a, b),
                Vec3::new(a, b, 0.0),
                Vec3::new(b, 0.0, a),
            ] {
                positions.push(center + v.normalize() * radius_m);
            }
        }
        let normals = positions.iter().map(|p| *p - center).collect();
        BubbleMesh {
            thickness_nm: vec![500.0; positions.len()],
            positions,
            normals,
            triangles: Vec::new(),
        }
    }

    /// Distance along unit `dir` from the origin to where it enters the sphere, if it does.
    fn entry(dir: Vec3, center: Vec3, radius_m: f32) -> Option<f32> {
        let b = dir.dot(center);
        let h2 = center.length_squared() - b * b;
        let t = b - (radius_m * radius_m - h2).sqrt();
        (h2 < radius_m * radius_m && t > 0.0).then_some(t)
    }

    #[test]
    fn large_bubble_in_front_of_a_small_one_with_a_nearer_centre_is_drawn_last() {
        // The large bubble's centre (1.2 m) is farther than the small one's (1.19 m), yet
        // along the ray at 56° the large one spans 0.57–0.77 m and the small one starts at
        // 1.09 m: sorting by centre distance drew the large one first.
        let large = (Vec3::new(0.0, 0.0, -1.2), 1.0);
        let a = 56f32.to_radians();
        let small = (Vec3::new(a.sin(), 0.0, -a.cos()) * 1.19, 0.1);
        assert!(
            large.0.distance(small.0) > large.1 + small.1,
            "they overlap"
        );
        let ray = Vec3::new(a.sin(), 0.0, -a.cos());
        assert!(entry(ray, large.0, large.1).unwrap() < entry(ray, small.0, small.1).unwrap());
        let bubbles = [icosahedron(large.0, large.1), icosahedron(small.0, small.1)];
        assert_eq!(far_to_near(&bubbles, Vec3::ZERO), vec![1, 0]);
    }

    proptest! {
        #[test]
        fn a_bubble_in_front_along_any_ray_is_drawn_later(
            c0 in prop::array::uniform3(-3.0f32..3.0),
            c1 in prop::array::uniform3(-3.0f32..3.0),
            r0 in 0.05f32..1.5,
            r1 in 0.05f32..1.5,
            t in 0.0f32..1.0,
        ) {
            let (c0, c1) = (Vec3::from(c0), Vec3::from(c1));
            // Non-overlapping spheres, the eye (origin) outside both.
            prop_assume!(c0.distance(c1) > (r0 + r1) * 1.001);
            prop_assume!(c0.length() > r0 * 1.001 && c1.length() > r1 * 1.001);
            // A ray through a point between the two centres often hits both.
            let dir = c0.lerp(c1, t).normalize();
            if let (Some(e0), Some(e1)) = (entry(dir, c0, r0), entry(dir, c1, r1)) {
                prop_assume!((e0 - e1).abs() > 1e-3);
                let order = far_to_near(&[icosahedron(c0, r0), icosahedron(c1, r1)], Vec3::ZERO);
                let nearer = if e0 < e1 { 0 } else { 1 };
                prop_assert_eq!(order[1], nearer, "entries {} and {}", e0, e1);
            }
        }

        #[test]
        fn a_small_bubble_behind_the_rim_of_a_large_one_is_drawn_first(
            radius_m in 0.5f32..2.0,
            distance in 1.05f32..3.0,
            small in 0.02f32..0.3,
            angle_offset in -0.15f32..0.15,
            depth in 0.85f32..1.05,
            aim in prop::array::uniform2(-1.0f32..1.0),
        ) {
            // Where centre distance fails: a small bubble about as far as the large one's
            // centre, seen just inside the large one's silhouette.
            let c0 = Vec3::new(0.0, 0.0, -radius_m * distance);
            let r1 = small * radius_m;
            let theta = (1.0 / distance).asin() + angle_offset;
            let c1 = Vec3::new(theta.sin(), 0.0, -theta.cos()) * (c0.length() * depth);
            if c0.distance(c1) <= (radius_m + r1) * 1.001 || c1.length() <= r1 * 1.001 {
                return Ok(());
            }
            let dir = (c1 + Vec3::new(aim[0], aim[1], 0.0) * r1).normalize();
            if let (Some(e0), Some(e1)) = (entry(dir, c0, radius_m), entry(dir, c1, r1)) {
                let order = far_to_near(
                    &[icosahedron(c0, radius_m), icosahedron(c1, r1)],
                    Vec3::ZERO,
                );
                let nearer = if e0 < e1 { 0 } else { 1 };
                prop_assert_eq!(order[1], nearer, "entries {} and {}", e0, e1);
            }
        }
    }
}

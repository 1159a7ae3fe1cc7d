//! [`Renderer`]: runs the passes of a frame and keeps their buffers between frames.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;
use render_scene::camera::View;
use render_scene::cubemap::FACE_BASES;
use render_scene::ground_view::{GroundFilter, GroundView};
use render_scene::lut_sampler::LutSampler;
use render_scene::parallax::proxy_ground_height_m;
use render_scene::reflection::Reflection;
use render_scene::tessellate::{Geometry, tessellate};
use render_scene::{
    CubeMap, Environment, FilmField, FilmTables, Frame, FrameTimings, Material, PartialShading,
    ReflectionFilter, ReflectionMode, ReflectionParallax, RenderError, RenderScene, RenderSettings,
};

use crate::cube_reuse::{CubeMapReuse, CubeReuseState, bounds};
use crate::passes::bubble::{BubbleCtx, setup_bubble_tris};
use crate::passes::opaque::OpaqueCtx;
use crate::passes::water::{WaterPass, setup_water};
use crate::raster::{SamplePattern, SetupTri, setup_geometry};
use crate::strip::{Bins, STRIP_ROWS};

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
    /// The water's triangles set up per parallel chunk, before joining `opaque_tris`.
    water_chunks: Vec<Vec<SetupTri>>,
    opaque_bins: Bins,
    bubble_tris: Vec<SetupTri>,
    /// Each bubble's triangles, set up in parallel before joining `bubble_tris`.
    bubble_layers: Vec<Vec<SetupTri>>,
    bubble_bins: Bins,
    /// The environment rendered into cube faces, reused while the environment is unchanged
    /// (kept only for the cheap-to-compare procedural kinds).
    env_cube: Option<(Environment, CubeMap)>,
    water: WaterPass,
    filter: ReflectionFilter,
    partial: PartialShading,
    parallax: ReflectionParallax,
    /// Each bubble's centre, where its cube map was rendered from.
    centres: Vec<Vec3>,
    /// When bubbles' cube maps may be kept from an earlier frame.
    cube_reuse: CubeMapReuse,
    cube_state: CubeReuseState,
    cube_maps_rendered: usize,
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

    /// Chooses where bubbles' reflected rays read their dynamic cube maps from, from the
    /// next frame on (default: corrected for the ground's parallax; the centre is seed
    /// 000's read, kept to measure the correction against).
    pub fn set_reflection_parallax(&mut self, parallax: ReflectionParallax) {
        self.parallax = parallax;
    }

    /// Chooses how bubble pixels covered in part by a triangle are shaded from the next
    /// frame on (default: once per surface; per triangle is kept to measure it against).
    pub fn set_partial_shading(&mut self, partial: PartialShading) {
        self.partial = partial;
    }

    /// Lets a bubble's dynamic cube map be kept from an earlier frame while it lags a
    /// fresh one by at most `reuse` (from the next frame on; default [`CubeMapReuse::OFF`]:
    /// every map every frame, so a frame does not depend on the frames before it).
    pub fn set_cube_map_reuse(&mut self, reuse: CubeMapReuse) {
        self.cube_reuse = reuse;
    }

    /// How many bubbles' cube maps the last frame rendered afresh (the others were kept).
    pub fn cube_maps_rendered(&self) -> usize {
        self.cube_maps_rendered
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
        scene.validate()?;
        tables.validate_for(scene)?;
        let start = Instant::now();
        let view = scene.camera.view(settings.width, settings.height);
        let pattern = SamplePattern::new(settings.samples);
        let materials = self.tessellate(scene);
        let strips = settings.height.div_ceil(STRIP_ROWS);

        self.opaque_tris.clear();
        setup_geometry(&self.objects, &view, &mut self.opaque_tris);
        if settings.draw_lights {
            setup_geometry(&self.light_spheres, &view, &mut self.opaque_tris);
        }
        if let Some(w) = &scene.water {
            setup_water(w, &view, &mut self.opaque_tris, &mut self.water_chunks);
        }
        self.opaque_bins.build(&self.opaque_tris, strips);
        self.setup_bubbles(scene, &view);
        self.bubble_bins.build(&self.bubble_tris, strips);
        let setup_s = start.elapsed().as_secs_f64();

        // Only dynamic cube maps have centres (the parallax correction reads them).
        self.centres.clear();
        let t = Instant::now();
        self.cube_maps_rendered = 0;
        if let ReflectionMode::DynamicCubeMap { face_size } = settings.reflection {
            let bounds = bounds(&self.objects.positions);
            let fresh = self
                .cube_state
                .plan(scene, face_size, self.cube_reuse, bounds);
            self.centres.clone_from(&self.cube_state.centres);
            self.cube_maps_rendered = fresh.iter().filter(|&&f| f).count();
            self.render_cube_maps(scene, &materials, face_size, &fresh);
        }
        let mut cube_maps_s = t.elapsed().as_secs_f64();
        if let Some(w) = &scene.water {
            self.water.prepare_tables(w.ior);
        }

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
        let films: Vec<Option<&FilmField>> = scene
            .bubbles
            .iter()
            .map(|b| b.film.as_ref().map(|f| &*f.field))
            .collect();
        let ground_height_m = proxy_ground_height_m(self.parallax, &settings.reflection, scene);
        let bubbles = BubbleCtx {
            view,
            pattern,
            reflectivity: LutSampler::new(&tables.reflectivity),
            transmittance: tables.transmittance.as_ref().map(LutSampler::new),
            lights: &scene.lights,
            light_tables: &light_tables,
            reflections: &reflections,
            films: &films,
            filter: self.filter,
            parallax_centres: &self.centres,
            ground_height_m,
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
                    setup_geometry(objects, v, out);
                    if settings.draw_lights {
                        setup_geometry(lights, v, out);
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
            .map(|w| water_pass.shading(w, scene, settings, &ambient));
        let (w, h) = (settings.width, settings.height);
        // The fused pass's clock starts here: the water's cube map above is cube-map time
        // (it was counted twice, in the cube maps and apportioned to these phases).
        let t = Instant::now();
        let phase_ns = [(); 3].map(|_| AtomicU64::new(0));
        // Each strip runs opaque → bubbles → resolve on a per-thread sample buffer, so its
        // samples stay in cache and never travel to memory.
        self.frame
            .resize_pixels(w, h)
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
        self.frame.timings = FrameTimings {
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
        setup_bubble_tris(scene, view, &mut self.bubble_tris, &mut self.bubble_layers);
    }

    /// Renders the six cube faces (the scene without bubbles or light spheres) of each
    /// bubble `fresh` marks, from its centre in `self.centres`.
    fn render_cube_maps(
        &mut self,
        scene: &RenderScene,
        materials: &[&Material],
        face_size: usize,
        fresh: &[bool],
    ) {
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
        let ambient = scene.irradiance.plus_uniform(scene.ambient_rgb);
        let objects = &self.objects;
        let jobs: Vec<_> = self
            .cube_maps
            .iter_mut()
            .flat_map(|c| c.faces_mut())
            .zip(self.faces.iter_mut())
            .enumerate()
            .filter(|(j, _)| fresh[j / 6])
            .collect();
        jobs.into_par_iter().for_each(|(j, (texels, scratch))| {
            let (major, s_axis, t_axis) = FACE_BASES[j % 6];
            let wide = m as f32 / face_size as f32;
            let view = View::new(
                self.centres[j / 6],
                [major, s_axis, -t_axis],
                (wide, wide),
                (m, m),
                scene.camera.near_m(),
            );
            scratch.tris.clear();
            setup_geometry(objects, &view, &mut scratch.tris);
            let strips = m.div_ceil(STRIP_ROWS);
            scratch.bins.build(&scratch.tris, strips);
            scratch.depth.resize(m * m, 0.0);
            let ctx = OpaqueCtx {
                view,
                pattern: SamplePattern::new(1),
                env: &scene.environment,
                sky_texels: env_cube.map(|c| c.face(j % 6)),
                // Reflection lookups filter the faces again: one box per texel.
                ground: scene
                    .ground
                    .as_ref()
                    .and_then(|g| GroundView::new(g, &view))
                    .map(|g| g.with_filter(GroundFilter::Pixel)),
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
        self.cube_maps
            .par_iter_mut()
            .zip(fresh)
            .filter(|(_, fresh)| **fresh)
            .for_each(|(c, _)| c.build_mips());
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

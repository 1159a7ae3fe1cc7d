//! [`GpuRenderer`]: one frame on the GPU, mirroring [`crate::Renderer::render`].

use std::time::Instant;

use wgpu::util::DeviceExt;

use super::pipelines::{DEPTH_FORMAT, HDR_FORMAT, Layouts, Pipelines};
use super::scene_data::{
    BUBBLE_VERTEX_BYTES, CubeReads, SceneData, VIEW_BYTES, bubble_vertices, ground_triangles,
    view_bytes,
};
use super::{Gpu, GpuError, GpuOptions};
use glam::Vec3;
use render_scene::camera::View;
use render_scene::cubemap::FACE_BASES;
use render_scene::ground_view::{GroundFilter, GroundView};
use render_scene::{
    BubbleMesh, CubeMap, FilmTables, Frame, FrameTimings, ReflectionFilter, ReflectionMode,
    ReflectionParallax, RenderScene, RenderSettings,
};

/// Size `(width, height, layers)` and sample count of a cached texture.
type TextureKey = ((u32, u32, u32), u32);

/// Makes a texture: device, label, size and layers, samples.
type MakeTexture = fn(&wgpu::Device, &str, (u32, u32, u32), u32) -> wgpu::Texture;

/// Bytes between two views in the view uniform buffer (the dynamic-offset alignment).
const VIEW_STRIDE: u64 = 256;

/// Renders [`RenderScene`]s with wgpu, headless; the CPU backend is its specification.
///
/// # Guarantees
/// Holds an open device with the scene pipelines compiled; every frame is read back to
/// the CPU as a linear HDR [`Frame`], except those [`GpuRenderer::present`] puts on a
/// window.
#[derive(Debug)]
pub struct GpuRenderer {
    pub(super) gpu: Gpu,
    layouts: Layouts,
    pipelines: Vec<Pipelines>,
    frame: Frame,
    /// Render targets kept from frame to frame, by role, with their size and samples.
    textures: Vec<(&'static str, TextureKey, wgpu::Texture)>,
    /// How bubbles read their dynamic cube maps.
    reads: CubeReads,
    /// The last frame's cube mip chains, for [`GpuRenderer::read_cube_mips`].
    last_mips: Option<wgpu::Buffer>,
    /// `CubeMap::border_source_table` of the last face size the mip passes built.
    border_sources: Option<(usize, wgpu::Buffer)>,
}

/// The water's draw: its vertices and bind group (group 3), and with dynamic cube maps
/// the bubbles' vertices for the six faces seen from the mirrored eye and each face's
/// draw ranges.
struct WaterDraw {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
    group: wgpu::BindGroup,
    /// The cube map's six faces, with dynamic cube maps.
    cube: Option<wgpu::Texture>,
    face_bubbles: Option<(wgpu::Buffer, Vec<Vec<std::ops::Range<u32>>>)>,
}

/// The targets one view renders into.
struct Target<'a> {
    color: &'a wgpu::TextureView,
    resolve: Option<&'a wgpu::TextureView>,
    depth: &'a wgpu::TextureView,
}

impl GpuRenderer {
    /// Opens the device (see [`Gpu::new`]) and compiles the pipelines.
    pub fn new(options: GpuOptions) -> Result<GpuRenderer, GpuError> {
        Ok(GpuRenderer::from_gpu(Gpu::new(options)?))
    }

    /// The renderer on an open device (headless, or one that presents to a window).
    pub(super) fn from_gpu(gpu: Gpu) -> GpuRenderer {
        let layouts = Layouts::new(&gpu.device);
        GpuRenderer {
            gpu,
            layouts,
            pipelines: Vec::new(),
            frame: Frame::default(),
            textures: Vec::new(),
            reads: CubeReads::default(),
            last_mips: None,
            border_sources: None,
        }
    }

    /// Chooses how bubbles read their dynamic cube maps, as
    /// [`crate::Renderer::set_reflection_filter`] (default: the footprint filter).
    pub fn set_reflection_filter(&mut self, filter: ReflectionFilter) {
        self.reads.filter = filter;
    }

    /// Chooses where bubbles' reflected rays read their dynamic cube maps from, as
    /// [`crate::Renderer::set_reflection_parallax`] (default: corrected for the ground).
    pub fn set_reflection_parallax(&mut self, parallax: ReflectionParallax) {
        self.reads.parallax = parallax;
    }

    /// The device.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// The cube mip chains the GPU built for the last frame's bubbles, as f32 RGB laid out
    /// as `CubeMap`'s levels one bubble after another (see [`CubeMap::level_texels`]), or
    /// `None` when that frame had no dynamic cube maps: for checking them against the
    /// CPU's `CubeMap::build_mips`.
    pub fn read_cube_mips(&self) -> Result<Option<Vec<f32>>, GpuError> {
        let Some(mips) = &self.last_mips else {
            return Ok(None);
        };
        let bytes = self.gpu.read_buffer(mips)?;
        let floats = bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        Ok(Some(floats.collect()))
    }

    /// Renders one frame: cube maps, opaque scene, sorted bubble blend, resolve; the linear
    /// HDR result is read back. Timings: `setup_s` is the CPU's packing, and the GPU's
    /// work (submission to read-back) is `resolve_s`, which it cannot split further.
    pub fn render(
        &mut self,
        scene: &RenderScene,
        tables: &FilmTables,
        settings: &RenderSettings,
    ) -> Result<&Frame, GpuError> {
        let start = Instant::now();
        let (encoder, resolved, size) = self.encode(scene, tables, settings)?;
        let setup_s = start.elapsed().as_secs_f64();
        let t = Instant::now();
        let texels = self.gpu.read_back(encoder, &resolved, size, 8)?;
        let rgb = self.frame.resize_pixels(settings.width, settings.height);
        for (px, p) in rgb.iter_mut().zip(texels.chunks_exact(8)) {
            *px = std::array::from_fn(|k| f16_to_f32(u16::from_le_bytes([p[2 * k], p[2 * k + 1]])));
        }
        self.frame.timings = FrameTimings {
            setup_s,
            resolve_s: t.elapsed().as_secs_f64(),
            ..FrameTimings::default()
        };
        Ok(&self.frame)
    }

    /// Renders one frame and tone-maps it on the GPU (the tone-map pass): interleaved 8-bit
    /// sRGB, row-major, as [`Frame::to_srgb8`] of [`GpuRenderer::render`]'s frame.
    pub fn render_srgb8(
        &mut self,
        scene: &RenderScene,
        tables: &FilmTables,
        settings: &RenderSettings,
    ) -> Result<Vec<u8>, GpuError> {
        let (encoder, resolved, size) = self.encode(scene, tables, settings)?;
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu
            .tone_map_texture(&resolved, size, settings.exposure_ev, settings.tonemap)
    }

    /// Records the frame's passes; returns the encoder and the resolved HDR texture.
    pub(super) fn encode(
        &mut self,
        scene: &RenderScene,
        tables: &FilmTables,
        settings: &RenderSettings,
    ) -> Result<(wgpu::CommandEncoder, wgpu::Texture, wgpu::Extent3d), GpuError> {
        settings.validate()?;
        scene.validate()?;
        tables.validate_for(scene)?;
        let (w, h) = (settings.width as u32, settings.height as u32);
        self.gpu.check_size(w, h)?;
        let view = scene.camera.view(settings.width, settings.height);
        let max_side = self.gpu.device.limits().max_texture_dimension_2d;
        // The nearest count the device renders (the caller is told by `sample_count_for`).
        let samples = self.gpu.sample_count_for(settings.samples);
        let data = SceneData::new(
            scene,
            tables,
            settings,
            (&view, samples),
            max_side,
            self.reads,
        )?;
        check_water_fits(&data, self.gpu.device.limits().max_buffer_size)?;
        let face_size = match settings.reflection {
            ReflectionMode::DynamicCubeMap { face_size } => Some(face_size),
            _ => None,
        };
        let face_views = face_size.map_or(Vec::new(), |n| cube_face_views(scene, n));
        // With dynamic cube maps the water reflects six faces seen from the mirrored eye.
        let water_views = match (&scene.water, face_size) {
            (Some(w), Some(n)) => {
                let eye = scene.camera.eye();
                let mirrored = Vec3::new(eye.x, 2.0 * w.rest_height_m - eye.y, eye.z);
                face_views_from(mirrored, n, scene.camera.near_m())
            }
            _ => Vec::new(),
        };
        if let Some(n) = face_size {
            self.gpu.check_size(n as u32 + 2, n as u32 + 2)?;
            let max_layers = self.gpu.device.limits().max_texture_array_layers as usize;
            if face_views.len() > max_layers {
                return Err(GpuError::Unsupported(format!(
                    "{} bubbles with dynamic cube maps (this device holds {} cube faces, \
                     6 per bubble)",
                    scene.bubbles.len(),
                    max_layers
                )));
            }
        }
        let m = face_size.map_or(1, |n| n as u32 + 2);
        let layers = if face_size.is_some() {
            6 * scene.bubbles.len().max(1) as u32
        } else {
            1
        };
        let cubes = self.texture("cube faces", ((m, m, layers), 1), hdr_texture);
        let face_depth = self.texture("face depth", ((m, m, 1), 1), depth_texture);
        let resolved = self.texture("frame", ((w, h, 1), 1), hdr_texture);
        let msaa =
            (samples > 1).then(|| self.texture("frame samples", ((w, h, 1), samples), hdr_texture));
        let depth = self.texture("depth", ((w, h, 1), samples), depth_texture);
        let mut views = vec![view];
        views.extend(&face_views);
        // The water's faces leave the ground out (raster's `WaterPass::render_cube`).
        let grounded = views.len();
        views.extend(&water_views);
        let (view_buffer, ground, ground_draws) = self.view_buffers(scene, &views, grounded);
        let water = self.water_draw(scene, &data, &water_views, m);
        let device = &self.gpu.device;
        let buffer = |label, contents: &[u8], usage| self.gpu.buffer(label, contents, usage);
        let scene_uniform = buffer("scene", &data.scene, wgpu::BufferUsages::UNIFORM);
        let materials = buffer("materials", &data.materials, wgpu::BufferUsages::STORAGE);
        let lights = buffer("lights", &data.lights, wgpu::BufferUsages::STORAGE);
        let lut_info = buffer("lut info", &data.lut_info, wgpu::BufferUsages::STORAGE);
        let vertex = wgpu::BufferUsages::VERTEX;
        let objects = (data.all_vertices > 0).then(|| buffer("objects", &data.objects, vertex));
        let bubbles = (!data.bubbles.is_empty()).then(|| buffer("bubbles", &data.bubbles, vertex));
        let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("views"),
            layout: &self.layouts.view,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &view_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(VIEW_BYTES),
                }),
            }],
        });
        let images = self.data_texture("images", wgpu::TextureFormat::Rgba32Float, &data.images);
        let scene_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &self.layouts.scene,
            entries: &[
                bind(0, scene_uniform.as_entire_binding()),
                bind(1, materials.as_entire_binding()),
                bind(2, lights.as_entire_binding()),
                bind(
                    3,
                    wgpu::BindingResource::TextureView(&images.create_view(&Default::default())),
                ),
            ],
        });
        // The dynamic cube maps' chains, or the static environment's cube faces' chain.
        let mip_floats = face_size.map_or((data.env_chain.len() as u64 / 4).max(3), |n| {
            3 * CubeMap::stored_texels(n) as u64 * scene.bubbles.len().max(1) as u64
        });
        let limits = device.limits();
        let max_bytes = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        if 4 * mip_floats > max_bytes {
            let what = match face_size {
                Some(n) => format!(
                    "{} bubbles with cube maps of {n} texels",
                    scene.bubbles.len()
                ),
                None => "the environment's cube faces".to_string(),
            };
            return Err(GpuError::Unsupported(format!(
                "{what} (their mip chains take {} bytes, this device binds at most \
                 {max_bytes})",
                4 * mip_floats
            )));
        }
        let mips_usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let mips = if face_size.is_none() && !data.env_chain.is_empty() {
            buffer("cube mips", &data.env_chain, mips_usage)
        } else {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("cube mips"),
                size: 4 * mip_floats,
                usage: mips_usage,
                mapped_at_creation: false,
            })
        };
        let lut_texture = self.data_texture("luts", wgpu::TextureFormat::Rgba32Float, &data.luts);
        let film_texture =
            self.data_texture("film fields", wgpu::TextureFormat::Rg32Float, &data.films);
        let bubble_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bubble tables"),
            layout: &self.layouts.bubble,
            entries: &[
                bind(
                    0,
                    wgpu::BindingResource::TextureView(
                        &lut_texture.create_view(&Default::default()),
                    ),
                ),
                bind(1, lut_info.as_entire_binding()),
                bind(
                    2,
                    wgpu::BindingResource::TextureView(&cubes.create_view(
                        &wgpu::TextureViewDescriptor {
                            dimension: Some(wgpu::TextureViewDimension::D2Array),
                            ..Default::default()
                        },
                    )),
                ),
                bind(3, mips.as_entire_binding()),
                bind(
                    4,
                    wgpu::BindingResource::TextureView(
                        &film_texture.create_view(&Default::default()),
                    ),
                ),
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        let single = self.pipelines_for(1);
        let face_depth = face_depth.create_view(&Default::default());
        for (k, _) in face_views.iter().enumerate() {
            let layer = array_layer(&cubes, k);
            let target = Target {
                color: &layer,
                resolve: None,
                depth: &face_depth,
            };
            let mut pass = begin(&mut encoder, &target);
            let offset = (VIEW_STRIDE * (k as u64 + 1)) as u32;
            pass.set_bind_group(0, &view_group, &[offset]);
            pass.set_bind_group(1, &scene_group, &[]);
            let ground = (&ground, ground_draws[k + 1].clone());
            draw_opaque(
                &mut pass,
                &self.pipelines[single],
                ground,
                objects.as_ref(),
                data.object_vertices,
            );
        }
        if let Some(n) = face_size {
            self.encode_mips(&mut encoder, (&cubes, &mips), &scene_group, n, layers);
        }
        if let Some(water) = &water {
            let groups = [&view_group, &scene_group, &bubble_group];
            let first_view = 1 + face_views.len();
            let opaque = (objects.as_ref(), data.all_vertices);
            self.encode_water_cube(&mut encoder, water, groups, first_view, &face_depth, opaque);
        }
        self.last_mips = face_size.map(|_| mips.clone());
        let main = self.pipelines_for(samples);
        let resolved_view = resolved.create_view(&Default::default());
        let msaa_view = msaa.as_ref().map(|t| t.create_view(&Default::default()));
        let depth = depth.create_view(&Default::default());
        let target = match &msaa_view {
            Some(v) => Target {
                color: v,
                resolve: Some(&resolved_view),
                depth: &depth,
            },
            None => Target {
                color: &resolved_view,
                resolve: None,
                depth: &depth,
            },
        };
        {
            let p = &self.pipelines[main];
            let mut pass = begin(&mut encoder, &target);
            pass.set_bind_group(0, &view_group, &[0]);
            pass.set_bind_group(1, &scene_group, &[]);
            let ground = (&ground, ground_draws[0].clone());
            draw_opaque(&mut pass, p, ground, objects.as_ref(), data.all_vertices);
            if let Some(water) = water.as_ref().filter(|w| w.count > 0) {
                pass.set_pipeline(&p.water);
                pass.set_bind_group(3, &water.group, &[]);
                pass.set_vertex_buffer(0, water.vertices.slice(..));
                pass.set_index_buffer(water.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..water.count, 0, 0..1);
            }
            if let Some(bubbles) = &bubbles {
                pass.set_bind_group(2, &bubble_group, &[]);
                draw_bubbles(&mut pass, p, bubbles, &data.bubble_draws);
            }
        }
        let size = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        Ok((encoder, resolved, size))
    }

    /// The mip chain of every bubble's cube map, built on the GPU from the faces it just
    /// rendered, exactly as the CPU's `CubeMap::build_mips` builds it from its own.
    ///
    /// Why compute passes into a storage buffer rather than a mip-mapped texture: the CPU's
    /// level `k` is `N >> k` texels plus a one-texel border, which a texture's mip chain of
    /// `N + 2` (halving the bordered size) cannot hold, and its borders are refilled from
    /// the neighbouring faces at every level, which a hardware mip generator does not do.
    /// Reading the faces back to build the chain on the CPU would stall the frame on a
    /// copy; the passes are O(level-0 texels) on the device, and a buffer laid out like
    /// `CubeMap`'s levels is read with the same index arithmetic as the CPU's.
    fn encode_mips(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        (faces, mips): (&wgpu::Texture, &wgpu::Buffer),
        scene_group: &wgpu::BindGroup,
        face_size: usize,
        layers: u32,
    ) {
        let border_sources = self.border_sources(face_size);
        let device = &self.gpu.device;
        let faces = faces.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sizes: Vec<usize> =
            std::iter::successors(Some(face_size), |&n| (n > 1).then_some(n / 2)).collect();
        let groups: Vec<wgpu::BindGroup> = (0..sizes.len())
            .map(|level| {
                let step = [
                    level as u32,
                    sizes[level.saturating_sub(1)] as u32,
                    sizes[level] as u32,
                    0,
                ];
                let bytes: Vec<u8> = step.iter().flat_map(|x| x.to_le_bytes()).collect();
                let uniform = self
                    .gpu
                    .buffer("mip step", &bytes, wgpu::BufferUsages::UNIFORM);
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("cube mips"),
                    layout: &self.layouts.mip,
                    entries: &[
                        bind(0, wgpu::BindingResource::TextureView(&faces)),
                        bind(1, mips.as_entire_binding()),
                        bind(2, uniform.as_entire_binding()),
                        bind(6, border_sources.as_entire_binding()),
                    ],
                })
            })
            .collect();
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_bind_group(1, scene_group, &[]);
        let groups_of = |texels: usize| (texels as u32).div_ceil(8);
        let m = groups_of(face_size + 2);
        pass.set_pipeline(&self.layouts.mip_copy);
        pass.set_bind_group(3, &groups[0], &[]);
        pass.dispatch_workgroups(m, m, layers);
        for (level, &n) in sizes.iter().enumerate().skip(1) {
            pass.set_bind_group(3, &groups[level], &[]);
            pass.set_pipeline(&self.layouts.mip_downsample);
            pass.dispatch_workgroups(groups_of(n), groups_of(n), layers);
            pass.set_pipeline(&self.layouts.mip_borders);
            pass.dispatch_workgroups(groups_of(n + 2), groups_of(n + 2), layers);
        }
    }

    /// `CubeMap::border_source_table(face_size)` on the device, uploaded once per face
    /// size.
    fn border_sources(&mut self, face_size: usize) -> wgpu::Buffer {
        if let Some((n, buffer)) = &self.border_sources
            && *n == face_size
        {
            return buffer.clone();
        }
        let table = CubeMap::border_source_table(face_size);
        let bytes: Vec<u8> = table.iter().flat_map(|x| x.to_le_bytes()).collect();
        let buffer = self
            .gpu
            .buffer("border sources", &bytes, wgpu::BufferUsages::STORAGE);
        self.border_sources = Some((face_size, buffer.clone()));
        buffer
    }

    /// The water's vertices, bind group and cube texture (`m`² texels a face, six faces,
    /// with dynamic cube maps; one unused texel otherwise), and the bubbles' vertices for
    /// each of `water_views` (sorted and split by side for the mirrored eye, their
    /// highlight filter's rate for each face, as the CPU sets them up per face); `None`
    /// without water.
    fn water_draw(
        &mut self,
        scene: &RenderScene,
        data: &SceneData,
        water_views: &[View],
        m: u32,
    ) -> Option<WaterDraw> {
        let water = data.water.as_ref()?;
        let key = if water_views.is_empty() {
            ((1, 1, 1), 1)
        } else {
            ((m, m, 6), 1)
        };
        let cube = self.texture("water cube", key, hdr_texture);
        let device = &self.gpu.device;
        let buffer = |label, contents: &[u8], usage| self.gpu.buffer(label, contents, usage);
        let uniform = buffer("water", &water.uniform, wgpu::BufferUsages::UNIFORM);
        let fresnel = buffer("fresnel", &water.fresnel, wgpu::BufferUsages::STORAGE);
        let cube_view = cube.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("water"),
            layout: &self.layouts.water,
            entries: &[
                bind(3, uniform.as_entire_binding()),
                bind(4, fresnel.as_entire_binding()),
                bind(5, wgpu::BindingResource::TextureView(&cube_view)),
            ],
        });
        let scene_bubbles = !data.bubbles.is_empty() && !water_views.is_empty();
        let face_bubbles = scene_bubbles.then(|| {
            let mut bytes = Vec::new();
            let mut draws = Vec::with_capacity(water_views.len());
            for v in water_views {
                let first = (bytes.len() as u64 / BUBBLE_VERTEX_BYTES) as u32;
                let (b, ranges) = bubble_vertices(scene, v, &data.film_places);
                bytes.extend(b);
                draws.push(
                    ranges
                        .into_iter()
                        .map(|r| r.start + first..r.end + first)
                        .collect(),
                );
            }
            (
                buffer("water face bubbles", &bytes, wgpu::BufferUsages::VERTEX),
                draws,
            )
        });
        let vertices = buffer(
            "water vertices",
            &water.vertices,
            wgpu::BufferUsages::VERTEX,
        );
        let indices = buffer("water indices", &water.indices, wgpu::BufferUsages::INDEX);
        Some(WaterDraw {
            vertices,
            indices,
            count: water.index_count,
            group,
            cube: (!water_views.is_empty()).then_some(cube),
            face_bubbles,
        })
    }

    /// The water's cube map, as raster's `WaterPass::render_cube`: per face (views
    /// `first_view..first_view + 6`), the sky, the objects and light spheres of `opaque`
    /// (no ground, no water), then the bubbles blended over them reading their own cube
    /// maps (`groups`: view, scene, bubble tables).
    fn encode_water_cube(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        water: &WaterDraw,
        groups: [&wgpu::BindGroup; 3],
        first_view: usize,
        face_depth: &wgpu::TextureView,
        (objects, vertices): (Option<&wgpu::Buffer>, u32),
    ) {
        let Some(cube) = &water.cube else {
            return;
        };
        let single = self.pipelines_for(1);
        let p = &self.pipelines[single];
        for face in 0..6 {
            let layer = array_layer(cube, face);
            let target = Target {
                color: &layer,
                resolve: None,
                depth: face_depth,
            };
            let mut pass = begin(encoder, &target);
            let offset = (VIEW_STRIDE * (first_view + face) as u64) as u32;
            pass.set_bind_group(0, groups[0], &[offset]);
            pass.set_bind_group(1, groups[1], &[]);
            let no_ground = (&water.vertices, 0..0);
            draw_opaque(&mut pass, p, no_ground, objects, vertices);
            if let Some((bubbles, draws)) = &water.face_bubbles {
                pass.set_bind_group(2, groups[2], &[]);
                draw_bubbles(&mut pass, p, bubbles, &draws[face]);
            }
        }
    }

    /// The texture of `role` with `key`, made on first use and when its key changes.
    fn texture(&mut self, role: &'static str, key: TextureKey, make: MakeTexture) -> wgpu::Texture {
        if let Some((_, k, t)) = self.textures.iter().find(|(r, ..)| *r == role) {
            if *k == key {
                return t.clone();
            }
        }
        let texture = make(&self.gpu.device, role, key.0, key.1);
        self.textures.retain(|(r, ..)| *r != role);
        self.textures.push((role, key, texture.clone()));
        texture
    }

    /// Index of the pipelines for `samples`, compiled on first use.
    fn pipelines_for(&mut self, samples: u32) -> usize {
        if let Some(i) = self.pipelines.iter().position(|p| p.samples == samples) {
            return i;
        }
        self.pipelines
            .push(Pipelines::new(&self.gpu.device, &self.layouts, samples));
        self.pipelines.len() - 1
    }

    /// Every view's `View` uniform, `VIEW_STRIDE` bytes apart; the ground triangles of
    /// every view before `grounded` in one vertex buffer, and each view's vertex range in
    /// it (empty from `grounded` on).
    fn view_buffers(
        &self,
        scene: &RenderScene,
        views: &[View],
        grounded: usize,
    ) -> (wgpu::Buffer, wgpu::Buffer, Vec<std::ops::Range<u32>>) {
        let mut bytes = Vec::with_capacity(views.len() * VIEW_STRIDE as usize);
        let mut ground_bytes: Vec<u8> = Vec::new();
        let mut ranges = Vec::with_capacity(views.len());
        for (k, v) in views.iter().enumerate() {
            // The main view (first) filters the checker over half pixels, the cube faces
            // over one box per texel, as the CPU's `render_cube_maps`.
            let filter = if k == 0 {
                GroundFilter::Halves
            } else {
                GroundFilter::Pixel
            };
            let ground = scene
                .ground
                .as_ref()
                .filter(|_| k < grounded)
                .and_then(|g| GroundView::new(g, v))
                .map(|g| g.with_filter(filter));
            bytes.extend(view_bytes(v, ground.as_ref()));
            bytes.resize(bytes.len().next_multiple_of(VIEW_STRIDE as usize), 0);
            let start = (ground_bytes.len() / 12) as u32;
            for vertex in ground.map_or(Vec::new(), |g| ground_triangles(v, &g)) {
                ground_bytes.extend(vertex.iter().flat_map(|x| x.to_le_bytes()));
            }
            ranges.push(start..(ground_bytes.len() / 12) as u32);
        }
        // A vertex buffer may not be empty.
        ground_bytes.resize(ground_bytes.len().max(12), 0);
        let buffer = |label, contents: &[u8], usage| self.gpu.buffer(label, contents, usage);
        (
            buffer("views", &bytes, wgpu::BufferUsages::UNIFORM),
            buffer("ground", &ground_bytes, wgpu::BufferUsages::VERTEX),
            ranges,
        )
    }

    /// A data texture of `format` (the stacked LUT tables, the film fields), read with
    /// `textureLoad` only.
    fn data_texture(
        &self,
        label: &str,
        format: wgpu::TextureFormat,
        (width, height, texels): &(u32, u32, Vec<u8>),
    ) -> wgpu::Texture {
        self.gpu.device.create_texture_with_data(
            &self.gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: *width,
                    height: *height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            texels,
        )
    }
}

/// Refuses a water surface whose vertex buffer is larger than the device's
/// `max_buffer_size`, naming the limit and the value (an adapter limit, not a refusal of
/// water).
fn check_water_fits(data: &SceneData, max_buffer_size: u64) -> Result<(), GpuError> {
    match &data.water {
        Some(w) if w.vertices.len().max(w.indices.len()) as u64 > max_buffer_size => {
            Err(GpuError::Unsupported(format!(
                "a water surface of {} triangles (its vertices take {} bytes and its indices \
                 {}, this device's max_buffer_size is {max_buffer_size})",
                w.index_count / 3,
                w.vertices.len(),
                w.indices.len()
            )))
        }
        _ => Ok(()),
    }
}

/// The six face views of each bubble's cube map, exactly as the CPU's `render_cube_maps`.
fn cube_face_views(scene: &RenderScene, face_size: usize) -> Vec<View> {
    let near_m = scene.camera.near_m();
    (scene.bubbles.iter().map(BubbleMesh::center))
        .flat_map(|centre| face_views_from(centre, face_size, near_m))
        .collect()
}

/// The six face views of a cube map seen from `centre`, as the CPU's `render_cube_maps`
/// and `WaterPass::render_cube` make them: one texel wider on each side for the border
/// ring.
fn face_views_from(centre: Vec3, face_size: usize, near_m: f32) -> Vec<View> {
    let m = face_size + 2;
    let wide = m as f32 / face_size as f32;
    FACE_BASES
        .iter()
        .map(|&(major, s_axis, t_axis)| {
            View::new(
                centre,
                [major, s_axis, -t_axis],
                (wide, wide),
                (m, m),
                near_m,
            )
        })
        .collect()
}

/// Per side of each bubble, in `draws`' order: dest ← dest ⊙ T, then dest ← dest + added
/// light, which is the CPU's dest ⊙ T + add where a side's triangles do not overlap.
fn draw_bubbles(
    pass: &mut wgpu::RenderPass<'_>,
    p: &Pipelines,
    bubbles: &wgpu::Buffer,
    draws: &[std::ops::Range<u32>],
) {
    pass.set_vertex_buffer(0, bubbles.slice(..));
    for range in draws {
        pass.set_pipeline(&p.transmit);
        pass.draw(range.clone(), 0..1);
        pass.set_pipeline(&p.add);
        pass.draw(range.clone(), 0..1);
    }
}

fn begin<'e>(encoder: &'e mut wgpu::CommandEncoder, target: &Target<'_>) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: None,
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target.color,
            depth_slice: None,
            resolve_target: target.resolve,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: target.depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Sky, the view's ground triangles, then the first `vertices` object vertices.
fn draw_opaque(
    pass: &mut wgpu::RenderPass<'_>,
    p: &Pipelines,
    (ground, ground_range): (&wgpu::Buffer, std::ops::Range<u32>),
    objects: Option<&wgpu::Buffer>,
    vertices: u32,
) {
    pass.set_pipeline(&p.sky);
    pass.draw(0..3, 0..1);
    if !ground_range.is_empty() {
        pass.set_pipeline(&p.ground);
        pass.set_vertex_buffer(0, ground.slice(..));
        pass.draw(ground_range, 0..1);
    }
    if let (Some(objects), true) = (objects, vertices > 0) {
        pass.set_pipeline(&p.objects);
        pass.set_vertex_buffer(0, objects.slice(..));
        pass.draw(0..vertices, 0..1);
    }
}

/// Layer `k` of a 2-D array texture as a plain 2-D render target.
fn array_layer(texture: &wgpu::Texture, k: usize) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_array_layer: k as u32,
        array_layer_count: Some(1),
        ..Default::default()
    })
}

/// Bind-group entry `binding` holding `resource`.
pub(super) fn bind(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

fn hdr_texture(
    device: &wgpu::Device,
    label: &str,
    (width, height, layers): (u32, u32, u32),
    samples: u32,
) -> wgpu::Texture {
    let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    if samples == 1 {
        usage |= wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC;
    }
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format: HDR_FORMAT,
        usage,
        view_formats: &[],
    })
}

fn depth_texture(
    device: &wgpu::Device,
    label: &str,
    (width, height, _): (u32, u32, u32),
    samples: u32,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format: DEPTH_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    })
}

/// An IEEE half-precision value as f32 (exact: every f16 is an f32).
pub(super) fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x3ff);
    sign * match exponent {
        0 => mantissa * (-24f32).exp2(),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + mantissa / 1024.0) * ((e - 15) as f32).exp2(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f16_decoding_matches_known_values() {
        for (bits, want) in [
            (0x0000u16, 0.0f32),
            (0x3c00, 1.0),
            (0xc000, -2.0),
            (0x3555, 0.333_251_95),
            (0x7bff, 65504.0),
            (0x0001, 5.960_464_5e-8),
            (0x0400, 6.103_515_6e-5),
        ] {
            assert_eq!(f16_to_f32(bits), want, "{bits:#06x}");
        }
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
    }
}

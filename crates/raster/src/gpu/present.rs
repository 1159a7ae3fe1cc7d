//! [`WindowSurface`]: a window's wgpu surface, and the pass that puts a frame on it with no
//! read-back: the resolved HDR frame is tone-mapped and upscaled (nearest) straight into the
//! surface texture, and the overlay is alpha-blended on top in the same render pass.
//!
//! Why the overlay is a small premultiplied RGBA texture uploaded each frame rather than
//! text drawn by a shader: the caller's overlay (the viewer's bitmap font) stays one piece
//! of code for both presenters, and a text box of a few hundred pixels a side is a few
//! hundred kilobytes a frame at most, against the megabytes a read-back of the frame moves.

use std::time::Instant;

use super::renderer::bind;
use super::shader_source::present_wgsl;
use super::{Gpu, GpuError, GpuOptions, GpuRenderer};
use render_scene::{FilmTables, FrameTimings, RenderScene, RenderSettings, ToneMap};

/// Bytes of the shader's `Present` uniform.
pub(super) const PRESENT_BYTES: u64 = 48;

/// An overlay to blend over the frame: premultiplied-alpha RGBA8 texels, row-major,
/// `size.0` × `size.1`, its top-left corner at `origin` in window pixels.
#[derive(Debug, Clone, Copy)]
pub struct Overlay<'a> {
    /// The texels, 4 bytes each, colour already multiplied by alpha.
    pub rgba: &'a [u8],
    /// Width and height in texels.
    pub size: (u32, u32),
    /// Top-left corner on the window, in pixels.
    pub origin: (u32, u32),
}

/// A window's surface, configured for one [`GpuRenderer`]'s device, with the present pass.
///
/// # Guarantees
/// Made only by [`GpuRenderer::for_window`], on the device that renders into it.
#[derive(Debug)]
pub struct WindowSurface {
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    frame: wgpu::RenderPipeline,
    overlay: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    /// The overlay's texture, grown to the largest overlay so far, and its size.
    overlay_texture: Option<(wgpu::Texture, (u32, u32))>,
}

impl GpuRenderer {
    /// Opens a device that can present to `window` (a winit window in an `Arc`, say) and
    /// configures its surface at `size` pixels.
    ///
    /// # Errors
    /// [`GpuError::Surface`] when no surface can be made or configured for the window,
    /// else [`GpuRenderer::new`]'s.
    pub fn for_window(
        options: GpuOptions,
        window: impl Into<wgpu::SurfaceTarget<'static>>,
        size: (u32, u32),
    ) -> Result<(GpuRenderer, WindowSurface), GpuError> {
        let instance = super::context::instance();
        let surface = instance.create_surface(window).map_err(|e| {
            GpuError::Surface(format!(
                "no Vulkan surface for the window ({e}); a Vulkan driver is needed (on \
                     Debian, mesa-vulkan-drivers gives lavapipe; VK_DRIVER_FILES names its ICD \
                     json)"
            ))
        })?;
        let gpu = Gpu::open(&instance, options, Some(&surface))?;
        let window = WindowSurface::new(&gpu, surface, size)?;
        Ok((GpuRenderer::from_gpu(gpu), window))
    }

    /// Renders one frame and presents it on `window` with `overlay` on top, without
    /// reading it back. Timings: `setup_s` is the CPU's packing and encoding, `resolve_s`
    /// the GPU's work, waited for so the caller can adapt its resolution to it. A surface
    /// that is occluded or times out skips the frame (zero timings).
    pub fn present(
        &mut self,
        (scene, tables, settings): (&RenderScene, &FilmTables, &RenderSettings),
        window: &mut WindowSurface,
        overlay: Option<Overlay<'_>>,
    ) -> Result<FrameTimings, GpuError> {
        let start = Instant::now();
        let Some(target) = window.acquire(&self.gpu.device)? else {
            return Ok(FrameTimings::default());
        };
        let (mut encoder, resolved, _) = self.encode(scene, tables, settings)?;
        let tone = (settings.exposure_ev.exp2(), settings.tonemap);
        window.encode(&self.gpu, &mut encoder, (&resolved, &target), tone, overlay);
        let setup_s = start.elapsed().as_secs_f64();
        let t = Instant::now();
        let index = self.gpu.queue.submit([encoder.finish()]);
        self.gpu
            .device
            .poll(wgpu::PollType::Wait {
                submission_index: Some(index),
                timeout: None,
            })
            .map_err(|e| GpuError::Surface(e.to_string()))?;
        let resolve_s = t.elapsed().as_secs_f64();
        self.gpu.queue.present(target);
        Ok(FrameTimings {
            setup_s,
            resolve_s,
            ..FrameTimings::default()
        })
    }
}

impl WindowSurface {
    fn new(gpu: &Gpu, surface: wgpu::Surface<'static>, size: (u32, u32)) -> Result<Self, GpuError> {
        let caps = surface.get_capabilities(&gpu.adapter);
        // A UNORM format takes the shader's own sRGB encoding, the CPU viewer's bytes; an
        // sRGB-only surface encodes in hardware (the overlay then blends in linear light).
        let format = [
            wgpu::TextureFormat::Bgra8Unorm,
            wgpu::TextureFormat::Rgba8Unorm,
        ]
        .into_iter()
        .find(|f| caps.formats.contains(f))
        .or_else(|| caps.formats.first().copied())
        .ok_or_else(|| GpuError::Surface("the adapter cannot present to this window".into()))?;
        let mut config = surface
            .get_default_config(&gpu.adapter, size.0.max(1), size.1.max(1))
            .ok_or_else(|| GpuError::Surface("the adapter cannot present to this window".into()))?;
        config.format = format;
        // As the CPU presenter (softbuffer), frames are not held to the display's refresh:
        // the overlay's fps is the renderer's, and the adaptive scale aims at --target-fps.
        config.present_mode = wgpu::PresentMode::AutoNoVsync;
        surface.configure(&gpu.device, &config);
        let (frame, overlay, layout) = pipelines(&gpu.device, format);
        let params = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("present"),
            size: PRESENT_BYTES,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(WindowSurface {
            surface,
            config,
            frame,
            overlay,
            layout,
            params,
            overlay_texture: None,
        })
    }

    /// The surface's texture format (a UNORM one where the surface offers it).
    pub fn format(&self) -> wgpu::TextureFormat {
        self.config.format
    }

    /// Reconfigures the surface for a window of `width` × `height` pixels (ignores zero).
    pub fn resize(&mut self, renderer: &GpuRenderer, width: u32, height: u32) {
        if width == 0 || height == 0 || (width, height) == (self.config.width, self.config.height) {
            return;
        }
        self.config.width = width;
        self.config.height = height;
        self.surface.configure(&renderer.gpu.device, &self.config);
    }

    /// The next surface texture; `None` to skip a frame (occluded, timed out). An outdated
    /// or suboptimal surface is reconfigured once.
    fn acquire(&mut self, device: &wgpu::Device) -> Result<Option<wgpu::SurfaceTexture>, GpuError> {
        use wgpu::CurrentSurfaceTexture as Current;
        for _ in 0..2 {
            match self.surface.get_current_texture() {
                Current::Success(t) => return Ok(Some(t)),
                Current::Suboptimal(t) => {
                    drop(t);
                    self.surface.configure(device, &self.config);
                }
                Current::Timeout | Current::Occluded => return Ok(None),
                Current::Outdated => self.surface.configure(device, &self.config),
                other => {
                    return Err(GpuError::Surface(format!(
                        "the window's surface failed: {other:?}"
                    )));
                }
            }
        }
        Ok(None)
    }

    /// Records the present pass: the frame tone-mapped into `target`, then the overlay.
    fn encode(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        (hdr, target): (&wgpu::Texture, &wgpu::SurfaceTexture),
        (scale, tonemap): (f32, ToneMap),
        overlay: Option<Overlay<'_>>,
    ) {
        let overlay_view = self.upload_overlay(gpu, overlay);
        let source = (hdr.width(), hdr.height());
        let target_size = (self.config.width, self.config.height);
        let placed = overlay.map_or(((0, 0), (0, 0)), |o| (o.origin, o.size));
        let bytes = params_bytes(
            (scale, tonemap, !self.config.format.is_srgb()),
            [source, target_size, placed.0, placed.1],
        );
        gpu.queue.write_buffer(&self.params, 0, &bytes);
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("present"),
            layout: &self.layout,
            entries: &[
                bind(
                    0,
                    wgpu::BindingResource::TextureView(&hdr.create_view(&Default::default())),
                ),
                bind(1, wgpu::BindingResource::TextureView(&overlay_view)),
                bind(2, self.params.as_entire_binding()),
            ],
        });
        let view = target.texture.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("present"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &bind, &[]);
        pass.set_pipeline(&self.frame);
        pass.draw(0..3, 0..1);
        if overlay.is_some_and(|o| o.size.0 > 0 && o.size.1 > 0) {
            pass.set_pipeline(&self.overlay);
            pass.draw(0..6, 0..1);
        }
    }

    /// Writes the overlay's texels into the overlay texture (grown when too small) and
    /// returns a view of it (1×1 when there is no overlay, for the bind group).
    fn upload_overlay(&mut self, gpu: &Gpu, overlay: Option<Overlay<'_>>) -> wgpu::TextureView {
        let need = overlay.map_or((1, 1), |o| (o.size.0.max(1), o.size.1.max(1)));
        let fits = self
            .overlay_texture
            .as_ref()
            .is_some_and(|(_, (w, h))| *w >= need.0 && *h >= need.1);
        if !fits {
            let have = self.overlay_texture.as_ref().map_or((1, 1), |(_, s)| *s);
            let size = (need.0.max(have.0), need.1.max(have.1));
            self.overlay_texture = Some((overlay_texture(&gpu.device, size), size));
        }
        let (texture, _) = self.overlay_texture.as_ref().expect("made above");
        if let Some(o) = overlay.filter(|o| o.size.0 > 0 && o.size.1 > 0) {
            gpu.queue.write_texture(
                texture.as_image_copy(),
                o.rgba,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * o.size.0),
                    rows_per_image: None,
                },
                wgpu::Extent3d {
                    width: o.size.0,
                    height: o.size.1,
                    depth_or_array_layers: 1,
                },
            );
        }
        texture.create_view(&Default::default())
    }
}

/// The shader's `Present` uniform: scale, curve, whether to encode sRGB, then the
/// source, target, overlay origin and overlay size as pairs of u32.
pub(super) fn params_bytes(
    (scale, tonemap, encode): (f32, ToneMap, bool),
    pairs: [(u32, u32); 4],
) -> Vec<u8> {
    let curve: u32 = match tonemap {
        ToneMap::Clamp => 0,
        ToneMap::Reinhard => 1,
        ToneMap::AcesFitted => 2,
    };
    let mut words = vec![scale.to_bits(), curve, u32::from(encode), 0];
    words.extend(pairs.iter().flat_map(|&(a, b)| [a, b]));
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// The frame pipeline (no blending) and the overlay pipeline (premultiplied alpha:
/// `dest ← src + (1 − src.a) · dest`), both writing `format`, and their bind group layout.
fn pipelines(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
) -> (
    wgpu::RenderPipeline,
    wgpu::RenderPipeline,
    wgpu::BindGroupLayout,
) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("present"),
        source: wgpu::ShaderSource::Wgsl(present_wgsl().into()),
    });
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("present"),
        entries: &[
            texture(0),
            texture(1),
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(PRESENT_BYTES),
                },
                count: None,
            },
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("present"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let make = |vs, fs, blend| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(fs),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let frame = make("vs_frame", "fs_frame", None);
    let overlay = make(
        "vs_overlay",
        "fs_overlay",
        Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
    );
    (frame, overlay, layout)
}

fn overlay_texture(device: &wgpu::Device, (width, height): (u32, u32)) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("overlay"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

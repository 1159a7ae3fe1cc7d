//! The last pass: linear HDR frame → tone-mapped 8-bit sRGB, read back to the CPU.

use super::renderer::bind;
use super::shader_source::tonemap_wgsl;
use super::{Gpu, GpuError};
use render_scene::{Frame, ToneMap};

/// Work-group side of the compute shader (`@workgroup_size(8, 8)`).
const GROUP_SIDE: u32 = 8;

/// The compiled tone-map pipeline.
#[derive(Debug)]
pub(super) struct ToneMapPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl ToneMapPass {
    pub(super) fn new(device: &wgpu::Device) -> ToneMapPass {
        let source = tonemap_wgsl();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("tonemap"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("tonemap"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let layout = pipeline.get_bind_group_layout(0);
        ToneMapPass { pipeline, layout }
    }
}

/// The shader's `Params`, as its uniform buffer holds it.
fn params_bytes(scale: f32, tonemap: ToneMap, width: u32, height: u32) -> Vec<u8> {
    let curve: u32 = match tonemap {
        ToneMap::Clamp => 0,
        ToneMap::Reinhard => 1,
        ToneMap::AcesFitted => 2,
    };
    [scale.to_bits(), curve, width, height]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

impl Gpu {
    /// Tone-maps `frame` on the GPU: the same bytes as [`Frame::to_srgb8`] up to one
    /// code value where the GPU's `pow` rounds differently (interleaved RGB, row-major).
    pub fn tone_map_srgb8(
        &self,
        frame: &Frame,
        exposure_ev: f32,
        tonemap: ToneMap,
    ) -> Result<Vec<u8>, GpuError> {
        let (w, h) = (frame.width() as u32, frame.height() as u32);
        self.check_size(w, h)?;
        let size = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        let hdr = self.upload_hdr(frame, size);
        self.tone_map_texture(&hdr, size, exposure_ev, tonemap)
    }

    /// Tone-maps the HDR texture `hdr` (already written, or written by work submitted
    /// before this call) into interleaved 8-bit sRGB, as [`Frame::to_srgb8`].
    pub(super) fn tone_map_texture(
        &self,
        hdr: &wgpu::Texture,
        size: wgpu::Extent3d,
        exposure_ev: f32,
        tonemap: ToneMap,
    ) -> Result<Vec<u8>, GpuError> {
        let (w, h) = (size.width, size.height);
        let ldr = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("ldr"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Uint,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let params = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tonemap params"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bytes = params_bytes(exposure_ev.exp2(), tonemap, w, h);
        self.queue.write_buffer(&params, 0, &bytes);
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tonemap"),
            layout: &self.tone_map.layout,
            entries: &[
                bind(
                    0,
                    wgpu::BindingResource::TextureView(&hdr.create_view(&Default::default())),
                ),
                bind(
                    1,
                    wgpu::BindingResource::TextureView(&ldr.create_view(&Default::default())),
                ),
                bind(2, params.as_entire_binding()),
            ],
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.tone_map.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(w.div_ceil(GROUP_SIDE), h.div_ceil(GROUP_SIDE), 1);
        }
        let rgba = self.read_back(encoder, &ldr, size, 4)?;
        Ok(rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect())
    }

    /// Uploads the frame's radiance as an `Rgba32Float` texture (alpha 1).
    fn upload_hdr(&self, frame: &Frame, size: wgpu::Extent3d) -> wgpu::Texture {
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("hdr"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let bytes: Vec<u8> = frame
            .rgb()
            .iter()
            .flat_map(|p| [p[0], p[1], p[2], 1.0])
            .flat_map(f32::to_le_bytes)
            .collect();
        self.queue.write_texture(
            texture.as_image_copy(),
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(size.width * 16),
                rows_per_image: None,
            },
            size,
        );
        texture
    }

    /// Copies a texture of `texel_bytes` per texel into a mappable buffer and returns its
    /// rows without the 256-byte row padding that texture-to-buffer copies require.
    pub(super) fn read_back(
        &self,
        mut encoder: wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        size: wgpu::Extent3d,
        texel_bytes: u32,
    ) -> Result<Vec<u8>, GpuError> {
        let row_bytes = size.width * texel_bytes;
        let padded = row_bytes.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read back"),
            size: u64::from(padded) * u64::from(size.height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: None,
                },
            },
            size,
        );
        let view = self.submit_and_map(encoder, &buffer)?;
        let mut out = Vec::with_capacity((row_bytes * size.height) as usize);
        for row in view.chunks_exact(padded as usize) {
            out.extend_from_slice(&row[..row_bytes as usize]);
        }
        Ok(out)
    }

    /// The bytes of a storage `buffer` made with `COPY_SRC` (after the work submitted).
    pub(super) fn read_buffer(&self, source: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read back"),
            size: source.size(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(source, 0, &buffer, 0, source.size());
        Ok(self.submit_and_map(encoder, &buffer)?.to_vec())
    }

    /// Submits `encoder`, waits, and maps `buffer` for reading.
    fn submit_and_map(
        &self,
        encoder: wgpu::CommandEncoder,
        buffer: &wgpu::Buffer,
    ) -> Result<wgpu::BufferView, GpuError> {
        self.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        rx.recv()
            .map_err(|e| GpuError::Readback(e.to_string()))?
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        buffer
            .get_mapped_range(..)
            .map_err(|e| GpuError::Readback(e.to_string()))
    }
}

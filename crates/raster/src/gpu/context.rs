//! [`Gpu`]: a headless wgpu device, chosen once and reused for every frame.

use super::GpuError;
use super::tonemap::ToneMapPass;

/// How to choose the adapter.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// Ask for a CPU (software) adapter such as Mesa's lavapipe instead of a GPU.
    pub force_cpu_adapter: bool,
}

/// A headless wgpu device with the backend's pipelines compiled.
///
/// # Guarantees
/// Holds an open device and queue; a window's surface, when there is one, is a
/// [`super::WindowSurface`] beside it.
#[derive(Debug)]
pub struct Gpu {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    /// The adapter, kept to ask what a window surface offers.
    pub(super) adapter: wgpu::Adapter,
    pub(super) tone_map: ToneMapPass,
    /// The frame's sample counts this device renders, ascending (always 1 and 4).
    sample_counts: Vec<u32>,
}

impl Gpu {
    /// A buffer holding `contents`, for `usage`.
    pub(super) fn buffer(
        &self,
        label: &str,
        contents: &[u8],
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        use wgpu::util::DeviceExt;
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
    }

    /// Opens the first suitable adapter (Vulkan first) and compiles the pipelines.
    pub fn new(options: GpuOptions) -> Result<Gpu, GpuError> {
        Gpu::open(&instance(), options, None)
    }

    /// Opens the first adapter that can present to `surface` (made by `instance`), as
    /// [`Gpu::new`] does.
    pub(super) fn open(
        instance: &wgpu::Instance,
        options: GpuOptions,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Gpu, GpuError> {
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: options.force_cpu_adapter,
            compatible_surface: surface,
            ..Default::default()
        }))
        .map_err(|e| GpuError::NoAdapter {
            reason: e.to_string(),
        })?;
        // Sample counts besides 1 and 4 need the adapter's own format features.
        let specific =
            adapter.features() & wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("raster"),
            required_features: specific,
            required_limits: wgpu::Limits {
                // Six cube faces per bubble, as many as the adapter holds.
                max_texture_array_layers: adapter.limits().max_texture_array_layers,
                ..wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits())
            },
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        let tone_map = ToneMapPass::new(&device);
        Ok(Gpu {
            info: adapter.get_info(),
            device,
            queue,
            tone_map,
            sample_counts: sample_counts(&adapter, !specific.is_empty()),
            adapter,
        })
    }

    /// The adapter's name and driver, for reports (`"llvmpipe (LLVM 15.0.6, 256 bits), Mesa 22.3.6"`).
    pub fn adapter_name(&self) -> String {
        let i = &self.info;
        format!(
            "{} ({:?}), {} {}",
            i.name, i.device_type, i.driver, i.driver_info
        )
    }

    /// The sample count the frame is rendered with for `requested`: `requested` where the
    /// device renders it, else the nearest count it does (the lower one on a tie), so 9
    /// becomes 8 everywhere and 16 becomes 8 where 16 is not offered.
    pub fn sample_count_for(&self, requested: u32) -> u32 {
        let nearest = self
            .sample_counts
            .iter()
            .min_by_key(|&&n| (n.abs_diff(requested), n));
        *nearest.expect("1 and 4 are always offered")
    }

    /// The frame's sample counts this device renders, ascending.
    pub fn sample_counts(&self) -> &[u32] {
        &self.sample_counts
    }

    /// Whether the adapter is a CPU (software) implementation.
    pub fn is_cpu_adapter(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Fails with [`GpuError::TooLarge`] when a `width` × `height` texture exceeds the device.
    pub(super) fn check_size(&self, width: u32, height: u32) -> Result<(), GpuError> {
        let max_side = self.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max_side || height > max_side {
            return Err(GpuError::TooLarge {
                size: (width, height),
                max_side,
            });
        }
        Ok(())
    }
}

/// The Vulkan instance (with wgpu's environment overrides) every device is opened from.
pub(super) fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    desc.backends = wgpu::Backends::VULKAN;
    wgpu::Instance::new(desc)
}

/// The frame's sample counts: 1, 4 (every WebGPU device), and with the adapter's own format
/// features each of 2, 8 and 16 that both the frame's HDR colour (rendered and resolved)
/// and its depth take.
fn sample_counts(adapter: &wgpu::Adapter, specific: bool) -> Vec<u32> {
    use super::pipelines::{DEPTH_FORMAT, HDR_FORMAT};
    let hdr = adapter.get_texture_format_features(HDR_FORMAT).flags;
    let depth = adapter.get_texture_format_features(DEPTH_FORMAT).flags;
    let resolves = hdr.contains(wgpu::TextureFormatFeatureFlags::MULTISAMPLE_RESOLVE);
    [1, 2, 4, 8, 16]
        .into_iter()
        .filter(|&n| {
            n == 1
                || n == 4
                || (specific
                    && resolves
                    && hdr.sample_count_supported(n)
                    && depth.sample_count_supported(n))
        })
        .collect()
}

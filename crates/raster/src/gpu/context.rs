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
/// Holds an open device and queue; no window or surface is involved.
#[derive(Debug)]
pub struct Gpu {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    pub(super) tone_map: ToneMapPass,
}

impl Gpu {
    /// Opens the first suitable adapter (Vulkan first) and compiles the pipelines.
    pub fn new(options: GpuOptions) -> Result<Gpu, GpuError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: options.force_cpu_adapter,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| GpuError::NoAdapter {
            reason: e.to_string(),
        })?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("raster"),
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

//! [`GpuError`]: why the wgpu backend could not start or finish a frame.

// Without the `wgpu` feature only the naga layout test uses this module.
#![cfg_attr(not(feature = "wgpu"), allow(dead_code))]

use std::fmt;

/// Why the wgpu backend failed.
#[derive(Debug, Clone, PartialEq)]
pub enum GpuError {
    /// No adapter (GPU or software Vulkan driver) was found.
    NoAdapter {
        /// wgpu's own explanation.
        reason: String,
    },
    /// The adapter refused to open a device with the limits the backend needs.
    Device(String),
    /// A frame or image is larger than the device's texture limit.
    TooLarge {
        /// Requested width and height in pixels.
        size: (u32, u32),
        /// The device's maximum texture side.
        max_side: u32,
    },
    /// Mapping the read-back buffer failed.
    Readback(String),
    /// A window's surface could not be made, configured or presented to.
    Surface(String),
    /// The scene or settings are invalid (the same check as the CPU backend's).
    Invalid(render_scene::RenderError),
    /// The scene uses something the wgpu backend does not draw (named).
    Unsupported(String),
}

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GpuError::NoAdapter { reason } => write!(
                f,
                "no wgpu adapter found ({reason}); install a Vulkan driver (on Debian, the \
                 packages mesa-vulkan-drivers and libvulkan1 give the CPU driver lavapipe), \
                 point VK_DRIVER_FILES at its ICD json if it is not found, or use --backend cpu"
            ),
            GpuError::Device(reason) => write!(f, "the wgpu device could not be opened: {reason}"),
            GpuError::TooLarge { size, max_side } => write!(
                f,
                "image {}x{} is larger than this GPU's texture limit of {max_side} pixels a side",
                size.0, size.1
            ),
            GpuError::Readback(reason) => write!(f, "reading the frame back failed: {reason}"),
            GpuError::Surface(reason) => write!(f, "the window's wgpu surface failed: {reason}"),
            GpuError::Invalid(e) => write!(f, "{e}"),
            GpuError::Unsupported(what) => write!(
                f,
                "the wgpu backend does not support {what} yet; use --backend cpu"
            ),
        }
    }
}

impl std::error::Error for GpuError {}

impl From<render_scene::RenderError> for GpuError {
    fn from(e: render_scene::RenderError) -> Self {
        GpuError::Invalid(e)
    }
}

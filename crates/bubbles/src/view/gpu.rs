//! The wgpu presenter (`bubbles view --backend wgpu`): the GPU renders each frame and puts
//! it on the window's surface (`raster::gpu::GpuRenderer::present`), nothing read back;
//! the overlay is the CPU viewer's bitmap text as a small RGBA texture blended on top.

use super::font;
use super::present::{OVERLAY_AT, OVERLAY_SCALE};
use crate::error::CliError;
use crate::frame::FrameJob;
use crate::frame::gpu::note_sample_count;
use raster::gpu::{GpuError, GpuOptions, GpuRenderer, Overlay, WindowSurface};
use raster::{Frame, FrameTimings, ReflectionParallax};
use std::sync::Arc;
use winit::window::Window;

/// The GPU renderer, the window's surface, and whether the sample-count notice was given.
pub(super) struct GpuPresenter {
    renderer: GpuRenderer,
    surface: WindowSurface,
    said_samples: bool,
}

impl GpuPresenter {
    /// Opens a device that presents to `window` at its current size, reading cube maps
    /// with `parallax`.
    pub(super) fn open(
        window: &Arc<Window>,
        parallax: ReflectionParallax,
    ) -> Result<GpuPresenter, GpuError> {
        let size = window.inner_size();
        let (mut renderer, surface) = GpuRenderer::for_window(
            GpuOptions::default(),
            window.clone(),
            (size.width, size.height),
        )?;
        renderer.set_reflection_parallax(parallax);
        Ok(GpuPresenter {
            renderer,
            surface,
            said_samples: false,
        })
    }

    /// `wgpu on <adapter>`.
    pub(super) fn name(&self) -> String {
        format!("wgpu on {}", self.renderer.gpu().adapter_name())
    }

    /// Reconfigures the surface for the window's new size.
    pub(super) fn resize(&mut self, width: u32, height: u32) {
        self.surface.resize(&self.renderer, width, height);
    }

    /// Renders and presents the job's current state with `overlay` on top.
    pub(super) fn draw(
        &mut self,
        job: &mut FrameJob,
        overlay: Option<&str>,
    ) -> Result<FrameTimings, CliError> {
        let inputs = job.frame_inputs();
        let gpu = self.renderer.gpu();
        note_sample_count(gpu, inputs.2.samples, &mut self.said_samples);
        let text = overlay.map(|t| font::text_rgba(t, OVERLAY_SCALE));
        let overlay = text.as_ref().map(|(w, h, rgba)| Overlay {
            rgba,
            size: (*w as u32, *h as u32),
            origin: (OVERLAY_AT.0 as u32, OVERLAY_AT.1 as u32),
        });
        let presented = self.renderer.present(inputs, &mut self.surface, overlay);
        presented.map_err(|e| frame_error(&job.origin(), e))
    }

    /// The job's current state rendered on the GPU and read back (for screenshots).
    pub(super) fn frame(&mut self, job: &mut FrameJob) -> Result<&Frame, CliError> {
        let (scene, tables, settings) = job.frame_inputs();
        let rendered = self.renderer.render(scene, tables, settings);
        rendered.map_err(|e| frame_error(&job.origin(), e))
    }
}

/// A failed frame: the scene's fault (unsupported, invalid, too large) is an input error
/// (exit 2, as `bubbles render --backend wgpu`), the device's or the window's a runtime one.
fn frame_error(origin: &str, e: GpuError) -> CliError {
    let message = format!("{origin}: {e}");
    match e {
        GpuError::Surface(_) | GpuError::Readback(_) | GpuError::Device(_) => {
            CliError::runtime(message)
        }
        _ => CliError::input(message),
    }
}

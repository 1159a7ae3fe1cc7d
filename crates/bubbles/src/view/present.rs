//! How a frame reaches the window: [`Presenter`] is the one seam between the event loop
//! (window.rs, shared) and the two ways of drawing. The CPU presenter renders with the
//! job's own renderer, tone-maps and upscales on the CPU and copies into softbuffer; the
//! wgpu presenter (`--backend wgpu`, view/gpu.rs) renders, tone-maps and upscales on the GPU
//! straight into the window's surface.

use super::font;
use super::pixels::WindowPixels;
use crate::error::CliError;
use crate::frame::FrameJob;
use bubble_dynamics::Event;
use raster::FrameTimings;
use std::num::NonZeroU32;
use std::path::Path;
use std::sync::Arc;
use winit::window::Window;

/// Where the overlay's top-left corner sits, in window pixels, and its font scale.
pub(super) const OVERLAY_AT: (usize, usize) = (8, 8);
pub(super) const OVERLAY_SCALE: usize = 2;

/// The window's presenter.
pub(super) enum Presenter {
    /// softbuffer, fed by the CPU.
    Cpu(CpuPresenter),
    /// A wgpu surface, fed by the GPU.
    #[cfg(feature = "wgpu")]
    Gpu(Box<super::gpu::GpuPresenter>),
}

/// The CPU presenter: the window's softbuffer surface (on X11 a MIT-SHM segment where the
/// server offers it, as Xvfb does) and what fills it.
pub(super) struct CpuPresenter {
    surface: softbuffer::Surface<Arc<Window>, Arc<Window>>,
    pixels: WindowPixels,
}

impl Presenter {
    /// The CPU presenter on `window`.
    pub(super) fn cpu(window: &Arc<Window>) -> Result<Presenter, String> {
        let context = softbuffer::Context::new(window.clone()).map_err(|e| e.to_string())?;
        let surface =
            softbuffer::Surface::new(&context, window.clone()).map_err(|e| e.to_string())?;
        Ok(Presenter::Cpu(CpuPresenter {
            surface,
            pixels: WindowPixels::default(),
        }))
    }

    /// Who draws, for the overlay: `cpu` or `wgpu on <adapter>`.
    pub(super) fn name(&self) -> String {
        match self {
            Presenter::Cpu(_) => "cpu".to_string(),
            #[cfg(feature = "wgpu")]
            Presenter::Gpu(gpu) => gpu.name(),
        }
    }

    /// Whether frames are drawn on the GPU (their timings are encode and GPU time).
    pub(super) fn is_gpu(&self) -> bool {
        !matches!(self, Presenter::Cpu(_))
    }

    /// Resizes the presenter's surface to `width` × `height`; false when it could not.
    pub(super) fn resize(&mut self, width: NonZeroU32, height: NonZeroU32) -> bool {
        match self {
            Presenter::Cpu(cpu) => cpu.surface.resize(width, height).is_ok(),
            #[cfg(feature = "wgpu")]
            Presenter::Gpu(gpu) => {
                gpu.resize(width.get(), height.get());
                true
            }
        }
    }

    /// Renders the job's state at its size, upscales it to the window's `size`, draws
    /// `overlay` over it and presents, with `steps` solver steps: the CPU presenter
    /// renders the state before them while they run on the other core; the GPU presenter
    /// takes them first. Returns the render's timings, the steps' events and their wall
    /// time, s.
    pub(super) fn draw_while_stepping(
        &mut self,
        job: &mut FrameJob,
        size: (u32, u32),
        overlay: Option<&str>,
        steps: u32,
    ) -> Result<(FrameTimings, Vec<Event>, f64), CliError> {
        match self {
            Presenter::Cpu(cpu) => cpu.draw_while_stepping(job, size, overlay, steps),
            #[cfg(feature = "wgpu")]
            Presenter::Gpu(gpu) => {
                let (events, sim_s) = job.step_timed(steps)?;
                Ok((gpu.draw(job, overlay)?, events, sim_s))
            }
        }
    }

    /// Renders the job's current state at its size (no overlay) into a PNG at `path`;
    /// returns the image's size.
    pub(super) fn screenshot(
        &mut self,
        job: &mut FrameJob,
        path: &Path,
    ) -> Result<(usize, usize), CliError> {
        let (ev, tone) = (job.settings().exposure_ev, job.settings().tonemap);
        let frame = match self {
            Presenter::Cpu(_) => job.render()?,
            #[cfg(feature = "wgpu")]
            Presenter::Gpu(gpu) => gpu.frame(job)?,
        };
        frame
            .write_png(path, ev, tone)
            .map_err(|e| CliError::runtime(format!("cannot write {}: {e}", path.display())))?;
        Ok((frame.width(), frame.height()))
    }
}

impl CpuPresenter {
    /// Renders while the solver takes `steps` steps on the other core
    /// ([`FrameJob::render_while_stepping`]), fills the window's buffer (tone-mapped,
    /// upscaled if smaller), draws the overlay and presents. Allocates nothing once the
    /// buffers have grown.
    fn draw_while_stepping(
        &mut self,
        job: &mut FrameJob,
        (w, h): (u32, u32),
        overlay: Option<&str>,
        steps: u32,
    ) -> Result<(FrameTimings, Vec<Event>, f64), CliError> {
        let tone = (job.settings().exposure_ev, job.settings().tonemap);
        let internal_size = (job.settings().width, job.settings().height);
        let window_size = (w as usize, h as usize);
        let (frame, events, sim_s) = job.render_while_stepping(steps)?;
        // Waits for the X server to finish reading the last frame from the shared buffer.
        let mut buffer = self
            .surface
            .buffer_mut()
            .map_err(|e| CliError::runtime(format!("window buffer: {e}")))?;
        (self.pixels).fill(&mut buffer, window_size, frame.rgb(), internal_size, tone);
        if let Some(text) = overlay {
            let (x, y) = OVERLAY_AT;
            font::draw_text(&mut buffer, window_size.0, x, y, OVERLAY_SCALE, text);
        }
        buffer
            .present()
            .map_err(|e| CliError::runtime(format!("window present: {e}")))?;
        Ok((frame.timings, events, sim_s))
    }
}

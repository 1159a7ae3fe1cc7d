//! `--backend wgpu`: the wgpu renderer when the binary was built with the `wgpu` feature,
//! else an error saying how to get it.

use crate::error::CliError;
use raster::{FilmTables, Frame, RenderScene, RenderSettings};

/// The wgpu renderer (only with the `wgpu` feature), and whether the sample-count notice
/// was given.
#[cfg(feature = "wgpu")]
pub struct GpuBackend(raster::gpu::GpuRenderer, bool);

/// Stands in for the wgpu renderer in a build without the feature; never constructed.
#[cfg(not(feature = "wgpu"))]
pub enum GpuBackend {}

#[cfg(feature = "wgpu")]
impl GpuBackend {
    /// Opens the first suitable adapter, reading cube maps with `parallax`; without one,
    /// an input error (exit 2) naming the driver package, `VK_DRIVER_FILES` and
    /// `--backend cpu`.
    pub fn open(parallax: raster::ReflectionParallax) -> Result<Self, CliError> {
        raster::gpu::GpuRenderer::new(raster::gpu::GpuOptions::default())
            .map(|mut renderer| {
                renderer.set_reflection_parallax(parallax);
                GpuBackend(renderer, false)
            })
            .map_err(|e| CliError::input(format!("--backend wgpu: {e}")))
    }

    /// The adapter's name and driver.
    pub fn adapter_name(&self) -> String {
        self.0.gpu().adapter_name()
    }

    /// Renders one frame on the GPU and reads it back. A sample count the device does not
    /// render is replaced by the nearest one it does, said once on stderr.
    pub fn render(
        &mut self,
        scene: &RenderScene,
        tables: &FilmTables,
        settings: &RenderSettings,
    ) -> Result<&Frame, raster::gpu::GpuError> {
        note_sample_count(self.0.gpu(), settings.samples, &mut self.1);
        self.0.render(scene, tables, settings)
    }
}

/// Says once on stderr (`said` remembers) when `gpu` renders `requested` samples with
/// another count, the nearest it offers.
#[cfg(feature = "wgpu")]
pub fn note_sample_count(gpu: &raster::gpu::Gpu, requested: u32, said: &mut bool) {
    let used = gpu.sample_count_for(requested);
    if used != requested && !*said {
        *said = true;
        eprintln!(
            "bubbles: --samples {requested} is rendered with {used} samples on {} (the nearest \
             count it offers: {:?})",
            gpu.adapter_name(),
            gpu.sample_counts()
        );
    }
}

/// The input error (exit 2) for `--backend wgpu` in a build without the wgpu backend.
#[cfg(not(feature = "wgpu"))]
pub fn unavailable() -> CliError {
    CliError::input(
        "--backend wgpu: this bubbles was built without the wgpu backend; rebuild it with \
         `cargo build --release -p bubbles --features wgpu`, or use --backend cpu",
    )
}

#[cfg(not(feature = "wgpu"))]
impl GpuBackend {
    /// Always an input error (exit 2): this binary has no wgpu backend.
    pub fn open(_: raster::ReflectionParallax) -> Result<Self, CliError> {
        Err(unavailable())
    }

    /// Unreachable: no value of this type exists.
    pub fn adapter_name(&self) -> String {
        match *self {}
    }

    /// Unreachable: no value of this type exists.
    pub fn render(
        &mut self,
        _: &RenderScene,
        _: &FilmTables,
        _: &RenderSettings,
    ) -> Result<&Frame, std::convert::Infallible> {
        match *self {}
    }
}

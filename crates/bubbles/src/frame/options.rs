//! The renderer's command-line choices shared by `render`, `bench` and `animate` (flags
//! override the scene's `[render]` table).

/// Renderer options shared by `render` and `bench` (flags override the scene's `[render]`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct Options {
    /// Image width in pixels, 1..=16384 (default 800).
    #[arg(long)]
    pub width: Option<usize>,
    /// Image height in pixels, 1..=16384 (default 600).
    #[arg(long)]
    pub height: Option<usize>,
    /// Anti-aliasing samples per pixel: 1, 4, 8, 9 or 16 (default: the scene's, else 4).
    #[arg(long)]
    pub samples: Option<u32>,
    /// Rendering backend: the real-time CPU rasteriser, the same frame on the GPU through
    /// wgpu (needs a build with `--features wgpu`), or the spectral reference tracer.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub backend: Backend,
    #[command(flatten)]
    pub reference: super::reference::ReferenceOptions,
    /// Bubble reflections: dynamic cube maps, the static environment, or a sphere map (seed 002).
    #[arg(long, value_enum)]
    pub reflection: Option<Reflection>,
    /// Where reflected rays read the dynamic cube maps from: where they meet the ground
    /// (parallax-corrected), or the bubble's centre, as seed 000 reads them (to measure the
    /// correction against). CPU and wgpu backends.
    #[arg(long, value_enum, default_value_t = ReflectionOrigin::Film)]
    pub reflection_origin: ReflectionOrigin,
    /// Face size of the dynamic cube maps, 1..=1024 texels (default: the scene's, else 128).
    #[arg(long)]
    pub cube_map_size: Option<usize>,
    /// Film-table columns over thickness, 2..=16384 (default: the scene's, else 4096).
    #[arg(long)]
    pub lut_thickness_samples: Option<usize>,
    /// Film-table rows over cos θ, 2..=1024 (default: the scene's, else 128).
    #[arg(long)]
    pub lut_angle_samples: Option<usize>,
    /// CPU backend: how a bubble pixel a triangle covers only in part is shaded: once per
    /// bubble layer (about a third fewer shadings), or once per triangle, as the wgpu backend
    /// does (to compare the two backends like for like).
    #[arg(long, value_enum, default_value_t = PartialShading::PerSurface)]
    pub partial_shading: PartialShading,
    /// CPU backend: keep a bubble's dynamic cube map from an earlier frame while what it
    /// shows has moved by at most this many of its texels, 0..=0.5 (default: 0.25 in `bench`
    /// and `view`, which run in real time; 0, a fresh map every frame, in `render` and
    /// `animate`, so that each frame is the same however the run is split).
    #[arg(long)]
    pub cube_map_reuse: Option<f32>,
    /// Exposure multiplier applied before tone mapping (default: the scene's, else 1).
    #[arg(long)]
    pub exposure: Option<f64>,
    /// Tone curve for PNG output (default: the scene's, else aces).
    #[arg(long, value_enum)]
    pub tonemap: Option<Tone>,
}

/// `--cube-map-reuse` of the real-time commands (`bench`, `view`) when none is given, in
/// texels (docs/performance.md measures what it saves and the error it adds).
pub const REAL_TIME_CUBE_MAP_REUSE: f32 = 0.25;

impl Options {
    /// `--width` and `--height`, or 800 × 600.
    pub fn size(&self) -> (usize, usize) {
        (self.width.unwrap_or(800), self.height.unwrap_or(600))
    }

    /// These options with `--cube-map-reuse` defaulting to [`REAL_TIME_CUBE_MAP_REUSE`].
    pub fn real_time(&self) -> Options {
        let mut options = self.clone();
        options
            .cube_map_reuse
            .get_or_insert(REAL_TIME_CUBE_MAP_REUSE);
        options
    }
}

/// Rendering backends.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// The pure-CPU sorted-triangle renderer.
    #[default]
    Cpu,
    /// The same pipeline on the GPU through wgpu (Vulkan; a build with `--features wgpu`).
    Wgpu,
    /// The spectral reference ray tracer (slow; the truth the CPU backend is measured against).
    Reference,
}

/// Where bubble reflections come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Reflection {
    /// A cube map of the scene rendered from each bubble's centre, every frame.
    Dynamic,
    /// The environment alone (fastest; no ground or objects in reflections).
    Static,
    /// A sphere map made from the environment (seed 002).
    SphereMap,
}

/// Where reflected rays start when they read a dynamic cube map (`raster::ReflectionParallax`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ReflectionOrigin {
    /// From the film: rays that meet the ground read it where they meet it.
    #[default]
    Film,
    /// From the bubble's centre (seed 000 §4.2.2).
    Centre,
}

impl ReflectionOrigin {
    /// The renderers' setting.
    pub fn parallax(self) -> raster::ReflectionParallax {
        match self {
            Self::Film => raster::ReflectionParallax::Ground,
            Self::Centre => raster::ReflectionParallax::Centre,
        }
    }
}

/// How the CPU backend shades partly covered bubble pixels (`raster::PartialShading`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum PartialShading {
    /// Once per pixel and bubble layer, shared by neighbouring triangles.
    #[default]
    PerSurface,
    /// Once per triangle (the wgpu backend's rule).
    PerTriangle,
}

/// Tone curves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Tone {
    /// Hill's ACES fit.
    Aces,
    /// x / (1 + x).
    Reinhard,
    /// Clamp to [0, 1].
    Clamp,
}

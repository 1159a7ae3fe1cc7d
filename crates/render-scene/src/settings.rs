//! [`RenderSettings`]: resolution, anti-aliasing, reflection mode and tone mapping.

use std::sync::Arc;

use crate::{RenderError, SphereMap};

/// Where a bubble's reflected environment comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum ReflectionMode {
    /// Per bubble and frame, a cube map of the scene (without bubbles) rendered from the
    /// bubble's centre (seed 000 §4.2.2): nearby objects and the ground show in reflections.
    DynamicCubeMap {
        /// Edge length of each face in texels.
        face_size: usize,
    },
    /// Sample the scene's environment directly: no ground or objects in reflections, fastest.
    StaticEnvironment,
    /// Look the reflected direction up in a sphere map (seed 002).
    SphereMap(Arc<SphereMap>),
}

impl Default for ReflectionMode {
    /// Dynamic cube maps of 128² texels per face.
    fn default() -> Self {
        Self::DynamicCubeMap { face_size: 128 }
    }
}

/// How bubbles read their cube maps (dynamic or environment cube faces).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReflectionFilter {
    /// One bilinear tap of the full-resolution faces: aliases wherever the reflected
    /// direction turns by more than a texel per pixel (bubble rims). Kept to measure the
    /// filter against (crates/raster/tests/rim_aliasing.rs).
    Bilinear,
    /// Filtered by the reflected direction's footprint per pixel: trilinear taps between
    /// the mip levels that match it, spread along its long axis (anisotropic; `lod.rs`).
    #[default]
    Footprint,
}

/// Where a bubble's reflected rays start when they read its dynamic cube map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReflectionParallax {
    /// From the film: a ray heading for the ground reads the cube map towards the point
    /// where it meets the ground plane (`parallax::ground_parallax`), so the near ground
    /// reflects where a ray traced from the film finds it.
    #[default]
    Ground,
    /// From the bubble's centre, as the cube map was rendered (seed 000 §4.2.2): the near
    /// ground shifts by up to a bubble radius. Kept to measure the correction against.
    Centre,
}

/// How the bubble pass shades a pixel that a triangle covers only in part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PartialShading {
    /// Once per surface: the triangles of one bubble layer that share the pixel reuse one
    /// shading (from a covered sample of the first), as a pixel's samples already share
    /// one shading within a triangle. Never near a light's highlight, which is shaded per
    /// triangle. About a third fewer shadings on `paper` (docs/performance.md).
    #[default]
    PerSurface,
    /// Once per triangle, at one of its covered samples. Kept to measure the default against.
    PerTriangle,
}

/// The tone curve applied when converting HDR radiance to display values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ToneMap {
    /// Clamp to `[0, 1]`.
    Clamp,
    /// `x / (1 + x)` per channel.
    Reinhard,
    /// Stephen Hill's fit of the ACES RRT + ODT (sRGB primaries).
    #[default]
    AcesFitted,
}

/// Largest accepted image side, in pixels.
pub const MAX_IMAGE_SIDE: usize = 16384;

/// Sample counts accepted for anti-aliasing.
pub const SAMPLE_COUNTS: [u32; 5] = [1, 4, 8, 9, 16];

/// How to render a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Coverage samples per pixel (1, 4, 8, 9 or 16): geometry edges are anti-aliased by
    /// coverage while each triangle is shaded once per pixel (MSAA).
    pub samples: u32,
    /// Source of bubble reflections.
    pub reflection: ReflectionMode,
    /// Exposure in stops applied before tone mapping (0 = unchanged).
    pub exposure_ev: f32,
    /// Tone curve for 8-bit output.
    pub tonemap: ToneMap,
    /// Draw the light spheres themselves (they never appear in cube maps, whose bubbles
    /// reflect lights through the light tables instead).
    pub draw_lights: bool,
}

impl Default for RenderSettings {
    /// 400 × 400, 4 samples, dynamic 128² cube maps, exposure 0, ACES, lights drawn.
    fn default() -> Self {
        Self {
            width: 400,
            height: 400,
            samples: 4,
            reflection: ReflectionMode::default(),
            exposure_ev: 0.0,
            tonemap: ToneMap::default(),
            draw_lights: true,
        }
    }
}

impl RenderSettings {
    /// Checks every field, naming the first bad one.
    pub fn validate(&self) -> Result<(), RenderError> {
        if !(1..=MAX_IMAGE_SIDE).contains(&self.width) {
            return Err(RenderError::setting(
                "width",
                self.width,
                "1 ..= 16384 pixels",
            ));
        }
        if !(1..=MAX_IMAGE_SIDE).contains(&self.height) {
            return Err(RenderError::setting(
                "height",
                self.height,
                "1 ..= 16384 pixels",
            ));
        }
        if !SAMPLE_COUNTS.contains(&self.samples) {
            return Err(RenderError::setting(
                "samples",
                self.samples,
                "one of 1, 4, 8, 9, 16",
            ));
        }
        if let ReflectionMode::DynamicCubeMap { face_size } = self.reflection {
            if !(1..=crate::cubemap::MAX_FACE_SIZE).contains(&face_size) {
                return Err(RenderError::setting(
                    "face_size",
                    face_size,
                    "1 ..= 8192 texels",
                ));
            }
        }
        if !self.exposure_ev.is_finite() {
            return Err(RenderError::setting(
                "exposure_ev",
                self.exposure_ev,
                "a finite number of stops",
            ));
        }
        Ok(())
    }
}

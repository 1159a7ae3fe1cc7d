//! [`GroundView`]: the ground plane's constants for one view, which the CPU opaque pass and
//! the GPU's `fs_ground` (through `view_bytes`) both read, and its [`GroundFilter`].

use glam::Vec3;

use crate::Ground;
use crate::camera::View;

/// How the ground's checker is box-filtered over a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GroundFilter {
    /// Two half-pixel boxes along the pixel's longer side
    /// (`shading::ground_albedo_over_pixel`): the main view.
    #[default]
    Halves,
    /// One box over the pixel's axis-aligned footprint: cube-map faces, which the
    /// reflection lookups filter again (half the checker's work).
    Pixel,
}

/// The ground plane prepared for one view: its inverse depth is affine in pixel coordinates.
#[derive(Debug, Clone, Copy)]
pub struct GroundView<'a> {
    /// How its checker is filtered over a pixel.
    pub filter: GroundFilter,
    /// The plane.
    pub ground: &'a Ground,
    /// `1/t = c + gx·px + gy·py`; the plane is in front where positive.
    pub c: f32,
    /// `∂(1/t)/∂px`.
    pub gx: f32,
    /// `∂(1/t)/∂py`.
    pub gy: f32,
    /// Unit normal facing the eye.
    pub normal: Vec3,
    /// `1 / (height − eye.y)`.
    pub inv_height: f32,
    /// Change of the (unnormalised) view ray per pixel along x and y.
    pub ddx: Vec3,
    /// Change of the view ray per pixel along y.
    pub ddy: Vec3,
}

impl<'a> GroundView<'a> {
    /// `None` when the eye lies in the plane (it is seen edge-on: nothing to draw).
    pub fn new(ground: &'a Ground, view: &View) -> Option<Self> {
        let height = ground.height_m - view.eye.y;
        if height == 0.0 || !height.is_finite() {
            return None;
        }
        let (sx, sy) = (view.x_per_px, view.y_per_px);
        let inv_h = 1.0 / height;
        Some(Self {
            filter: GroundFilter::default(),
            ground,
            c: (view.forward.y - view.tan_half_x * view.right.y + view.tan_half_y * view.up.y)
                * inv_h,
            gx: sx * view.right.y * inv_h,
            gy: -sy * view.up.y * inv_h,
            normal: if height < 0.0 { Vec3::Y } else { -Vec3::Y },
            inv_height: inv_h,
            ddx: view.right * sx,
            ddy: -view.up * sy,
        })
    }

    /// This view with its checker filtered by `filter`.
    pub fn with_filter(self, filter: GroundFilter) -> Self {
        Self { filter, ..self }
    }

    /// Inverse depth `1/t` of the plane behind pixel-space point `(px, py)`.
    #[inline]
    pub fn inv_depth(&self, px: f32, py: f32) -> f32 {
        self.c + self.gx * px + self.gy * py
    }
}

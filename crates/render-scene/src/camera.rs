//! [`Camera`] (look-at with a vertical field of view) and [`View`] (a camera fitted to a
//! pixel grid, also used for cube-map faces: what every backend projects with).

use glam::{Mat3, Vec3};

use crate::RenderError;

/// Default distance of the near clipping plane, in metres.
pub const DEFAULT_NEAR_M: f32 = 0.01;

/// A pinhole camera with a perspective projection; world space is right-handed, Y up.
///
/// # Guarantees
/// - `forward`, `right`, `up` are unit length and mutually orthogonal;
/// - `0 < vfov_deg < 180` and `near_m` is finite and positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    vfov_deg: f32,
    near_m: f32,
}

impl Camera {
    /// Camera at `eye` looking at `target`, `up` hinting the vertical, `vfov_deg` the vertical field of view.
    ///
    /// # Panics
    /// Panics on the inputs [`Camera::try_look_at`] rejects.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, vfov_deg: f32) -> Camera {
        match Self::try_look_at(eye, target, up, vfov_deg) {
            Ok(c) => c,
            Err(e) => panic!("{e}"),
        }
    }

    /// Checked [`Camera::look_at`]: rejects non-finite input, `eye == target`, a zero `up`
    /// and a field of view outside `(0, 180)` degrees.
    ///
    /// When `up` is parallel to the view direction (a camera looking straight up or down),
    /// the screen's up is the limit of tilting towards that pose from the +Z side (for
    /// `up = Y`: −Z looking down, +Z looking up; X when the view runs along Z).
    pub fn try_look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        vfov_deg: f32,
    ) -> Result<Camera, RenderError> {
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(RenderError::scene(
                "camera",
                format!("eye {eye}, target {target} and up {up} must be finite"),
            ));
        }
        if !(vfov_deg > 0.0 && vfov_deg < 180.0) {
            return Err(RenderError::setting(
                "vfov_deg",
                vfov_deg,
                "0 < vfov_deg < 180",
            ));
        }
        let forward = (target - eye).normalize_or_zero();
        if forward == Vec3::ZERO {
            return Err(RenderError::scene(
                "camera",
                format!("eye and target are both {eye}"),
            ));
        }
        if up.length_squared() == 0.0 {
            return Err(RenderError::scene("camera", format!("up {up} is zero")));
        }
        let up = if forward.cross(up).length() < 1e-6 * up.length() {
            fallback_up(forward, up)
        } else {
            up
        };
        let right = forward.cross(up).normalize();
        Ok(Camera {
            eye,
            forward,
            right,
            up: right.cross(forward),
            vfov_deg,
            near_m: DEFAULT_NEAR_M,
        })
    }

    /// The same camera with another near-plane distance; `None` unless finite and positive.
    pub fn with_near_m(self, near_m: f32) -> Option<Camera> {
        (near_m.is_finite() && near_m > 0.0).then_some(Camera { near_m, ..self })
    }

    /// Position of the pinhole.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Unit vector pointing right on screen.
    pub fn right(&self) -> Vec3 {
        self.right
    }

    /// Unit vector pointing up on screen.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// Vertical field of view in degrees.
    pub fn vfov_deg(&self) -> f32 {
        self.vfov_deg
    }

    /// Near clipping distance in metres.
    pub fn near_m(&self) -> f32 {
        self.near_m
    }

    /// OpenGL eye-space axes in world space: columns right, up and backward (−forward).
    pub fn world_from_eye(&self) -> Mat3 {
        Mat3::from_cols(self.right, self.up, -self.forward)
    }

    /// Fits the camera to a `width` × `height` pixel grid (square pixels).
    pub fn view(&self, width: usize, height: usize) -> View {
        let tan_half_y = (self.vfov_deg.to_radians() * 0.5).tan();
        let tan_half_x = tan_half_y * width as f32 / height as f32;
        View::new(
            self.eye,
            [self.forward, self.right, self.up],
            (tan_half_x, tan_half_y),
            (width, height),
            self.near_m,
        )
    }
}

/// An up hint for a view direction parallel to `up`: the world axis Z (X when the view
/// runs along Z), signed as the limit of a camera tilting into that pose from +Z.
fn fallback_up(forward: Vec3, up: Vec3) -> Vec3 {
    let axis = if forward.z.abs() < 0.9 {
        Vec3::Z
    } else {
        Vec3::X
    };
    axis * forward.dot(up).signum()
}

/// A camera fitted to a pixel grid: the projection every pass shares.
///
/// Pixel `(px, py)` (y down) has NDC `x = 2 px / W − 1`, `y = 1 − 2 py / H`, and looks along
/// `forward + x·tan_half_x·right + y·tan_half_y·up` (a ray whose forward component is 1, so
/// the ray parameter equals the view depth).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Eye position in metres.
    pub eye: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Unit screen right.
    pub right: Vec3,
    /// Unit screen up.
    pub up: Vec3,
    /// Tangent of half the horizontal field of view.
    pub tan_half_x: f32,
    /// Tangent of half the vertical field of view.
    pub tan_half_y: f32,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Distance of the near clipping plane in metres.
    pub near_m: f32,
    /// Screen-plane step per pixel along x, `2·tan_half_x / width`.
    pub x_per_px: f32,
    /// Screen-plane step per pixel along y, `2·tan_half_y / height`.
    pub y_per_px: f32,
}

impl View {
    /// A view from its frame (`[forward, right, up]`, unit and orthogonal), half-angle
    /// tangents, pixel size and near distance.
    pub fn new(
        eye: Vec3,
        axes: [Vec3; 3],
        tan_half: (f32, f32),
        size: (usize, usize),
        near_m: f32,
    ) -> View {
        let [forward, right, up] = axes;
        View {
            eye,
            forward,
            right,
            up,
            tan_half_x: tan_half.0,
            tan_half_y: tan_half.1,
            width: size.0,
            height: size.1,
            near_m,
            x_per_px: 2.0 * tan_half.0 / size.0 as f32,
            y_per_px: 2.0 * tan_half.1 / size.1 as f32,
        }
    }

    /// Unnormalised ray direction through pixel-space point `(px, py)`; its forward component is 1.
    #[inline]
    pub fn ray(&self, px: f32, py: f32) -> Vec3 {
        let (ax, ay) = self.ray_coefficients(px, py);
        self.forward + self.right * ax + self.up * ay
    }

    /// Screen-plane coordinates `(x·tan_half_x, y·tan_half_y)` of pixel-space point `(px, py)`.
    #[inline]
    pub fn ray_coefficients(&self, px: f32, py: f32) -> (f32, f32) {
        (
            px * self.x_per_px - self.tan_half_x,
            self.tan_half_y - py * self.y_per_px,
        )
    }

    /// Clip coordinates `(x, y, w)` of a world point; `w` is the view depth.
    #[inline]
    pub fn clip(&self, p: Vec3) -> [f32; 3] {
        let rel = p - self.eye;
        [
            rel.dot(self.right) / self.tan_half_x,
            rel.dot(self.up) / self.tan_half_y,
            rel.dot(self.forward),
        ]
    }

    /// Pixel coordinates of clip coordinates with `w > 0`.
    #[inline]
    pub fn pixel_of_clip(&self, x: f32, y: f32, w: f32) -> (f32, f32) {
        let inv_w = 1.0 / w;
        (
            (x * inv_w + 1.0) * 0.5 * self.width as f32,
            (1.0 - y * inv_w) * 0.5 * self.height as f32,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_ray_is_forward() {
        let cam = Camera::look_at(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Y, 60.0);
        let view = cam.view(40, 20);
        let r = view.ray(20.0, 10.0);
        assert!(
            (r - cam.forward()).length() < 1e-6,
            "off by {}",
            (r - cam.forward()).length()
        );
    }

    #[test]
    fn projection_inverts_the_ray() {
        let cam = Camera::look_at(
            Vec3::new(0.3, 1.0, 4.0),
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::Y,
            45.0,
        );
        let view = cam.view(64, 48);
        for &(px, py) in &[(0.0, 0.0), (13.5, 40.25), (64.0, 48.0)] {
            let p = view.eye + view.ray(px, py) * 2.5;
            let [x, y, w] = view.clip(p);
            let (qx, qy) = view.pixel_of_clip(x, y, w);
            assert!((w - 2.5).abs() < 1e-5, "depth off by {}", w - 2.5);
            assert!(
                (qx - px).abs() < 1e-3 && (qy - py).abs() < 1e-3,
                "({qx},{qy}) vs ({px},{py})"
            );
        }
    }

    #[test]
    fn camera_looking_straight_up_or_down_gets_the_limit_of_a_tilted_camera() {
        for (eye, target) in [
            (Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO),
            (Vec3::new(0.0, -2.0, 0.0), Vec3::ZERO),
            (Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO),
            (Vec3::new(0.0, 0.0, -2.0), Vec3::ZERO),
        ] {
            let up = if eye.y == 0.0 { Vec3::Z } else { Vec3::Y };
            let straight = Camera::try_look_at(eye, target, up, 45.0).unwrap();
            // Tilt the eye a little towards +Z (or +X when the view runs along Z).
            let nudge = if eye.y == 0.0 { Vec3::X } else { Vec3::Z } * 1e-3;
            let tilted = Camera::try_look_at(eye + nudge, target, up, 45.0).unwrap();
            for (a, b) in [
                (straight.up(), tilted.up()),
                (straight.right(), tilted.right()),
            ] {
                assert!((a - b).length() < 1e-2, "{eye}: {a} vs tilted {b}");
            }
            let (f, r, u) = (straight.forward(), straight.right(), straight.up());
            assert!(f.dot(r).abs() < 1e-6 && f.dot(u).abs() < 1e-6 && r.dot(u).abs() < 1e-6);
        }
    }

    #[test]
    fn rejects_degenerate_cameras() {
        assert!(Camera::try_look_at(Vec3::ONE, Vec3::ONE, Vec3::Y, 45.0).is_err());
        assert!(Camera::try_look_at(Vec3::ZERO, Vec3::Y, Vec3::ZERO, 45.0).is_err());
        assert!(Camera::try_look_at(Vec3::ZERO, Vec3::X, Vec3::Y, 180.0).is_err());
        assert!(Camera::try_look_at(Vec3::ZERO, Vec3::X, Vec3::Y, f32::NAN).is_err());
        assert!(Camera::try_look_at(Vec3::NAN, Vec3::X, Vec3::Y, 45.0).is_err());
    }
}

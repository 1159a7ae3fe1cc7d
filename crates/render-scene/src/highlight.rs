//! A light's highlight on a film: the filter every backend draws it with.

use glam::Vec3;

use crate::Light;

/// Width of the highlight filter in pixels: wide enough that the Gaussian's sum over the
/// pixel grid ripples by 2·exp(−2π²σ²) ≈ 0.16 % with the sub-pixel offset.
pub const HIGHLIGHT_SIGMA_PX: f32 = 0.6;

/// Where a light lies from a shaded point, as its highlight ([`LightSight::visibility`]) and
/// the sharing test ([`LightSight::within_reach`]) both need it, computed once per light
/// and point.
pub struct LightSight {
    to_light: Vec3,
    dist: f32,
    /// Cosine of the angle between the reflected direction and the light's centre.
    cos_gamma: f32,
}

impl LightSight {
    /// Where `light` lies from point `p`, for the unit reflected direction `reflected`.
    #[inline]
    pub fn new(light: &Light, p: Vec3, reflected: Vec3) -> Self {
        let to_light = light.position - p;
        let dist = to_light.length();
        Self {
            to_light,
            dist,
            cos_gamma: reflected.dot(to_light) / dist,
        }
    }

    /// Whether the reflected direction passes within the reach of
    /// [`LightSight::visibility`]'s filter, widened by `margin_px` pixels; where it does not,
    /// the visibility is 0. A point inside the light is always within reach.
    ///
    /// asin x ≤ πx/2 bounds the light's angular radius and 1 − cos γ ≤ γ²/2, so this
    /// rejects only rays beyond both the Gaussian's 4 s and the ramp's reach (most rays,
    /// cheaply).
    #[inline]
    pub fn within_reach(&self, light: &Light, pixel_angle_rad: f32, margin_px: f32) -> bool {
        if self.dist <= light.radius_m {
            return true;
        }
        let w = pixel_angle_rad.max(1e-5);
        let reach = std::f32::consts::PI * (light.radius_m / self.dist) + (2.5 + margin_px) * w;
        1.0 - self.cos_gamma <= 0.5 * reach * reach
    }

    /// Fraction of a pixel's reflected rays (unit `reflected` at its centre) that hit `light`,
    /// given the angle the reflected direction sweeps per pixel, `pixel_angle_rad`.
    ///
    /// A light of angular radius α at angle γ from `reflected` is filtered by a Gaussian of
    /// σ = 0.6 pixel in reflected directions: `vis = α²/(2s²) · exp(−γ²/2s²)` with
    /// `s² = σ² + α²/4` (the disc's own variance), whose integral over directions is the
    /// light's solid angle πα² for every α; and a normalised Gaussian this wide sums to one
    /// over the pixel grid at any sub-pixel offset (within 0.2 %), so a highlight's energy
    /// in the image is the light's power, whatever its radius. Lights wider than 2σ (whose
    /// peak reaches 1) get a one-pixel linear ramp across the disc's rim instead, within
    /// 6 % of the same energy and with a sharp edge.
    #[inline]
    pub fn visibility(&self, light: &Light, reflected: Vec3, pixel_angle_rad: f32) -> f32 {
        if self.dist <= light.radius_m {
            return 1.0;
        }
        if !self.within_reach(light, pixel_angle_rad, 0.0) {
            return 0.0;
        }
        let w = pixel_angle_rad.max(1e-5);
        let alpha = (light.radius_m / self.dist).asin();
        // atan2 keeps small angles exact where acos(cos γ) would round them to 3e-4 rad.
        let gamma = reflected
            .cross(self.to_light)
            .length()
            .atan2(self.cos_gamma * self.dist);
        let sigma = HIGHLIGHT_SIGMA_PX * w;
        if alpha <= 2.0 * sigma {
            let s2 = sigma * sigma + 0.25 * alpha * alpha;
            alpha * alpha / (2.0 * s2) * (-gamma * gamma / (2.0 * s2)).exp()
        } else {
            ((alpha - gamma) / w + 0.5).clamp(0.0, 1.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The highlight filter from point `p`, as the shader computes it.
    fn light_visibility(light: &Light, p: Vec3, reflected: Vec3, w: f32) -> f32 {
        LightSight::new(light, p, reflected).visibility(light, reflected, w)
    }

    #[test]
    fn light_visibility_is_one_inside_zero_outside_and_half_on_the_rim() {
        let light = Light {
            position: Vec3::new(0.0, 0.0, -10.0),
            radius_m: 0.5,
            radiance: [1.0; 3],
            light_lut: None,
        };
        let w = 0.001;
        assert_eq!(light_visibility(&light, Vec3::ZERO, -Vec3::Z, w), 1.0);
        assert_eq!(light_visibility(&light, Vec3::ZERO, Vec3::X, w), 0.0);
        let alpha = (0.5f32 / 10.0).asin();
        let rim = Vec3::new(alpha.sin(), 0.0, -alpha.cos());
        let v = light_visibility(&light, Vec3::ZERO, rim, w);
        assert!((v - 0.5).abs() < 0.05, "rim visibility {v}");
        // A light far smaller than a pixel: its solid angle times the filter's peak.
        let tiny = Light {
            radius_m: 1e-4,
            ..light
        };
        let (alpha, w) = (1e-5f32, 0.01f32);
        let sigma = HIGHLIGHT_SIGMA_PX * w;
        let v = light_visibility(&tiny, Vec3::ZERO, -Vec3::Z, w);
        let want =
            std::f32::consts::PI * alpha * alpha / (2.0 * std::f32::consts::PI * sigma * sigma);
        assert!((v - want).abs() < 1e-3 * want, "tiny light {v} vs {want}");
        // Inside the light everything is visible.
        assert_eq!(light_visibility(&light, light.position, Vec3::X, w), 1.0);
    }
}

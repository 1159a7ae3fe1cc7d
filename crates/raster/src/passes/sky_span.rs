//! The sky's span kernel: the environment behind a run of pixel centres along one row.
//!
//! For the procedural [`render_scene::Sky`] without a sun disc it is straight-line f32 code over
//! small arrays, which the compiler keeps in SIMD registers; each pixel still gets
//! [`Environment::radiance`]'s operations on its [`View::ray`] in their order, so the
//! result is bit-identical. Other environments take the scalar path.

use render_scene::Environment;
use render_scene::camera::View;
use render_scene::index_f32::index_f32;

use super::SPAN;

/// Environment radiance along the view rays through the centres of pixels
/// `x0 .. x0 + out.len()` of row `y`, written to `out`.
///
/// # Panics
/// Panics if `out.len() > SPAN`.
pub(crate) fn sky_span(view: &View, env: &Environment, y: usize, x0: usize, out: &mut [[f32; 3]]) {
    let n = out.len();
    assert!(n <= SPAN, "span of {n} pixels exceeds {SPAN}");
    let cy = y as f32 + 0.5;
    let sky = match env {
        Environment::Sky(sky) if sky.sun_rgb == [0.0; 3] => sky,
        _ => {
            for (i, o) in out.iter_mut().enumerate() {
                *o = env.radiance(view.ray((x0 + i) as f32 + 0.5, cy));
            }
            return;
        }
    };
    let (_, ay) = view.ray_coefficients(0.0, cy);
    let (f, r, u) = (view.forward, view.right, view.up);
    let mut unit_y = [0.0f32; SPAN];
    for (i, uy) in unit_y[..n].iter_mut().enumerate() {
        let (ax, _) = view.ray_coefficients(index_f32(x0 + i) + 0.5, cy);
        // `View::ray`'s sums, then `Vec3::normalize_or(Vec3::Y)`'s y, lane by lane.
        let d = [
            f.x + r.x * ax + u.x * ay,
            f.y + r.y * ax + u.y * ay,
            f.z + r.z * ax + u.z * ay,
        ];
        let rcp = 1.0 / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        *uy = if rcp.is_finite() && rcp > 0.0 {
            d[1] * rcp
        } else {
            1.0
        };
    }
    for (o, &uy) in out.iter_mut().zip(&unit_y[..n]) {
        *o = sky.gradient(uy);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use render_scene::{Camera, Sky, Vec3};

    /// Every pixel of a few views, spans at odd offsets, against the scalar lookup.
    #[test]
    fn sky_span_is_bit_identical_to_the_scalar_radiance() {
        let sunless = Sky::default();
        let sunny = Sky {
            sun_rgb: [5.0, 4.0, 3.0],
            sun_radius_deg: 20.0,
            ..sunless
        };
        let envs = [
            Environment::Sky(sunless),
            Environment::Sky(sunny),
            Environment::Uniform([0.3, 0.2, 0.1]),
        ];
        let cameras = [
            (Vec3::new(0.0, 0.1, 0.4), Vec3::new(0.0, 0.07, 0.0)),
            (Vec3::new(0.3, 2.0, -0.2), Vec3::new(0.0, -1.0, 0.0)),
            (Vec3::new(-1.0, -0.5, 0.3), Vec3::new(0.2, 3.0, 0.1)),
        ];
        let (w, h) = (157, 61);
        for env in &envs {
            for &(eye, target) in &cameras {
                let view = Camera::look_at(eye, target, Vec3::Y, 70.0).view(w, h);
                for y in 0..h {
                    for x0 in (0..w).step_by(37) {
                        let n = SPAN.min(w - x0).min(37);
                        let mut out = [[f32::NAN; 3]; SPAN];
                        sky_span(&view, env, y, x0, &mut out[..n]);
                        for (i, got) in out[..n].iter().enumerate() {
                            let x = (x0 + i) as f32 + 0.5;
                            let want = env.radiance(view.ray(x, y as f32 + 0.5));
                            assert_eq!(
                                got.map(f32::to_bits),
                                want.map(f32::to_bits),
                                "pixel ({x}, {y})"
                            );
                        }
                    }
                }
            }
        }
    }
}

//! Parallax-correct reads of a dynamic cube map: a reflected ray leaves the film at its
//! hit point, not at the bubble's centre the cube map was rendered from, so the ground it
//! meets appears in another direction from the centre. [`ground_parallax`] intersects the
//! ray with the ground plane (the proxy) and turns the lookup towards the point it meets,
//! with the per-pixel derivatives the footprint filter needs (the GPU's
//! `ground_parallax` ports it).
//!
//! The cube map still supplies the radiance: the ground as the opaque pass lit and
//! filtered it, and any object standing between the centre and that point. Rays that miss
//! the ground (the sky, objects seen against it) keep their direction: they are far away.

use glam::Vec3;

/// A cube-map read turned towards where a reflected ray meets the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParallaxRead {
    /// Unit direction from the cube map's centre to the ground point.
    pub dir: Vec3,
    /// Its change per pixel along x and y.
    pub derivatives: [Vec3; 2],
}

/// The read for a ray from film point `p` along unit `dir` (changing per pixel by
/// `d_dir`, with `p` changing by `d_p`) reflected in a bubble whose cube map was rendered
/// from `centre`, over the ground plane `y = height_m`.
///
/// `None` when the ray does not meet the plane, or `p` and `centre` lie on opposite
/// sides of it (the cube map sees the other side): the caller reads along `dir`.
/// Non-finite derivatives (a ray grazing the plane) come back as zero, as
/// `lod::reflection_derivatives` returns them.
#[inline]
pub fn ground_parallax(
    centre: Vec3,
    p: Vec3,
    dir: Vec3,
    d_p: [Vec3; 2],
    d_dir: [Vec3; 2],
    height_m: f32,
) -> Option<ParallaxRead> {
    let above = p.y - height_m;
    // The ray must head towards the plane, and the centre be on the point's side of it.
    if !(dir.y * above < 0.0 && (centre.y - height_m) * above > 0.0) {
        return None;
    }
    let t = -above / dir.y;
    let to_hit = p + dir * t - centre;
    let len = to_hit.length();
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    let u = to_hit / len;
    let derivatives = [0, 1].map(|k| {
        // The hit moves with the ray and stays in the plane: ∂t = −(∂p.y + t·∂dir.y)/dir.y.
        let dt = -(d_p[k].y + t * d_dir[k].y) / dir.y;
        let dq = d_p[k] + d_dir[k] * t + dir * dt;
        let du = (dq - u * u.dot(dq)) / len;
        if du.is_finite() { du } else { Vec3::ZERO }
    });
    Some(ParallaxRead { dir: u, derivatives })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        let ok = (a - b).abs().max_element() <= tol;
        if !ok {
            eprintln!("{a} vs {b}: difference {}", a - b);
        }
        ok
    }

    fn read(p: Vec3, dir: Vec3, d_p: [Vec3; 2], d_dir: [Vec3; 2]) -> Option<ParallaxRead> {
        ground_parallax(Vec3::new(0.0, 1.0, 0.0), p, dir, d_p, d_dir, 0.0)
    }

    #[test]
    fn read_points_from_the_centre_at_where_the_ray_meets_the_ground() {
        // From (0.1, 1, 0) straight down the ray meets (0.1, 0, 0): seen from the centre
        // (0, 1, 0) that is along (0.1, −1, 0), not straight down.
        let r = read(Vec3::new(0.1, 1.0, 0.0), -Vec3::Y, [Vec3::ZERO; 2], [Vec3::ZERO; 2]);
        let r = r.expect("the ray meets the ground");
        assert!(close(r.dir, Vec3::new(0.1, -1.0, 0.0).normalize(), 1e-6));
    }

    #[test]
    fn rays_from_the_centre_keep_their_direction() {
        let dir = Vec3::new(0.3, -0.8, 0.2).normalize();
        let r = read(Vec3::Y, dir, [Vec3::ZERO; 2], [Vec3::ZERO; 2]).unwrap();
        assert!(close(r.dir, dir, 1e-6));
    }

    #[test]
    fn rays_away_from_the_ground_or_across_it_are_not_turned() {
        let up = Vec3::new(0.0, 0.5, 0.5).normalize();
        assert_eq!(read(Vec3::new(0.1, 1.0, 0.0), up, [Vec3::ZERO; 2], [Vec3::ZERO; 2]), None);
        // A film point below the plane while the centre is above it.
        let below = Vec3::new(0.0, -0.1, 0.0);
        assert_eq!(read(below, Vec3::Y, [Vec3::ZERO; 2], [Vec3::ZERO; 2]), None);
        // Parallel to the plane.
        assert_eq!(read(Vec3::Y, Vec3::X, [Vec3::ZERO; 2], [Vec3::ZERO; 2]), None);
    }

    #[test]
    fn derivatives_match_finite_differences_of_the_read() {
        let p = Vec3::new(0.07, 1.05, -0.04);
        let dir = Vec3::new(0.4, -0.7, 0.3).normalize();
        let d_p = [Vec3::new(1e-3, 2e-4, 0.0), Vec3::new(0.0, -5e-4, 8e-4)];
        // A unit direction changes at right angles to itself.
        let d_dir = [Vec3::new(0.02, 0.01, -0.01), Vec3::new(-0.01, 0.015, 0.02)]
            .map(|v| v - dir * dir.dot(v));
        let exact = read(p, dir, d_p, d_dir).unwrap().derivatives;
        for k in 0..2 {
            let h = 1e-2;
            let at = |s: f32| {
                let moved = (dir + d_dir[k] * s).normalize();
                read(p + d_p[k] * s, moved, d_p, d_dir).unwrap().dir
            };
            let fd = (at(h) - at(-h)) / (2.0 * h);
            assert!(close(exact[k], fd, 2e-4), "axis {k}");
        }
    }
}

//! The order and sides in which bubbles' triangles are drawn, and how fast their
//! reflections turn per pixel: decided once on the CPU for every backend.

use glam::Vec3;

use crate::BubbleMesh;
use crate::camera::View;

/// Bubble indices in drawing order, far to near, by the power distance `|c − e|² − r²` of
/// each bubble's sphere (centre `c`, `r²` the mean squared vertex distance from it) to the
/// eye `e`: for non-overlapping spheres, a sphere in front of another along any ray has
/// the smaller power distance, whatever their sizes (the centre distance alone is not).
pub fn far_to_near(bubbles: &[BubbleMesh], eye: Vec3) -> Vec<usize> {
    let mut order: Vec<(f64, usize)> = bubbles
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let c = b.center().as_dvec3();
            let r2 = b
                .positions
                .iter()
                .map(|p| (p.as_dvec3() - c).length_squared())
                .sum::<f64>()
                / b.positions.len().max(1) as f64;
            ((c - eye.as_dvec3()).length_squared() - r2, k)
        })
        .collect();
    // Stable, far first; NaN-free because the scene was validated.
    order.sort_by(|a, b| b.0.total_cmp(&a.0));
    order.into_iter().map(|(_, k)| k).collect()
}

/// Whether triangle `t` faces the eye, its outward side taken from the vertex normals
/// (so the mesh's winding does not matter).
pub fn is_front_facing(bubble: &BubbleMesh, t: [u32; 3], eye: Vec3) -> bool {
    let [a, b, c] = t.map(|i| bubble.positions[i as usize]);
    let geometric = (b - a).cross(c - a);
    let normals: Vec3 = t.iter().map(|&i| bubble.normals[i as usize]).sum();
    let outward = if geometric.dot(normals) < 0.0 {
        -geometric
    } else {
        geometric
    };
    outward.dot(eye - a) > 0.0
}

/// Angle swept by the reflected direction per pixel across triangle `t` (radians), for
/// anti-aliasing light highlights; clamped to `[1e-4, 0.5]`.
pub fn reflection_rate(view: &View, bubble: &BubbleMesh, t: [u32; 3]) -> f32 {
    let mut reflected = [Vec3::ZERO; 3];
    let mut pixels = [(0.0f32, 0.0f32); 3];
    for (k, &i) in t.iter().enumerate() {
        let p = bubble.positions[i as usize];
        let [x, y, w] = view.clip(p);
        if w <= view.near_m {
            return 0.5;
        }
        pixels[k] = view.pixel_of_clip(x, y, w);
        let v = (p - view.eye).normalize_or_zero();
        let mut n = bubble.normals[i as usize].normalize_or_zero();
        if v.dot(n) > 0.0 {
            n = -n;
        }
        reflected[k] = v - n * (2.0 * v.dot(n));
    }
    let mut rate = 1e-4f32;
    for k in 0..3 {
        let j = (k + 1) % 3;
        let (dx, dy) = (pixels[j].0 - pixels[k].0, pixels[j].1 - pixels[k].1);
        let len_px = (dx * dx + dy * dy).sqrt();
        if len_px > 1e-3 {
            rate = rate.max((reflected[j] - reflected[k]).length() / len_px);
        }
    }
    if rate.is_finite() { rate.min(0.5) } else { 0.5 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// An icosahedron inscribed in the sphere: its vertex mean is the centre exactly.
    fn icosahedron(center: Vec3, radius_m: f32) -> BubbleMesh {
        let phi = (1.0 + 5f32.sqrt()) / 2.0;
        let mut positions = Vec::new();
        for (a, b) in [(1.0, phi), (-1.0, phi), (1.0, -phi), (-1.0, -phi)] {
            for v in [
                Vec3::new(0.0, a, b),
                Vec3::new(a, b, 0.0),
                Vec3::new(b, 0.0, a),
            ] {
                positions.push(center + v.normalize() * radius_m);
            }
        }
        let normals = positions.iter().map(|p| *p - center).collect();
        BubbleMesh {
            thickness_nm: vec![500.0; positions.len()],
            positions,
            normals,
            triangles: Vec::new(),
            film: None,
        }
    }

    /// Distance along unit `dir` from the origin to where it enters the sphere, if it does.
    fn entry(dir: Vec3, center: Vec3, radius_m: f32) -> Option<f32> {
        let b = dir.dot(center);
        let h2 = center.length_squared() - b * b;
        let t = b - (radius_m * radius_m - h2).sqrt();
        (h2 < radius_m * radius_m && t > 0.0).then_some(t)
    }

    #[test]
    fn large_bubble_in_front_of_a_small_one_with_a_nearer_centre_is_drawn_last() {
        // The large bubble's centre (1.2 m) is farther than the small one's (1.19 m), yet
        // along the ray at 56° the large one spans 0.57–0.77 m and the small one starts at
        // 1.09 m: sorting by centre distance drew the large one first.
        let large = (Vec3::new(0.0, 0.0, -1.2), 1.0);
        let a = 56f32.to_radians();
        let small = (Vec3::new(a.sin(), 0.0, -a.cos()) * 1.19, 0.1);
        assert!(
            large.0.distance(small.0) > large.1 + small.1,
            "they overlap"
        );
        let ray = Vec3::new(a.sin(), 0.0, -a.cos());
        assert!(entry(ray, large.0, large.1).unwrap() < entry(ray, small.0, small.1).unwrap());
        let bubbles = [icosahedron(large.0, large.1), icosahedron(small.0, small.1)];
        assert_eq!(far_to_near(&bubbles, Vec3::ZERO), vec![1, 0]);
    }

    proptest! {
        #[test]
        fn a_bubble_in_front_along_any_ray_is_drawn_later(
            c0 in prop::array::uniform3(-3.0f32..3.0),
            c1 in prop::array::uniform3(-3.0f32..3.0),
            r0 in 0.05f32..1.5,
            r1 in 0.05f32..1.5,
            t in 0.0f32..1.0,
        ) {
            let (c0, c1) = (Vec3::from(c0), Vec3::from(c1));
            // Non-overlapping spheres, the eye (origin) outside both.
            prop_assume!(c0.distance(c1) > (r0 + r1) * 1.001);
            prop_assume!(c0.length() > r0 * 1.001 && c1.length() > r1 * 1.001);
            // A ray through a point between the two centres often hits both.
            let dir = c0.lerp(c1, t).normalize();
            if let (Some(e0), Some(e1)) = (entry(dir, c0, r0), entry(dir, c1, r1)) {
                prop_assume!((e0 - e1).abs() > 1e-3);
                let order = far_to_near(&[icosahedron(c0, r0), icosahedron(c1, r1)], Vec3::ZERO);
                let nearer = if e0 < e1 { 0 } else { 1 };
                prop_assert_eq!(order[1], nearer, "entries {} and {}", e0, e1);
            }
        }

        #[test]
        fn a_small_bubble_behind_the_rim_of_a_large_one_is_drawn_first(
            radius_m in 0.5f32..2.0,
            distance in 1.05f32..3.0,
            small in 0.02f32..0.3,
            angle_offset in -0.15f32..0.15,
            depth in 0.85f32..1.05,
            aim in prop::array::uniform2(-1.0f32..1.0),
        ) {
            // Where centre distance fails: a small bubble about as far as the large one's
            // centre, seen just inside the large one's silhouette.
            let c0 = Vec3::new(0.0, 0.0, -radius_m * distance);
            let r1 = small * radius_m;
            let theta = (1.0 / distance).asin() + angle_offset;
            let c1 = Vec3::new(theta.sin(), 0.0, -theta.cos()) * (c0.length() * depth);
            if c0.distance(c1) <= (radius_m + r1) * 1.001 || c1.length() <= r1 * 1.001 {
                return Ok(());
            }
            let dir = (c1 + Vec3::new(aim[0], aim[1], 0.0) * r1).normalize();
            if let (Some(e0), Some(e1)) = (entry(dir, c0, radius_m), entry(dir, c1, r1)) {
                let order = far_to_near(
                    &[icosahedron(c0, radius_m), icosahedron(c1, r1)],
                    Vec3::ZERO,
                );
                let nearer = if e0 < e1 { 0 } else { 1 };
                prop_assert_eq!(order[1], nearer, "entries {} and {}", e0, e1);
            }
        }
    }
}

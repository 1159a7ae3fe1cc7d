//! Helpers shared by the integration tests: tolerant comparisons that print the
//! difference, scene builders, and independent geometry (winding numbers, point–triangle
//! distances) to judge the simulator with.
#![allow(dead_code)]

use bubble_dynamics::{BubbleParams, DVec3, World, WorldParams};

/// Asserts |actual − expected| ≤ rel·|expected|, printing both and the relative error.
#[track_caller]
pub fn assert_rel(what: &str, actual: f64, expected: f64, rel: f64) {
    let err = (actual - expected).abs() / expected.abs();
    assert!(
        err <= rel,
        "{what}: actual {actual:.9e}, expected {expected:.9e}, relative error {err:.3e} > {rel:.1e}"
    );
}

/// Asserts |actual − expected| ≤ abs, printing both and the difference.
#[track_caller]
pub fn assert_abs(what: &str, actual: f64, expected: f64, abs: f64) {
    let diff = (actual - expected).abs();
    assert!(
        diff <= abs,
        "{what}: actual {actual:.9e}, expected {expected:.9e}, difference {diff:.3e} > {abs:.1e}"
    );
}

/// A world with no gravity, no air (no drag, no buoyancy, no added mass), no colliders:
/// only the bubbles' internal forces act.
pub fn isolated() -> WorldParams {
    WorldParams {
        gravity_m_per_s2: DVec3::ZERO,
        air_density_kg_per_m3: 0.0,
        air_viscosity_pa_s: 0.0,
        ..WorldParams::default()
    }
}

/// A bubble with a uniform film and no swirl, for clean closed-form checks.
pub fn plain_bubble(radius_m: f64, subdivisions: u32) -> BubbleParams {
    BubbleParams {
        radius_m,
        subdivisions,
        thickness_variation: 0.0,
        slosh_speed_m_per_s: 0.0,
        ..BubbleParams::default()
    }
}

/// Builds a world or fails the test with the parameter error.
#[track_caller]
pub fn world(params: WorldParams, bubbles: Vec<BubbleParams>) -> World {
    World::try_new(params, bubbles).unwrap_or_else(|e| panic!("test scene rejected: {e}"))
}

/// Mean of the vertex positions.
pub fn centroid(x: &[DVec3]) -> DVec3 {
    x.iter().copied().sum::<DVec3>() / x.len() as f64
}

/// Generalised winding number of a closed mesh around `p` (Van Oosterom & Strackee
/// solid angles): 1 inside, 0 outside.
pub fn winding_number(p: DVec3, x: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let mut total = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| x[i as usize] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

/// Distance from `p` to triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
pub fn point_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return p.distance(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    p.distance(a + ab * (vb * denom) + ac * (vc * denom))
}

/// How deep `p` lies inside the closed mesh (0 when outside).
pub fn penetration_depth(p: DVec3, x: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    if winding_number(p, x, triangles) < 0.5 {
        return 0.0;
    }
    triangles
        .iter()
        .map(|t| point_triangle_distance(p, x[t[0] as usize], x[t[1] as usize], x[t[2] as usize]))
        .fold(f64::INFINITY, f64::min)
}

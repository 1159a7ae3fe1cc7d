//! Contacts: bubble–collider and bubble–bubble, resolved per substep by a position
//! projection (no interpenetration) plus a momentum-conserving impulse with restitution
//! and Coulomb friction. Broad phase: bounding spheres with sort-and-sweep on x.

use glam::DVec3;

use crate::bubble::Bubble;
use crate::collider::Collider;

/// Normal approach speed below which a contact is treated as resting (no bounce), m/s;
/// keeps a bubble lying on the ground from chattering.
const RESTING_SPEED_M_PER_S: f64 = 0.01;

/// Bounding sphere of a bubble's vertices.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bounds {
    pub(crate) center_m: DVec3,
    pub(crate) radius_m: f64,
}

impl Bounds {
    pub(crate) fn of(positions: &[DVec3]) -> Self {
        let center_m = positions.iter().copied().sum::<DVec3>() / positions.len() as f64;
        // √ is monotone: one root of the largest square, not one per vertex.
        let radius_m = positions
            .iter()
            .map(|x| x.distance_squared(center_m))
            .fold(0.0, f64::max)
            .sqrt();
        Self { center_m, radius_m }
    }
}

/// A contact between a point and something it must stay outside of.
struct Contact {
    normal: DVec3,
    depth_m: f64,
    restitution: f64,
    friction: f64,
}

/// Pushes every vertex of `bubble` out of every collider and applies the contact impulse.
pub(crate) fn resolve_static(bubble: &mut Bubble, colliders: &[Collider]) {
    let bounds = Bounds::of(&bubble.positions_m);
    for collider in colliders {
        // Signed distances are 1-Lipschitz: a far centre means no vertex can touch.
        if collider.signed_distance_m(bounds.center_m).0 > bounds.radius_m {
            continue;
        }
        let (restitution, friction) = collider.contact();
        for (x, v) in bubble
            .positions_m
            .iter_mut()
            .zip(bubble.velocities_m_per_s.iter_mut())
        {
            let (distance, normal) = collider.signed_distance_m(*x);
            if distance < 0.0 {
                *x -= normal * distance;
                let contact = Contact {
                    normal,
                    depth_m: -distance,
                    restitution,
                    friction,
                };
                *v += contact_impulse(&contact, *v, 1.0);
            }
        }
    }
}

/// Contact impulse (N·s) for relative velocity `v_rel` and effective inverse mass
/// `inv_mass_sum`: stops the approach along the normal, bounces with restitution above
/// the resting speed, and slides with Coulomb friction (|J_t| ≤ μ J_n).
fn contact_impulse(c: &Contact, v_rel: DVec3, inv_mass_sum: f64) -> DVec3 {
    let vn = v_rel.dot(c.normal);
    if vn >= 0.0 || c.depth_m < 0.0 {
        return DVec3::ZERO;
    }
    let e = if -vn > RESTING_SPEED_M_PER_S {
        c.restitution
    } else {
        0.0
    };
    let jn = -(1.0 + e) * vn / inv_mass_sum;
    let vt = v_rel - c.normal * vn;
    let speed_t = vt.length();
    let jt = if speed_t > 0.0 {
        (c.friction * jn).min(speed_t / inv_mass_sum)
    } else {
        0.0
    };
    c.normal * jn - vt.normalize_or_zero() * jt
}

/// Candidate pairs (i < j) whose bounding spheres overlap, in a deterministic order.
pub(crate) fn candidate_pairs(bounds: &[Bounds]) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..bounds.len()).collect();
    let lo = |i: usize| bounds[i].center_m.x - bounds[i].radius_m;
    order.sort_by(|&a, &b| lo(a).total_cmp(&lo(b)).then(a.cmp(&b)));
    let mut pairs = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        let hi = bounds[i].center_m.x + bounds[i].radius_m;
        for &j in order[k + 1..].iter().take_while(|&&j| lo(j) <= hi) {
            let reach = bounds[i].radius_m + bounds[j].radius_m;
            if bounds[i].center_m.distance_squared(bounds[j].center_m) < reach * reach {
                pairs.push((i.min(j), i.max(j)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// Gauss–Seidel sweeps over each touching pair: a second sweep settles the vertices that
/// the other bubble's correction pushed back in.
const CONTACT_SWEEPS: usize = 2;

/// Resolves all bubble–bubble contacts.
pub(crate) fn resolve_bubbles(bubbles: &mut [Bubble], restitution: f64, friction: f64) {
    if bubbles.len() < 2 {
        return;
    }
    let bounds: Vec<Bounds> = bubbles.iter().map(|b| Bounds::of(&b.positions_m)).collect();
    for (i, j) in candidate_pairs(&bounds) {
        let (head, tail) = bubbles.split_at_mut(j);
        let (a, b) = (&mut head[i], &mut tail[0]);
        let material = (restitution, friction);
        for _ in 0..CONTACT_SWEEPS {
            push_vertices_out(a, b, Bounds::of(&b.positions_m), material);
            push_vertices_out(b, a, Bounds::of(&a.positions_m), material);
        }
    }
}

/// Where a point lies against a bubble surface: the face hit by the ray from the bubble's
/// centre through the point, with barycentric weights.
struct SurfaceHit {
    corners: [usize; 3],
    weights: [f64; 3],
    normal: DVec3,
    depth_m: f64,
}

/// Every vertex of `a` that lies inside `b` is moved onto `b`'s surface, `b`'s face moving
/// the other way in proportion to inverse masses (the centre of mass stays put), and the
/// pair exchanges an equal and opposite contact impulse.
fn push_vertices_out(
    a: &mut Bubble,
    b: &mut Bubble,
    bounds_b: Bounds,
    (restitution, friction): (f64, f64),
) {
    let mut hint = 0;
    for i in 0..a.positions_m.len() {
        let p = a.positions_m[i];
        if p.distance_squared(bounds_b.center_m) >= bounds_b.radius_m * bounds_b.radius_m {
            continue;
        }
        let Some(hit) = locate_on_surface(b, bounds_b.center_m, p, &mut hint) else {
            continue;
        };
        if hit.depth_m <= 0.0 {
            continue;
        }
        let inv_a = 1.0 / a.inertial_mass_kg[i];
        // How far each corner of b's face moves per unit of the pair's correction.
        let share: [f64; 3] =
            std::array::from_fn(|k| hit.weights[k] / b.inertial_mass_kg[hit.corners[k]]);
        let inv_sum = inv_a + (0..3).map(|k| hit.weights[k] * share[k]).sum::<f64>();
        let lambda = hit.depth_m / inv_sum;
        a.positions_m[i] += hit.normal * (lambda * inv_a);
        for (&corner, s) in hit.corners.iter().zip(share) {
            b.positions_m[corner] -= hit.normal * (lambda * s);
        }
        let v_b: DVec3 = (0..3)
            .map(|k| b.velocities_m_per_s[hit.corners[k]] * hit.weights[k])
            .sum();
        let contact = Contact {
            normal: hit.normal,
            depth_m: hit.depth_m,
            restitution,
            friction,
        };
        let impulse = contact_impulse(&contact, a.velocities_m_per_s[i] - v_b, inv_sum);
        a.velocities_m_per_s[i] += impulse * inv_a;
        for (&corner, s) in hit.corners.iter().zip(share) {
            b.velocities_m_per_s[corner] -= impulse * s;
        }
    }
}

/// Finds the face of `b` crossed by the ray from `center` through `p` (a bubble is
/// star-shaped about its centre), walking greedily over vertices from `hint`.
fn locate_on_surface(b: &Bubble, center: DVec3, p: DVec3, hint: &mut usize) -> Option<SurfaceHit> {
    let dir = (p - center).try_normalize()?;
    let x = &b.positions_m;
    let topo = &b.topology;
    let alignment = |k: usize| (x[k] - center).normalize_or_zero().dot(dir);
    let mut best = (*hint).min(x.len() - 1);
    let mut best_score = alignment(best);
    loop {
        let next = topo
            .neighbors_of(best)
            .iter()
            .map(|&k| (k as usize, alignment(k as usize)))
            .fold(
                (best, best_score),
                |acc, cand| if cand.1 > acc.1 { cand } else { acc },
            );
        if next.0 == best {
            break;
        }
        (best, best_score) = next;
    }
    *hint = best;
    // The best-aligned vertex is almost always a corner of the face the ray crosses;
    // when it is not (obtuse or sheared triangles), the face is one ring further out.
    let hit_face = |f: u32| {
        let corners = topo.triangles()[f as usize].map(|k| k as usize);
        let [q0, q1, q2] = corners.map(|k| x[k]);
        let (u, v) = ray_triangle(center, dir, q0, q1, q2)?;
        let normal = (q1 - q0).cross(q2 - q0).try_normalize()?;
        Some(SurfaceHit {
            corners,
            weights: [1.0 - u - v, u, v],
            normal,
            depth_m: (q0 - p).dot(normal),
        })
    };
    topo.faces_of(best)
        .iter()
        .find_map(|&f| hit_face(f))
        .or_else(|| {
            topo.neighbors_of(best)
                .iter()
                .find_map(|&n| topo.faces_of(n as usize).iter().find_map(|&f| hit_face(f)))
        })
}

/// Möller–Trumbore: barycentric (u, v) of the hit of ray o + t·d (t > 0) on triangle
/// (a, b, c), edges included.
fn ray_triangle(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<(f64, f64)> {
    const EDGE_TOLERANCE: f64 = 1e-9;
    let e1 = b - a;
    let e2 = c - a;
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    if det.abs() < f64::MIN_POSITIVE {
        return None;
    }
    let inv = 1.0 / det;
    let tvec = o - a;
    let u = tvec.dot(pvec) * inv;
    let qvec = tvec.cross(e1);
    let v = d.dot(qvec) * inv;
    let t = e2.dot(qvec) * inv;
    let inside = u >= -EDGE_TOLERANCE && v >= -EDGE_TOLERANCE && u + v <= 1.0 + EDGE_TOLERANCE;
    (inside && t > 0.0).then_some((u, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweep_finds_exactly_the_overlapping_pairs() {
        let b = |x: f64, y: f64, r: f64| Bounds {
            center_m: DVec3::new(x, y, 0.0),
            radius_m: r,
        };
        let bounds = [
            b(0.0, 0.0, 1.0),
            b(1.5, 0.0, 1.0),
            b(5.0, 0.0, 1.0),
            b(0.5, 10.0, 1.0),
            b(-0.5, 0.5, 0.2),
        ];
        let mut brute = Vec::new();
        for i in 0..bounds.len() {
            for j in i + 1..bounds.len() {
                let reach = bounds[i].radius_m + bounds[j].radius_m;
                if bounds[i].center_m.distance(bounds[j].center_m) < reach {
                    brute.push((i, j));
                }
            }
        }
        assert_eq!(candidate_pairs(&bounds), brute);
    }

    #[test]
    fn ray_hits_triangle_interior_with_barycentrics() {
        let (u, v) = ray_triangle(
            DVec3::ZERO,
            DVec3::Z,
            DVec3::new(-1.0, -1.0, 2.0),
            DVec3::new(2.0, -1.0, 2.0),
            DVec3::new(-1.0, 2.0, 2.0),
        )
        .expect("hit");
        assert!(
            (u - 1.0 / 3.0).abs() < 1e-12 && (v - 1.0 / 3.0).abs() < 1e-12,
            "u = {u}, v = {v}"
        );
        assert!(
            ray_triangle(
                DVec3::ZERO,
                -DVec3::Z,
                DVec3::new(-1.0, -1.0, 2.0),
                DVec3::new(2.0, -1.0, 2.0),
                DVec3::new(-1.0, 2.0, 2.0)
            )
            .is_none()
        );
    }
}

//! Contacts: bubble–collider and bubble–bubble, resolved per substep by a position
//! projection (no interpenetration) and per-vertex impulses that stop each touching
//! vertex's approach, with the restitution applied to centres of mass: a static
//! collider's through a contact episode (the bubble squashes and springs back, and leaves
//! at −e times its arrival speed), a pair's by an impulse on both centres of mass along
//! the line of centres. Broad phase: bounding spheres with sort-and-sweep on x.

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

/// One bubble's impact on one static collider, from the first touch to the separation.
///
/// The film and gas squash and spring back under the per-vertex contacts as they would;
/// the episode only sets how fast the centre of mass leaves: while it moves away and
/// still touches, any normal speed above e times the arrival speed is taken out (the
/// spring gives back more than e asks); at the separation any shortfall is added (the
/// wobble kept what e = 1 asks back). A restitution phase lasts at most as long as the
/// compression did (a spring's two halves), so a bubble that came to rest on the ground
/// is not held there afterwards.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Episode {
    /// Unit contact normal at the first touch.
    normal: DVec3,
    /// Normal speed of the centre of mass towards the collider at the first touch, m/s
    /// (0 when no episode is open).
    arrival_m_per_s: f64,
    /// Time the centre of mass has spent approaching, s.
    compression_s: f64,
    /// Time since it stopped approaching, s.
    restitution_s: f64,
}

/// Pushes every vertex of `bubble` out of every collider it touches and stops each
/// touching vertex's approach (friction included), then sets the centre of mass's
/// leaving speed to the collider's restitution through the bubble's contact episode with
/// it. `substep_s` is the substep just taken.
pub(crate) fn resolve_static(bubble: &mut Bubble, colliders: &[Collider], substep_s: f64) {
    if bubble.episodes.len() != colliders.len() {
        bubble.episodes = vec![Episode::default(); colliders.len()];
    }
    let bounds = Bounds::of(&bubble.positions_m);
    let mut touching = Vec::new();
    for (k, collider) in colliders.iter().enumerate() {
        // Signed distances are 1-Lipschitz: a far centre means no vertex can touch.
        let far = collider.signed_distance_m(bounds.center_m).0 > bounds.radius_m;
        let (restitution, friction) = collider.contact();
        touching.clear();
        let mut normal_sum = DVec3::ZERO;
        if !far {
            for (i, x) in bubble.positions_m.iter().enumerate() {
                let (distance, normal) = collider.signed_distance_m(*x);
                if distance < 0.0 {
                    normal_sum += normal * -distance;
                    touching.push((i, normal, -distance));
                }
            }
        }
        for &(i, normal, depth_m) in &touching {
            bubble.positions_m[i] += normal * depth_m;
            let contact = Contact {
                normal,
                depth_m,
                restitution: 0.0,
                friction,
            };
            let v = &mut bubble.velocities_m_per_s[i];
            *v += contact_impulse(&contact, *v, 1.0);
        }
        let touch_normal = normal_sum.try_normalize();
        let mut episode = bubble.episodes[k];
        if episode.arrival_m_per_s == 0.0 {
            let Some(normal) = touch_normal else {
                continue;
            };
            // Opened by an impact only: a resting or grazing touch is left to the
            // vertices, so nothing is held to the ground.
            let arrival = -bubble.velocity_m_per_s().dot(normal);
            if arrival <= RESTING_SPEED_M_PER_S {
                continue;
            }
            episode = Episode {
                normal,
                arrival_m_per_s: arrival,
                compression_s: 0.0,
                restitution_s: 0.0,
            };
        }
        let v_n = bubble.velocity_m_per_s().dot(episode.normal);
        if v_n < 0.0 && episode.restitution_s == 0.0 {
            episode.compression_s += substep_s;
        } else {
            episode.restitution_s += substep_s;
        }
        let target = restitution * episode.arrival_m_per_s;
        let held = touch_normal.is_some() && v_n > target;
        if held {
            shift_normal_velocity(bubble, episode.normal, target - v_n);
        }
        // Over once the bubble is clear and leaving, or once the spring has had its time
        // and no longer pushes past e (the energy it held has gone into the contacts).
        let separated = touch_normal.is_none() && v_n >= 0.0;
        let spring_over = episode.restitution_s > episode.compression_s && !held;
        if separated || spring_over {
            // A bubble pressed back in (wind, gravity, a neighbour) when the spring's time
            // is over gets nothing: its contact has become a resting one.
            if (0.0..target).contains(&v_n) {
                // What the spring did not give back: first from the wobble's kinetic
                // energy, the rest added (the wobble keeps its potential energy).
                boost_from_wobble(bubble, episode.normal, v_n, target);
                let v_n = bubble.velocity_m_per_s().dot(episode.normal);
                shift_normal_velocity(bubble, episode.normal, target - v_n);
            }
            episode = Episode::default();
        }
        bubble.episodes[k] = episode;
    }
}

/// Raises the centre of mass's normal speed from `v_n` towards `target` with kinetic
/// energy taken from the motion relative to it (the wobble the impact left), so the
/// bounce creates no kinetic energy: relative velocities shrink by the common factor
/// that pays for the raise, or vanish if they cannot pay for all of it.
fn boost_from_wobble(bubble: &mut Bubble, normal: DVec3, v_n: f64, target: f64) {
    let mass_kg = bubble.inertial_mass_kg();
    let v_cm = bubble.velocity_m_per_s();
    let relative_j: f64 = bubble
        .velocities_m_per_s
        .iter()
        .zip(&bubble.inertial_mass_kg)
        .map(|(v, m)| 0.5 * m * (*v - v_cm).length_squared())
        .sum();
    let needed_j = 0.5 * mass_kg * (target * target - v_n * v_n);
    let (scale, new_v_n) = if relative_j >= needed_j {
        ((1.0 - needed_j / relative_j).sqrt(), target)
    } else {
        (0.0, (v_n * v_n + 2.0 * relative_j / mass_kg).sqrt())
    };
    let dv = normal * (new_v_n - v_n);
    for v in &mut bubble.velocities_m_per_s {
        *v = v_cm + (*v - v_cm) * scale + dv;
    }
}

/// Adds `dv_m_per_s` along the unit `normal` to every vertex: the centre of mass's
/// normal velocity changes by that much, the shape not at all.
fn shift_normal_velocity(bubble: &mut Bubble, normal: DVec3, dv_m_per_s: f64) {
    let dv = normal * dv_m_per_s;
    bubble.velocities_m_per_s.iter_mut().for_each(|v| *v += dv);
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

/// Resolves all bubble–bubble contacts: positions first, then the pair's centres of mass
/// bounce with `restitution`, then each touching vertex's remaining approach is stopped.
pub(crate) fn resolve_bubbles(bubbles: &mut [Bubble], restitution: f64, friction: f64) {
    if bubbles.len() < 2 {
        return;
    }
    let bounds: Vec<Bounds> = bubbles.iter().map(|b| Bounds::of(&b.positions_m)).collect();
    let material = (restitution, friction);
    let (mut a_in_b, mut b_in_a) = (Vec::new(), Vec::new());
    for (i, j) in candidate_pairs(&bounds) {
        let (head, tail) = bubbles.split_at_mut(j);
        let (a, b) = (&mut head[i], &mut tail[0]);
        a_in_b.clear();
        b_in_a.clear();
        for _ in 0..CONTACT_SWEEPS {
            push_vertices_out(a, b, Bounds::of(&b.positions_m), &mut a_in_b);
            push_vertices_out(b, a, Bounds::of(&a.positions_m), &mut b_in_a);
        }
        if a_in_b.is_empty() && b_in_a.is_empty() {
            continue;
        }
        bounce_pair(a, b, material);
        for hit in &a_in_b {
            vertex_impulse(a, b, hit, material);
        }
        for hit in &b_in_a {
            vertex_impulse(b, a, hit, material);
        }
    }
}

/// The whole-bubble part of a bubble–bubble contact, along the line of centres: equal and
/// opposite impulses, each spread evenly over a bubble's vertices (shapes untouched), so
/// the relative normal velocity of the centres of mass leaves at −e times its approach.
fn bounce_pair(a: &mut Bubble, b: &mut Bubble, (restitution, friction): (f64, f64)) {
    let Some(normal) = (a.center_m() - b.center_m()).try_normalize() else {
        return;
    };
    let (mass_a, mass_b) = (a.inertial_mass_kg(), b.inertial_mass_kg());
    let contact = Contact {
        normal,
        depth_m: 0.0,
        restitution,
        friction,
    };
    let v_rel = a.velocity_m_per_s() - b.velocity_m_per_s();
    let impulse = contact_impulse(&contact, v_rel, 1.0 / mass_a + 1.0 / mass_b);
    if impulse == DVec3::ZERO {
        return;
    }
    let (dv_a, dv_b) = (impulse / mass_a, impulse / mass_b);
    a.velocities_m_per_s.iter_mut().for_each(|v| *v += dv_a);
    b.velocities_m_per_s.iter_mut().for_each(|v| *v -= dv_b);
}

/// Where a vertex of one bubble was pushed out of a face of another.
struct SurfaceHit {
    /// The vertex of the bubble that was pushed.
    vertex: usize,
    corners: [usize; 3],
    weights: [f64; 3],
    normal: DVec3,
    depth_m: f64,
}

/// Every vertex of `a` that lies inside `b` is moved onto `b`'s surface, `b`'s face moving
/// the other way in proportion to inverse masses (the centre of mass stays put); each such
/// contact is added to `hits`.
fn push_vertices_out(a: &mut Bubble, b: &mut Bubble, bounds_b: Bounds, hits: &mut Vec<SurfaceHit>) {
    let mut hint = 0;
    for i in 0..a.positions_m.len() {
        let p = a.positions_m[i];
        if p.distance_squared(bounds_b.center_m) >= bounds_b.radius_m * bounds_b.radius_m {
            continue;
        }
        let Some(mut hit) = locate_on_surface(b, bounds_b.center_m, p, &mut hint) else {
            continue;
        };
        if hit.depth_m <= 0.0 {
            continue;
        }
        let inv_a = 1.0 / a.inertial_mass_kg[i];
        let (share, inv_sum) = face_shares(b, &hit, inv_a);
        let lambda = hit.depth_m / inv_sum;
        a.positions_m[i] += hit.normal * (lambda * inv_a);
        for (&corner, s) in hit.corners.iter().zip(share) {
            b.positions_m[corner] -= hit.normal * (lambda * s);
        }
        hit.vertex = i;
        hits.push(hit);
    }
}

/// How far each corner of `b`'s face moves per unit of the pair's correction, and the
/// effective inverse mass of the contact (1/kg).
fn face_shares(b: &Bubble, hit: &SurfaceHit, inv_a: f64) -> ([f64; 3], f64) {
    let share: [f64; 3] =
        std::array::from_fn(|k| hit.weights[k] / b.inertial_mass_kg[hit.corners[k]]);
    let inv_sum = inv_a + (0..3).map(|k| hit.weights[k] * share[k]).sum::<f64>();
    (share, inv_sum)
}

/// The equal and opposite impulse between a pushed vertex of `a` and `b`'s face: stops
/// what approach is left after the centres of mass bounced.
fn vertex_impulse(
    a: &mut Bubble,
    b: &mut Bubble,
    hit: &SurfaceHit,
    (restitution, friction): (f64, f64),
) {
    let i = hit.vertex;
    let inv_a = 1.0 / a.inertial_mass_kg[i];
    let (share, inv_sum) = face_shares(b, hit, inv_a);
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
            vertex: 0,
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

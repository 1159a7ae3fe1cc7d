//! A bounding-volume hierarchy over triangles (median split on the longest centroid
//! axis) and the exact Möller–Trumbore ray–triangle test.

use glam::Vec3;

/// Triangles per leaf at most.
const LEAF_SIZE: usize = 4;

/// A ray's closest triangle hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TriHit {
    /// Index into the triangle list the BVH was built over.
    pub tri: u32,
    /// Ray parameter (the ray direction's length is the unit).
    pub t: f32,
    /// Barycentric weights of vertices 1 and 2 (vertex 0 has `1 − u − v`).
    pub u: f32,
    pub v: f32,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: first index into `order`; interior: index of the second child (the first
    /// child follows the node).
    start_or_right: u32,
    /// Triangles in a leaf, 0 for an interior node.
    count: u32,
}

/// A BVH over a triangle list it does not own.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over `tris`.
    pub fn build(tris: &[[Vec3; 3]]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * tris.len() / LEAF_SIZE + 1),
            order: (0..tris.len() as u32).collect(),
        };
        if !tris.is_empty() {
            let centroids: Vec<Vec3> = tris.iter().map(|t| (t[0] + t[1] + t[2]) / 3.0).collect();
            bvh.split(tris, &centroids, 0, tris.len());
        }
        bvh
    }

    fn split(&mut self, tris: &[[Vec3; 3]], centroids: &[Vec3], a: usize, b: usize) {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let (mut clo, mut chi) = (lo, hi);
        for &i in &self.order[a..b] {
            for p in tris[i as usize] {
                lo = lo.min(p);
                hi = hi.max(p);
            }
            clo = clo.min(centroids[i as usize]);
            chi = chi.max(centroids[i as usize]);
        }
        let me = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            start_or_right: a as u32,
            count: (b - a) as u32,
        });
        if b - a <= LEAF_SIZE {
            return;
        }
        let axis = (chi - clo).max_position();
        let mid = (a + b) / 2;
        self.order[a..b].select_nth_unstable_by(mid - a, |&x, &y| {
            centroids[x as usize][axis].total_cmp(&centroids[y as usize][axis])
        });
        self.nodes[me].count = 0;
        self.split(tris, centroids, a, mid);
        self.nodes[me].start_or_right = self.nodes.len() as u32;
        self.split(tris, centroids, mid, b);
    }

    /// The closest hit of `origin + t·dir` with `t_min < t < t_max`, ignoring triangle `skip`.
    pub fn closest(
        &self,
        tris: &[[Vec3; 3]],
        origin: Vec3,
        dir: Vec3,
        (t_min, t_max): (f32, f32),
        skip: Option<u32>,
    ) -> Option<TriHit> {
        if self.nodes.is_empty() {
            return None;
        }
        let inv = dir.recip();
        let mut best: Option<TriHit> = None;
        let mut limit = t_max;
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let index = stack[top];
            let node = self.nodes[index as usize];
            if !slab(node.lo, node.hi, origin, inv, t_min, limit) {
                continue;
            }
            if node.count == 0 {
                // The first child is stored right after its parent.
                stack[top] = node.start_or_right;
                stack[top + 1] = index + 1;
                top += 2;
                continue;
            }
            let start = node.start_or_right as usize;
            for &i in &self.order[start..start + node.count as usize] {
                if Some(i) == skip {
                    continue;
                }
                if let Some((t, u, v)) = intersect(&tris[i as usize], origin, dir) {
                    if t > t_min && t < limit {
                        limit = t;
                        best = Some(TriHit { tri: i, t, u, v });
                    }
                }
            }
        }
        best
    }
}

/// Whether the ray meets the box within `(t_min, t_max)`.
#[inline]
fn slab(lo: Vec3, hi: Vec3, origin: Vec3, inv: Vec3, t_min: f32, t_max: f32) -> bool {
    let a = (lo - origin) * inv;
    let b = (hi - origin) * inv;
    let near = a.min(b).max_element().max(t_min);
    let far = a.max(b).min_element().min(t_max);
    near <= far
}

/// Möller–Trumbore: `(t, u, v)` where the line `origin + t·dir` crosses the triangle.
#[inline]
pub(crate) fn intersect(tri: &[Vec3; 3], origin: Vec3, dir: Vec3) -> Option<(f32, f32, f32)> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - tri[0];
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some((e2.dot(q) * inv_det, u, v))
}

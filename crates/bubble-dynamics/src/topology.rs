//! Mesh connectivity: edges with their two faces, and vertex → face / vertex → vertex
//! adjacency in compressed (CSR) form. Built once per subdivision level and shared.

use std::collections::BTreeMap;

/// An undirected edge of a closed mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    /// End vertices, `vertices[0] < vertices[1]`.
    pub vertices: [u32; 2],
    /// `faces[0]` traverses the edge from `vertices[0]` to `vertices[1]` (counter-clockwise),
    /// `faces[1]` traverses it the other way.
    pub faces: [u32; 2],
}

/// Connectivity of a closed, consistently oriented triangle mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Topology {
    triangles: Vec<[u32; 3]>,
    edges: Vec<Edge>,
    /// Per edge, the third vertex of `faces[0]` and of `faces[1]`.
    opposite_vertices: Vec<[u32; 2]>,
    /// Per edge, the same two corners as `3·face + slot` (slot in `triangles[face]`).
    opposite_corners: Vec<[u32; 2]>,
    vertex_face_offsets: Vec<u32>,
    vertex_faces: Vec<u32>,
    neighbor_offsets: Vec<u32>,
    neighbors: Vec<u32>,
}

impl Topology {
    /// Builds the connectivity of `triangles` over `vertex_count` vertices.
    ///
    /// Returns `None` unless the mesh is closed and consistently oriented (every edge is
    /// used exactly twice, once in each direction) and every vertex is used.
    ///
    /// # Guarantees
    /// Every edge has two distinct faces; every vertex has at least three faces and as
    /// many neighbours; neighbour lists are sorted.
    pub fn try_new(triangles: Vec<[u32; 3]>, vertex_count: usize) -> Option<Self> {
        let edges = collect_edges(&triangles, vertex_count)?;
        let (vertex_face_offsets, vertex_faces) = csr(
            vertex_count,
            triangles
                .iter()
                .enumerate()
                .flat_map(|(f, t)| t.iter().map(move |&v| (v, f as u32))),
        );
        let (neighbor_offsets, neighbors) = csr(
            vertex_count,
            edges.iter().flat_map(|e| {
                [
                    (e.vertices[0], e.vertices[1]),
                    (e.vertices[1], e.vertices[0]),
                ]
            }),
        );
        let opposite_vertices = edges
            .iter()
            .map(|e| {
                e.faces
                    .map(|f| third_vertex(triangles[f as usize], e.vertices))
            })
            .collect();
        let opposite_corners = edges
            .iter()
            .map(|e| {
                e.faces
                    .map(|f| 3 * f + third_slot(triangles[f as usize], e.vertices))
            })
            .collect();
        let topology = Self {
            triangles,
            edges,
            opposite_vertices,
            opposite_corners,
            vertex_face_offsets,
            vertex_faces,
            neighbor_offsets,
            neighbors,
        };
        (0..vertex_count)
            .all(|v| topology.faces_of(v).len() >= 3)
            .then_some(topology)
    }

    /// Triangles, counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Every undirected edge once, sorted by vertex pair.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Per edge (in [`Topology::edges`] order), the vertex opposite it in each of its
    /// two faces, in the order of `Edge::faces`.
    pub fn opposite_vertices(&self) -> &[[u32; 2]] {
        &self.opposite_vertices
    }

    /// Per edge, the corners of [`Topology::opposite_vertices`] as `3·face + slot`, the
    /// slot being the vertex's position in its triangle: an index into per-corner data.
    pub fn opposite_corners(&self) -> &[[u32; 2]] {
        &self.opposite_corners
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.vertex_face_offsets.len() - 1
    }

    /// Faces that contain vertex `v`, ascending.
    ///
    /// # Panics
    /// If `v` is not a vertex index.
    pub fn faces_of(&self, v: usize) -> &[u32] {
        &self.vertex_faces
            [self.vertex_face_offsets[v] as usize..self.vertex_face_offsets[v + 1] as usize]
    }

    /// Vertices joined to vertex `v` by an edge, ascending.
    ///
    /// # Panics
    /// If `v` is not a vertex index.
    pub fn neighbors_of(&self, v: usize) -> &[u32] {
        &self.neighbors[self.neighbor_offsets[v] as usize..self.neighbor_offsets[v + 1] as usize]
    }
}

/// The corner of `triangle` that is neither end of `edge`.
fn third_vertex(triangle: [u32; 3], edge: [u32; 2]) -> u32 {
    let [a, b, c] = triangle;
    a + b + c - edge[0] - edge[1]
}

/// The position in `triangle` of the corner that is neither end of `edge`.
fn third_slot(triangle: [u32; 3], edge: [u32; 2]) -> u32 {
    let k = third_vertex(triangle, edge);
    triangle
        .iter()
        .position(|&v| v == k)
        .expect("a triangle's own corner") as u32
}

fn collect_edges(triangles: &[[u32; 3]], vertex_count: usize) -> Option<Vec<Edge>> {
    let mut halves: BTreeMap<(u32, u32), [Option<u32>; 2]> = BTreeMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a == b || a as usize >= vertex_count || b as usize >= vertex_count {
                return None;
            }
            let slot = usize::from(a > b);
            let entry = halves.entry((a.min(b), a.max(b))).or_default();
            if entry[slot].replace(f as u32).is_some() {
                return None;
            }
        }
    }
    halves
        .into_iter()
        .map(|((a, b), faces)| {
            Some(Edge {
                vertices: [a, b],
                faces: [faces[0]?, faces[1]?],
            })
        })
        .collect()
}

/// Compressed rows from (row, value) pairs; values within a row sorted ascending.
fn csr(rows: usize, pairs: impl Iterator<Item = (u32, u32)>) -> (Vec<u32>, Vec<u32>) {
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); rows];
    for (r, v) in pairs {
        lists[r as usize].push(v);
    }
    let mut offsets = Vec::with_capacity(rows + 1);
    let mut values = Vec::new();
    offsets.push(0);
    for mut list in lists {
        list.sort_unstable();
        values.extend_from_slice(&list);
        offsets.push(values.len() as u32);
    }
    (offsets, values)
}

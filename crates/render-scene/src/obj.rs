//! A small Wavefront OBJ reader: `v`, `vn`, `vt` and `f` (polygons fan-triangulated);
//! other statements (`o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, ...) are skipped.

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;

use crate::{RenderError, TriMesh};

impl TriMesh {
    /// Reads an OBJ file; errors name the path and line.
    pub fn load_obj(path: impl AsRef<Path>) -> Result<TriMesh, RenderError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| RenderError::ImageRead {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Self::parse_obj(&text).map_err(|e| match e {
            RenderError::Obj { line, message, .. } => RenderError::Obj {
                path: Some(path.to_path_buf()),
                line,
                message,
            },
            other => other,
        })
    }

    /// Parses OBJ text. Faces without `vn` get their flat geometric normal.
    pub fn parse_obj(text: &str) -> Result<TriMesh, RenderError> {
        let mut reader = ObjReader::default();
        for (k, line) in text.lines().enumerate() {
            reader.line(line).map_err(|message| RenderError::Obj {
                path: None,
                line: k + 1,
                message,
            })?;
        }
        Ok(reader.mesh)
    }
}

/// One face corner: indices into positions, texture coordinates and normals.
type Corner = (usize, Option<usize>, Option<usize>);

#[derive(Default)]
struct ObjReader {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<[f32; 2]>,
    /// Output vertex of each smooth (v, vt, vn) corner seen so far.
    shared: HashMap<Corner, u32>,
    mesh: TriMesh,
}

impl ObjReader {
    fn line(&mut self, line: &str) -> Result<(), String> {
        let line = line.split('#').next().unwrap_or("");
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            return Ok(());
        };
        match keyword {
            "v" => {
                let [x, y, z] = floats::<3>(&mut words, "v")?;
                self.positions.push(Vec3::new(x, y, z));
            }
            "vn" => {
                let [x, y, z] = floats::<3>(&mut words, "vn")?;
                let n = Vec3::new(x, y, z).normalize_or_zero();
                if n == Vec3::ZERO {
                    return Err(format!("vn {x} {y} {z} has zero length"));
                }
                self.normals.push(n);
            }
            "vt" => {
                let [u, v] = floats::<2>(&mut words, "vt")?;
                // OBJ's v runs up the image; ours runs down.
                self.uvs.push([u, 1.0 - v]);
            }
            "f" => self.face(words)?,
            _ => {}
        }
        Ok(())
    }

    fn face<'a>(&mut self, words: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let corners = words
            .map(|w| self.corner(w))
            .collect::<Result<Vec<_>, _>>()?;
        if corners.len() < 3 {
            return Err(format!(
                "face has {} vertices, needs at least 3",
                corners.len()
            ));
        }
        let flat = corners
            .iter()
            .any(|c| c.2.is_none())
            .then(|| self.polygon_normal(&corners));
        let ids: Vec<u32> = corners.iter().map(|&c| self.vertex(c, flat)).collect();
        for k in 1..ids.len() - 1 {
            self.mesh.triangles.push([ids[0], ids[k], ids[k + 1]]);
        }
        Ok(())
    }

    /// Parses `v`, `v/vt`, `v//vn` or `v/vt/vn` (1-based, or negative from the end).
    fn corner(&self, word: &str) -> Result<Corner, String> {
        let mut parts = word.split('/');
        let v = index(parts.next(), self.positions.len(), "v", word)?
            .ok_or_else(|| format!("face corner `{word}` has no vertex index"))?;
        let vt = index(parts.next(), self.uvs.len(), "vt", word)?;
        let vn = index(parts.next(), self.normals.len(), "vn", word)?;
        if parts.next().is_some() {
            return Err(format!("face corner `{word}` has more than three indices"));
        }
        Ok((v, vt, vn))
    }

    /// Newell's normal of the polygon: robust for non-planar and concave polygons.
    fn polygon_normal(&self, corners: &[Corner]) -> Vec3 {
        let origin = self.positions[corners[0].0];
        let mut n = Vec3::ZERO;
        for (k, c) in corners.iter().enumerate() {
            let a = self.positions[c.0] - origin;
            let b = self.positions[corners[(k + 1) % corners.len()].0] - origin;
            n += a.cross(b);
        }
        // A degenerate polygon gets an arbitrary normal; it covers no pixels anyway.
        n.normalize_or(Vec3::Y)
    }

    fn vertex(&mut self, corner: Corner, flat: Option<Vec3>) -> u32 {
        if flat.is_none() {
            if let Some(&id) = self.shared.get(&corner) {
                return id;
            }
        }
        let id = self.mesh.positions.len() as u32;
        self.mesh.positions.push(self.positions[corner.0]);
        self.mesh
            .normals
            .push(flat.unwrap_or_else(|| self.normals[corner.2.unwrap_or(0)]));
        let uv = corner.1.map_or([0.0, 0.0], |t| self.uvs[t]);
        self.mesh.uvs.push(uv);
        if flat.is_none() {
            self.shared.insert(corner, id);
        }
        id
    }
}

fn floats<const N: usize>(
    words: &mut dyn Iterator<Item = &str>,
    keyword: &str,
) -> Result<[f32; N], String> {
    let mut out = [0.0; N];
    for (k, o) in out.iter_mut().enumerate() {
        let w = words
            .next()
            .ok_or_else(|| format!("`{keyword}` needs {N} numbers, found {k}"))?;
        *o = w
            .parse::<f32>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("`{w}` is not a finite number"))?;
    }
    Ok(out)
}

/// Resolves one OBJ index field: empty → None, 1-based or negative relative to `count`.
fn index(
    field: Option<&str>,
    count: usize,
    kind: &str,
    word: &str,
) -> Result<Option<usize>, String> {
    let Some(field) = field.filter(|f| !f.is_empty()) else {
        return Ok(None);
    };
    let i: i64 = field
        .parse()
        .map_err(|_| format!("`{field}` in face corner `{word}` is not an integer"))?;
    let resolved = if i > 0 { i - 1 } else { count as i64 + i };
    if i == 0 || resolved < 0 || resolved >= count as i64 {
        return Err(format!(
            "{kind} index {i} in face corner `{word}` is out of range (1..={count} defined so far)"
        ));
    }
    Ok(Some(resolved as usize))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_with_normals_becomes_two_shared_triangles() {
        let text =
            "# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n";
        let mesh = TriMesh::parse_obj(text).unwrap();
        mesh.validate("quad").unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.positions.len(), 4);
        assert!(mesh.normals.iter().all(|n| *n == Vec3::Z));
    }

    #[test]
    fn faces_without_normals_get_flat_normals_and_negative_indices_work() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 0 -1\nf -3 -2 -1\n";
        let mesh = TriMesh::parse_obj(text).unwrap();
        // (1,0,0) × (0,0,-1) points up.
        for n in &mesh.normals {
            assert!((*n - Vec3::Y).length() < 1e-6, "normal {n}");
        }
    }

    #[test]
    fn texture_coordinates_are_flipped_to_v_down() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
        let mesh = TriMesh::parse_obj(text).unwrap();
        assert_eq!(mesh.uvs[0], [0.25, 1.0]);
        assert_eq!(mesh.uvs[2], [0.0, 0.0]);
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            ("v 0 0 0\nv 1 0\n", 2, "needs 3"),
            ("v 0 0 0\nv 1 0 x\n", 2, "not a finite"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n", 5, "out of range"),
            ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3"),
            ("v 0 0 0\nf 1 1 1/1\n", 2, "vt index"),
            ("vn 0 0 0\n", 1, "zero length"),
            ("v 0 0 0\nf 0 1 1\n", 2, "out of range"),
        ];
        for (text, line, needle) in cases {
            let e = TriMesh::parse_obj(text).unwrap_err();
            let msg = e.to_string();
            assert!(
                matches!(e, RenderError::Obj { line: l, .. } if l == line),
                "{text:?}: {msg}"
            );
            assert!(msg.contains(needle), "{text:?}: {msg}");
        }
    }

    #[test]
    fn load_obj_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("broken.obj");
        std::fs::write(&path, "v 0 0 0\nf 1 2 3\n").unwrap();
        let msg = TriMesh::load_obj(&path).unwrap_err().to_string();
        assert!(msg.contains("broken.obj:2:"), "{msg}");
        let missing = TriMesh::load_obj(dir.path().join("missing.obj"))
            .unwrap_err()
            .to_string();
        assert!(missing.contains("missing.obj"), "{missing}");
    }
}

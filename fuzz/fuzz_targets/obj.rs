//! OBJ meshes: the triangle count the scene check uses, then raster's parser. A mesh the
//! parser accepts is valid (finite positions, indices in range).
#![no_main]
use libfuzzer_sys::fuzz_target;
use raster::TriMesh;

fuzz_target!(|text: &str| {
    if let Ok(mesh) = TriMesh::parse_obj(text) {
        mesh.validate("fuzzed mesh").expect("a parsed mesh is valid");
        for t in &mesh.triangles {
            assert!(t.iter().all(|&i| (i as usize) < mesh.positions.len()));
        }
    }
});

//! naga over the generated WGSL, without a GPU or wgpu: both shaders parse and validate, and
//! every struct the Rust side packs (`scene_data`) has the size the Rust side writes. A
//! shader mistake or a layout drift then fails `cargo test` before lavapipe ever sees it.

use glam::Vec3;
use naga::valid::{Capabilities, ValidationFlags, Validator};
use naga::{Module, TypeInner};
use render_scene::water::FRESNEL_STEPS;
use render_scene::{
    Camera, Environment, FilmTables, Ground, Light, Lut, Material, Object, RenderScene,
    RenderSettings, WaterSurface,
};

use super::scene_data::{
    BUBBLE_VERTEX_BYTES, CubeReads, OBJECT_VERTEX_BYTES, SceneData, VIEW_BYTES, view_bytes,
};
use super::shader_source::{present_wgsl, scene_wgsl, tonemap_wgsl};

/// `source` parsed and validated, or a panic with naga's report.
fn validated(source: &str) -> Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("WGSL does not parse:\n{}", e.emit_to_string(source)));
    Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("WGSL does not validate:\n{}", e.emit_to_string(source)));
    module
}

/// Byte size (with WGSL's alignment padding) of the struct named `name`.
fn struct_size(module: &Module, name: &str) -> u64 {
    let ty = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name} in the shader"));
    match ty.1.inner {
        TypeInner::Struct { span, .. } => u64::from(span),
        ref other => panic!("{name} is not a struct: {other:?}"),
    }
}

/// Sum of the member sizes of struct `name`: the bytes of a tightly packed vertex.
fn packed_size(module: &Module, name: &str) -> u64 {
    let ty = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name} in the shader"));
    let TypeInner::Struct { members, .. } = &ty.1.inner else {
        panic!("{name} is not a struct");
    };
    members
        .iter()
        .map(|m| u64::from(module.types[m.ty].inner.size(module.to_ctx())))
        .sum()
}

/// A scene using every packed array: three materials (an object's, the ground's and the
/// water floor's), one light, three tables (reflectivity, transmittance, the light's own)
/// and a water surface.
fn packed_scene() -> (SceneData, usize, usize, usize) {
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 2.0), Vec3::ZERO, Vec3::Y, 45.0);
    let mut scene = RenderScene::new(camera, Environment::Uniform([0.2; 3]));
    scene.objects.push(Object::Sphere {
        center: Vec3::ZERO,
        radius_m: 0.3,
        material: Material::checker([0.8; 3], [0.1; 3], 0.1),
    });
    scene.ground = Some(Ground {
        height_m: -0.5,
        material: Material::matte([0.5; 3]),
    });
    scene.water = Some(WaterSurface {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
        normals: vec![Vec3::Y; 3],
        triangles: vec![[0, 2, 1]],
        rest_height_m: 0.0,
        ior: 1.333,
        floor_depth_m: 0.5,
        floor: Material::matte([0.5; 3]),
        absorption_per_m: [0.1, 0.2, 0.3],
    });
    scene.lights.push(Light {
        position: Vec3::new(1.0, 2.0, 1.0),
        radius_m: 0.1,
        radiance: [10.0; 3],
        light_lut: Some(0),
    });
    let table = Lut::try_from_fn(8, 4, 1000.0, |d, c| [d * 1e-3, c, 0.5]).unwrap();
    let tables = FilmTables {
        reflectivity: table.clone(),
        transmittance: Some(table.clone()),
        lights: vec![table],
    };
    let settings = RenderSettings::default();
    let view = scene.camera.view(64, 48);
    let data = SceneData::new(
        &scene,
        &tables,
        &settings,
        (&view, 4),
        8192,
        CubeReads::default(),
    )
    .unwrap();
    (data, 3, 1, 3)
}

#[test]
fn every_shader_parses_and_validates() {
    validated(&scene_wgsl());
    validated(&tonemap_wgsl());
    validated(&present_wgsl());
}

#[test]
fn uniform_and_storage_structs_have_the_sizes_scene_data_writes() {
    let module = validated(&scene_wgsl());
    let (data, materials, lights, tables) = packed_scene();
    let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0);
    let view = view_bytes(&camera.view(8, 8), None);
    let water = data.water.as_ref().expect("the packed scene has water");
    // Two Fresnel tables (from air, from water) of FRESNEL_STEPS + 1 samples each.
    assert_eq!(water.fresnel.len(), 2 * 4 * (FRESNEL_STEPS + 1));
    let checks = [
        ("View", 1, VIEW_BYTES as usize),
        ("View", 1, view.len()),
        ("Scene", 1, data.scene.len()),
        ("Material", materials, data.materials.len()),
        ("Light", lights, data.lights.len()),
        ("LutInfo", tables, data.lut_info.len()),
        ("Water", 1, water.uniform.len()),
    ];
    for (name, count, rust_bytes) in checks {
        let wgsl = struct_size(&module, name) as usize * count;
        assert_eq!(
            wgsl, rust_bytes,
            "{count} × WGSL {name} is {wgsl} bytes, the Rust side writes {rust_bytes}"
        );
    }
}

#[test]
fn vertex_structs_match_the_packed_vertex_streams() {
    let module = validated(&scene_wgsl());
    for (name, rust_bytes) in [
        ("ObjectIn", OBJECT_VERTEX_BYTES),
        ("BubbleIn", BUBBLE_VERTEX_BYTES),
    ] {
        let wgsl = packed_size(&module, name);
        assert_eq!(
            wgsl, rust_bytes,
            "WGSL {name}'s members take {wgsl} bytes, the Rust vertex stream {rust_bytes}"
        );
    }
    let (data, ..) = packed_scene();
    assert_eq!(data.objects.len() as u64 % OBJECT_VERTEX_BYTES, 0);
    // The water's vertices are object vertices (`fs_water` shares `vs_object`).
    let water = data.water.as_ref().expect("the packed scene has water");
    assert_eq!(water.vertices.len() as u64, OBJECT_VERTEX_BYTES * 3);
    assert_eq!((water.index_count, water.indices.len()), (3, 12));
    assert!(
        !data.objects.is_empty(),
        "the packed scene has object vertices"
    );
}

#[cfg(feature = "wgpu")]
#[test]
fn the_present_uniform_has_the_size_present_rs_writes() {
    use super::present::{PRESENT_BYTES, params_bytes};
    let module = validated(&present_wgsl());
    let bytes = params_bytes((1.0, render_scene::ToneMap::AcesFitted, true), [(1, 1); 4]);
    assert_eq!(struct_size(&module, "Present"), PRESENT_BYTES);
    assert_eq!(bytes.len() as u64, PRESENT_BYTES);
}

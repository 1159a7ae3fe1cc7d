//! Shared test scenes: an icosphere bubble builder, synthetic film tables, the paper scene.
#![allow(dead_code)]

use std::collections::HashMap;

use render_scene::Vec3;
use render_scene::{
    BubbleFilm, BubbleMesh, Camera, Environment, FilmField, FilmTables, Frame, Ground, Irradiance,
    Light, Lut, Material, Object, ReflectionMode, RenderScene, RenderSettings, Sky,
};

/// Default settings at the given size, sample count and reflection mode.
pub fn settings(
    width: usize,
    height: usize,
    samples: u32,
    reflection: ReflectionMode,
) -> RenderSettings {
    RenderSettings {
        width,
        height,
        samples,
        reflection,
        ..RenderSettings::default()
    }
}

/// A unit icosphere subdivided `level` times, outward-wound.
pub fn icosphere(level: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid = HashMap::new();
        let mut next = Vec::with_capacity(f.len() * 4);
        let mut midpoint = |a: u32, b: u32, v: &mut Vec<Vec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                v.len() as u32 - 1
            })
        };
        for [a, b, c] in f {
            let ab = midpoint(a, b, &mut v);
            let bc = midpoint(b, c, &mut v);
            let ca = midpoint(c, a, &mut v);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    (v, f)
}

/// A spherical bubble with thickness given by `thickness(unit normal)`.
pub fn bubble(
    center: Vec3,
    radius_m: f32,
    level: u32,
    thickness: impl Fn(Vec3) -> f32,
) -> BubbleMesh {
    let (unit, triangles) = icosphere(level);
    BubbleMesh {
        positions: unit.iter().map(|n| center + *n * radius_m).collect(),
        normals: unit.clone(),
        thickness_nm: unit.iter().map(|n| thickness(*n)).collect(),
        triangles,
        film: None,
    }
}

/// `bubble` (a [`bubble`] mesh) with film field `field`, each vertex at its unit normal's
/// material direction.
pub fn with_film(mut bubble: BubbleMesh, field: FilmField) -> BubbleMesh {
    bubble.film = Some(BubbleFilm {
        field: std::sync::Arc::new(field),
        material_dirs: bubble.normals.clone(),
    });
    bubble
}

/// A film field of `face_size` texels a face with `(thickness nm, coverage)` at each
/// texel centre's direction.
pub fn film_field(face_size: usize, f: impl Fn(Vec3) -> (f32, f32)) -> FilmField {
    let (mut h, mut c) = (Vec::new(), Vec::new());
    for face in 0..6 {
        for y in 0..face_size {
            for x in 0..face_size {
                let (a, b) = f(FilmField::texel_direction(face_size, face, x, y));
                h.push(a);
                c.push(b);
            }
        }
    }
    FilmField::try_new(face_size, h, c).unwrap()
}

/// Draining film: thin on top, thick at the bottom (nm).
pub fn draining(n: Vec3) -> f32 {
    300.0 + 500.0 * (1.0 - n.y)
}

/// A smooth, colourful synthetic reflectivity (not physics; just distinct per channel).
pub fn synthetic_reflectivity() -> Lut {
    Lut::try_from_fn(64, 16, 1000.0, |d, c| {
        let base = 0.1 + 0.6 * (1.0 - c).powi(5);
        let phase = d / 1000.0 * std::f32::consts::TAU;
        [
            base * (1.0 + phase.sin()) * 0.5,
            base * (1.0 + (phase * 1.3).cos()) * 0.5,
            base * (1.0 + (phase * 1.7).sin()) * 0.5,
        ]
    })
    .unwrap()
}

/// Synthetic tables with R arbitrary in [0, 1] and T = 1 − R explicitly.
pub fn lossless_tables() -> FilmTables {
    let r = Lut::try_from_fn(32, 8, 1000.0, |d, c| {
        let x = d / 1000.0;
        [
            (x * 7.0 + c).fract(),
            (x * 3.0 + 0.5 * c).fract(),
            (1.0 - x) * c,
        ]
    })
    .unwrap();
    let t = Lut::try_new(
        r.width(),
        r.height(),
        r.thickness_max_nm(),
        r.texels().iter().map(|t| t.map(|v| 1.0 - v)).collect(),
    )
    .unwrap();
    FilmTables {
        reflectivity: r,
        transmittance: Some(t),
        lights: Vec::new(),
    }
}

/// The paper-like scene: two level-3 bubbles of radius 0.5 m, one above a checker ground,
/// a sky and one small light.
pub fn paper_scene() -> RenderScene {
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.2, 3.2),
        Vec3::new(0.0, 0.7, 0.0),
        Vec3::Y,
        45.0,
    );
    let mut scene = RenderScene::new(camera, Environment::Sky(Sky::default()));
    scene.ambient_rgb = [0.5, 0.55, 0.65];
    scene.ground = Some(Ground {
        height_m: 0.0,
        material: Material::checker([0.8; 3], [0.1; 3], 0.5),
    });
    scene.lights.push(Light {
        position: Vec3::new(-1.5, 3.0, 2.0),
        radius_m: 0.08,
        radiance: [400.0, 380.0, 350.0],
        light_lut: None,
    });
    scene
        .bubbles
        .push(bubble(Vec3::new(-0.55, 0.6, 0.0), 0.5, 3, draining));
    scene
        .bubbles
        .push(bubble(Vec3::new(0.6, 1.1, -0.6), 0.5, 3, draining));
    scene
}

/// Centre of the rim scene's bubble.
pub const RIM_BUBBLE_CENTER: Vec3 = Vec3::new(0.0, 0.6, 0.0);
/// Radius of the rim scene's bubble.
pub const RIM_BUBBLE_RADIUS_M: f32 = 0.5;

/// A bubble over a 5 cm checker ground beside a 4 cm checker ball, under the sky: at its
/// rim the reflected direction sweeps the fine checkers fast (crates/raster/tests/rim_aliasing.rs).
pub fn rim_scene() -> RenderScene {
    let camera = Camera::look_at(Vec3::new(0.0, 0.9, 1.6), RIM_BUBBLE_CENTER, Vec3::Y, 40.0);
    let sky = Environment::Sky(Sky::default());
    let mut scene = RenderScene::new(camera, sky.clone());
    scene.irradiance = Irradiance::from_environment(&sky);
    scene.ground = Some(Ground {
        height_m: 0.0,
        material: Material::checker([0.9; 3], [0.05; 3], 0.05),
    });
    scene.objects.push(Object::Sphere {
        center: Vec3::new(0.9, 0.4, -0.6),
        radius_m: 0.4,
        material: Material::checker([0.9, 0.2, 0.1], [0.1, 0.2, 0.9], 0.04),
    });
    scene
        .bubbles
        .push(bubble(RIM_BUBBLE_CENTER, RIM_BUBBLE_RADIUS_M, 5, |_| 500.0));
    scene
}

/// A perfect mirror film: R = 1, T = 0 at every thickness and angle.
pub fn mirror_tables() -> FilmTables {
    let constant = |v: f32| Lut::try_from_fn(4, 4, 1000.0, move |_, _| [v; 3]).unwrap();
    FilmTables {
        reflectivity: constant(1.0),
        transmittance: Some(constant(0.0)),
        lights: Vec::new(),
    }
}

/// Each `factor × factor` block of `hi` averaged into one pixel.
///
/// # Panics
/// Panics if `factor` does not divide both sides.
pub fn box_downsample(hi: &Frame, factor: usize) -> Frame {
    assert!(hi.width() % factor == 0 && hi.height() % factor == 0);
    let (w, h) = (hi.width() / factor, hi.height() / factor);
    let mut out = vec![[0.0f32; 3]; w * h];
    let weight = 1.0 / (factor * factor) as f32;
    for y in 0..hi.height() {
        for x in 0..hi.width() {
            let p = hi.pixel(x, y);
            let o = &mut out[(y / factor) * w + x / factor];
            for k in 0..3 {
                o[k] += p[k] * weight;
            }
        }
    }
    Frame::try_from_rgb(w, h, out).unwrap()
}

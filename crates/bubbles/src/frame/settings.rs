//! The scene's `[render]` table and the flags resolved into the renderer's settings,
//! each within the limits `limits` names.

use std::sync::Arc;

use raster::{ReflectionMode, RenderScene, RenderSettings, SAMPLE_COUNTS, SphereMap, ToneMap};

use super::{Options, Reflection, Tone};
use crate::error::CliError;
use crate::limits;
use crate::scene::Scene;
use crate::scene::schema::RenderSpec;
use crate::scene::values::{Exposure, Num, plain};

/// Size of the sphere map made from the environment in sphere-map mode.
const SPHERE_MAP_SIZE: usize = 512;

pub(super) fn settings(
    scene: &Scene,
    render_scene: &RenderScene,
    o: &Options,
) -> Result<RenderSettings, CliError> {
    let r = &scene.file.render;
    let reflection = match (o.reflection, r.reflection.as_deref()) {
        (Some(Reflection::Dynamic), _) | (None, None | Some("dynamic")) => {
            ReflectionMode::DynamicCubeMap {
                face_size: cube_map_size(o, r)?,
            }
        }
        (Some(Reflection::Static), _) | (None, Some("static")) => ReflectionMode::StaticEnvironment,
        (Some(Reflection::SphereMap), _) | (None, Some("sphere-map")) => {
            let map = SphereMap::from_environment(
                &render_scene.environment,
                SPHERE_MAP_SIZE,
                raster::Mat3::IDENTITY,
            )
            .map_err(|e| CliError::input(e.to_string()))?;
            ReflectionMode::SphereMap(Arc::new(map))
        }
        (None, Some(other)) => {
            return Err(CliError::input(format!(
                "{}: render.reflection {other:?}: use dynamic, static or sphere-map",
                scene.origin
            )));
        }
    };
    let tonemap = match (o.tonemap, r.tonemap.as_deref()) {
        (Some(Tone::Aces), _) | (None, None | Some("aces")) => ToneMap::AcesFitted,
        (Some(Tone::Reinhard), _) | (None, Some("reinhard")) => ToneMap::Reinhard,
        (Some(Tone::Clamp), _) | (None, Some("clamp")) => ToneMap::Clamp,
        (None, Some(other)) => {
            return Err(CliError::input(format!(
                "{}: render.tonemap {other:?}: use aces, reinhard or clamp",
                scene.origin
            )));
        }
    };
    let exposure = match o.exposure {
        Some(e) => Num::<Exposure>::try_new(e)
            .map_err(|m| CliError::input(format!("--exposure {}: {m}", plain(e))))?
            .get(),
        None => r.exposure.map_or(1.0, Num::get),
    };
    let (width, height) = o.size();
    for (flag, side) in [("--width", width), ("--height", height)] {
        check_side(flag, side)?;
    }
    let settings = RenderSettings {
        width,
        height,
        samples: samples(scene, o, r)?,
        reflection,
        exposure_ev: exposure.log2() as f32,
        tonemap,
        draw_lights: true,
    };
    settings
        .validate()
        .map_err(|e| CliError::input(e.to_string()))?;
    // One cube map per bubble, and one for the water's reflections.
    let cube_maps = scene.file.bubbles.len() + usize::from(scene.file.water.is_some());
    check_memory(cube_maps, &settings, width, height)?;
    Ok(settings)
}

/// The cube-map face size from `--cube-map-size`, else `[render] cube_map_size`, else 128.
fn cube_map_size(o: &Options, r: &RenderSpec) -> Result<usize, CliError> {
    match o.cube_map_size {
        Some(s) if (1..=limits::MAX_CUBE_MAP_SIZE).contains(&s) => Ok(s),
        Some(s) => Err(CliError::input(format!(
            "--cube-map-size {s} is outside 1..={} texels (see --help)",
            limits::MAX_CUBE_MAP_SIZE
        ))),
        None => Ok(r.cube_map_size.map_or(128, |s| s.get() as usize)),
    }
}

/// The film tables' size: each side from its flag, else `[render]`, else `lut`'s default;
/// refused when the tables (one per distinct light spectrum, plus the reflectivity) would
/// pass the memory limit.
pub(super) fn lut_size(scene: &Scene, o: &Options) -> Result<(usize, usize), CliError> {
    let r = &scene.file.render;
    let side = |flag: Option<usize>, name: &str, max: usize, key: Option<u32>, default: usize| {
        match flag {
            Some(v) if (2..=max).contains(&v) => Ok(v),
            Some(v) => Err(CliError::input(format!(
                "--{name} {v} is outside 2..={max} (see --help)"
            ))),
            None => Ok(key.map_or(default, |k| k as usize)),
        }
    };
    let width = side(
        o.lut_thickness_samples,
        "lut-thickness-samples",
        limits::MAX_LUT_THICKNESS_SAMPLES,
        r.lut_thickness_samples.map(|c| c.get()),
        lut::config::DEFAULT_WIDTH,
    )?;
    let height = side(
        o.lut_angle_samples,
        "lut-angle-samples",
        limits::MAX_LUT_ANGLE_SAMPLES,
        r.lut_angle_samples.map(|c| c.get()),
        lut::config::DEFAULT_HEIGHT,
    )?;
    let tables = 1 + scene.file.lights.len();
    let bytes = limits::lut_bytes(width, height, tables);
    if bytes > limits::MEMORY_BUDGET_BYTES {
        return Err(CliError::input(format!(
            "{tables} film tables of {width}x{height} (lut_thickness_samples x lut_angle_samples) need {:.2} GiB, above the {} GiB limit (see --help)",
            bytes as f64 / f64::from(1u32 << 30),
            limits::MEMORY_BUDGET_BYTES >> 30
        )));
    }
    Ok((width, height))
}

/// Samples per pixel from `--samples`, else `[render] samples`, else 4.
fn samples(scene: &Scene, o: &Options, r: &RenderSpec) -> Result<u32, CliError> {
    let (value, key) = match (o.samples, r.samples) {
        (Some(s), _) => (s, "--samples".to_string()),
        (None, Some(s)) => (s.get(), format!("{}: render.samples =", scene.origin)),
        (None, None) => return Ok(4),
    };
    if SAMPLE_COUNTS.contains(&value) {
        Ok(value)
    } else {
        Err(CliError::input(format!(
            "{key} {value} must be one of {SAMPLE_COUNTS:?}"
        )))
    }
}

/// Refuses an image side outside `1..=MAX_IMAGE_SIDE`, naming the flag.
fn check_side(flag: &str, side: usize) -> Result<(), CliError> {
    if (1..=limits::MAX_IMAGE_SIDE).contains(&side) {
        Ok(())
    } else {
        Err(CliError::input(format!(
            "{flag} {side} is outside 1..={} pixels (see --help)",
            limits::MAX_IMAGE_SIDE
        )))
    }
}

pub(super) fn check_memory(
    bubbles: usize,
    settings: &RenderSettings,
    width: usize,
    height: usize,
) -> Result<(), CliError> {
    let cube = match settings.reflection {
        ReflectionMode::DynamicCubeMap { face_size } => Some(face_size),
        _ => None,
    };
    crate::scene::check_memory(bubbles, cube, width, height, settings.samples)
}

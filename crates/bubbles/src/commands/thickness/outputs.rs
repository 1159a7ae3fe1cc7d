//! The map's files and the summary printed at the end.

use crate::commands::compare::heatmap;
use crate::error::CliError;
use film_inverse::{Photo, Status, ThicknessMap};
use std::path::{Path, PathBuf};

/// Where each output goes.
pub struct Paths {
    /// The EXR map.
    pub exr: PathBuf,
    /// The map with a colour bar.
    pub png: PathBuf,
    /// Photo and re-rendered colour side by side.
    pub rerender: PathBuf,
    /// The ΔE2000 residual with a colour bar.
    pub residual: PathBuf,
}

impl Paths {
    /// The outputs of `--out MAP.exr`; refuses another extension, a directory, or an
    /// output that would overwrite the photo.
    pub fn from_out(out: &Path, photo: &Path) -> Result<Paths, CliError> {
        let is_exr = out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if !is_exr || out.is_dir() {
            return Err(CliError::input(format!(
                "--out {}: the thickness map is an EXR file (MAP.exr); the PNG figures go beside it",
                out.display()
            )));
        }
        let stem = out.with_extension("");
        let beside = |suffix: &str| PathBuf::from(format!("{}{suffix}", stem.display()));
        let paths = Paths {
            exr: out.to_path_buf(),
            png: beside(".png"),
            rerender: beside(".rerender.png"),
            residual: beside(".residual.png"),
        };
        for p in [&paths.exr, &paths.png, &paths.rerender, &paths.residual] {
            crate::output::refuse_overwriting("--out", p, &[photo], "the thickness map's outputs")?;
        }
        Ok(paths)
    }
}

/// Writes the EXR and the three figures, two at a time.
pub fn write_all(paths: &Paths, photo: &Photo, map: &ThicknessMap) -> Result<(), CliError> {
    let fitted = |v: &[f32]| -> Vec<f64> {
        v.iter()
            .zip(&map.status)
            .map(|(v, s)| {
                if *s == Status::Fitted {
                    f64::from(*v)
                } else {
                    f64::NAN
                }
            })
            .collect()
    };
    let size = (map.width, map.height);
    let (a, b) = rayon::join(
        || {
            write_exr(&paths.exr, map)?;
            let top = (map.summary.thickness_max_nm / 100.0).ceil().max(1.0) * 100.0;
            heatmap::write(&paths.png, &fitted(&map.thickness_nm), size, top)
        },
        || {
            let top_de = map.summary.residual_max_de.ceil().max(1.0);
            heatmap::write(&paths.residual, &fitted(&map.residual_de), size, top_de)?;
            heatmap::save(&paths.rerender, &side_by_side(photo, map))
        },
    );
    a.and(b)
}

/// The photo (left) and the colour the map predicts (right).
fn side_by_side(photo: &Photo, map: &ThicknessMap) -> image::RgbImage {
    let (w, h) = (map.width, map.height);
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    image::RgbImage::from_fn(2 * w, h, |x, y| {
        let p = (y * w + (x % w)) as usize;
        let v = if x < w {
            photo.encoded()[p]
        } else {
            map.rerender[p]
        };
        image::Rgb(v.map(byte))
    })
}

/// RGBA f32 EXR: thickness, uncertainty, residual, fitted; through a temporary file.
fn write_exr(out: &Path, map: &ThicknessMap) -> Result<(), CliError> {
    let data: Vec<f32> = (0..map.status.len())
        .flat_map(|p| {
            let fitted = map.status[p] == Status::Fitted;
            [
                map.thickness_nm[p],
                map.uncertainty_nm[p],
                map.residual_de[p],
                f32::from(u8::from(fitted)),
            ]
        })
        .collect();
    let img = image::Rgba32FImage::from_raw(map.width, map.height, data)
        .ok_or_else(|| CliError::runtime("the map's buffer does not match its size"))?;
    let cannot =
        |e: &dyn std::fmt::Display| CliError::input(format!("cannot write {}: {e}", out.display()));
    let tmp = crate::commands::animate::sink::temporary_beside(out).map_err(CliError::input)?;
    image::DynamicImage::ImageRgba32F(img)
        .write_to(
            &mut std::io::BufWriter::new(tmp.as_file()),
            image::ImageFormat::OpenExr,
        )
        .map_err(|e| cannot(&e))?;
    tmp.persist(out).map(drop).map_err(|e| cannot(&e.error))
}

/// Prints what was found, as text or JSON.
pub fn print_summary(map: &ThicknessMap, paths: &Paths, json: bool) {
    let s = &map.summary;
    let c = &s.camera;
    if json {
        println!(
            "{{\"width\": {}, \"height\": {}, \"fitted\": {}, \"saturated\": {}, \"excluded\": {}, \"unexplained\": {}, \"ambiguous\": {}, \
\"thickness_min_nm\": {}, \"thickness_median_nm\": {}, \"thickness_max_nm\": {}, \"uncertainty_median_nm\": {}, \
\"residual_mean_de\": {}, \"residual_p95_de\": {}, \"residual_max_de\": {}, \"noise_encoded\": {}, \
\"calibration\": \"{}\", \"exposure\": {}, \"gains\": [{}, {}, {}], \"regions\": {}, \"regions_anchored\": {}, \"regions_shifted\": {}, \"regions_unplaced\": {}, \"regions_refolded\": {}, \"regions_lost\": {}}}",
            map.width,
            map.height,
            s.fitted,
            s.saturated,
            s.excluded,
            s.unexplained,
            s.ambiguous,
            s.thickness_min_nm,
            s.thickness_median_nm,
            s.thickness_max_nm,
            s.uncertainty_median_nm,
            s.residual_mean_de,
            s.residual_p95_de,
            s.residual_max_de,
            s.noise_encoded,
            s.calibration,
            c.exposure,
            c.gains[0],
            c.gains[1],
            c.gains[2],
            s.regions.regions,
            s.regions.anchored,
            s.regions.shifted,
            s.regions.unplaced,
            s.regions.refolded,
            s.regions.lost
        );
        return;
    }
    println!(
        "{}x{}: {} pixels fitted, {} saturated, {} excluded, {} unexplained, {} ambiguous",
        map.width, map.height, s.fitted, s.saturated, s.excluded, s.unexplained, s.ambiguous
    );
    println!(
        "thickness {:.1} to {:.1} nm (median {:.1}), median uncertainty {:.1} nm",
        s.thickness_min_nm, s.thickness_max_nm, s.thickness_median_nm, s.uncertainty_median_nm
    );
    println!(
        "residual ΔE2000: mean {:.2}, 95th percentile {:.2}, max {:.2}",
        s.residual_mean_de, s.residual_p95_de, s.residual_max_de
    );
    println!(
        "camera ({}): exposure {:.4}, gains {:.4}, {:.4}, {:.4}; {} region(s), {} anchored, {} moved by the order vote",
        s.calibration,
        c.exposure,
        c.gains[0],
        c.gains[1],
        c.gains[2],
        s.regions.regions,
        s.regions.anchored,
        s.regions.shifted
    );
    println!(
        "wrote {}, {}, {}, {}",
        paths.exr.display(),
        paths.png.display(),
        paths.rerender.display(),
        paths.residual.display()
    );
}

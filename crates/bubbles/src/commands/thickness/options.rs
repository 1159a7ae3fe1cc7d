//! The command line turned into the inverse's photo, model and settings.

use super::Args;
use crate::error::CliError;
use crate::input;
use film_inverse::{Anchor, Calibration, Camera, FilmModel, Photo, Rect, Settings, Viewing};
use std::path::Path;
use thinfilm::{Observer, RefractiveIndex};

/// A decoded photo, with the pixels its alpha channel leaves out.
pub struct Loaded {
    /// The photo.
    pub photo: Photo,
    /// `false` where the alpha channel is not fully opaque; `None` without alpha.
    pub opaque: Option<Vec<bool>>,
}

fn cannot(path: &Path, e: &dyn std::fmt::Display) -> CliError {
    CliError::input(format!("cannot read {}: {e}", path.display()))
}

/// Decodes an image within the input limits (checked from its header first).
fn decode(path: &Path, what: &str) -> Result<image::DynamicImage, CliError> {
    input::check_image_file(path, what)?;
    let mut reader = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| cannot(path, &e))?;
    reader.no_limits();
    reader.decode().map_err(|e| cannot(path, &e))
}

/// Reads the photo: 8- or 16-bit sRGB, or linear float (EXR).
pub fn load_photo(path: &Path) -> Result<Loaded, CliError> {
    use image::DynamicImage as D;
    let img = decode(path, "photo")?;
    let (w, h) = (img.width(), img.height());
    let bad = |e: film_inverse::InverseError| CliError::input(format!("{}: {e}", path.display()));
    let opaque = match &img {
        D::ImageLumaA8(_) | D::ImageRgba8(_) => {
            Some(img.to_rgba8().pixels().map(|p| p[3] == u8::MAX).collect())
        }
        D::ImageLumaA16(_) | D::ImageRgba16(_) => {
            Some(img.to_rgba16().pixels().map(|p| p[3] == u16::MAX).collect())
        }
        D::ImageRgba32F(b) => Some(b.pixels().map(|p| p[3] >= 1.0).collect()),
        _ => None,
    };
    let photo = match &img {
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
            Photo::try_from_linear(w, h, img.to_rgb32f().as_raw())
        }
        D::ImageLuma16(_) | D::ImageLumaA16(_) | D::ImageRgb16(_) | D::ImageRgba16(_) => {
            Photo::try_from_srgb16(w, h, img.to_rgb16().as_raw())
        }
        _ => Photo::try_from_srgb8(w, h, img.to_rgb8().as_raw()),
    }
    .map_err(bad)?;
    Ok(Loaded { photo, opaque })
}

/// The forward model from the film options.
pub fn model(args: &Args) -> Result<FilmModel, CliError> {
    let n_film = match args.n_film.trim() {
        "water" => RefractiveIndex::Water,
        s => {
            let n: f64 = s.parse().map_err(|_| {
                CliError::input(format!("--n-film `{s}` is neither a number nor `water`"))
            })?;
            RefractiveIndex::constant(n)
                .map_err(|e| CliError::input(format!("--n-film {s}: {e}")))?
        }
    };
    let observer = Observer::from_name(&args.observer).ok_or_else(|| {
        CliError::input(format!(
            "--observer `{}` is not a CIE observer; valid: 1931, 1964",
            args.observer
        ))
    })?;
    let spectrum = crate::commands::color::illuminant_spectrum(&args.illuminant)?;
    FilmModel::try_new(
        args.n_outside,
        n_film,
        &spectrum,
        observer,
        args.thickness_max_nm,
    )
    .map_err(|e| CliError::input(format!("film: {e}")))
}

/// Comma-separated numbers, exactly `N` of them.
fn numbers<const N: usize>(flag: &str, text: &str) -> Result<[f64; N], CliError> {
    let bad = || {
        CliError::input(format!(
            "--{flag} `{text}` is not {N} comma-separated numbers"
        ))
    };
    let parts: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    let values: [f64; N] = parts.try_into().map_err(|_| bad())?;
    if values.iter().all(|v| v.is_finite()) {
        Ok(values)
    } else {
        Err(bad())
    }
}

/// A region `X,Y,W,H` of whole, non-negative pixels.
fn rect(flag: &str, text: &str) -> Result<Rect, CliError> {
    let [x, y, w, h] = numbers::<4>(flag, text)?;
    let whole = |v: f64| v >= 0.0 && v.fract() == 0.0 && v <= f64::from(u32::MAX);
    if ![x, y, w, h].into_iter().all(whole) {
        return Err(CliError::input(format!(
            "--{flag} `{text}`: X,Y,W,H must be whole pixels ≥ 0"
        )));
    }
    Ok(Rect {
        x: x as u32,
        y: y as u32,
        w: w as u32,
        h: h as u32,
    })
}

/// `LEFT=NM`, the thickness a number.
fn with_thickness<'a>(flag: &str, text: &'a str) -> Result<(&'a str, f64), CliError> {
    let (left, nm) = text
        .split_once('=')
        .ok_or_else(|| CliError::input(format!("--{flag} `{text}` has no `=NM`")))?;
    let nm: f64 = nm.trim().parse().map_err(|_| {
        CliError::input(format!(
            "--{flag} `{text}`: `{nm}` is not a thickness in nm"
        ))
    })?;
    Ok((left, nm))
}

fn calibration(args: &Args) -> Result<Calibration, CliError> {
    if let Some(w) = &args.white {
        return Ok(Calibration::White(rect("white", w)?));
    }
    if let Some(r) = &args.reference {
        let (region, nm) = with_thickness("reference", r)?;
        return Ok(Calibration::Known(rect("reference", region)?, nm));
    }
    if let Some(exposure) = args.exposure {
        let gains = args
            .gains
            .as_deref()
            .map(|g| numbers::<3>("gains", g))
            .transpose()?
            .unwrap_or([1.0; 3]);
        return Ok(Calibration::Given(Camera { exposure, gains }));
    }
    Ok(Calibration::Auto)
}

fn anchors(args: &Args) -> Result<Vec<Anchor>, CliError> {
    args.anchor
        .iter()
        .map(|a| {
            let (xy, nm) = with_thickness("anchor", a)?;
            let [x, y] = numbers::<2>("anchor", xy)?;
            if !(x >= 0.0
                && y >= 0.0
                && x.fract() == 0.0
                && y.fract() == 0.0
                && x.max(y) <= f64::from(u32::MAX))
            {
                return Err(CliError::input(format!(
                    "--anchor `{a}`: X,Y must be whole pixels ≥ 0"
                )));
            }
            Ok(Anchor {
                x: x as u32,
                y: y as u32,
                thickness_nm: nm,
            })
        })
        .collect()
}

fn viewing(args: &Args, photo: &Photo) -> Result<Viewing, CliError> {
    if let Some(s) = &args.sphere {
        let [cx, cy, r] = numbers::<3>("sphere", s)?;
        return Ok(Viewing::Sphere {
            centre_px: [cx, cy],
            radius_px: r,
        });
    }
    if let Some(path) = &args.angle_map {
        let img = decode(path, "angle map")?;
        if (img.width(), img.height()) != (photo.width(), photo.height()) {
            return Err(CliError::input(format!(
                "angle map {} is {}x{} but the photo is {}x{}",
                path.display(),
                img.width(),
                img.height(),
                photo.width(),
                photo.height()
            )));
        }
        let deg = img.to_rgb32f();
        let mut cos = Vec::with_capacity(photo.len());
        for (i, p) in deg.pixels().enumerate() {
            let a = f64::from(p[0]);
            if !(0.0..=90.0).contains(&a) {
                return Err(CliError::input(format!(
                    "angle map {} has {a} degrees at ({}, {}): angles lie in [0, 90]",
                    path.display(),
                    i % photo.width() as usize,
                    i / photo.width() as usize
                )));
            }
            cos.push(a.to_radians().cos() as f32);
        }
        return Ok(Viewing::CosMap(cos));
    }
    Ok(Viewing::Angle(args.angle_deg.unwrap_or(0.0)))
}

fn mask(args: &Args, photo: &Loaded) -> Result<Option<Vec<bool>>, CliError> {
    let Some(path) = &args.mask else {
        return Ok(photo.opaque.clone());
    };
    let img = decode(path, "mask")?;
    let p = &photo.photo;
    if (img.width(), img.height()) != (p.width(), p.height()) {
        return Err(CliError::input(format!(
            "mask {} is {}x{} but the photo is {}x{}",
            path.display(),
            img.width(),
            img.height(),
            p.width(),
            p.height()
        )));
    }
    let luma = img.to_luma8();
    let used = luma.pixels().map(|v| v[0] > 0);
    Ok(Some(match &photo.opaque {
        Some(o) => used.zip(o).map(|(a, b)| a && *b).collect(),
        None => used.collect(),
    }))
}

/// The inverse's settings from the command line.
pub fn settings(args: &Args, photo: &Loaded) -> Result<Settings, CliError> {
    Ok(Settings {
        viewing: viewing(args, &photo.photo)?,
        calibration: calibration(args)?,
        anchors: anchors(args)?,
        mask: mask(args, photo)?,
        max_residual_de: args.max_residual_de,
        smoothness_nm: args.smoothness_nm,
    })
}

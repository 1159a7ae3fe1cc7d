//! Reading a saved [`LutSet`] back: EXR bit-exactly, else the 16-bit PNG twin; every
//! file is checked against `lut.json` (version, names, size, checksum) before use.

use std::fmt;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use image::codecs::openexr::OpenExrDecoder;
use image::codecs::png::PngDecoder;
use image::{ColorType, DynamicImage, ImageDecoder};

use crate::checksum::{codes_fnv1a64, texels_fnv1a64, to_hex};
use crate::meta::{Axes, FORMAT_NAME, FORMAT_VERSION, LutDocument, Png16Entry, TextureEntry};
use crate::save::DESCRIPTION_FILE;
use crate::set::{is_valid_light_name, light_stem};
use crate::{Format, Lut, LutError, LutSet, MAX_SIDE};

/// Why a saved [`LutSet`] could not be loaded.
#[derive(Debug)]
pub enum LoadError {
    /// A file could not be opened or read.
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// `lut.json` is not valid JSON or lacks a field.
    Json {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// `lut.json` was written by another format version.
    Version {
        /// The file.
        path: PathBuf,
        /// The version found (as written).
        found: String,
    },
    /// `lut.json` parses but contradicts itself or names an unexpected file.
    Inconsistent {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A texture file is corrupt, truncated, of the wrong size or pixel type.
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A texture's values differ from the checksum recorded in `lut.json`.
    Checksum {
        /// The file.
        path: PathBuf,
        /// The recorded checksum.
        expected: String,
        /// The checksum of the decoded values.
        found: String,
    },
    /// The decoded values break a [`Lut`] guarantee (e.g. a NaN texel).
    Table {
        /// The file.
        path: PathBuf,
        /// The broken guarantee.
        source: LutError,
    },
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, source } => write!(f, "cannot read {}: {source}", path.display()),
            Self::Json { path, message } => write!(f, "{}: {message}", path.display()),
            Self::Version { path, found } => write!(
                f,
                "{}: format_version {found} is not supported (this build reads version {FORMAT_VERSION}); re-bake the tables",
                path.display()
            ),
            Self::Inconsistent { path, message } => write!(f, "{}: {message}", path.display()),
            Self::Corrupt { path, message } => {
                write!(f, "{} is corrupt or truncated: {message}", path.display())
            }
            Self::Checksum {
                path,
                expected,
                found,
            } => write!(
                f,
                "{} is corrupt: its values have checksum {found}, lut.json records {expected}",
                path.display()
            ),
            Self::Table { path, source } => write!(f, "{}: {source}", path.display()),
        }
    }
}

impl std::error::Error for LoadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            Self::Table { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl LutSet {
    /// Loads the set that [`LutSet::save`] wrote into `dir`.
    ///
    /// Each table is read from its EXR file when one was saved (bit-exact), else from its
    /// 16-bit PNG (exact to the 16-bit quantisation stated in `lut.json`).
    pub fn load(dir: &Path) -> Result<Self, LoadError> {
        let json_path = dir.join(DESCRIPTION_FILE);
        let document = read_document(&json_path)?;
        check_document(&document, &json_path)?;
        let mut tables = Vec::with_capacity(document.textures.len());
        for entry in &document.textures {
            tables.push(load_texture(dir, entry, &document, &json_path)?);
        }
        let mut tables = tables.into_iter();
        let (reflectivity, transmittance) = match (tables.next(), tables.next()) {
            (Some(r), Some(t)) => (r, t),
            _ => unreachable!("check_document requires both tables"),
        };
        let lights = document.textures[2..]
            .iter()
            .zip(tables)
            .map(|(entry, lut)| (entry.light.clone().unwrap_or_default(), lut))
            .collect();
        Ok(Self {
            reflectivity,
            transmittance,
            lights,
            meta: document.meta,
        })
    }
}

fn read_document(path: &Path) -> Result<LutDocument, LoadError> {
    let text = std::fs::read_to_string(path).map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
    })?;
    let json_error = |message: String| LoadError::Json {
        path: path.to_owned(),
        message,
    };
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| json_error(e.to_string()))?;
    if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT_NAME) {
        return Err(json_error(format!(
            "not a bubbles LUT description (\"format\" must be {FORMAT_NAME:?})"
        )));
    }
    match value.get("format_version") {
        Some(v) if v.as_u64() == Some(u64::from(FORMAT_VERSION)) => {}
        Some(v) => {
            return Err(LoadError::Version {
                path: path.to_owned(),
                found: v.to_string(),
            });
        }
        None => return Err(json_error("missing field `format_version`".into())),
    }
    serde_json::from_value(value).map_err(|e| json_error(e.to_string()))
}

fn check_document(doc: &LutDocument, path: &Path) -> Result<(), LoadError> {
    let fail = |message: String| {
        Err(LoadError::Inconsistent {
            path: path.to_owned(),
            message,
        })
    };
    if !(2..=MAX_SIDE).contains(&doc.width) || !(2..=MAX_SIDE).contains(&doc.height) {
        return fail(format!(
            "resolution {}x{} is invalid",
            doc.width, doc.height
        ));
    }
    if doc.axes != Axes::new(doc.width, doc.height, doc.meta.thickness_max_nm) {
        return fail("axes do not match width, height and thickness_max_nm".into());
    }
    let names: Vec<&str> = doc.textures.iter().map(|t| t.name.as_str()).collect();
    if names.len() < 2 || names[0] != "reflectivity" || names[1] != "transmittance" {
        return fail("textures must start with reflectivity, transmittance".into());
    }
    for (k, entry) in doc.textures.iter().enumerate().skip(2) {
        let Some(light) = entry.light.as_deref().filter(|l| is_valid_light_name(l)) else {
            return fail(format!("texture {:?} has no valid light name", entry.name));
        };
        if entry.name != light_stem(light) || names[..k].contains(&entry.name.as_str()) {
            return fail(format!("texture {:?} is misnamed or repeated", entry.name));
        }
    }
    for entry in &doc.textures {
        check_file_names(entry).or_else(fail)?;
    }
    Ok(())
}

/// File names must be the ones [`Format::file_name`] gives, so `lut.json` cannot point
/// outside its directory.
fn check_file_names(entry: &TextureEntry) -> Result<(), String> {
    let expect = |format: Format, got: Option<&String>| match got {
        Some(name) if *name != format.file_name(&entry.name) => Err(format!(
            "texture {:?} names file {name:?}, expected {:?}",
            entry.name,
            format.file_name(&entry.name)
        )),
        _ => Ok(()),
    };
    expect(Format::Exr, entry.exr.as_ref())?;
    expect(Format::Png16, entry.png16.as_ref().map(|p| &p.file))?;
    expect(Format::Png8, entry.png8_preview.as_ref())?;
    if entry.exr.is_none() && entry.png16.is_none() {
        return Err(format!(
            "texture {:?} has neither an EXR nor a 16-bit PNG file to load",
            entry.name
        ));
    }
    Ok(())
}

fn load_texture(
    dir: &Path,
    entry: &TextureEntry,
    doc: &LutDocument,
    json_path: &Path,
) -> Result<Lut, LoadError> {
    if let Some(file) = &entry.exr {
        let path = dir.join(file);
        let texels = read_exr(&path, doc.width, doc.height)?;
        let found = to_hex(texels_fnv1a64(&texels));
        if found != entry.texels_fnv1a64 {
            return Err(LoadError::Checksum {
                path,
                expected: entry.texels_fnv1a64.clone(),
                found,
            });
        }
        return make_lut(doc, texels, path);
    }
    let png = entry
        .png16
        .as_ref()
        .ok_or_else(|| LoadError::Inconsistent {
            path: json_path.to_owned(),
            message: format!("texture {:?} has no file to load", entry.name),
        })?;
    let path = dir.join(&png.file);
    let texels = read_png16(&path, png, doc.width, doc.height)?;
    make_lut(doc, texels, path)
}

fn make_lut(doc: &LutDocument, texels: Vec<[f32; 3]>, path: PathBuf) -> Result<Lut, LoadError> {
    Lut::try_new(doc.width, doc.height, doc.meta.thickness_max_nm, texels)
        .map_err(|source| LoadError::Table { path, source })
}

fn open(path: &Path) -> Result<BufReader<File>, LoadError> {
    File::open(path)
        .map(BufReader::new)
        .map_err(|source| LoadError::Io {
            path: path.to_owned(),
            source,
        })
}

fn corrupt(path: &Path, message: impl fmt::Display) -> LoadError {
    LoadError::Corrupt {
        path: path.to_owned(),
        message: message.to_string(),
    }
}

/// Decodes `decoder` after checking its size and pixel type, before any large allocation.
fn decode(
    path: &Path,
    decoder: impl ImageDecoder,
    width: usize,
    height: usize,
    color: ColorType,
) -> Result<DynamicImage, LoadError> {
    let (w, h) = decoder.dimensions();
    if (w as usize, h as usize) != (width, height) {
        return Err(corrupt(
            path,
            format_args!("image is {w}x{h}, lut.json says {width}x{height}"),
        ));
    }
    if decoder.color_type() != color {
        return Err(corrupt(
            path,
            format_args!("pixels are {:?}, expected {color:?}", decoder.color_type()),
        ));
    }
    DynamicImage::from_decoder(decoder).map_err(|e| corrupt(path, e))
}

fn read_exr(path: &Path, width: usize, height: usize) -> Result<Vec<[f32; 3]>, LoadError> {
    let decoder = OpenExrDecoder::with_alpha_preference(open(path)?, Some(false))
        .map_err(|e| corrupt(path, e))?;
    match decode(path, decoder, width, height, ColorType::Rgb32F)? {
        DynamicImage::ImageRgb32F(image) => Ok(image
            .as_raw()
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect()),
        other => Err(corrupt(
            path,
            format_args!("decoded as {:?}", other.color()),
        )),
    }
}

fn read_png16(
    path: &Path,
    entry: &Png16Entry,
    width: usize,
    height: usize,
) -> Result<Vec<[f32; 3]>, LoadError> {
    let decoder = PngDecoder::new(open(path)?).map_err(|e| corrupt(path, e))?;
    let DynamicImage::ImageRgb16(image) = decode(path, decoder, width, height, ColorType::Rgb16)?
    else {
        return Err(corrupt(path, "not 16-bit RGB"));
    };
    let found = to_hex(codes_fnv1a64(image.as_raw()));
    if found != entry.codes_fnv1a64 {
        return Err(LoadError::Checksum {
            path: path.to_owned(),
            expected: entry.codes_fnv1a64.clone(),
            found,
        });
    }
    let value = |code: u16| entry.offset + entry.scale * (f32::from(code) / 65535.0);
    Ok(image
        .as_raw()
        .chunks_exact(3)
        .map(|c| [value(c[0]), value(c[1]), value(c[2])])
        .collect())
}

//! Writing a [`LutSet`] to a directory: each file goes to a temporary file in the same
//! directory and is renamed into place, `lut.json` last, so a reader never sees a
//! half-written file and a failed save leaves no new file behind.

use std::fmt;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use image::{ImageBuffer, ImageFormat, Rgb};
use tempfile::NamedTempFile;

use crate::checksum::{codes_fnv1a64, texels_fnv1a64, to_hex};
use crate::meta::{Axes, FORMAT_NAME, FORMAT_VERSION, LutDocument, Png16Entry, TextureEntry};
use crate::set::{is_valid_light_name, light_stem};
use crate::{Format, Lut, LutSet};

/// Name of the description file in a saved set.
pub const DESCRIPTION_FILE: &str = "lut.json";

/// Why a [`LutSet`] could not be saved.
#[derive(Debug)]
pub enum SaveError {
    /// No format was asked for.
    NoFormats,
    /// A table's resolution or thickness range differs from the reflectivity table's
    /// (or `meta.thickness_max_nm` does).
    Inconsistent {
        /// File stem of the odd table, or `meta`.
        table: String,
    },
    /// A light name is empty, too long, or holds characters unsafe in a file name.
    BadLightName(String),
    /// Two lights share a name.
    DuplicateLight(String),
    /// The directory could not be created or written to.
    Io {
        /// The file or directory involved.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// An image encoder failed.
    Encode {
        /// The file being written.
        path: PathBuf,
        /// The encoder's message.
        message: String,
    },
}

impl fmt::Display for SaveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoFormats => f.write_str("no output format given"),
            Self::Inconsistent { table } => write!(
                f,
                "table {table:?} differs from the reflectivity table in resolution or thickness range"
            ),
            Self::BadLightName(name) => write!(
                f,
                "light name {name:?} is invalid: use 1 to 64 ASCII letters, digits, '_' or '-'"
            ),
            Self::DuplicateLight(name) => write!(f, "light {name:?} appears twice"),
            Self::Io { path, source } => {
                write!(f, "cannot write {}: {source}", path.display())
            }
            Self::Encode { path, message } => {
                write!(f, "cannot encode {}: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for SaveError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl LutSet {
    /// Writes every table in each of `formats`, plus `lut.json`, into `dir` (created if
    /// missing), returning the paths written in order. Existing files of the same names are
    /// replaced.
    ///
    /// Nothing is renamed into place until every file has been encoded, and `lut.json`
    /// is renamed last; on failure the temporary files are removed.
    pub fn save(&self, dir: &Path, formats: &[Format]) -> Result<Vec<PathBuf>, SaveError> {
        self.check_saveable(formats)?;
        std::fs::create_dir_all(dir).map_err(|source| SaveError::Io {
            path: dir.to_owned(),
            source,
        })?;
        let mut staged = Vec::new();
        let mut entries = Vec::new();
        for (stem, lut) in self.named_tables() {
            entries.push(self.stage_table(dir, &stem, lut, formats, &mut staged)?);
        }
        let document = LutDocument {
            format: FORMAT_NAME.into(),
            format_version: FORMAT_VERSION,
            width: self.reflectivity.width(),
            height: self.reflectivity.height(),
            axes: Axes::new(
                self.reflectivity.width(),
                self.reflectivity.height(),
                self.reflectivity.thickness_max_nm(),
            ),
            meta: self.meta.clone(),
            textures: entries,
        };
        let json_path = dir.join(DESCRIPTION_FILE);
        let json = serde_json::to_value(&document)
            .map(|v| crate::json_layout::to_pretty_string(&v))
            .map_err(|e| SaveError::Encode {
                path: json_path.clone(),
                message: e.to_string(),
            })?;
        staged.push(stage(dir, &json_path, |w| {
            w.write_all(json.as_bytes()).map_err(Into::into)
        })?);
        commit(staged)
    }

    fn check_saveable(&self, formats: &[Format]) -> Result<(), SaveError> {
        if formats.is_empty() {
            return Err(SaveError::NoFormats);
        }
        let reference = &self.reflectivity;
        if self.meta.thickness_max_nm != reference.thickness_max_nm() {
            return Err(SaveError::Inconsistent {
                table: "meta".into(),
            });
        }
        for (stem, lut) in self.named_tables() {
            if lut.width() != reference.width()
                || lut.height() != reference.height()
                || lut.thickness_max_nm() != reference.thickness_max_nm()
            {
                return Err(SaveError::Inconsistent { table: stem });
            }
        }
        for (k, (name, _)) in self.lights.iter().enumerate() {
            if !is_valid_light_name(name) {
                return Err(SaveError::BadLightName(name.clone()));
            }
            if self.lights[..k].iter().any(|(other, _)| other == name) {
                return Err(SaveError::DuplicateLight(name.clone()));
            }
        }
        Ok(())
    }

    fn stage_table(
        &self,
        dir: &Path,
        stem: &str,
        lut: &Lut,
        formats: &[Format],
        staged: &mut Vec<(NamedTempFile, PathBuf)>,
    ) -> Result<TextureEntry, SaveError> {
        let light = self
            .lights
            .iter()
            .find(|(name, _)| light_stem(name) == stem)
            .map(|(name, _)| name.clone());
        let mut entry = TextureEntry {
            name: stem.to_owned(),
            quantity: quantity_of(stem, light.as_deref()),
            light,
            texels_fnv1a64: to_hex(texels_fnv1a64(lut.texels())),
            exr: None,
            png16: None,
            png8_preview: None,
        };
        for &format in formats {
            let file = format.file_name(stem);
            let path = dir.join(&file);
            match format {
                Format::Exr => {
                    let image = exr_image(lut);
                    staged.push(stage(dir, &path, |w| {
                        write_image(&image, w, ImageFormat::OpenExr)
                    })?);
                    entry.exr = Some(file);
                }
                Format::Png16 => {
                    let (image, offset, scale) =
                        png16_image(lut).ok_or_else(|| SaveError::Encode {
                            path: path.clone(),
                            message: "values span too wide a range for 16-bit codes".into(),
                        })?;
                    staged.push(stage(dir, &path, |w| {
                        write_image(&image, w, ImageFormat::Png)
                    })?);
                    entry.png16 = Some(Png16Entry {
                        file,
                        offset,
                        scale,
                        codes_fnv1a64: to_hex(codes_fnv1a64(image.as_raw())),
                    });
                }
                Format::Png8 => {
                    let image = png8_preview_image(lut);
                    staged.push(stage(dir, &path, |w| {
                        write_image(&image, w, ImageFormat::Png)
                    })?);
                    entry.png8_preview = Some(file);
                }
            }
        }
        Ok(entry)
    }
}

/// What the texels of table `stem` mean, for `lut.json`.
fn quantity_of(stem: &str, light: Option<&str>) -> String {
    match (stem, light) {
        ("reflectivity", _) => "reflectivity R_rgb: linear sRGB of the film's reflection of the reference illuminant, divided channel by channel by that of a perfect reflector".into(),
        ("transmittance", _) => "transmittance T_rgb: linear sRGB of the film's transmission of the reference illuminant, divided channel by channel by that of a perfect transmitter".into(),
        (_, Some(name)) => format!("light-source texture: linear sRGB of the light {name:?} reflected by the film, scaled so that the light itself has Y = 1"),
        _ => "unknown".into(),
    }
}

type WriteResult = Result<(), Box<dyn std::error::Error + Send + Sync>>;

/// Writes `fill` into a new temporary file beside `path`, returning it unrenamed.
fn stage(
    dir: &Path,
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<&mut std::fs::File>) -> WriteResult,
) -> Result<(NamedTempFile, PathBuf), SaveError> {
    let io_error = |source| SaveError::Io {
        path: path.to_owned(),
        source,
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".lut-").suffix(".tmp");
    // Temporaries are private (0600) by default; the tables are ordinary files, so let
    // the umask decide as it would for `File::create`.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut temp = builder.tempfile_in(dir).map_err(io_error)?;
    let mut writer = BufWriter::new(temp.as_file_mut());
    fill(&mut writer).map_err(|e| match e.downcast::<std::io::Error>() {
        Ok(io) => io_error(*io),
        Err(other) => SaveError::Encode {
            path: path.to_owned(),
            message: other.to_string(),
        },
    })?;
    writer
        .into_inner()
        .map_err(|e| io_error(e.into_error()))?
        .sync_all()
        .map_err(io_error)?;
    Ok((temp, path.to_owned()))
}

/// Renames every staged file into place, in order; if one rename fails, the files this
/// save already renamed are removed again, so the directory holds no part of the new set.
fn commit(staged: Vec<(NamedTempFile, PathBuf)>) -> Result<Vec<PathBuf>, SaveError> {
    let mut written = Vec::with_capacity(staged.len());
    for (temp, path) in staged {
        // Dropping the `PersistError` (and the rest of `staged`) deletes the temporaries.
        if let Err(e) = temp.persist(&path) {
            for done in &written {
                let _ = std::fs::remove_file(done);
            }
            return Err(SaveError::Io {
                path,
                source: e.error,
            });
        }
        written.push(path);
    }
    Ok(written)
}

fn write_image<P, C>(
    image: &ImageBuffer<P, C>,
    writer: &mut BufWriter<&mut std::fs::File>,
    format: ImageFormat,
) -> WriteResult
where
    P: image::Pixel + image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    image.write_to(writer, format).map_err(|e| match e {
        image::ImageError::IoError(io) => io.into(),
        other => other.to_string().into(),
    })
}

/// The table as an EXR image, borrowing its texels (no copy: a 16384 × 4096 table is
/// 805 MB).
fn exr_image(lut: &Lut) -> ImageBuffer<Rgb<f32>, &[f32]> {
    ImageBuffer::from_raw(
        lut.width() as u32,
        lut.height() as u32,
        lut.texels().as_flattened(),
    )
    .expect("a Lut holds width × height texels")
}

/// A 16-bit RGB image.
type Png16Image = ImageBuffer<Rgb<u16>, Vec<u16>>;

/// The 16-bit codes of `lut` and their decoding `value = offset + scale · code / 65535`.
///
/// The range always covers 0..1, so tables inside it decode as plain `code / 65535`;
/// values outside (out-of-gamut negatives, bright lights) widen it. `None` if the range
/// overflows f32.
pub(crate) fn png16_image(lut: &Lut) -> Option<(Png16Image, f32, f32)> {
    let (lo, hi) = lut
        .texels()
        .iter()
        .flatten()
        .fold((0.0f32, 1.0f32), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let scale = hi - lo;
    if !scale.is_finite() {
        return None;
    }
    let codes = lut
        .texels()
        .iter()
        .flatten()
        .map(|&v| ((v - lo) / scale * 65535.0).round().clamp(0.0, 65535.0) as u16)
        .collect();
    let image = ImageBuffer::from_raw(lut.width() as u32, lut.height() as u32, codes)
        .expect("a Lut holds width × height texels");
    Some((image, lo, scale))
}

fn png8_preview_image(lut: &Lut) -> ImageBuffer<Rgb<u8>, Vec<u8>> {
    let bytes = lut
        .texels()
        .iter()
        .flat_map(|rgb| thinfilm::colorspace::srgb8_from_linear(rgb.map(f64::from)))
        .collect();
    ImageBuffer::from_raw(lut.width() as u32, lut.height() as u32, bytes)
        .expect("a Lut holds width × height texels")
}

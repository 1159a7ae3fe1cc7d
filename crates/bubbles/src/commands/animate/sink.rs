//! Where finished frames go: numbered PNG files in a directory, one APNG, or one GIF.

use super::apng::ApngSink;
use super::gif::{DeltaE, GifSink};
use std::path::{Path, PathBuf};

/// One tone-mapped frame, 8-bit sRGB, interleaved RGB, row-major.
pub struct Rgb8 {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// `3 × width × height` bytes.
    pub bytes: Vec<u8>,
}

/// The output named by `--out`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Output {
    /// `DIR/frame_00000.png`, … (one file per frame).
    Dir(PathBuf),
    /// One animated PNG (`.apng` or `.png`).
    Apng(PathBuf),
    /// One GIF preview.
    Gif(PathBuf),
}

impl Output {
    /// Classifies `--out`: `.apng`/`.png` and `.gif` are files, a path without an
    /// extension (or an existing directory) is a frame directory.
    ///
    /// # Errors
    /// Any other extension, naming it, or a file extension on an existing directory.
    pub fn from_path(path: &Path) -> Result<Self, String> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let file = matches!(ext.as_deref(), Some("apng" | "png" | "gif"));
        if path.is_dir() && file {
            return Err(format!(
                "--out {}: is a directory, but .{} names one animation file",
                path.display(),
                ext.unwrap_or_default()
            ));
        }
        if path.is_dir() {
            return Ok(Self::Dir(path.to_path_buf()));
        }
        match ext.as_deref() {
            None => Ok(Self::Dir(path.to_path_buf())),
            Some("apng" | "png") => Ok(Self::Apng(path.to_path_buf())),
            Some("gif") => Ok(Self::Gif(path.to_path_buf())),
            Some(other) => Err(format!(
                "--out {}: .{other} is not an output: give a directory (frames), \
                 PATH.apng / PATH.png (animated PNG) or PATH.gif",
                path.display()
            )),
        }
    }
}

/// The file of frame `k` in a frame directory.
pub fn frame_path(dir: &Path, k: u64) -> PathBuf {
    dir.join(format!("frame_{k:05}.png"))
}

/// A private temporary file in `path`'s directory (so the final rename stays on one
/// file system), readable like any other file once renamed.
pub fn temporary_beside(path: &Path) -> Result<tempfile::NamedTempFile, String> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".bubbles-").suffix(".tmp");
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    builder
        .tempfile_in(dir)
        .map_err(|e| format!("cannot create a file in {}: {e}", dir.display()))
}

/// An open output.
pub enum Sink {
    /// Frames go to `frame_path(dir, k)` as they finish.
    Dir(PathBuf),
    /// Frames go into one APNG, renamed into place at the end.
    Apng(ApngSink),
    /// Frames go into one GIF, renamed into place at the end.
    Gif(GifSink),
}

impl Sink {
    /// Adds frame `k`.
    pub fn push(&mut self, k: u64, frame: &Rgb8) -> Result<(), String> {
        match self {
            Sink::Dir(dir) => {
                let path = frame_path(dir, k);
                let cannot = |e: String| format!("cannot write {}: {e}", path.display());
                let sum = write_png(&path, frame).map_err(cannot)?;
                record_checksum(dir, k, sum)
            }
            Sink::Apng(apng) => apng
                .push(frame)
                .map_err(|e| format!("cannot write {}: {e}", apng.path().display())),
            Sink::Gif(gif) => gif
                .push(frame)
                .map_err(|e| format!("cannot write {}: {e}", gif.path().display())),
        }
    }

    /// Completes the output; a GIF returns its palette error.
    pub fn finish(self) -> Result<Option<DeltaE>, String> {
        match self {
            Sink::Dir(_) => Ok(None),
            Sink::Apng(apng) => apng.finish().map(|()| None),
            Sink::Gif(gif) => gif.finish().map(Some),
        }
    }
}

/// The checksum the manifest records per frame: FNV-1a (64-bit) of the file's bytes.
pub fn checksum(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The manifest line recording frame `k`'s checksum.
pub fn checksum_line(k: u64, sum: u64) -> String {
    format!("frame {k:05} fnv1a64 {sum:016x}\n")
}

/// Appends frame `k`'s checksum to the directory's manifest (one short line, appended in
/// one write, so runs of several `--frames` ranges can share the directory).
fn record_checksum(dir: &Path, k: u64, sum: u64) -> Result<(), String> {
    use std::io::Write as _;
    let path = dir.join(super::MANIFEST);
    std::fs::OpenOptions::new()
        .append(true)
        .open(&path)
        .and_then(|mut f| f.write_all(checksum_line(k, sum).as_bytes()))
        .map_err(|e| format!("cannot record frame {k} in {}: {e}", path.display()))
}

/// Writes one still PNG through a temporary file, so a killed run leaves no partial
/// frame; returns the file's checksum.
fn write_png(path: &Path, frame: &Rgb8) -> Result<u64, String> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, frame.width as u32, frame.height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer
        .write_image_data(&frame.bytes)
        .map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    let tmp = temporary_beside(path)?;
    std::fs::write(tmp.path(), &bytes).map_err(|e| e.to_string())?;
    tmp.as_file().sync_all().map_err(|e| e.to_string())?;
    tmp.persist(path).map_err(|e| e.error.to_string())?;
    Ok(checksum(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_paths_are_classified_by_extension() {
        let p = |s: &str| Output::from_path(Path::new(s));
        assert_eq!(p("a/b.apng"), Ok(Output::Apng("a/b.apng".into())));
        assert_eq!(p("b.PNG"), Ok(Output::Apng("b.PNG".into())));
        assert_eq!(p("c.gif"), Ok(Output::Gif("c.gif".into())));
        assert_eq!(
            p("no/such/frames"),
            Ok(Output::Dir("no/such/frames".into()))
        );
        let err = p("movie.mp4").unwrap_err();
        assert!(err.contains(".mp4") && err.contains("movie.mp4"), "{err}");
    }
}

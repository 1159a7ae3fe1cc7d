//! One animated PNG (APNG), streamed frame by frame into a temporary file that is renamed
//! over the target only when the last frame is in.

use super::sink::{Rgb8, temporary_beside};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// An APNG being written.
pub struct ApngSink {
    path: PathBuf,
    tmp: tempfile::NamedTempFile,
    writer: Option<png::Writer<BufWriter<File>>>,
}

impl ApngSink {
    /// The file this sink writes (renamed into place at the end).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Starts `path` with room for `frames` frames of `width` × `height` at `fps`.
    pub fn create(
        path: &Path,
        width: u32,
        height: u32,
        frames: u32,
        fps: f64,
    ) -> Result<Self, String> {
        let tmp = temporary_beside(path)?;
        let file = tmp.reopen().map_err(|e| e.to_string())?;
        let mut encoder = png::Encoder::new(BufWriter::new(file), width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let (num, den) = frame_delay(fps);
        let text = |e: png::EncodingError| e.to_string();
        encoder.set_animated(frames, 0).map_err(text)?;
        encoder.set_frame_delay(num, den).map_err(text)?;
        let writer = encoder.write_header().map_err(text)?;
        Ok(Self {
            path: path.to_path_buf(),
            tmp,
            writer: Some(writer),
        })
    }

    /// Appends one frame.
    pub fn push(&mut self, frame: &Rgb8) -> Result<(), String> {
        let writer = self.writer.as_mut().ok_or("the APNG is already finished")?;
        writer
            .write_image_data(&frame.bytes)
            .map_err(|e| e.to_string())
    }

    /// Writes the trailer and renames the file into place.
    pub fn finish(mut self) -> Result<(), String> {
        let writer = self.writer.take().ok_or("the APNG is already finished")?;
        writer.finish().map_err(|e| e.to_string())?;
        self.tmp.as_file().sync_all().map_err(|e| e.to_string())?;
        self.tmp
            .persist(&self.path)
            .map(drop)
            .map_err(|e| e.error.to_string())
    }
}

/// The APNG frame delay `num / den` seconds nearest to `1 / fps`.
pub fn frame_delay(fps: f64) -> (u16, u16) {
    if fps.fract() == 0.0 && fps >= 1.0 && fps <= f64::from(u16::MAX) {
        (1, fps as u16)
    } else {
        ((10_000.0 / fps).round().clamp(1.0, 65_535.0) as u16, 10_000)
    }
}

#[cfg(test)]
mod tests {
    use super::frame_delay;

    #[test]
    fn frame_delay_is_one_over_fps() {
        assert_eq!(frame_delay(15.0), (1, 15));
        assert_eq!(frame_delay(29.97), (334, 10_000));
        assert_eq!(frame_delay(0.5), (20_000, 10_000));
    }
}

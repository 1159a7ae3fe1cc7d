//! `--resume`: which frames in a frame directory are whole and can be kept. A frame is
//! kept only if its bytes match the checksum the manifest recorded when it was written
//! (when there is one), and it decodes completely (PNG's chunk CRCs and zlib's Adler-32
//! catch a truncated or damaged file) at the animation's size; any other is rendered
//! again. Temporaries a killed run left behind are removed first.

use super::sink::{checksum, frame_path};
use crate::error::CliError;
use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

/// Prefix and suffix of the temporary files the frame writers create.
const TEMP_PREFIX: &str = ".bubbles-";
const TEMP_SUFFIX: &str = ".tmp";

/// Removes the temporaries (`.bubbles-*.tmp`) a killed run left in `dir`; returns how many.
pub fn remove_stale_temporaries(dir: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .filter_map(Result::ok)
        .filter(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name.starts_with(TEMP_PREFIX) && name.ends_with(TEMP_SUFFIX)
        })
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count()
}

/// For each frame of `range`, whether `dir` holds it whole at `width × height`. A damaged
/// frame is reported on stderr and left to be rendered again.
///
/// # Errors
/// A frame path that is a directory (it could never be written), naming the frame.
pub fn whole_frames(
    dir: &Path,
    range: Range<u64>,
    (width, height): (usize, usize),
) -> Result<Vec<bool>, CliError> {
    let recorded = recorded_checksums(dir);
    range
        .map(|k| {
            let path = frame_path(dir, k);
            if path.is_dir() {
                return Err(CliError::input(format!(
                    "frame {k}: {} is a directory, not a frame: remove it",
                    path.display()
                )));
            }
            if !path.exists() {
                return Ok(false);
            }
            match check_frame(&path, recorded.get(&k).copied(), width, height) {
                Ok(()) => Ok(true),
                Err(why) => {
                    eprintln!("frame {k}: {} {why}: rendering it again", path.display());
                    Ok(false)
                }
            }
        })
        .collect()
}

/// Whether a directory holds frames (`frame_*.png`) of some earlier run.
pub fn has_frames(dir: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    entries.filter_map(Result::ok).any(|e| {
        let name = e.file_name();
        let name = name.to_string_lossy();
        name.starts_with("frame_") && name.ends_with(".png")
    })
}

/// The last checksum the manifest records for each frame (`frame K fnv1a64 HEX` lines;
/// a line damaged by a crash is skipped, leaving its frame to the decode check).
fn recorded_checksums(dir: &Path) -> HashMap<u64, u64> {
    let text = std::fs::read_to_string(dir.join(super::MANIFEST)).unwrap_or_default();
    text.lines()
        .filter_map(|line| {
            let mut words = line.split(' ');
            let (Some("frame"), Some(k), Some("fnv1a64"), Some(sum), None) = (
                words.next(),
                words.next(),
                words.next(),
                words.next(),
                words.next(),
            ) else {
                return None;
            };
            Some((k.parse().ok()?, u64::from_str_radix(sum, 16).ok()?))
        })
        .collect()
}

/// Checks the frame at `path` against its recorded checksum, then decodes it whole and
/// checks its size.
fn check_frame(
    path: &Path,
    recorded: Option<u64>,
    width: usize,
    height: usize,
) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot be read ({e})"))?;
    if recorded.is_some_and(|sum| sum != checksum(&bytes)) {
        return Err(format!(
            "does not match its checksum in {}",
            super::MANIFEST
        ));
    }
    let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("is no PNG ({e})"))?;
    let info = reader.info();
    let size = (info.width as usize, info.height as usize);
    if size != (width, height) {
        return Err(format!("is {}x{}, not {width}x{height}", size.0, size.1));
    }
    let mut buf = vec![0; reader.output_buffer_size().ok_or("is too large")?];
    reader
        .next_frame(&mut buf)
        .map_err(|e| format!("is damaged ({e})"))?;
    reader.finish().map_err(|e| format!("is damaged ({e})"))
}

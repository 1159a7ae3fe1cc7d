//! Bounded reading of user files: text inputs are capped at
//! [`limits::MAX_INPUT_BYTES`] and images at [`limits::MAX_IMAGE_PIXELS`] before any
//! decoding, so `/dev/zero` or a decompression bomb is refused instead of eating memory.

use crate::error::CliError;
use crate::limits;
use std::io::Read;
use std::path::Path;

/// Reads the UTF-8 text file at `path`, refusing more than `MAX_INPUT_BYTES`; `what`
/// names the file's role in messages ("scene", "OBJ mesh", …).
pub fn read_text(path: &Path, what: &str) -> Result<String, CliError> {
    let cannot = |e: &dyn std::fmt::Display| {
        CliError::input(format!("cannot read {what} {}: {e}", path.display()))
    };
    let file = std::fs::File::open(path).map_err(|e| cannot(&e))?;
    read_capped(file, &format!("{what} {}", path.display()))
}

/// Reads all of `reader` as UTF-8, refusing more than `MAX_INPUT_BYTES`; `name` names
/// the input in messages.
pub fn read_capped(reader: impl Read, name: &str) -> Result<String, CliError> {
    let mut bytes = Vec::new();
    reader
        .take(limits::MAX_INPUT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| CliError::input(format!("cannot read {name}: {e}")))?;
    if bytes.len() as u64 > limits::MAX_INPUT_BYTES {
        return Err(too_big(name));
    }
    String::from_utf8(bytes).map_err(|e| {
        CliError::input(format!(
            "{name} is not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// Checks that `path` is a regular file of at most `MAX_INPUT_BYTES`, for inputs that
/// another crate reads itself (OBJ meshes, spectrum CSVs).
pub fn check_text_file(path: &Path, what: &str) -> Result<(), CliError> {
    let name = format!("{what} {}", path.display());
    let meta =
        std::fs::metadata(path).map_err(|e| CliError::input(format!("cannot read {name}: {e}")))?;
    if !meta.is_file() {
        return Err(CliError::input(format!("{name} is not a regular file")));
    }
    if meta.len() > limits::MAX_INPUT_BYTES {
        return Err(too_big(&name));
    }
    Ok(())
}

/// Checks an image file's size from its header alone, before anything decodes it.
pub fn check_image_file(path: &Path, what: &str) -> Result<(), CliError> {
    let name = format!("{what} {}", path.display());
    let cannot = |e: &dyn std::fmt::Display| CliError::input(format!("cannot read {name}: {e}"));
    let meta = std::fs::metadata(path).map_err(|e| cannot(&e))?;
    if !meta.is_file() {
        return Err(CliError::input(format!("{name} is not a regular file")));
    }
    let (width, height) = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| cannot(&e))?
        .into_dimensions()
        .map_err(|e| cannot(&e))?;
    let pixels = u64::from(width) * u64::from(height);
    if pixels > limits::MAX_IMAGE_PIXELS {
        return Err(CliError::input(format!(
            "{name} is {width}x{height} = {pixels} pixels, above the limit of {} (see --help)",
            limits::MAX_IMAGE_PIXELS
        )));
    }
    Ok(())
}

fn too_big(name: &str) -> CliError {
    CliError::input(format!(
        "{name} is larger than the {} MiB input limit (see --help)",
        limits::MAX_INPUT_BYTES >> 20
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endless_input_is_refused_at_the_cap() {
        let endless = std::io::repeat(b'a');
        let msg = read_capped(endless, "stdin").unwrap_err().to_string();
        assert!(msg.contains("stdin is larger than the 64 MiB"), "{msg}");
    }

    #[test]
    fn small_input_is_read() {
        assert_eq!(read_capped(&b"abc"[..], "x").unwrap(), "abc");
    }
}

//! [`Format`]: the file formats a [`crate::LutSet`] can be saved in.

use std::fmt;

/// A file format for the baked textures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// OpenEXR, RGB 32-bit float, linear, unclamped, uncompressed; loads back bit-exactly.
    Exr,
    /// PNG, RGB 16-bit, linear; `value = offset + scale · code / 65535` per texture (see `lut.json`).
    Png16,
    /// PNG, RGB 8-bit, sRGB-encoded and clamped to 0..1: a preview for eyes, never loaded.
    Png8,
}

impl Format {
    /// Every format, in the order files are written.
    pub const ALL: [Format; 3] = [Format::Exr, Format::Png16, Format::Png8];

    /// The formats written when none are asked for.
    pub const DEFAULT: [Format; 2] = [Format::Exr, Format::Png16];

    /// The name used on the command line and in `lut.json`.
    pub fn name(self) -> &'static str {
        match self {
            Format::Exr => "exr",
            Format::Png16 => "png16",
            Format::Png8 => "png8",
        }
    }

    /// File name of texture `stem` in this format (`reflectivity.exr`, `reflectivity.png`,
    /// `reflectivity.preview.png`).
    pub fn file_name(self, stem: &str) -> String {
        match self {
            Format::Exr => format!("{stem}.exr"),
            Format::Png16 => format!("{stem}.png"),
            Format::Png8 => format!("{stem}.preview.png"),
        }
    }

    /// Parses one format name (`exr`, `png16`, `png8`), ignoring ASCII case.
    pub fn from_name(name: &str) -> Result<Self, UnknownFormat> {
        Self::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(name.trim()))
            .ok_or_else(|| UnknownFormat(name.to_owned()))
    }

    /// Parses a comma-separated list such as `exr,png16`, dropping repeats.
    ///
    /// # Guarantees
    /// On success the list is non-empty and holds each format at most once, in the order given.
    pub fn parse_list(list: &str) -> Result<Vec<Self>, UnknownFormat> {
        let mut formats = Vec::new();
        for name in list.split(',') {
            let format = Self::from_name(name)?;
            if !formats.contains(&format) {
                formats.push(format);
            }
        }
        Ok(formats)
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A format name that is not one of [`Format::ALL`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownFormat(pub String);

impl fmt::Display for UnknownFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let valid: Vec<_> = Format::ALL.iter().map(|f| f.name()).collect();
        write!(
            f,
            "unknown format {:?}: valid formats are {}",
            self.0,
            valid.join(", ")
        )
    }
}

impl std::error::Error for UnknownFormat {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_lists_and_names_the_bad_entry() {
        assert_eq!(
            Format::parse_list("exr, PNG16,exr").unwrap(),
            vec![Format::Exr, Format::Png16]
        );
        let err = Format::parse_list("exr,tiff").unwrap_err();
        assert!(err.to_string().contains("\"tiff\""), "{err}");
        assert!(err.to_string().contains("png16"), "{err}");
        assert!(Format::parse_list("").is_err());
    }

    #[test]
    fn file_names_do_not_collide() {
        let names: Vec<_> = Format::ALL.iter().map(|f| f.file_name("x")).collect();
        assert_eq!(names, ["x.exr", "x.png", "x.preview.png"]);
    }
}

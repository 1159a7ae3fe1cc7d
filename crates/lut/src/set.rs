//! [`LutSet`]: the reflectivity, transmittance and light-source tables of one bake.

use crate::{Lut, LutMeta};

/// Every table of one bake, sharing one resolution and thickness range.
#[derive(Debug, Clone, PartialEq)]
pub struct LutSet {
    /// Linear-sRGB reflectivity for white light, normalised so a perfect mirror is (1, 1, 1).
    pub reflectivity: Lut,
    /// Linear-sRGB transmittance for white light, normalised the same way.
    pub transmittance: Lut,
    /// One light-source table per light, by light name: linear sRGB of the reflected
    /// light, scaled so that the light itself has Y = 1.
    pub lights: Vec<(String, Lut)>,
    /// What the tables were made from.
    pub meta: LutMeta,
}

impl LutSet {
    /// The light-source table of the light called `name`, if baked.
    pub fn light(&self, name: &str) -> Option<&Lut> {
        self.lights
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, lut)| lut)
    }

    /// Every table with its file stem: `reflectivity`, `transmittance`, `light_<name>`.
    pub fn named_tables(&self) -> Vec<(String, &Lut)> {
        let mut tables = vec![
            ("reflectivity".to_owned(), &self.reflectivity),
            ("transmittance".to_owned(), &self.transmittance),
        ];
        for (name, lut) in &self.lights {
            tables.push((light_stem(name), lut));
        }
        tables
    }
}

/// File stem of the light-source table of light `name`.
pub fn light_stem(name: &str) -> String {
    format!("light_{name}")
}

/// Whether `name` can name a light: 1 to 64 of ASCII letters, digits, `_` and `-`.
///
/// Light names become file names, so they must be safe on every file system.
pub fn is_valid_light_name(name: &str) -> bool {
    (1..=64).contains(&name.len())
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

//! Cross-crate tests: laws that hold end to end across thinfilm, lut, dynamics and raster.

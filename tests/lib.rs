//! Cross-crate tests live in this package; see `cross_crate.rs`.

//! Criterion benches (filled in by the crate owner).
fn main() {}

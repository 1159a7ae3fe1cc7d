//! Renders the paper-like scene to `paper.png` (or the path given) for a visual check.

#[path = "../tests/common/mod.rs"]
mod common;

use raster::{FilmTables, RenderSettings, Renderer};

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "paper.png".into());
    let scene = common::paper_scene();
    let tables = FilmTables::from_reflectivity(common::synthetic_reflectivity());
    let settings = RenderSettings::default();
    let mut renderer = Renderer::new();
    let frame = renderer.render(&scene, &tables, &settings).expect("render");
    println!("{:?}", frame.timings);
    frame
        .write_png(&out, settings.exposure_ev, settings.tonemap)
        .expect("write");
}

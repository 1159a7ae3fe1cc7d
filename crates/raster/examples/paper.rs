//! Renders the paper-like scene to `paper.png` (or the path given) for a visual check;
//! a second argument renders that many extra frames (for profiling), a third sets the
//! samples per pixel.

#[path = "../tests/common/mod.rs"]
mod common;

use raster::{FilmTables, RenderSettings, Renderer};

fn main() {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "paper.png".into());
    let repeat: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(0);
    let scene = common::paper_scene();
    let tables = FilmTables::from_reflectivity(common::synthetic_reflectivity());
    let samples = args.next().and_then(|s| s.parse().ok()).unwrap_or(4);
    let settings = RenderSettings {
        samples,
        ..RenderSettings::default()
    };
    let mut renderer = Renderer::new();
    for _ in 0..repeat {
        renderer.render(&scene, &tables, &settings).expect("render");
    }
    let frame = renderer.render(&scene, &tables, &settings).expect("render");
    println!("{:?}", frame.timings);
    frame
        .write_png(&out, settings.exposure_ev, settings.tonemap)
        .expect("write");
}

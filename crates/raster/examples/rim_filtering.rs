//! The before/after figure of docs/rendering.md ("Rims without aliasing"): a crop of the
//! rim scene's bubble (crates/raster/tests/rim_aliasing.rs) rendered with the single
//! bilinear cube-map tap, with the footprint-filtered lookup, and as the 64-sample
//! reference, side by side and enlarged 4× (nearest neighbour).
//!
//! `cargo run --release -p raster --example rim_filtering -- docs/figures/rim-filtering.png`

#[path = "../tests/common/mod.rs"]
mod common;

use raster::{Frame, ReflectionFilter, ReflectionMode, RenderSettings, Renderer};

const SIZE: usize = 128;
const FACE: usize = 64;
const SUPER: usize = 8;
/// The crop: `[x0, y0, side]` in pixels: the bubble's right rim, reflecting the ball and the ground.
const CROP: [usize; 3] = [80, 56, 48];
const ZOOM: usize = 4;
const GAP: usize = 4;

fn render(size: usize, face_size: usize, filter: ReflectionFilter) -> Frame {
    let mut renderer = Renderer::new();
    renderer.set_reflection_filter(filter);
    let settings = common::settings(size, size, 4, ReflectionMode::DynamicCubeMap { face_size });
    renderer
        .render(&common::rim_scene(), &common::mirror_tables(), &settings)
        .expect("render")
        .clone()
}

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "rim-filtering.png".into());
    let panels = [
        render(SIZE, FACE, ReflectionFilter::Bilinear),
        render(SIZE, FACE, ReflectionFilter::Footprint),
        common::box_downsample(
            &render(SIZE * SUPER, FACE * SUPER, ReflectionFilter::Bilinear),
            SUPER,
        ),
    ];
    let [x0, y0, side] = CROP;
    let panel = side * ZOOM;
    let width = panels.len() * panel + (panels.len() - 1) * GAP;
    let mut rgb = vec![[1.0f32; 3]; width * panel];
    for (k, frame) in panels.iter().enumerate() {
        for y in 0..panel {
            for x in 0..panel {
                rgb[y * width + k * (panel + GAP) + x] = frame.pixel(x0 + x / ZOOM, y0 + y / ZOOM);
            }
        }
    }
    let settings = RenderSettings::default();
    Frame::try_from_rgb(width, panel, rgb)
        .expect("finite pixels")
        .write_png(&out, settings.exposure_ev, settings.tonemap)
        .expect("write");
    println!("{out}: single bilinear tap | filtered by footprint | 64-sample reference");
}

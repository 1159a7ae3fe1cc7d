//! Writes a synthetic 8-bit photo of a draining film and its true thickness map:
//! `cargo run --release -p film-inverse --example synthetic_photo -- OUT.png [WIDTH HEIGHT MAX_NM]`
//! (`OUT.truth.exr` beside it). Camera: the tests' standard shot (exposure +10 %, white
//! balance ±5 %, 2 % shot noise, seed 7). Photos over 1 Mpx use the colour table rather
//! than the exact spectrum, for speed.

use film_inverse::synth::{
    CameraModel, draining_film, film_colours, nominal_exposure, photograph8,
};
use film_inverse::{Camera, FilmModel};
use thinfilm::Illuminant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = std::path::PathBuf::from(
        args.first()
            .expect("usage: synthetic_photo OUT.png [W H MAX_NM]"),
    );
    let num = |i: usize, d: f64| args.get(i).map_or(d, |s| s.parse().expect("a number"));
    let (w, h, max) = (num(1, 480.0) as u32, num(2, 640.0) as u32, num(3, 1200.0));
    let model = FilmModel::soap(&Illuminant::D65.spectrum());
    let truth = draining_film(w, h, max);
    let cos = vec![1.0f32; truth.len()];
    let colours = film_colours(&model, &truth, &cos, truth.len() <= 1 << 20);
    let camera = Camera {
        exposure: nominal_exposure(&model) * 1.1,
        gains: [1.05, 1.0, 0.95],
    };
    println!(
        "true camera: exposure {:.4}, gains {:?}",
        camera.exposure, camera.gains
    );
    let px = photograph8(
        &colours,
        &CameraModel {
            camera,
            noise: 0.02,
            seed: 7,
        },
    );
    image::RgbImage::from_raw(w, h, px)
        .expect("size")
        .save(&out)
        .expect("write the photo");
    let truth_rgba: Vec<f32> = truth.iter().flat_map(|&t| [t, 0.0, 0.0, 1.0]).collect();
    image::Rgba32FImage::from_raw(w, h, truth_rgba)
        .expect("size")
        .save(out.with_extension("truth.exr"))
        .expect("write the truth");
}

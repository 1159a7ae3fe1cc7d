//! `bubbles compare A.png B.png`: CIEDE2000 between two renders (mean, 95th and 99th
//! percentiles, maximum), optionally a heat map with a colour bar.
//!
//! Inputs are single-frame, opaque PNG images within the input limits (`--help`): each
//! header is checked before anything is decoded, and an animated PNG, a pixel that is
//! not fully opaque or a heat map that would overwrite an input is refused with exit
//! code 2 (ΔE2000 is defined between colours, not between colours over an unknown
//! background).

use crate::error::{CliError, CliResult};
use crate::input;
use std::path::{Path, PathBuf};
use thinfilm::colorspace::{XYZ_FROM_SRGB, apply, srgb_decode};
use thinfilm::{Lab, ciede2000, lab_from_xyz};

/// Arguments of `bubbles compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// First image (opaque, single-frame sRGB PNG, 8 or 16 bits), e.g. the reference.
    pub a: PathBuf,
    /// Second image, the same size.
    pub b: PathBuf,
    /// Also write a heat map of ΔE2000 with a colour bar (PNG; not one of the inputs).
    #[arg(long)]
    pub heatmap: Option<PathBuf>,
    /// ΔE2000 at the top of the heat map's scale (larger values are clipped to it).
    #[arg(long, default_value_t = 10.0)]
    pub heatmap_max: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Summary of a per-pixel ΔE2000 map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Mean ΔE2000.
    pub mean: f64,
    /// 95th percentile (nearest rank).
    pub p95: f64,
    /// 99th percentile (nearest rank).
    pub p99: f64,
    /// Largest ΔE2000.
    pub max: f64,
}

/// Runs `bubbles compare`.
pub fn run(args: Args) -> CliResult {
    if !(args.heatmap_max.is_finite() && args.heatmap_max > 0.0) {
        return Err(CliError::input(format!(
            "--heatmap-max {}: must be a finite number > 0",
            crate::scene::values::plain(args.heatmap_max)
        )));
    }
    if let Some(out) = &args.heatmap {
        crate::output::refuse_overwriting("--heatmap", out, &[&args.a, &args.b], "the heat map")?;
        crate::output::check_file("--heatmap", out)?;
    }
    let size_a = check_header(&args.a)?;
    let size_b = check_header(&args.b)?;
    if size_a != size_b {
        return Err(CliError::input(format!(
            "{} is {}x{} but {} is {}x{}: compare needs images of the same size",
            args.a.display(),
            size_a.0,
            size_a.1,
            args.b.display(),
            size_b.0,
            size_b.1
        )));
    }
    let a = load(&args.a)?;
    let b = load(&args.b)?;
    let de = delta_e_map(a.as_raw(), b.as_raw());
    let stats = stats(&de);
    if let Some(out) = &args.heatmap {
        heatmap::write(out, &de, (a.width(), a.height()), args.heatmap_max)?;
    }
    if args.json {
        println!(
            "{{\"width\": {}, \"height\": {}, \"mean\": {}, \"p95\": {}, \"p99\": {}, \"max\": {}}}",
            a.width(),
            a.height(),
            stats.mean,
            stats.p95,
            stats.p99,
            stats.max
        );
    } else {
        println!(
            "ΔE2000 over {}x{} pixels: mean {:.3}, 95th percentile {:.3}, 99th percentile {:.3}, max {:.3}",
            a.width(),
            a.height(),
            stats.mean,
            stats.p95,
            stats.p99,
            stats.max
        );
    }
    Ok(())
}

/// Checks an input from its header alone, before anything decodes it: within the pixel
/// limit (the message `render` gives), a PNG, and one frame. Returns its size.
fn check_header(path: &Path) -> Result<(u32, u32), CliError> {
    input::check_image_file(path, "image")?;
    let cannot = |e: &dyn std::fmt::Display| {
        CliError::input(format!("cannot read image {}: {e}", path.display()))
    };
    let file = std::fs::File::open(path).map_err(|e| cannot(&e))?;
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| {
            CliError::input(format!(
                "image {} is not a PNG compare can read ({e}): compare reads PNG images",
                path.display()
            ))
        })?;
    let info = reader.info();
    if let Some(animation) = info.animation_control
        && animation.num_frames > 1
    {
        return Err(CliError::input(format!(
            "image {} is an animated PNG of {} frames: compare reads one frame; compare the frames as separate PNGs",
            path.display(),
            animation.num_frames
        )));
    }
    Ok((info.width, info.height))
}

/// Decodes a checked input (its pixels are within the limit, so the decoder's own
/// allocation cap is lifted) and refuses one with a pixel that is not fully opaque.
fn load(path: &Path) -> Result<image::RgbImage, CliError> {
    let cannot = |e: &dyn std::fmt::Display| {
        CliError::input(format!("cannot read image {}: {e}", path.display()))
    };
    let mut reader = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| cannot(&e))?;
    reader.no_limits();
    let img = reader.decode().map_err(|e| cannot(&e))?;
    if let Some((index, alpha, max)) = first_translucent(&img) {
        let (x, y) = (
            index as u64 % u64::from(img.width()),
            index as u64 / u64::from(img.width()),
        );
        return Err(CliError::input(format!(
            "image {} has a pixel that is not opaque at ({x}, {y}), alpha {alpha} of {max}: compare reads opaque images only (ΔE2000 needs the colour under the alpha); flatten it onto its background first",
            path.display()
        )));
    }
    Ok(img.to_rgb8())
}

/// The first pixel whose alpha is below full, as (pixel index, alpha, full alpha).
fn first_translucent(img: &image::DynamicImage) -> Option<(usize, f64, f64)> {
    use image::DynamicImage as D;
    fn find<T: Copy + PartialEq + Into<f64>>(
        raw: &[T],
        channels: usize,
        full: T,
    ) -> Option<(usize, f64, f64)> {
        raw.chunks_exact(channels)
            .position(|px| px[channels - 1] != full)
            .map(|i| (i, raw[i * channels + channels - 1].into(), full.into()))
    }
    match img {
        D::ImageLumaA8(b) => find(b.as_raw(), 2, u8::MAX),
        D::ImageRgba8(b) => find(b.as_raw(), 4, u8::MAX),
        D::ImageLumaA16(b) => find(b.as_raw(), 2, u16::MAX),
        D::ImageRgba16(b) => find(b.as_raw(), 4, u16::MAX),
        D::ImageRgba32F(b) => find(b.as_raw(), 4, 1.0f32),
        _ => None,
    }
}

/// CIELAB of an 8-bit sRGB pixel, relative to the sRGB white.
fn lab_of(px: &[u8]) -> Lab {
    let linear = [0, 1, 2].map(|c| srgb_decode(f64::from(px[c]) / 255.0));
    let white = apply(&XYZ_FROM_SRGB, [1.0; 3]);
    lab_from_xyz(apply(&XYZ_FROM_SRGB, linear), white)
}

/// Per-pixel ΔE2000 of two interleaved RGB8 buffers of the same length.
///
/// # Panics
/// Panics if the buffers differ in length.
pub fn delta_e_map(a: &[u8], b: &[u8]) -> Vec<f64> {
    assert_eq!(a.len(), b.len(), "images of the same size");
    a.chunks_exact(3)
        .zip(b.chunks_exact(3))
        .map(|(p, q)| ciede2000(lab_of(p), lab_of(q)))
        .collect()
}

/// Mean, 95th and 99th percentiles (nearest rank) and maximum; all zero for no pixels.
pub fn stats(de: &[f64]) -> Stats {
    if de.is_empty() {
        return Stats {
            mean: 0.0,
            p95: 0.0,
            p99: 0.0,
            max: 0.0,
        };
    }
    let mut sorted = de.to_vec();
    sorted.sort_by(f64::total_cmp);
    let percentile = |p: f64| {
        let rank = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
        sorted[rank - 1]
    };
    Stats {
        mean: sorted.iter().sum::<f64>() / sorted.len() as f64,
        p95: percentile(0.95),
        p99: percentile(0.99),
        max: sorted[sorted.len() - 1],
    }
}

pub(crate) mod heatmap {
    //! A map of values (ΔE, thickness) in a magma-like ramp, with a labelled colour bar on
    //! the right; non-finite values (masked pixels) show grey.

    use super::CliError;
    use std::path::Path;

    /// Stops of the ramp (approximately matplotlib's magma at 0, ¼, ½, ¾, 1).
    const RAMP: [[f32; 3]; 5] = [
        [0.0, 0.0, 4.0],
        [81.0, 18.0, 124.0],
        [183.0, 55.0, 121.0],
        [252.0, 137.0, 97.0],
        [252.0, 253.0, 191.0],
    ];
    /// Columns added for the bar and its labels.
    const BAR_MARGIN: u32 = 6;
    const BAR_WIDTH: u32 = 12;
    const LABEL_WIDTH: u32 = 4 * 8 + 6;

    /// 3 × 5 digits and a dot, one row per `u8`, bit 2 leftmost.
    const GLYPHS: [(char, [u8; 5]); 11] = [
        ('0', [7, 5, 5, 5, 7]),
        ('1', [2, 6, 2, 2, 7]),
        ('2', [7, 1, 7, 4, 7]),
        ('3', [7, 1, 7, 1, 7]),
        ('4', [5, 5, 7, 1, 1]),
        ('5', [7, 4, 7, 1, 7]),
        ('6', [7, 4, 7, 5, 7]),
        ('7', [7, 1, 1, 1, 1]),
        ('8', [7, 5, 7, 5, 7]),
        ('9', [7, 5, 7, 1, 7]),
        ('.', [0, 0, 0, 0, 2]),
    ];

    pub(crate) fn colour(t: f64) -> [u8; 3] {
        if !t.is_finite() {
            return [128, 128, 128];
        }
        let x = (t.clamp(0.0, 1.0) * 4.0) as f32;
        let i = (x as usize).min(3);
        let f = x - i as f32;
        [0, 1, 2].map(|c| (RAMP[i][c] * (1.0 - f) + RAMP[i + 1][c] * f + 0.5) as u8)
    }

    /// Writes the map, `max` at the top of the scale, through a temporary file.
    pub(crate) fn write(
        out: &Path,
        de: &[f64],
        (w, h): (u32, u32),
        max: f64,
    ) -> Result<(), CliError> {
        let height = h.max(40);
        let width = w + BAR_MARGIN + BAR_WIDTH + LABEL_WIDTH;
        let mut img = image::RgbImage::from_pixel(width, height, image::Rgb([255, 255, 255]));
        for (i, &d) in de.iter().enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            img.put_pixel(x, y, image::Rgb(colour(d / max)));
        }
        let x0 = w + BAR_MARGIN;
        for y in 0..height {
            let t = 1.0 - f64::from(y) / f64::from(height - 1);
            for x in x0..x0 + BAR_WIDTH {
                img.put_pixel(x, y, image::Rgb(colour(t)));
            }
        }
        let label_x = x0 + BAR_WIDTH + 3;
        text(&mut img, &format_value(max), label_x, 0);
        text(&mut img, "0", label_x, height - 10);
        save(out, &img)
    }

    fn format_value(v: f64) -> String {
        let s = format!("{v:.1}");
        s.strip_suffix(".0").map_or(s.clone(), str::to_owned)
    }

    /// Draws `s` in the 3 × 5 font at twice its size, top-left at `(x, y)`.
    fn text(img: &mut image::RgbImage, s: &str, x: u32, y: u32) {
        for (k, ch) in s.chars().enumerate() {
            let Some((_, rows)) = GLYPHS.iter().find(|(c, _)| *c == ch) else {
                continue;
            };
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..3u32 {
                    if bits & (4 >> col) != 0 {
                        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                            let px = x + k as u32 * 8 + col * 2 + dx;
                            let py = y + r as u32 * 2 + dy;
                            if px < img.width() && py < img.height() {
                                img.put_pixel(px, py, image::Rgb([0, 0, 0]));
                            }
                        }
                    }
                }
            }
        }
    }

    /// Writes an RGB image as PNG through a temporary file beside `out`.
    pub(crate) fn save(out: &Path, img: &image::RgbImage) -> Result<(), CliError> {
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .map_err(|e| CliError::runtime(format!("cannot encode PNG: {e}")))?;
        let dir = match out.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let name = out.file_name().map_or_else(
            || "heatmap.png".into(),
            |n| n.to_string_lossy().into_owned(),
        );
        let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
        std::fs::write(&tmp, &png)
            .and_then(|()| std::fs::rename(&tmp, out))
            .map_err(|e| {
                let _ = std::fs::remove_file(&tmp);
                CliError::input(format!("cannot write {}: {e}", out.display()))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_differ_by_zero_and_one_pixel_gives_its_own_delta_e() {
        let a: Vec<u8> = (0..30u32 * 3).map(|i| (i * 37 % 251) as u8).collect();
        assert_eq!(stats(&delta_e_map(&a, &a)).max, 0.0);
        let mut b = a.clone();
        b[3 * 7..3 * 7 + 3].copy_from_slice(&[250, 10, 40]);
        let own = ciede2000(lab_of(&a[21..24]), lab_of(&[250, 10, 40]));
        let s = stats(&delta_e_map(&a, &b));
        assert!(own > 1.0, "the change is visible: {own}");
        assert_eq!(s.max, own, "max {} vs {own}", s.max);
        assert!((s.mean - own / 30.0).abs() < 1e-12, "mean {}", s.mean);
    }

    #[test]
    fn percentile_is_the_nearest_rank() {
        let de: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = stats(&de);
        assert_eq!((s.p95, s.p99, s.max, s.mean), (95.0, 99.0, 100.0, 50.5));
    }

    #[test]
    fn ramp_runs_dark_to_light() {
        let lum = |c: [u8; 3]| u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2]);
        let mut last = 0;
        for k in 0..=20 {
            let l = lum(heatmap::colour(f64::from(k) / 20.0));
            assert!(l >= last, "step {k}: {l} < {last}");
            last = l;
        }
    }
}

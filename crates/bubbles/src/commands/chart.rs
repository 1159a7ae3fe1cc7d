//! `bubbles chart`: the interference colour chart, colour against thickness, as a PNG.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply, srgb8_from_linear};
use tiny_skia::{Paint, PathBuilder, Pixmap, PremultipliedColorU8, Stroke, Transform};

use super::color::{FilmColour, LightArgs};
use crate::error::{CliError, CliResult};

/// Angles of incidence of the chart's rows, top to bottom.
pub const ANGLES_DEG: [f64; 5] = [0.0, 30.0, 45.0, 60.0, 75.0];
/// Thickness at the right edge of the chart: the tables' range.
pub const MAX_THICKNESS_NM: f64 = lut::config::DEFAULT_THICKNESS_MAX_NM as f64;

const LEFT_PX: u32 = 28;
const RIGHT_PX: u32 = 12;
const TOP_PX: u32 = 10;
const BOTTOM_PX: u32 = 22;
const ROW_GAP_PX: u32 = 4;
const MIN_SIZE_PX: [u32; 2] = [200, 100];
const MAX_SIZE_PX: u32 = 16384;

/// Arguments of `bubbles chart`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Draw the interference colour chart of a soap film in air: reflected colour \
    against thickness 0–4000 nm (x axis; ticks every 100 nm, long ticks every 500 nm), one row \
    per angle of incidence 0°, 30°, 45°, 60°, 75° (top to bottom; the glyph left of each row \
    shows its ray). Colours are exact Airy reflectance integrated against the CIE tables, \
    shown in sRGB without chromatic adaptation.\n\n\
    Exposure: a soap film reflects at most about 8 % at normal incidence, so the linear sRGB is \
    scaled so that the brightest colour of the 0° row has its largest channel at 1; the same \
    scale applies to every row (--exposure overrides it). Oblique rows are brighter: a colour \
    whose largest channel then exceeds 1 is divided by that channel (keeping its hue), and \
    negative (out-of-gamut) channels are clipped to 0."
)]
pub struct Args {
    /// Output PNG file (written to a temporary file in its directory, then renamed).
    #[arg(long)]
    pub out: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 1200)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 500)]
    pub height: u32,
    /// Fixed linear exposure factor instead of the automatic one (see below).
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f64>,
    #[command(flatten)]
    pub light: LightArgs,
}

/// Runs `bubbles chart`.
pub fn run(args: Args) -> CliResult {
    check_out_path(&args.out)?;
    let size = [args.width, args.height];
    for (value, name, min) in [
        (size[0], "--width", MIN_SIZE_PX[0]),
        (size[1], "--height", MIN_SIZE_PX[1]),
    ] {
        if !(min..=MAX_SIZE_PX).contains(&value) {
            return Err(CliError::input(format!(
                "{name} {value} must be between {min} and {MAX_SIZE_PX} pixels"
            )));
        }
    }
    if let Some(e) = args.exposure
        && !(e.is_finite() && e > 0.0)
    {
        return Err(CliError::input(format!(
            "--exposure {e} must be a finite number > 0"
        )));
    }
    let colour = FilmColour::from_args(&args.light)?;
    let layout = Layout::new(size);
    let rows = row_colours(&colour, layout.plot_width)?;
    let exposure = args.exposure.unwrap_or_else(|| auto_exposure(&rows[0]));
    let pixmap = draw(&layout, &rows, exposure)?;
    write_png(&args.out, &pixmap)
}

/// Rejects an `--out` that cannot be created (a directory, a missing or read-only
/// directory) before any drawing.
fn check_out_path(out: &Path) -> CliResult {
    crate::output::check_file("--out", out)
}

/// The directory `out` will be written in.
fn out_dir(out: &Path) -> &Path {
    match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Where the chart's parts go, in pixels.
struct Layout {
    size: [u32; 2],
    plot_width: u32,
    row_height: u32,
}

impl Layout {
    fn new(size: [u32; 2]) -> Layout {
        let rows = ANGLES_DEG.len() as u32;
        let plot_height = size[1] - TOP_PX - BOTTOM_PX - ROW_GAP_PX * (rows - 1);
        Layout {
            size,
            plot_width: size[0] - LEFT_PX - RIGHT_PX,
            row_height: plot_height / rows,
        }
    }

    /// The top pixel row of chart row `row`.
    fn row_top(&self, row: usize) -> u32 {
        TOP_PX + row as u32 * (self.row_height + ROW_GAP_PX)
    }

    /// The bottom of the last row, where the axis is drawn.
    fn axis_y(&self) -> f32 {
        (self.row_top(ANGLES_DEG.len() - 1) + self.row_height) as f32 + 1.5
    }

    /// The x pixel coordinate of `thickness_nm`.
    fn x_of(&self, thickness_nm: f64) -> f32 {
        LEFT_PX as f32 + (thickness_nm / MAX_THICKNESS_NM) as f32 * self.plot_width as f32
    }
}

/// Linear sRGB of each row (angle), one colour per pixel column (at its centre's thickness).
fn row_colours(colour: &FilmColour, columns: u32) -> Result<Vec<Vec<[f64; 3]>>, CliError> {
    let thickness_nm: Vec<f32> = (0..columns)
        .map(|x| (MAX_THICKNESS_NM * (f64::from(x) + 0.5) / f64::from(columns)) as f32)
        .collect();
    ANGLES_DEG
        .par_iter()
        .map(|&angle| {
            let xyz = colour.xyz_row_f32(angle, &thickness_nm)?;
            Ok(xyz.into_iter().map(|v| apply(&SRGB_FROM_XYZ, v)).collect())
        })
        .collect()
}

/// The scale that brings the brightest channel of `row` to 1 (1 for an all-black row).
fn auto_exposure(row: &[[f64; 3]]) -> f64 {
    let brightest = row.iter().flatten().copied().fold(0.0, f64::max);
    if brightest > 0.0 {
        1.0 / brightest
    } else {
        1.0
    }
}

/// Exposed, gamut-mapped 8-bit sRGB: negatives clipped, then hue-preserving
/// division by the largest channel if it exceeds 1.
fn display_colour(linear: [f64; 3], exposure: f64) -> [u8; 3] {
    let rgb = linear.map(|c| (c * exposure).max(0.0));
    let peak = rgb[0].max(rgb[1]).max(rgb[2]);
    let rgb = if peak > 1.0 {
        rgb.map(|c| c / peak)
    } else {
        rgb
    };
    srgb8_from_linear(rgb)
}

/// Paints the colour rows, the thickness axis and the angle glyphs.
fn draw(layout: &Layout, rows: &[Vec<[f64; 3]>], exposure: f64) -> Result<Pixmap, CliError> {
    let [w, h] = layout.size;
    let mut pixmap = Pixmap::new(w, h)
        .ok_or_else(|| CliError::runtime(format!("cannot allocate a {w}×{h} image")))?;
    pixmap.fill(tiny_skia::Color::from_rgba8(24, 24, 24, 255));
    for (r, row) in rows.iter().enumerate() {
        let top = layout.row_top(r);
        let pixels = pixmap.pixels_mut();
        for (x, &linear) in row.iter().enumerate() {
            let [red, green, blue] = display_colour(linear, exposure);
            let Some(colour) = PremultipliedColorU8::from_rgba(red, green, blue, 255) else {
                continue;
            };
            for y in top..top + layout.row_height {
                pixels[(y * w + LEFT_PX) as usize + x] = colour;
            }
        }
    }
    draw_axis(&mut pixmap, layout);
    draw_angle_glyphs(&mut pixmap, layout);
    Ok(pixmap)
}

/// The thickness axis: a line with ticks every 100 nm, longer every 500 nm.
fn draw_axis(pixmap: &mut Pixmap, layout: &Layout) {
    let y = layout.axis_y();
    let mut pb = PathBuilder::new();
    pb.move_to(layout.x_of(0.0), y);
    pb.line_to(layout.x_of(MAX_THICKNESS_NM), y);
    for tick in (0..=MAX_THICKNESS_NM as u32).step_by(100) {
        let x = layout
            .x_of(f64::from(tick))
            .clamp(0.5, layout.size[0] as f32 - 0.5);
        let length = if tick % 500 == 0 { 12.0 } else { 5.0 };
        pb.move_to(x, y);
        pb.line_to(x, y + length);
    }
    stroke(pixmap, pb, 1.0);
}

/// Left of each row, a ray at the row's angle of incidence onto a short film line.
fn draw_angle_glyphs(pixmap: &mut Pixmap, layout: &Layout) {
    let mut pb = PathBuilder::new();
    for (r, angle) in ANGLES_DEG.iter().enumerate() {
        let bottom = (layout.row_top(r) + layout.row_height) as f32 - 2.0;
        let length = (layout.row_height as f32 - 4.0).clamp(4.0, 20.0);
        let cx = LEFT_PX as f32 / 2.0 + 4.0;
        let (sin, cos) = (angle.to_radians() as f32).sin_cos();
        pb.move_to(cx - 8.0, bottom);
        pb.line_to(cx + 6.0, bottom);
        pb.move_to(cx, bottom);
        pb.line_to(cx - length * sin, bottom - length * cos);
    }
    stroke(pixmap, pb, 1.5);
}

/// Strokes `pb` in light grey.
fn stroke(pixmap: &mut Pixmap, pb: PathBuilder, width: f32) {
    let Some(path) = pb.finish() else {
        return;
    };
    let mut paint = Paint::default();
    paint.set_color_rgba8(200, 200, 200, 255);
    paint.anti_alias = true;
    let stroke = Stroke {
        width,
        ..Stroke::default()
    };
    pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
}

/// Encodes `pixmap` as PNG and writes it through a temporary file in the same directory.
fn write_png(out: &Path, pixmap: &Pixmap) -> CliResult {
    // Every pixel is opaque, so premultiplied RGBA is plain RGBA.
    let image = image::RgbaImage::from_raw(pixmap.width(), pixmap.height(), pixmap.data().to_vec())
        .ok_or_else(|| CliError::runtime("chart buffer has the wrong size"))?;
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| CliError::runtime(format!("cannot encode PNG: {e}")))?;
    let file_name = out
        .file_name()
        .map_or_else(|| "chart.png".into(), |n| n.to_string_lossy().into_owned());
    let tmp = out_dir(out).join(format!(".{file_name}.{}.tmp", std::process::id()));
    let written = std::fs::write(&tmp, &png).and_then(|()| std::fs::rename(&tmp, out));
    written.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        CliError::input(format!("cannot write {}: {e}", out.display()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_colour_clips_negatives_and_keeps_hue_above_one() {
        assert_eq!(display_colour([-0.5, 0.0, 0.0], 1.0), [0, 0, 0]);
        assert_eq!(
            display_colour([2.0, 1.0, 0.0], 1.0),
            display_colour([1.0, 0.5, 0.0], 1.0)
        );
        assert_eq!(
            display_colour([0.5, 0.25, 0.0], 2.0),
            display_colour([1.0, 0.5, 0.0], 1.0)
        );
    }

    #[test]
    fn auto_exposure_brings_the_brightest_channel_to_one() {
        let row = [[0.01, 0.02, 0.05], [0.1, 0.04, 0.0]];
        assert!((auto_exposure(&row) - 10.0).abs() < 1e-12);
        assert_eq!(auto_exposure(&[[0.0; 3]]), 1.0);
    }

    #[test]
    fn layout_fits_the_smallest_image() {
        let l = Layout::new(MIN_SIZE_PX);
        let last = ANGLES_DEG.len() - 1;
        assert!(l.row_height >= 1);
        assert!(l.axis_y() + 12.0 <= MIN_SIZE_PX[1] as f32);
        assert!(l.row_top(last) + l.row_height <= MIN_SIZE_PX[1]);
        assert!(l.x_of(MAX_THICKNESS_NM) <= (MIN_SIZE_PX[0] - RIGHT_PX) as f32);
    }
}

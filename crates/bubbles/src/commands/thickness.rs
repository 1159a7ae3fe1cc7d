//! `bubbles thickness PHOTO --out MAP.exr`: the film's thickness map from a photo of it
//! in reflection (the inverse of `bubbles color`; see docs/inverse.md).
//!
//! Beside `MAP.exr` (R thickness nm, G one-sigma uncertainty nm, B ΔE2000 residual, A 1
//! where fitted and 0 where not) it writes `MAP.png` (the map with a colour bar),
//! `MAP.rerender.png` (the photo and the colour re-rendered from the map, side by side)
//! and `MAP.residual.png` (the ΔE2000 residual with a colour bar), each through a
//! temporary file.

mod options;
mod outputs;

use crate::error::{CliError, CliResult};
use std::path::PathBuf;

/// Arguments of `bubbles thickness`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Masked pixels (saturated, excluded by --mask or the geometry, or \
    unexplained: no thickness brings the colour within --max-residual-de) get no thickness: \
    0 with alpha 0 in the EXR, grey in the PNGs."
)]
pub struct Args {
    /// The photo: sRGB PNG (8 or 16 bits) or linear EXR, the film seen in reflection.
    pub photo: PathBuf,
    /// The thickness map (EXR); the PNG figures are written beside it.
    #[arg(long)]
    pub out: PathBuf,
    /// Light source: d65, d50, a, e, f2, f11, sodium, or a CSV spectrum file.
    #[arg(long, default_value = "d65", value_name = "NAME|PATH.csv")]
    pub illuminant: String,
    /// Film index: a number, or `water` (IAPWS dispersion).
    #[arg(long, default_value = "1.33")]
    pub n_film: String,
    /// Index around the film.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub n_outside: f64,
    /// CIE standard observer: 1931 (2°) or 1964 (10°).
    #[arg(long, default_value = "1931")]
    pub observer: String,
    /// Thickest film to consider (nm); fits may exceed it by up to a fifth.
    #[arg(long, default_value_t = 1500.0, allow_negative_numbers = true)]
    pub thickness_max_nm: f64,
    /// Angle of incidence of the whole photo (degrees).
    #[arg(long, conflicts_with_all = ["angle_map", "sphere"], allow_negative_numbers = true)]
    pub angle_deg: Option<f64>,
    /// Per-pixel angle of incidence (degrees) in the R channel of an EXR of the photo's size.
    #[arg(long, conflicts_with = "sphere")]
    pub angle_map: Option<PathBuf>,
    /// A bubble seen from afar: `CX,CY,R` in pixels (outside the disc is excluded).
    #[arg(long, allow_hyphen_values = true)]
    pub sphere: Option<String>,
    /// A region showing the light in a perfect mirror, `X,Y,W,H`: fixes exposure and white balance.
    #[arg(long, conflicts_with_all = ["reference", "exposure"], allow_hyphen_values = true)]
    pub white: Option<String>,
    /// A region of known thickness, `X,Y,W,H=NM`: fixes exposure and white balance.
    #[arg(long, conflicts_with = "exposure", allow_hyphen_values = true)]
    pub reference: Option<String>,
    /// Known exposure (linear value of a perfect mirror of the light); default: estimated.
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f64>,
    /// Known white-balance gains `R,G,B` (with --exposure).
    #[arg(long, requires = "exposure", allow_hyphen_values = true)]
    pub gains: Option<String>,
    /// A known thickness `X,Y=NM` (repeatable): fixes the fringe order around it.
    #[arg(long, allow_hyphen_values = true)]
    pub anchor: Vec<String>,
    /// Pixels to use: a PNG of the photo's size, white (non-zero) where the film is.
    #[arg(long)]
    pub mask: Option<PathBuf>,
    /// ΔE2000 above which a fitted pixel counts as unexplained.
    #[arg(long, default_value_t = 8.0, allow_negative_numbers = true)]
    pub max_residual_de: f64,
    /// Thickness step (nm) between neighbouring pixels that the continuity prior expects.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub smoothness_nm: f64,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `bubbles thickness`.
pub fn run(args: Args) -> CliResult {
    crate::signals::install();
    let paths = outputs::Paths::from_out(&args.out, &args.photo)?;
    for path in [&paths.exr, &paths.png, &paths.rerender, &paths.residual] {
        crate::output::check_file("--out", path)?;
    }
    let photo = options::load_photo(&args.photo)?;
    let model = options::model(&args)?;
    let settings = options::settings(&args, &photo)?;
    let map = film_inverse::recover(&photo.photo, &model, &settings)
        .map_err(|e| CliError::input(format!("{}: {e}", args.photo.display())))?;
    crate::signals::check()?;
    outputs::write_all(&paths, &photo.photo, &map)?;
    outputs::print_summary(&map, &paths, args.json);
    Ok(())
}

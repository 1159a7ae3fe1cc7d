//! `bubbles color`: the CIE colour of a soap film for each `thickness_nm,angle_deg` row on stdin.
//!
//! Also holds the light-source, observer and film options shared with `bubbles chart`.

use std::fmt::Write as _;
use std::io::Read as _;
use std::path::Path;

use rayon::prelude::*;
use thinfilm::airy::ThinFilm;
use thinfilm::cmf::Observer;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply, hex, srgb8_from_linear};
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::SpectralIntegrator;
use thinfilm::spectrum::Spectrum;

use crate::csv_table::CsvTable;
use crate::error::{CliError, CliResult};
use crate::scene::values::plain;

/// Arguments of `bubbles color`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "CIE colour of a soap film in air, from CSV `thickness_nm,angle_deg` on stdin.\n\n\
    Writes `thickness_nm,angle_deg,x,y,z,r_lin,g_lin,b_lin,srgb_hex`: XYZ of the reflected \
    light with the illuminant's perfect reflector at Y = 1 (exact Airy reflectance, integrated \
    against the CIE tables), linear sRGB (D65 primaries, unclamped, no chromatic adaptation: \
    under illuminant A a white shows orange, as a daylight-adapted eye sees it), and the hex of \
    the clamped, sRGB-encoded colour. A soap film reflects at most about 8 % at normal incidence, so \
    these colours are dark."
)]
pub struct Args {
    #[command(flatten)]
    pub light: LightArgs,
}

/// The CLI's sample spacing. Finer than `thinfilm::integrate::DEFAULT_STEP_NM`
/// (tuned for LUT bakes under daylight) so that line-rich lamps are exact too:
/// with cubic interpolation of R at 2 nm, a soap film's colour is within
/// ΔE2000 0.0001 (D65) and 0.003 (F11) of the CIE 1 nm sum (thickness 0–2000 nm,
/// angles 0–75°; `tests/colour_accuracy.rs` in `thinfilm`, `step_sweep`).
pub const CLI_STEP_NM: f64 = 2.0;

/// Options shared by `bubbles color` and `bubbles chart`.
#[derive(Debug, clap::Args)]
pub struct LightArgs {
    /// Light source: d65, d50, a, e, f2, f11, sodium, or a CSV spectrum file
    /// (header `wavelength_nm,value`).
    #[arg(long, default_value = "d65", value_name = "NAME|PATH.csv")]
    pub illuminant: String,
    /// Refractive index of the film, constant over wavelength.
    #[arg(long, default_value_t = 1.33, allow_negative_numbers = true)]
    pub n_film: f64,
    /// CIE standard observer: 1931 (2°) or 1964 (10°).
    #[arg(long, default_value = "1931")]
    pub observer: String,
}

/// A soap film's colour calculator: the validated options with the integrator built.
pub struct FilmColour {
    n_film: RefractiveIndex,
    integrator: SpectralIntegrator,
}

impl FilmColour {
    /// Validates the options and builds the integrator.
    pub fn from_args(args: &LightArgs) -> Result<FilmColour, CliError> {
        let n_film = RefractiveIndex::constant(args.n_film)
            .map_err(|e| CliError::input(format!("--n-film {:?}: {e}", args.n_film)))?;
        let observer = Observer::from_name(&args.observer).ok_or_else(|| {
            CliError::input(format!(
                "--observer `{}` is not a CIE observer; valid: 1931, 1964",
                args.observer
            ))
        })?;
        let spectrum = illuminant_spectrum(&args.illuminant)?;
        let integrator = SpectralIntegrator::new(observer, &spectrum, CLI_STEP_NM)
            .map_err(|e| CliError::input(format!("--illuminant {}: {e}", args.illuminant)))?;
        Ok(FilmColour { n_film, integrator })
    }

    /// XYZ of a row of films seen at `angle_deg`, by the f32 batch kernel
    /// (`thinfilm::batch`, within 2e-7 of the f64 path): fast enough for images.
    ///
    /// # Errors
    /// A runtime error if the kernel rejects its inputs (it cannot for validated options).
    pub fn xyz_row_f32(
        &self,
        angle_deg: f64,
        thickness_nm: &[f32],
    ) -> Result<Vec<[f64; 3]>, CliError> {
        let wavelength_nm: Vec<f32> = self
            .integrator
            .wavelengths_nm()
            .iter()
            .map(|&w| w as f32)
            .collect();
        let runtime = |e: thinfilm::OpticsError| {
            CliError::runtime(format!("optics failed at angle_deg {angle_deg}: {e}"))
        };
        // The CLI's film index is constant, so any wavelength gives it.
        let n = self.n_film.try_n_at(550.0).map_err(runtime)? as f32;
        let n_film = vec![n; wavelength_nm.len()];
        let weights: Vec<[f32; 3]> = self
            .integrator
            .weights()
            .iter()
            .map(|w| w.map(|c| c as f32))
            .collect();
        let cos_theta = angle_deg.to_radians().cos().clamp(0.0, 1.0) as f32;
        let mut out = vec![[0.0f32; 3]; thickness_nm.len()];
        thinfilm::batch::try_weighted_reflectance_row(
            1.0,
            cos_theta,
            &wavelength_nm,
            &n_film,
            &weights,
            thickness_nm,
            &mut out,
        )
        .map_err(runtime)?;
        Ok(out.into_iter().map(|v| v.map(f64::from)).collect())
    }

    /// XYZ (perfect reflector at Y = 1) of the film of `thickness_nm` seen at `angle_deg`.
    ///
    /// # Errors
    /// A runtime error if the optics fail (they cannot for validated inputs).
    pub fn xyz(&self, thickness_nm: f64, angle_deg: f64) -> Result<[f64; 3], CliError> {
        let film = ThinFilm {
            n_film: self.n_film,
            thickness_nm,
            ..ThinFilm::soap(0.0)
        };
        let cos_theta = angle_deg.to_radians().cos().clamp(0.0, 1.0);
        // A valid film goes through `film_xyz`, exact at grazing incidence (cell means);
        // anything else is sampled so that the failure surfaces as an error, not a panic.
        let valid = film.validate().is_ok() && thickness_nm.is_finite() && thickness_nm >= 0.0;
        let xyz = if valid {
            self.integrator.film_xyz(&film, cos_theta)
        } else {
            self.integrator
                .xyz(|w| film.try_response(w, cos_theta).map_or(f64::NAN, |r| r.r()))
        };
        if xyz.iter().all(|c| c.is_finite()) {
            Ok(xyz)
        } else {
            Err(CliError::runtime(format!(
                "optics failed for thickness_nm {}, angle_deg {}",
                plain(thickness_nm),
                plain(angle_deg)
            )))
        }
    }
}

/// The spectrum named by `--illuminant`: a built-in name, else a CSV file.
pub fn illuminant_spectrum(arg: &str) -> Result<Spectrum, CliError> {
    let unknown = match Illuminant::from_name(arg) {
        Ok(illuminant) => return Ok(illuminant.spectrum()),
        Err(unknown) => unknown,
    };
    let path = Path::new(arg);
    let looks_like_file = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if looks_like_file || path.exists() {
        return Spectrum::from_csv_path(path)
            .map_err(|e| CliError::input(format!("--illuminant {arg}: {e}")));
    }
    Err(CliError::input(format!(
        "--illuminant: {unknown}, or a CSV spectrum file (header `wavelength_nm,value`)"
    )))
}

/// Runs `bubbles color`.
pub fn run(args: Args) -> CliResult {
    let colour = FilmColour::from_args(&args.light)?;
    let mut input = String::new();
    std::io::stdin()
        .read_to_string(&mut input)
        .map_err(|e| CliError::input(format!("cannot read stdin as UTF-8 text: {e}")))?;
    let output = color_table(&colour, &input)?;
    print!("{output}");
    Ok(())
}

/// The whole output for CSV `input`, or the first error (nothing is printed on error).
fn color_table(colour: &FilmColour, input: &str) -> Result<String, CliError> {
    let table = CsvTable::parse(input, &["thickness_nm", "angle_deg"], &[])?;
    let mut queries = Vec::new();
    for row in table.rows() {
        let d = row.number("thickness_nm")?;
        let angle = row.number("angle_deg")?;
        if !(0.0..=crate::limits::MAX_LAYER_THICKNESS_NM).contains(&d) {
            let field = row.get("thickness_nm").unwrap_or_default();
            return Err(row.bad("thickness_nm", field, "is not a thickness in [0, 1e9] nm"));
        }
        if !(0.0..90.0).contains(&angle) {
            let field = row.get("angle_deg").unwrap_or_default();
            return Err(row.bad("angle_deg", field, "is outside [0, 90)"));
        }
        queries.push((d, angle));
    }
    let lines: Vec<String> = queries
        .par_iter()
        .map(|&(d, angle)| colour.xyz(d, angle).map(|xyz| format_row(d, angle, xyz)))
        .collect::<Result<_, _>>()?;
    let mut out = String::from("thickness_nm,angle_deg,x,y,z,r_lin,g_lin,b_lin,srgb_hex\n");
    for line in lines {
        out.push_str(&line);
    }
    Ok(out)
}

/// One output line.
fn format_row(thickness_nm: f64, angle_deg: f64, xyz: [f64; 3]) -> String {
    let rgb = apply(&SRGB_FROM_XYZ, xyz);
    let mut line = format!("{thickness_nm},{angle_deg}");
    for v in xyz.into_iter().chain(rgb) {
        // Writing to a String cannot fail.
        let _ = write!(line, ",{v:.8}");
    }
    let _ = writeln!(line, ",{}", hex(srgb8_from_linear(rgb)));
    line
}

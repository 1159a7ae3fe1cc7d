//! `bubbles bake`: bakes the reflectivity, transmittance and light-source tables and
//! writes them as EXR / 16-bit PNG (/ 8-bit preview PNG) with a `lut.json` description.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use lut::{BakeConfig, Format, Light};
use thinfilm::cmf::Observer;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::illuminant::Illuminant;

use crate::error::{CliError, CliResult};
use crate::limits;
use crate::scene::values::{Bounds, FilmIndex, FilmThickness, plain};

/// Bakes with more spectral samples than this show a progress bar (about a second).
const PROGRESS_THRESHOLD_SAMPLES: u64 = 500_000_000;

/// Arguments of `bubbles bake`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Directory to write the tables and lut.json into (created if missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Table size: thickness columns x cos θ rows, each 2..=16384.
    #[arg(long, value_name = "WxH", default_value_t = Resolution::DEFAULT)]
    resolution: Resolution,
    /// Thickness of the last column, in nm (the first is 0), 1..=100000.
    #[arg(long, value_name = "N", default_value_t = f64::from(lut::config::DEFAULT_THICKNESS_MAX_NM), allow_negative_numbers = true)]
    thickness_max_nm: f64,
    /// Lights to bake a light-source table for: a built-in name (d65, d50, a, e, f2, f11,
    /// sodium) or a CSV spectrum file (header `wavelength_nm,value`). Repeatable.
    #[arg(long = "illuminant", value_name = "NAME|PATH.csv", num_args = 1.., default_value = "sodium")]
    illuminants: Vec<String>,
    /// White light the reflectivity and transmittance tables are normalised to.
    #[arg(long, value_name = "NAME|PATH.csv", default_value = "d65")]
    reference: String,
    /// Output formats, comma-separated: exr, png16, png8 (sRGB preview).
    #[arg(long, value_name = "LIST", default_value = "exr,png16")]
    format: String,
    /// Constant film refractive index, 1..=4 (default: soap film with dispersion).
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        conflicts_with = "water_dispersion"
    )]
    n_film: Option<f64>,
    /// Use the dispersion of pure water for the film.
    #[arg(long)]
    water_dispersion: bool,
    /// CIE observer: 1931 (2°) or 1964 (10°).
    #[arg(long, value_name = "1931|1964", default_value = "1931")]
    observer: String,
    /// Spacing of the integration wavelengths, in nm.
    #[arg(long, value_name = "NM", default_value_t = lut::config::DEFAULT_STEP_NM, allow_negative_numbers = true)]
    step_nm: f64,
}

/// Runs `bubbles bake`.
pub fn run(args: Args) -> CliResult {
    let formats = Format::parse_list(&args.format).map_err(|e| CliError::input(e.to_string()))?;
    check_numbers(&args)?;
    let config = config_from(&args)?;
    check_memory(&config, &formats)?;
    crate::output::check_dir("--out", &args.out)?;
    let set = bake_with_bar(&config);
    let written = set.save(&args.out, &formats).map_err(|e| match e {
        lut::SaveError::Encode { .. } => CliError::runtime(e.to_string()),
        _ => CliError::input(e.to_string()),
    })?;
    let mut report = String::new();
    for path in &written {
        let _ = writeln!(report, "{}", path.display());
    }
    print!("{report}");
    Ok(())
}

/// Refuses, by flag and value, every number outside the range in which the bake stays
/// finite and physical, before anything narrows it to f32 or prints it in full.
fn check_numbers(args: &Args) -> Result<(), CliError> {
    let thickness = FilmThickness::MIN..=f64::from(lut::config::MAX_THICKNESS_NM);
    check_range(
        "--thickness-max-nm",
        args.thickness_max_nm,
        &thickness,
        "nm",
    )?;
    if let Some(n) = args.n_film {
        check_range("--n-film", n, &(FilmIndex::MIN..=FilmIndex::MAX), "")?;
    }
    check_range("--step-nm", args.step_nm, &lut::config::STEP_RANGE_NM, "nm")
}

/// `value` of `flag` must lie in `range` (NaN never does); the message names both.
fn check_range(
    flag: &str,
    value: f64,
    range: &std::ops::RangeInclusive<f64>,
    unit: &str,
) -> Result<(), CliError> {
    if range.contains(&value) {
        return Ok(());
    }
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    Err(CliError::input(format!(
        "{flag} {} is out of range: it must be in {}..={}{unit}",
        plain(value),
        plain(*range.start()),
        plain(*range.end())
    )))
}

/// Refuses a bake whose tables and largest writer would pass the planned-memory limit.
fn check_memory(config: &BakeConfig, formats: &[Format]) -> Result<(), CliError> {
    let bytes = limits::bake_bytes(
        config.width(),
        config.height(),
        config.lights().len(),
        formats,
    );
    if bytes > limits::MEMORY_BUDGET_BYTES {
        return Err(CliError::input(format!(
            "bake of {} tables of {}x{} texels in {} plans {:.2} GiB, above the {} GiB memory limit (see --help): lower --resolution or bake fewer --illuminant or --format",
            2 + config.lights().len(),
            config.width(),
            config.height(),
            formats
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(","),
            bytes as f64 / f64::from(1u32 << 30),
            limits::MEMORY_BUDGET_BYTES >> 30
        )));
    }
    Ok(())
}

/// Builds and validates the bake configuration from the flags.
fn config_from(args: &Args) -> Result<BakeConfig, CliError> {
    let Resolution { width, height } = args.resolution;
    let observer = Observer::from_name(&args.observer).ok_or_else(|| {
        CliError::input(format!(
            "unknown observer {:?}: valid observers are 1931 and 1964",
            args.observer
        ))
    })?;
    let film_index = match (args.n_film, args.water_dispersion) {
        (Some(n), _) => RefractiveIndex::Constant(n),
        (None, true) => RefractiveIndex::Water,
        (None, false) => RefractiveIndex::SOAP,
    };
    let lights = args
        .illuminants
        .iter()
        .map(|arg| light_from(arg))
        .collect::<Result<Vec<_>, _>>()?;
    BakeConfig::builder()
        .resolution(width, height)
        // check_numbers bounded it to 1..=1e5 nm, where f32 holds it to 6e-8 relative.
        .thickness_max_nm(args.thickness_max_nm as f32)
        .film_index(film_index)
        .observer(observer)
        .step_nm(args.step_nm)
        .reference(light_from(&args.reference)?)
        .lights(lights)
        .build()
        .map_err(|e| CliError::input(e.to_string()))
}

/// A table size, `WIDTHxHEIGHT` on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Resolution {
    width: usize,
    height: usize,
}

impl Resolution {
    const DEFAULT: Resolution = Resolution {
        width: lut::config::DEFAULT_WIDTH,
        height: lut::config::DEFAULT_HEIGHT,
    };
}

impl std::fmt::Display for Resolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

impl std::str::FromStr for Resolution {
    type Err = String;

    /// Parses `WxH` (also `W×H`), e.g. `512x128`, each side in `2..=MAX_SIDE`.
    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "resolution {text:?} is invalid: expected WIDTHxHEIGHT with each side in 2..={}, e.g. 512x128",
                lut::MAX_SIDE
            )
        };
        let (w, h) = text.split_once(['x', 'X', '×']).ok_or_else(bad)?;
        let side = |s: &str| s.trim().parse::<usize>().map_err(|_| bad());
        let (width, height) = (side(w)?, side(h)?);
        let sides = 2..=lut::MAX_SIDE;
        if !sides.contains(&width) || !sides.contains(&height) {
            return Err(bad());
        }
        Ok(Self { width, height })
    }
}

/// A built-in illuminant by name, or a CSV spectrum file if the argument looks like a path.
fn light_from(arg: &str) -> Result<Light, CliError> {
    let path = Path::new(arg);
    let looks_like_path = arg.contains(['/', '\\'])
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if looks_like_path {
        crate::scene::check_spectrum_file(path)?;
        return Light::try_from_csv_path(path).map_err(|e| CliError::input(e.to_string()));
    }
    Illuminant::from_name(arg)
        .map(Light::illuminant)
        .map_err(|e| CliError::input(format!("{e}; or give a path to a .csv spectrum")))
}

/// Bakes, drawing a progress bar on stderr when the bake is large.
fn bake_with_bar(config: &BakeConfig) -> lut::LutSet {
    let rows = lut::progress_rows(config);
    if lut::spectral_samples(config) < PROGRESS_THRESHOLD_SAMPLES {
        return lut::bake(config);
    }
    let bar = ProgressBar::with_draw_target(Some(rows as u64), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("baking {bar:40} {pos}/{len} rows {elapsed}") {
        bar.set_style(style);
    }
    let set = lut::bake_with_progress(config, &|| bar.inc(1));
    bar.finish_and_clear();
    set
}

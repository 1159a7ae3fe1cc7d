//! `bubbles reflectance`: spectral reflectance and transmittance of a film
//! `outside | film | outside`, exact (Airy sum of all orders, f64), or of any multilayer
//! stack with absorbing media (`--stack`, see [`stack`]), from CSV on stdin or from flags
//! for one query.
//!
//! Film input columns: `thickness_nm,angle_deg,wavelength_nm[,n_film]`, in any order.
//! Output: `thickness_nm,angle_deg,wavelength_nm,n_film,r_s,r_p,r,t` with full f64
//! precision (shortest round-trip decimal); `r` is the unpolarised mean and `t` the
//! unpolarised transmittance, computed from the transmitted amplitudes (not `1 − r`).
//! Stack input columns: `angle_deg,wavelength_nm[,thickness_nm]`; output adds the
//! absorbed fraction `a = 1 − r − t`.

pub(crate) mod stack;

use std::fmt::Write as _;
use std::io::{Read as _, Write as _};

use crate::limits::{MAX_INDEX, MAX_LAYER_THICKNESS_NM, MIN_INDEX};
use thinfilm::Incidence;
use thinfilm::airy::ThinFilm;
use thinfilm::dispersion::{CONSTANT_RANGE_NM, RefractiveIndex};

use crate::csv_table::{CsvRow, CsvTable};
use crate::error::{CliError, CliResult};
use crate::scene::values::plain;

/// The film index used when neither a column nor `--n-film` gives one.
const DEFAULT_N_FILM: f64 = 1.33;
/// Wavelengths accepted for a film, in nm: the range of a constant index.
const WAVELENGTH_RANGE_NM: [f64; 2] = CONSTANT_RANGE_NM;
const HEADER: &str = "thickness_nm,angle_deg,wavelength_nm,n_film,r_s,r_p,r,t";

/// Arguments of `bubbles reflectance`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Refractive index of the medium on both sides of the film.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1.0,
        allow_negative_numbers = true,
        conflicts_with = "stack"
    )]
    n_outside: f64,
    /// Film thickness in nm (single query; with --angle-deg and --wavelength-nm); with
    /// --stack, overrides the thickness of the --vary-layer layer.
    #[arg(long, value_name = "NM", allow_negative_numbers = true)]
    thickness_nm: Option<f64>,
    /// Angle of incidence in degrees, in [0, 90) (single query).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    angle_deg: Option<f64>,
    /// Vacuum wavelength in nm, in [100, 100000] for a constant index, else the range of
    /// the index models (single query).
    #[arg(long, value_name = "NM", allow_negative_numbers = true)]
    wavelength_nm: Option<f64>,
    /// Film refractive index [default: 1.33]; on stdin, used for rows when the CSV has no
    /// n_film column.
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        conflicts_with = "stack"
    )]
    n_film: Option<f64>,
    /// A multilayer stack, e.g. "1.0 | 1.38 @ 100 | 2.1 @ 60 | 0.18+3.4i": media from the
    /// incidence side, inner layers as `index @ thickness_nm`, or `index @ thickness_nm
    /// incoherent` for a layer whose reflections add in intensity (a 1 mm slide:
    /// `1.52 @ 1e6 incoherent`); an index is a number, a+bi, `water` or a
    /// `wavelength_nm,n,k` CSV file. CSV on stdin then gives
    /// `angle_deg,wavelength_nm[,thickness_nm]`.
    #[arg(long, value_name = "STACK")]
    stack: Option<String>,
    /// The inner layer (1-based) whose thickness a `thickness_nm` column or flag overrides.
    #[arg(long, value_name = "K", default_value_t = 1, requires = "stack")]
    vary_layer: usize,
    /// A graded layer (`linear(a, b) @ d`, `exponential(a, b) @ d` or `graded(PATH)` in
    /// --stack) is sliced until its estimated error in R and T is at most this.
    #[arg(long, value_name = "TOL", default_value_t = 1e-9, requires = "stack")]
    graded_tolerance: f64,
}

/// One validated query, with the input line it came from (0 for flags).
#[derive(Debug, Clone, Copy)]
struct Query {
    line: usize,
    thickness_nm: f64,
    angle_deg: f64,
    wavelength_nm: f64,
    n_film: f64,
}

/// Runs `bubbles reflectance`.
pub fn run(args: Args) -> CliResult {
    let table = match &args.stack {
        Some(text) => run_stack(text, &args)?,
        None => run_film(&args)?,
    };
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(table.as_bytes())
        .and_then(|()| stdout.flush())
        .map_err(|e| CliError::runtime(format!("cannot write to stdout: {e}")))
}

fn run_stack(text: &str, args: &Args) -> Result<String, CliError> {
    let (parsed, graded) = stack::parse_stack_graded(text)?;
    if !(args.graded_tolerance.is_finite() && args.graded_tolerance > 0.0) {
        return Err(CliError::input(format!(
            "--graded-tolerance {} is not finite and > 0",
            plain(args.graded_tolerance)
        )));
    }
    let queries = match (args.angle_deg, args.wavelength_nm) {
        (None, None) if args.thickness_nm.is_none() => stack::queries_from_csv(&read_stdin()?)?,
        (Some(angle_deg), Some(wavelength_nm)) => {
            if let Some(d) = args.thickness_nm {
                check_thickness(d).map_err(|what| {
                    CliError::input(format!("--thickness-nm {} {what}", plain(d)))
                })?;
            }
            vec![stack::StackQuery {
                line: 0,
                angle_deg,
                wavelength_nm,
                thickness_nm: args.thickness_nm,
            }]
        }
        _ => {
            return Err(CliError::input(
                "a single --stack query needs both --angle-deg and --wavelength-nm \
                 (or give neither and pipe CSV on stdin)",
            ));
        }
    };
    stack::render(
        &parsed,
        graded.as_ref(),
        args.graded_tolerance,
        args.vary_layer,
        &queries,
    )
}

fn read_stdin() -> Result<String, CliError> {
    let mut text = String::new();
    std::io::stdin()
        .read_to_string(&mut text)
        .map_err(|e| CliError::input(format!("cannot read CSV from stdin: {e}")))?;
    Ok(text)
}

fn run_film(args: &Args) -> Result<String, CliError> {
    check_index(args.n_outside)
        .map_err(|what| CliError::input(format!("--n-outside {} {what}", plain(args.n_outside))))?;
    let n_film_default = args.n_film.unwrap_or(DEFAULT_N_FILM);
    check_index(n_film_default)
        .map_err(|what| CliError::input(format!("--n-film {} {what}", plain(n_film_default))))?;
    let queries = match (args.thickness_nm, args.angle_deg, args.wavelength_nm) {
        (None, None, None) => queries_from_stdin(n_film_default)?,
        (Some(thickness_nm), Some(angle_deg), Some(wavelength_nm)) => {
            vec![query_from_flags(
                thickness_nm,
                angle_deg,
                wavelength_nm,
                n_film_default,
            )?]
        }
        _ => {
            return Err(CliError::input(
                "a single query needs all of --thickness-nm, --angle-deg and --wavelength-nm \
                 (or give none of them and pipe CSV on stdin)",
            ));
        }
    };
    render(args.n_outside, &queries)
}

fn queries_from_stdin(n_film_default: f64) -> Result<Vec<Query>, CliError> {
    let text = read_stdin()?;
    let table = CsvTable::parse(
        &text,
        &["thickness_nm", "angle_deg", "wavelength_nm"],
        &["n_film"],
    )?;
    table
        .rows()
        .map(|row| query_from_row(&row, n_film_default))
        .collect()
}

fn query_from_row(row: &CsvRow<'_>, n_film_default: f64) -> Result<Query, CliError> {
    let checked = |column: &str, value: f64, check: fn(f64) -> Result<(), &'static str>| {
        check(value).map_err(|what| row.bad(column, row.get(column).unwrap_or_default(), what))?;
        Ok::<f64, CliError>(value)
    };
    let n_film = checked(
        "n_film",
        row.number_or("n_film", n_film_default)?,
        check_index,
    )?;
    Ok(Query {
        line: row.line(),
        thickness_nm: checked("thickness_nm", row.number("thickness_nm")?, check_thickness)?,
        angle_deg: checked("angle_deg", row.number("angle_deg")?, check_angle)?,
        wavelength_nm: checked(
            "wavelength_nm",
            row.number("wavelength_nm")?,
            check_wavelength,
        )?,
        n_film,
    })
}

fn query_from_flags(
    thickness_nm: f64,
    angle_deg: f64,
    wavelength_nm: f64,
    n_film: f64,
) -> Result<Query, CliError> {
    let flag = |name: &str, value: f64, check: fn(f64) -> Result<(), &'static str>| {
        check(value).map_err(|what| CliError::input(format!("{name} {} {what}", plain(value))))
    };
    flag("--thickness-nm", thickness_nm, check_thickness)?;
    flag("--angle-deg", angle_deg, check_angle)?;
    flag("--wavelength-nm", wavelength_nm, check_wavelength)?;
    flag("--n-film", n_film, check_index)?;
    Ok(Query {
        line: 0,
        thickness_nm,
        angle_deg,
        wavelength_nm,
        n_film,
    })
}

/// A layer thickness the optics keep physical: in `0..=MAX_LAYER_THICKNESS_NM` (1e9 nm).
pub(crate) fn check_thickness(thickness_nm: f64) -> Result<(), &'static str> {
    if (0.0..=MAX_LAYER_THICKNESS_NM).contains(&thickness_nm) {
        Ok(())
    } else {
        Err("is not a thickness in [0, 1e9] nm")
    }
}

fn check_angle(angle_deg: f64) -> Result<(), &'static str> {
    if (0.0..90.0).contains(&angle_deg) {
        Ok(())
    } else {
        Err("is not an angle in [0, 90) degrees")
    }
}

fn check_wavelength(wavelength_nm: f64) -> Result<(), &'static str> {
    let [lo, hi] = WAVELENGTH_RANGE_NM;
    if (lo..=hi).contains(&wavelength_nm) {
        Ok(())
    } else {
        Err("is not a wavelength in [100, 100000] nm (the range of a constant index)")
    }
}

fn check_index(n: f64) -> Result<(), &'static str> {
    if (MIN_INDEX..=MAX_INDEX).contains(&n) {
        Ok(())
    } else {
        Err("is not a refractive index in [0.001, 1e6]")
    }
}

/// The whole output CSV, built before anything is printed.
fn render(n_outside: f64, queries: &[Query]) -> Result<String, CliError> {
    let mut out = String::with_capacity(64 * (queries.len() + 1));
    out.push_str(HEADER);
    out.push('\n');
    for q in queries {
        let film = ThinFilm::symmetric(
            n_outside,
            RefractiveIndex::Constant(q.n_film),
            q.thickness_nm,
        );
        let incidence = Incidence::try_from_angle_deg(q.angle_deg)
            .map_err(|e| CliError::input(format!("line {}: {e}", q.line)))?;
        let resp = film
            .try_response_at(q.wavelength_nm, incidence)
            .map_err(|e| CliError::input(format!("line {}: {e}", q.line)))?;
        // Writing to a String cannot fail.
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{}",
            q.thickness_nm,
            q.angle_deg,
            q.wavelength_nm,
            q.n_film,
            resp.r_s,
            resp.r_p,
            resp.r(),
            resp.t()
        );
    }
    Ok(out)
}

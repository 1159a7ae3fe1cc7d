//! `bubbles fit`: the thickness of a film, or of one layer of a stack, fitted to a measured
//! reflectance spectrum (`thinfilm::fit`: global search over the fringe order, 95 %
//! interval, residual).
//!
//! Input: `--spectrum F.csv` with columns `wavelength_nm,r` (unpolarised reflectance; `-`
//! reads stdin). Output: one CSV row
//! `thickness_nm,low_nm,high_nm,sigma_nm,systematic_nm,offset,rms_residual,runner_up_nm,runner_up_rms`.
//! With `--cauchy-a LO,HI` (and optionally `--cauchy-b-nm2 LO,HI`) the layer's index is
//! fitted too, as `a + b/λ²` (`thinfilm::fit::fit_thickness_and_index`), and the row is
//! `thickness_nm,low_nm,high_nm,sigma_nm,systematic_nm,a,a_low,a_high,a_sigma,a_systematic,
//! b_nm2,b_low,b_high,b_sigma,b_systematic,offset,rms_residual`.

use std::io::{Read as _, Write as _};

use thinfilm::dispersion::RefractiveIndex;
use thinfilm::fit::{
    CauchyRange, Fit, IndexFit, Measurement, Search, fit_thickness, fit_thickness_and_index,
};
use thinfilm::{Incidence, Layer, Stack};

use crate::csv_table::CsvTable;
use crate::error::{CliError, CliResult};
use crate::scene::values::plain;

/// Arguments of `bubbles fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The measured spectrum: CSV `wavelength_nm,r` (`-` for stdin).
    #[arg(long, value_name = "FILE")]
    spectrum: String,
    /// Film index of a free film `n_outside | n_film | n_outside` (without --stack).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1.33,
        conflicts_with = "stack"
    )]
    n_film: f64,
    /// Index on both sides of a free film (without --stack).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1.0,
        conflicts_with = "stack"
    )]
    n_outside: f64,
    /// A stack in `bubbles reflectance --stack` syntax; the thickness of layer
    /// --vary-layer is fitted (its written thickness is ignored).
    #[arg(long, value_name = "STACK")]
    stack: Option<String>,
    /// The inner layer (1-based) whose thickness is fitted.
    #[arg(long, value_name = "K", default_value_t = 1, requires = "stack")]
    vary_layer: usize,
    /// Angle of incidence in degrees, in [0, 90).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    angle_deg: f64,
    /// Thinnest thickness searched, nm.
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    min_nm: f64,
    /// Thickest thickness searched, nm.
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 5000.0,
        allow_negative_numbers = true
    )]
    max_nm: f64,
    /// Uncertainty of the spectrometer's wavelength calibration, nm (widens the interval).
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    wavelength_uncertainty_nm: f64,
    /// Fit the layer's index too, as Cauchy's `a + b/λ²`, with `a` in `LO,HI`.
    #[arg(long, value_name = "LO,HI", num_args = 1, value_delimiter = ',')]
    cauchy_a: Option<Vec<f64>>,
    /// With --cauchy-a: the range of Cauchy's `b` in nm² (default 0,10000).
    #[arg(
        long,
        value_name = "LO,HI",
        num_args = 1,
        value_delimiter = ',',
        requires = "cauchy_a"
    )]
    cauchy_b_nm2: Option<Vec<f64>>,
}

/// A `LO,HI` flag's pair, or an error naming the flag.
fn pair(flag: &str, values: &[f64]) -> Result<[f64; 2], CliError> {
    match values {
        [lo, hi] => Ok([*lo, *hi]),
        _ => Err(CliError::input(format!(
            "{flag} takes two numbers LO,HI, not {} value(s)",
            values.len()
        ))),
    }
}

/// Runs `bubbles fit`.
pub fn run(args: Args) -> CliResult {
    let text = if args.spectrum == "-" {
        let mut text = String::new();
        std::io::stdin()
            .read_to_string(&mut text)
            .map_err(|e| CliError::input(format!("cannot read the spectrum from stdin: {e}")))?;
        text
    } else {
        std::fs::read_to_string(&args.spectrum)
            .map_err(|e| CliError::input(format!("--spectrum {}: {e}", args.spectrum)))?
    };
    let table = CsvTable::parse(&text, &["wavelength_nm", "r"], &[])?;
    let (mut wavelength_nm, mut reflectance) = (Vec::new(), Vec::new());
    for row in table.rows() {
        wavelength_nm.push(row.number("wavelength_nm")?);
        reflectance.push(row.number("r")?);
    }
    if !(0.0..90.0).contains(&args.angle_deg) {
        return Err(CliError::input(format!(
            "--angle-deg {} is not an angle in [0, 90) degrees",
            plain(args.angle_deg)
        )));
    }
    let incidence = Incidence::try_from_angle_deg(args.angle_deg)
        .map_err(|e| CliError::input(format!("--angle-deg: {e}")))?;
    let (base, layer) = match &args.stack {
        Some(text) => {
            let stack = super::reflectance::stack::parse_stack(text)?;
            if !(1..=stack.layers.len()).contains(&args.vary_layer) {
                return Err(CliError::input(format!(
                    "--vary-layer {} names no layer: the stack has {} inner layer(s)",
                    args.vary_layer,
                    stack.layers.len()
                )));
            }
            (stack, args.vary_layer - 1)
        }
        None => {
            let film = Stack::new(
                args.n_outside,
                vec![Layer::new(args.n_film, 0.0)],
                args.n_outside,
            )
            .map_err(|e| {
                CliError::input(format!(
                    "--n-film {} / --n-outside {}: {e}",
                    plain(args.n_film),
                    plain(args.n_outside)
                ))
            })?;
            (film, 0)
        }
    };
    // The unknown layer's largest real index over the spectrum sets the scan step.
    let n_max = wavelength_nm
        .iter()
        .filter_map(|&w| base.layers[layer].index.try_n_at(w).ok())
        .fold(0.0f64, |m, n| m.max(n.re));
    let measurement = Measurement {
        wavelength_nm: &wavelength_nm,
        reflectance: &reflectance,
        incidence,
        wavelength_uncertainty_nm: args.wavelength_uncertainty_nm,
    };
    let out = if let Some(a) = &args.cauchy_a {
        let b = args.cauchy_b_nm2.as_deref().unwrap_or(&[0.0, 10000.0]);
        let range = CauchyRange {
            a: pair("--cauchy-a", a)?,
            b_nm2: pair("--cauchy-b-nm2", b)?,
        };
        let model = |d: f64, index: RefractiveIndex| {
            let mut stack = base.clone();
            stack.layers[layer] = Layer::new(index, d);
            Ok(stack)
        };
        let fit = fit_thickness_and_index(model, &measurement, args.min_nm, args.max_nm, range)
            .map_err(|e| CliError::input(e.to_string()))?;
        csv_row(&IndexFit::FIELDS, &fit.values())
    } else {
        let model = |d: f64| {
            let mut stack = base.clone();
            stack.layers[layer].thickness_nm = d;
            Ok(stack)
        };
        let search = Search {
            min_nm: args.min_nm,
            max_nm: args.max_nm,
            n_max: if n_max > 0.0 { n_max } else { 1.0 },
        };
        let fit = fit_thickness(model, &measurement, search)
            .map_err(|e| CliError::input(e.to_string()))?;
        csv_row(&Fit::FIELDS, &fit.values())
    };
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(out.as_bytes())
        .and_then(|()| stdout.flush())
        .map_err(|e| CliError::runtime(format!("cannot write to stdout: {e}")))
}

/// A header line and one row of values.
fn csv_row(fields: &[&str], values: &[f64]) -> String {
    let values: Vec<String> = values.iter().map(f64::to_string).collect();
    format!("{}\n{}\n", fields.join(","), values.join(","))
}

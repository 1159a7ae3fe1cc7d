//! `bubbles reflectance --stack`: the stack syntax and its queries.
//!
//! Syntax: media separated by `|`, from the incidence medium to the substrate; the first
//! and last are semi-infinite and give only an index, every one between is
//! `index @ thickness_nm`. An index is a real number (`1.38`), a complex one with `κ ≥ 0`
//! (`0.18+3.4i`), `water` (IAPWS, 200–1100 nm), or the path of a `wavelength_nm,n,k` CSV
//! table. The incidence medium must be a real number (its power flux must be defined).
//! A layer followed by the word `incoherent` (`1.52 @ 1e6 incoherent`, a 1 mm slide) adds
//! its multiple reflections in intensity, not amplitude (Byrnes' `inc_tmm`).
//! One inner layer may be graded-index: `linear(n_front, n_back) @ thickness_nm` (n and
//! κ linear in depth, e.g. `linear(1.0, 1.52) @ 500`), `exponential(n_front, n_back) @
//! thickness_nm` (real), or `graded(PATH)` with a `z_nm,n,k` CSV profile whose last z is
//! the thickness; each query then slices it until the estimated error is within
//! `--graded-tolerance`, reported in an `error_bound` column (`thinfilm::graded`).

use std::fmt::Write as _;
use std::path::Path;

use thinfilm::dispersion::RefractiveIndex;
use thinfilm::graded::{GradedLayer, Profile};
use thinfilm::{Complex64, Incidence, IndexModel, Layer, NkTable, Stack};

use crate::csv_table::{CsvRow, CsvTable};
use crate::error::CliError;

/// Header of the stack output without the optional leading `thickness_nm`.
const HEADER: &str = "angle_deg,wavelength_nm,r_s,r_p,r,t,a";

/// Parses `--stack` text into a validated stack without graded layers.
///
/// # Errors
/// An input error quoting the medium (1-based) and the bad token or value, or naming a
/// graded layer.
pub fn parse_stack(text: &str) -> Result<Stack, CliError> {
    match parse_stack_graded(text)? {
        (stack, None) => Ok(stack),
        (_, Some((k, _))) => Err(CliError::input(format!(
            "--stack \"{text}\": medium {}: a graded layer is not supported here",
            k + 2
        ))),
    }
}

/// A graded token's profile and thickness, or `None` if `medium` is no graded token.
fn parse_graded(medium: &str) -> Option<Result<(Profile, f64), String>> {
    let lower = medium.to_ascii_lowercase();
    if let Some(path) = lower
        .strip_prefix("graded(")
        .and_then(|r| r.strip_suffix(')'))
    {
        let path = &medium[7..7 + path.len()];
        let text = match std::fs::read_to_string(path.trim()) {
            Ok(text) => text,
            Err(e) => return Some(Err(format!("graded profile {}: {e}", path.trim()))),
        };
        return Some(Profile::from_csv(&text).map_err(|e| format!("{}: {e}", path.trim())));
    }
    let kind = ["linear(", "exponential("]
        .into_iter()
        .find(|k| lower.starts_with(k))?;
    let parsed = (|| {
        let (inner, thickness) = medium[kind.len()..]
            .split_once(')')
            .ok_or_else(|| format!("`{medium}` lacks its `)`"))?;
        let (front, back) = inner
            .split_once(',')
            .ok_or_else(|| format!("`{inner}` is not `n_front, n_back`"))?;
        let thickness = thickness
            .trim()
            .strip_prefix('@')
            .ok_or_else(|| format!("`{medium}` is not `{kind}n_front, n_back) @ thickness_nm`"))?
            .trim();
        let thickness_nm = parse_thickness(thickness)?;
        let index = |t: &str| {
            let t = t.trim();
            parse_real(t)
                .map(Complex64::from)
                .or_else(|| parse_complex(t))
                .ok_or_else(|| format!("`{t}` is not an index"))
        };
        let (front, back) = (index(front)?, index(back)?);
        let profile = if kind == "linear(" {
            Profile::Linear { front, back }
        } else {
            if front.im != 0.0 || back.im != 0.0 {
                return Err(format!("an exponential profile is real: `{inner}`"));
            }
            Profile::Exponential {
                front: front.re,
                back: back.re,
            }
        };
        Ok((profile, thickness_nm))
    })();
    Some(parsed)
}

/// Parses `--stack` text into a validated stack and its graded layer, if any: its position
/// among the inner layers (0-based) and the layer, whose place in the stack holds a
/// homogeneous stand-in of its front index and thickness.
///
/// # Errors
/// An input error quoting the medium (1-based) and the bad token or value.
#[allow(clippy::type_complexity)]
pub fn parse_stack_graded(text: &str) -> Result<(Stack, Option<(usize, GradedLayer)>), CliError> {
    let media: Vec<&str> = text.split('|').map(str::trim).collect();
    let bad = |k: usize, what: String| {
        CliError::input(format!("--stack \"{text}\": medium {}: {what}", k + 1))
    };
    if media.len() < 2 {
        return Err(bad(
            0,
            "needs at least an incidence medium and a substrate separated by `|`".into(),
        ));
    }
    let last = media.len() - 1;
    let n_incident = parse_real(media[0]).ok_or_else(|| {
        bad(
            0,
            format!(
                "`{}` is not a real index (the incidence medium must be one)",
                media[0]
            ),
        )
    })?;
    let mut layers = Vec::new();
    let mut graded = None;
    for (k, medium) in media.iter().enumerate().take(last).skip(1) {
        if let Some(parsed) = parse_graded(medium) {
            let (profile, thickness_nm) = parsed.map_err(|e| bad(k, e))?;
            let front = profile.index_at(0.0);
            let layer =
                GradedLayer::try_new(profile, thickness_nm).map_err(|e| bad(k, e.to_string()))?;
            if graded.is_some() {
                return Err(bad(k, "only one layer may be graded".into()));
            }
            graded = Some((k - 1, layer));
            layers.push(Layer::new(front, thickness_nm));
            continue;
        }
        let Some((index, thickness)) = medium.split_once('@') else {
            return Err(bad(k, format!("`{medium}` is not `index @ thickness_nm`")));
        };
        let index = parse_index(index.trim()).map_err(|e| bad(k, e))?;
        let (thickness, coherent) = match thickness.trim().rsplit_once(char::is_whitespace) {
            Some((d, word)) if word.eq_ignore_ascii_case("incoherent") => (d.trim(), false),
            _ => (thickness.trim(), true),
        };
        let thickness_nm = parse_thickness(thickness).map_err(|e| bad(k, e))?;
        layers.push(Layer {
            coherent,
            ..Layer::new(index, thickness_nm)
        });
    }
    let substrate = parse_index(media[last]).map_err(|e| bad(last, e))?;
    let stack = Stack::new(n_incident, layers, substrate)
        .map_err(|e| CliError::input(format!("--stack \"{text}\": {e}")))?;
    Ok((stack, graded))
}

/// A layer thickness token, in `0..=MAX_THICKNESS_NM` nm.
fn parse_thickness(token: &str) -> Result<f64, String> {
    parse_real(token)
        .filter(|d| super::check_thickness(*d).is_ok())
        .ok_or_else(|| format!("thickness `{token}` is not a number in [0, 1e9] nm"))
}

fn parse_real(token: &str) -> Option<f64> {
    token.parse::<f64>().ok().filter(|x| x.is_finite())
}

/// One index token: a real, `a+bi`, `water`, or a CSV table path.
fn parse_index(token: &str) -> Result<IndexModel, String> {
    if token.eq_ignore_ascii_case("water") {
        return Ok(RefractiveIndex::Water.into());
    }
    if token.to_ascii_lowercase().ends_with(".csv") {
        return NkTable::from_csv_path(Path::new(token))
            .map(IndexModel::from)
            .map_err(|e| e.to_string());
    }
    let model = if let Some(n) = parse_real(token) {
        IndexModel::from(n)
    } else {
        IndexModel::from(parse_complex(token).ok_or_else(|| {
            format!("`{token}` is not an index (a number, a+bi, water, or a .csv n,k table)")
        })?)
    };
    model.validate().map(|()| model).map_err(|e| e.to_string())
}

/// `a+bi` or `a-bi` (the sign splits at its last `+`/`-` that is not an exponent's).
fn parse_complex(token: &str) -> Option<Complex64> {
    let body = token.strip_suffix(['i', 'j'])?;
    let bytes = body.as_bytes();
    let split = (1..bytes.len())
        .rev()
        .find(|&k| matches!(bytes[k], b'+' | b'-') && !matches!(bytes[k - 1], b'e' | b'E'))?;
    let re = parse_real(&body[..split])?;
    let im_text = &body[split..];
    let im = parse_real(im_text.strip_prefix('+').unwrap_or(im_text))?;
    Some(Complex64::new(re, im))
}

/// One stack query: the angle, wavelength and the varied layer's thickness, if any.
#[derive(Debug, Clone, Copy)]
pub struct StackQuery {
    /// Input line (0 for flags).
    pub line: usize,
    /// Incidence angle in degrees.
    pub angle_deg: f64,
    /// Vacuum wavelength in nm.
    pub wavelength_nm: f64,
    /// Thickness override for the varied layer, in nm.
    pub thickness_nm: Option<f64>,
}

/// Queries from CSV `angle_deg,wavelength_nm[,thickness_nm]` text.
pub fn queries_from_csv(text: &str) -> Result<Vec<StackQuery>, CliError> {
    let table = CsvTable::parse(text, &["angle_deg", "wavelength_nm"], &["thickness_nm"])?;
    let has_thickness = table.has_column("thickness_nm");
    table
        .rows()
        .map(|row| {
            Ok(StackQuery {
                line: row.line(),
                angle_deg: row.number("angle_deg")?,
                wavelength_nm: row.number("wavelength_nm")?,
                thickness_nm: has_thickness.then(|| thickness(&row)).transpose()?,
            })
        })
        .collect()
}

fn thickness(row: &CsvRow<'_>) -> Result<f64, CliError> {
    let d = row.number("thickness_nm")?;
    super::check_thickness(d).map(|()| d).map_err(|what| {
        row.bad(
            "thickness_nm",
            row.get("thickness_nm").unwrap_or_default(),
            what,
        )
    })
}

/// The output CSV for `queries` on `stack`, varying layer `vary_layer` (1-based) where a
/// query overrides a thickness. Built whole before anything is printed.
pub fn render(
    stack: &Stack,
    graded: Option<&(usize, GradedLayer)>,
    tolerance: f64,
    vary_layer: usize,
    queries: &[StackQuery],
) -> Result<String, CliError> {
    if let Some(&(k, _)) = graded {
        if queries.iter().any(|q| q.thickness_nm.is_some()) && vary_layer == k + 1 {
            return Err(CliError::input(format!(
                "--vary-layer {vary_layer} names the graded layer, whose thickness is its profile's"
            )));
        }
    }
    let with_thickness = queries.iter().any(|q| q.thickness_nm.is_some());
    if with_thickness && !(1..=stack.layers.len()).contains(&vary_layer) {
        return Err(CliError::input(format!(
            "--vary-layer {vary_layer} names no layer: the stack has {} inner layer(s)",
            stack.layers.len()
        )));
    }
    let mut out = String::new();
    if with_thickness {
        out.push_str("thickness_nm,");
    }
    out.push_str(HEADER);
    if graded.is_some() {
        out.push_str(",error_bound");
    }
    out.push('\n');
    let mut varied = stack.clone();
    for q in queries {
        let at = |what: String| {
            let place = if q.line == 0 {
                "flags".to_string()
            } else {
                format!("line {}", q.line)
            };
            CliError::input(format!("{place}: {what}"))
        };
        let incidence = Incidence::try_from_angle_deg(q.angle_deg)
            .ok()
            .filter(|_| q.angle_deg < 90.0)
            .ok_or_else(|| {
                at(format!(
                    "angle_deg {} is not in [0, 90)",
                    crate::scene::values::plain(q.angle_deg)
                ))
            })?;
        if let Some(d) = q.thickness_nm {
            varied.layers[vary_layer - 1].thickness_nm = d;
            let _ = write!(out, "{d},");
        }
        let (resp, bound) = match graded {
            None => (
                varied
                    .try_response_at(q.wavelength_nm, incidence)
                    .map_err(|e| at(e.to_string()))?,
                None,
            ),
            Some((k, layer)) => {
                let with = |slices: Vec<Layer>| {
                    let mut s = varied.clone();
                    s.layers.splice(*k..=*k, slices);
                    Ok(s)
                };
                let c = layer
                    .converged_response(with, q.wavelength_nm, incidence, tolerance)
                    .map_err(|e| at(e.to_string()))?;
                (c.response, Some(c.error_bound))
            }
        };
        let _ = write!(
            out,
            "{},{},{},{},{},{},{}",
            q.angle_deg,
            q.wavelength_nm,
            resp.r_s,
            resp.r_p,
            resp.r(),
            resp.t(),
            resp.absorptance()
        );
        if let Some(bound) = bound {
            let _ = write!(out, ",{bound}");
        }
        out.push('\n');
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn complex_tokens_parse_with_exponents_and_signs() {
        assert_eq!(parse_complex("0.18+3.4i"), Some(Complex64::new(0.18, 3.4)));
        assert_eq!(parse_complex("1e-1+2E+1i"), Some(Complex64::new(0.1, 20.0)));
        assert_eq!(parse_complex("1.5-0.1i"), Some(Complex64::new(1.5, -0.1)));
        assert_eq!(parse_complex("1.5"), None);
        assert_eq!(parse_complex("+3i"), None);
    }

    #[test]
    fn incoherent_word_marks_a_layer() {
        let stack = parse_stack("1.0 | 1.33 @ 300 | 1.52 @ 1e6 INCOHERENT | 1.0").unwrap();
        let flags: Vec<bool> = stack.layers.iter().map(|l| l.coherent).collect();
        assert_eq!(flags, [true, false]);
        assert_eq!(stack.layers[1].thickness_nm, 1e6);
        let err = parse_stack("1.0 | 1.52 @ 1e6 incoherant | 1.0").unwrap_err();
        assert!(err.to_string().contains("1e6 incoherant"), "{err}");
    }

    #[test]
    fn stack_syntax_gives_the_layers_in_order() {
        let stack = parse_stack("1.0 | 1.38 @ 100 | 2.1 @ 60 | 0.18+3.4i").unwrap();
        assert_eq!(stack.n_incident, 1.0);
        let d: Vec<f64> = stack.layers.iter().map(|l| l.thickness_nm).collect();
        assert_eq!(d, [100.0, 60.0]);
        assert!(stack.layers.iter().all(|layer| layer.coherent));
        assert_eq!(
            stack.n_substrate.as_constant(),
            Some(Complex64::new(0.18, 3.4))
        );
    }
}

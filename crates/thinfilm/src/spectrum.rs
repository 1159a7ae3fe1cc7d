//! Spectra: piecewise-linear samples plus optional emission lines.
//!
//! A [`Spectrum`] is what a light source emits (or a surface reflects) per
//! nanometre of wavelength. Its continuous part is a piecewise-linear function
//! through sorted samples and zero outside them; its line part is a list of
//! delta functions `(wavelength_nm, power)`, where `power` is in the units of
//! the continuous part times nanometres. Line spectra such as the low-pressure
//! sodium lamp cannot be sampled on a grid without losing them, so they are
//! kept exact and integrated as delta terms (see [`crate::integrate`]).

use std::fmt;
use std::path::{Path, PathBuf};

/// Why a spectrum could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum SpectrumError {
    /// The wavelength and value vectors have different lengths.
    LengthMismatch {
        /// Number of wavelengths given.
        wavelengths: usize,
        /// Number of values given.
        values: usize,
    },
    /// Fewer than two samples (a piecewise-linear function needs two), or no lines.
    TooFewSamples {
        /// Number of samples (or lines) given.
        count: usize,
    },
    /// A wavelength or value is NaN or infinite, a wavelength is not positive,
    /// or a value is negative.
    BadSample {
        /// Which sample, counted from 0.
        index: usize,
        /// What is wrong, naming the bad value.
        message: String,
    },
    /// A wavelength is not greater than the one before it.
    NotIncreasing {
        /// Which sample, counted from 0.
        index: usize,
        /// The offending wavelength.
        wavelength_nm: f64,
        /// The wavelength of the sample before it.
        previous_nm: f64,
    },
    /// A CSV spectrum is malformed.
    Csv {
        /// The 1-based line number in the text.
        line: usize,
        /// What is wrong, naming the bad value.
        message: String,
    },
    /// A spectrum file could not be read.
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        message: String,
    },
}

impl fmt::Display for SpectrumError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LengthMismatch {
                wavelengths,
                values,
            } => write!(
                f,
                "spectrum has {wavelengths} wavelengths but {values} values"
            ),
            Self::TooFewSamples { count } => write!(
                f,
                "spectrum needs at least 2 samples (or 1 line), got {count}"
            ),
            Self::BadSample { index, message } => write!(f, "spectrum sample {index}: {message}"),
            Self::NotIncreasing {
                index,
                wavelength_nm,
                previous_nm,
            } => write!(
                f,
                "spectrum sample {index}: wavelength_nm {wavelength_nm} is not greater than the previous {previous_nm}"
            ),
            Self::Csv { line, message } => write!(f, "line {line}: {message}"),
            Self::Io { path, message } => {
                write!(f, "cannot read spectrum {}: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for SpectrumError {}

/// A spectral distribution: piecewise-linear samples plus emission lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    wavelength_nm: Vec<f64>,
    value: Vec<f64>,
    lines: Vec<(f64, f64)>,
}

impl Spectrum {
    /// A continuous spectrum through the samples `(wavelength_nm[i], value[i])`.
    ///
    /// # Errors
    /// The vectors differ in length, hold fewer than 2 samples, a wavelength is
    /// not finite and positive, a value is not finite or is negative, or the
    /// wavelengths are not strictly increasing.
    ///
    /// # Guarantees
    /// The spectrum's samples are finite, non-negative and strictly increasing in
    /// wavelength; it has no lines.
    pub fn try_from_samples(
        wavelength_nm: Vec<f64>,
        value: Vec<f64>,
    ) -> Result<Spectrum, SpectrumError> {
        if wavelength_nm.len() != value.len() {
            return Err(SpectrumError::LengthMismatch {
                wavelengths: wavelength_nm.len(),
                values: value.len(),
            });
        }
        if wavelength_nm.len() < 2 {
            return Err(SpectrumError::TooFewSamples {
                count: wavelength_nm.len(),
            });
        }
        for (index, (&w, &v)) in wavelength_nm.iter().zip(&value).enumerate() {
            check_sample(w, v).map_err(|message| SpectrumError::BadSample { index, message })?;
            if index > 0 && w <= wavelength_nm[index - 1] {
                return Err(SpectrumError::NotIncreasing {
                    index,
                    wavelength_nm: w,
                    previous_nm: wavelength_nm[index - 1],
                });
            }
        }
        Ok(Spectrum {
            wavelength_nm,
            value,
            lines: Vec::new(),
        })
    }

    /// A pure line spectrum of `(wavelength_nm, relative power)` delta functions.
    ///
    /// # Errors
    /// No lines, a wavelength not finite and positive, or a power not finite or negative.
    ///
    /// # Guarantees
    /// The lines are sorted by wavelength; the continuous part is zero everywhere.
    pub fn from_lines(mut lines: Vec<(f64, f64)>) -> Result<Spectrum, SpectrumError> {
        if lines.is_empty() {
            return Err(SpectrumError::TooFewSamples { count: 0 });
        }
        for (index, &(w, p)) in lines.iter().enumerate() {
            check_sample(w, p).map_err(|message| SpectrumError::BadSample { index, message })?;
        }
        lines.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(Spectrum {
            wavelength_nm: Vec::new(),
            value: Vec::new(),
            lines,
        })
    }

    /// This spectrum with `lines` added to its emission lines (a fluorescent lamp's
    /// mercury lines over its phosphor continuum, say).
    ///
    /// # Errors
    /// As [`Spectrum::from_lines`], except that an empty list is allowed.
    pub fn try_with_lines(mut self, lines: Vec<(f64, f64)>) -> Result<Spectrum, SpectrumError> {
        if lines.is_empty() {
            return Ok(self);
        }
        let extra = Spectrum::from_lines(lines)?;
        self.lines.extend(extra.lines);
        self.lines.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(self)
    }

    /// Parses CSV text with the header `wavelength_nm,value` and one sample a row.
    ///
    /// Blank lines and lines starting with `#` are skipped.
    ///
    /// # Errors
    /// [`SpectrumError::Csv`] naming the 1-based line and the bad value: a wrong
    /// header, a wrong column count, a non-numeric, non-finite, non-positive
    /// wavelength or negative value, wavelengths not strictly increasing, or
    /// fewer than two rows.
    pub fn from_csv_str(text: &str) -> Result<Spectrum, SpectrumError> {
        let mut rows = text
            .lines()
            .enumerate()
            .map(|(i, line)| (i + 1, line.trim()))
            .filter(|(_, line)| !line.is_empty() && !line.starts_with('#'));
        let csv_err = |line, message: String| SpectrumError::Csv { line, message };
        let (header_line, header) = rows.next().ok_or_else(|| {
            csv_err(
                1,
                "empty spectrum: expected header `wavelength_nm,value`".into(),
            )
        })?;
        let columns: Vec<&str> = header.split(',').map(str::trim).collect();
        if columns != ["wavelength_nm", "value"] {
            return Err(csv_err(
                header_line,
                format!("expected header `wavelength_nm,value`, found `{header}`"),
            ));
        }
        let mut wavelength_nm = Vec::new();
        let mut value = Vec::new();
        let mut last_line = header_line;
        for (line, row) in rows {
            let (w, v) = parse_row(row).map_err(|m| csv_err(line, m))?;
            if let Some(&previous) = wavelength_nm.last()
                && w <= previous
            {
                return Err(csv_err(
                    line,
                    format!("wavelength_nm {w} is not greater than the previous {previous}"),
                ));
            }
            wavelength_nm.push(w);
            value.push(v);
            last_line = line;
        }
        if wavelength_nm.len() < 2 {
            return Err(csv_err(
                last_line,
                format!(
                    "spectrum needs at least 2 rows, found {}",
                    wavelength_nm.len()
                ),
            ));
        }
        Spectrum::try_from_samples(wavelength_nm, value)
    }

    /// Reads a CSV spectrum file (see [`Spectrum::from_csv_str`]).
    ///
    /// # Errors
    /// [`SpectrumError::Io`] if the file cannot be read as UTF-8 text, else as
    /// [`Spectrum::from_csv_str`].
    pub fn from_csv_path(path: &Path) -> Result<Spectrum, SpectrumError> {
        let text = std::fs::read_to_string(path).map_err(|e| SpectrumError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Spectrum::from_csv_str(&text)
    }

    /// The continuous part at `wavelength_nm`, linearly interpolated; 0 outside
    /// its sampled range (and for NaN).
    pub fn value_at(&self, wavelength_nm: f64) -> f64 {
        let w = &self.wavelength_nm;
        let (Some(&first), Some(&last)) = (w.first(), w.last()) else {
            return 0.0;
        };
        // Also rejects NaN, which fails every comparison.
        if !(wavelength_nm >= first && wavelength_nm <= last) {
            return 0.0;
        }
        let upper = w.partition_point(|&x| x < wavelength_nm).max(1);
        let (w0, w1) = (w[upper - 1], w[upper]);
        let (v0, v1) = (self.value[upper - 1], self.value[upper]);
        let t = (wavelength_nm - w0) / (w1 - w0);
        // This form is exact at both ends (t = 0 and t = 1).
        (1.0 - t) * v0 + t * v1
    }

    /// The emission lines `(wavelength_nm, power)`, sorted by wavelength.
    pub fn lines(&self) -> &[(f64, f64)] {
        &self.lines
    }

    /// The continuous part's sample wavelengths (empty for a pure line spectrum).
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelength_nm
    }

    /// The continuous part's sample values, one per [`Spectrum::wavelengths_nm`].
    pub fn values(&self) -> &[f64] {
        &self.value
    }

    /// The same spectrum with every value and line power multiplied by `factor`.
    ///
    /// # Errors
    /// `factor` is negative or not finite.
    pub fn try_scaled(mut self, factor: f64) -> Result<Spectrum, SpectrumError> {
        if !(factor.is_finite() && factor >= 0.0) {
            return Err(SpectrumError::BadSample {
                index: 0,
                message: format!("scale factor {factor} is not finite and non-negative"),
            });
        }
        self.value.iter_mut().for_each(|v| *v *= factor);
        self.lines.iter_mut().for_each(|l| l.1 *= factor);
        Ok(self)
    }
}

/// Checks one `(wavelength, value)` pair, describing the first problem found.
/// The largest spectral value accepted: far above any physical spectrum in any unit, low
/// enough that integrating hundreds of samples against the CIE tables stays finite.
pub const MAX_SPECTRAL_VALUE: f64 = 1e100;

fn check_sample(wavelength_nm: f64, value: f64) -> Result<(), String> {
    if !(wavelength_nm.is_finite() && wavelength_nm > 0.0) {
        return Err(format!(
            "wavelength_nm {wavelength_nm} is not a finite positive number"
        ));
    }
    if !value.is_finite() {
        return Err(format!("value {value} is not finite"));
    }
    if value < 0.0 {
        return Err(format!("value {value} is negative"));
    }
    if value > MAX_SPECTRAL_VALUE {
        return Err(format!(
            "value {value:?} is above {MAX_SPECTRAL_VALUE:?} (scale the spectrum down)"
        ));
    }
    Ok(())
}

/// Parses one CSV data row `wavelength_nm,value` into checked numbers.
fn parse_row(row: &str) -> Result<(f64, f64), String> {
    let fields: Vec<&str> = row.split(',').map(str::trim).collect();
    if fields.len() != 2 {
        return Err(format!(
            "expected 2 columns `wavelength_nm,value`, found {} in `{row}`",
            fields.len()
        ));
    }
    let number = |name: &str, text: &str| {
        text.parse::<f64>()
            .map_err(|_| format!("{name} `{text}` is not a number"))
    };
    let w = number("wavelength_nm", fields[0])?;
    let v = number("value", fields[1])?;
    check_sample(w, v)?;
    Ok((w, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_at_interpolates_linearly_and_is_zero_outside() {
        let s = Spectrum::try_from_samples(vec![400.0, 500.0, 600.0], vec![1.0, 3.0, 2.0]).unwrap();
        assert_eq!(s.value_at(400.0), 1.0);
        assert_eq!(s.value_at(450.0), 2.0);
        assert_eq!(s.value_at(500.0), 3.0);
        assert_eq!(s.value_at(575.0), 2.25);
        assert_eq!(s.value_at(600.0), 2.0);
        assert_eq!(s.value_at(399.9), 0.0);
        assert_eq!(s.value_at(600.1), 0.0);
        assert_eq!(s.value_at(f64::NAN), 0.0);
    }

    #[test]
    fn csv_errors_name_line_and_value() {
        let e = Spectrum::from_csv_str("wavelength_nm,value\n400,1\n\n410,abc\n").unwrap_err();
        assert_eq!(e.to_string(), "line 4: value `abc` is not a number");
        let e = Spectrum::from_csv_str("wavelength_nm,value\n400,1\n410\n").unwrap_err();
        assert!(
            e.to_string().starts_with("line 3: expected 2 columns"),
            "{e}"
        );
        let e = Spectrum::from_csv_str("wavelength_nm,value\n400,1\n390,1\n").unwrap_err();
        assert!(
            e.to_string().contains("line 3") && e.to_string().contains("390"),
            "{e}"
        );
        let e = Spectrum::from_csv_str("wavelength_nm,value\n400,-1\n410,1\n").unwrap_err();
        assert_eq!(e.to_string(), "line 2: value -1 is negative");
        let e = Spectrum::from_csv_str("lambda,value\n400,1\n").unwrap_err();
        assert!(e.to_string().starts_with("line 1: expected header"), "{e}");
        let e = Spectrum::from_csv_str("wavelength_nm,value\n400,1\n").unwrap_err();
        assert!(e.to_string().contains("at least 2 rows"), "{e}");
        let e = Spectrum::from_csv_str("wavelength_nm,value\n400,1\n410,inf\n").unwrap_err();
        assert_eq!(e.to_string(), "line 3: value inf is not finite");
    }

    #[test]
    fn csv_round_trips_samples() {
        let s =
            Spectrum::from_csv_str("# comment\nwavelength_nm, value\n400,1.5\n410, 2\n").unwrap();
        assert_eq!(s.wavelengths_nm(), &[400.0, 410.0]);
        assert_eq!(s.values(), &[1.5, 2.0]);
        assert!(s.lines().is_empty());
    }

    #[test]
    fn constructors_reject_bad_samples() {
        assert!(matches!(
            Spectrum::try_from_samples(vec![400.0], vec![1.0, 2.0]),
            Err(SpectrumError::LengthMismatch { .. })
        ));
        assert!(matches!(
            Spectrum::try_from_samples(vec![400.0, 400.0], vec![1.0, 2.0]),
            Err(SpectrumError::NotIncreasing { index: 1, .. })
        ));
        assert!(matches!(
            Spectrum::try_from_samples(vec![400.0, f64::NAN], vec![1.0, 2.0]),
            Err(SpectrumError::BadSample { index: 1, .. })
        ));
        assert!(Spectrum::from_lines(vec![]).is_err());
        assert!(Spectrum::from_lines(vec![(589.0, -1.0)]).is_err());
        let lines = Spectrum::from_lines(vec![(589.6, 1.0), (589.0, 2.0)]).unwrap();
        assert_eq!(lines.lines(), &[(589.0, 2.0), (589.6, 1.0)]);
        assert_eq!(lines.value_at(589.0), 0.0);
    }
}

//! Complex (absorbing) index models for the layers and substrate of a [`crate::tmm::Stack`]:
//! any real [`RefractiveIndex`], a constant complex index, or a table of `n` and `k`
//! against wavelength (the `wavelength_nm,n,k` CSV of common refractive-index databases).
//!
//! ```
//! use thinfilm::index::{IndexModel, NkTable};
//!
//! let gold = NkTable::from_csv_str("wavelength_nm,n,k\n500,0.97,1.87\n600,0.25,2.98\n").unwrap();
//! let n = IndexModel::from(gold).try_n_at(550.0).unwrap();
//! assert!((n.re - 0.61).abs() < 1e-12 && (n.im - 2.425).abs() < 1e-12);
//! ```

use std::path::Path;
use std::sync::Arc;

use num_complex::Complex64;

use crate::dispersion::{CONSTANT_RANGE_NM, RefractiveIndex, check_in_range};
use crate::fresnel::{self, OpticsError};

/// A complex index `n + iκ` as a function of vacuum wavelength, with the range it covers.
#[derive(Clone, Debug, PartialEq)]
pub enum IndexModel {
    /// A real (lossless) model: constant, Cauchy, Sellmeier or water.
    Real(RefractiveIndex),
    /// The same complex index at every wavelength in [`CONSTANT_RANGE_NM`].
    Complex(Complex64),
    /// Tabulated `n` and `k`, linearly interpolated between rows.
    Tabulated(Arc<NkTable>),
}

impl IndexModel {
    /// Checks the model: the real model's own checks, or a complex index with finite parts,
    /// `Re > 0` and `Im ≥ 0`. Tables are checked when they are built.
    pub fn validate(&self) -> Result<(), OpticsError> {
        match self {
            IndexModel::Real(model) => model.validate(),
            IndexModel::Complex(n) => fresnel::check_complex_index("complex index", *n),
            IndexModel::Tabulated(_) => Ok(()),
        }
    }

    /// The wavelengths (nm) this model covers, `[lo, hi]`.
    pub fn range_nm(&self) -> [f64; 2] {
        match self {
            IndexModel::Real(model) => model.range_nm(),
            IndexModel::Complex(_) => CONSTANT_RANGE_NM,
            IndexModel::Tabulated(table) => table.range_nm(),
        }
    }

    /// The complex index at `wavelength_nm`, or an error naming the wavelength and the
    /// model's range if it lies outside it, or the value if the model gives no valid index.
    pub fn try_n_at(&self, wavelength_nm: f64) -> Result<Complex64, OpticsError> {
        match self {
            IndexModel::Real(model) => model.try_n_at(wavelength_nm).map(Complex64::from),
            IndexModel::Complex(n) => {
                fresnel::check_wavelength(wavelength_nm)?;
                check_in_range("constant index", CONSTANT_RANGE_NM, wavelength_nm)?;
                fresnel::check_complex_index("complex index", *n).map(|()| *n)
            }
            IndexModel::Tabulated(table) => table.try_n_at(wavelength_nm),
        }
    }

    /// The constant index this model always gives, if it is one.
    pub fn as_constant(&self) -> Option<Complex64> {
        match self {
            IndexModel::Real(RefractiveIndex::Constant(n)) => Some(Complex64::from(*n)),
            IndexModel::Complex(n) => Some(*n),
            _ => None,
        }
    }
}

impl From<RefractiveIndex> for IndexModel {
    fn from(model: RefractiveIndex) -> IndexModel {
        IndexModel::Real(model)
    }
}

impl From<f64> for IndexModel {
    fn from(n: f64) -> IndexModel {
        IndexModel::Real(RefractiveIndex::Constant(n))
    }
}

impl From<Complex64> for IndexModel {
    fn from(n: Complex64) -> IndexModel {
        IndexModel::Complex(n)
    }
}

impl From<NkTable> for IndexModel {
    fn from(table: NkTable) -> IndexModel {
        IndexModel::Tabulated(Arc::new(table))
    }
}

/// Rows of `(wavelength_nm, n, k)`, strictly increasing in wavelength.
#[derive(Clone, Debug, PartialEq)]
pub struct NkTable {
    rows: Vec<[f64; 3]>,
}

impl NkTable {
    /// A validated table.
    ///
    /// # Guarantees
    /// At least two rows; wavelengths finite, `> 0` and strictly increasing; every `n`
    /// finite and `> 0`, every `k` finite and `≥ 0`.
    pub fn new(rows: Vec<[f64; 3]>) -> Result<NkTable, OpticsError> {
        let bad = |reason: String| Err(OpticsError::Table { reason });
        if rows.len() < 2 {
            return bad(format!("needs at least 2 rows, found {}", rows.len()));
        }
        for (i, &[w, n, k]) in rows.iter().enumerate() {
            if !(w.is_finite() && w > 0.0) {
                return bad(format!("row {i}: wavelength_nm {w} is not finite and > 0"));
            }
            if !(n.is_finite() && n > 0.0) {
                return bad(format!("row {i}: n {n} is not finite and > 0"));
            }
            if !(k.is_finite() && k >= 0.0) {
                return bad(format!("row {i}: k {k} is not finite and >= 0"));
            }
            if i > 0 && w <= rows[i - 1][0] {
                let previous = rows[i - 1][0];
                return bad(format!(
                    "row {i}: wavelength_nm {w} is not greater than the previous {previous}"
                ));
            }
        }
        Ok(NkTable { rows })
    }

    /// Parses CSV text: the header `wavelength_nm,n,k`, then one row per line. Blank lines
    /// and lines starting with `#` are skipped.
    ///
    /// # Errors
    /// [`OpticsError::Table`] naming the line and the bad field or value.
    pub fn from_csv_str(text: &str) -> Result<NkTable, OpticsError> {
        let bad = |line: usize, message: String| OpticsError::Table {
            reason: format!("line {line}: {message}"),
        };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, line)| (i + 1, line.trim()))
            .filter(|(_, line)| !line.is_empty() && !line.starts_with('#'));
        let (header_line, header) = lines
            .next()
            .ok_or_else(|| bad(1, "empty: expected header `wavelength_nm,n,k`".into()))?;
        let columns: Vec<&str> = header.split(',').map(str::trim).collect();
        if columns != ["wavelength_nm", "n", "k"] {
            let message = format!("expected header `wavelength_nm,n,k`, found `{header}`");
            return Err(bad(header_line, message));
        }
        let mut rows = Vec::new();
        for (line, text) in lines {
            let fields: Vec<&str> = text.split(',').map(str::trim).collect();
            let [w, n, k] = fields[..] else {
                return Err(bad(line, format!("expected 3 fields, found `{text}`")));
            };
            let mut row = [0.0; 3];
            for (slot, (name, field)) in
                row.iter_mut()
                    .zip([("wavelength_nm", w), ("n", n), ("k", k)])
            {
                *slot = field
                    .parse()
                    .map_err(|_| bad(line, format!("{name} `{field}` is not a number")))?;
            }
            rows.push(row);
        }
        // Row numbers in `new`'s messages count data rows; say which line holds the first.
        NkTable::new(rows).map_err(|e| bad(header_line + 1, e.to_string()))
    }

    /// Reads a CSV file (see [`NkTable::from_csv_str`]); errors name the file.
    pub fn from_csv_path(path: &Path) -> Result<NkTable, OpticsError> {
        let name = path.display();
        let text = std::fs::read_to_string(path).map_err(|e| OpticsError::Table {
            reason: format!("{name}: {e}"),
        })?;
        NkTable::from_csv_str(&text).map_err(|e| OpticsError::Table {
            reason: format!("{name}: {e}"),
        })
    }

    /// The tabulated wavelengths' span `[first, last]` in nm.
    pub fn range_nm(&self) -> [f64; 2] {
        [self.rows[0][0], self.rows[self.rows.len() - 1][0]]
    }

    /// The rows `(wavelength_nm, n, k)`.
    pub fn rows(&self) -> &[[f64; 3]] {
        &self.rows
    }

    /// `n + ik` at `wavelength_nm`, linearly interpolated in n and k separately.
    pub fn try_n_at(&self, wavelength_nm: f64) -> Result<Complex64, OpticsError> {
        fresnel::check_wavelength(wavelength_nm)?;
        check_in_range("n,k table", self.range_nm(), wavelength_nm)?;
        let upper = self
            .rows
            .partition_point(|row| row[0] < wavelength_nm)
            .clamp(1, self.rows.len() - 1);
        let ([w0, n0, k0], [w1, n1, k1]) = (self.rows[upper - 1], self.rows[upper]);
        let t = (wavelength_nm - w0) / (w1 - w0);
        // This form is exact at both ends (t = 0 and t = 1).
        let lerp = |a: f64, b: f64| (1.0 - t) * a + t * b;
        Ok(Complex64::new(lerp(n0, n1), lerp(k0, k1)))
    }
}

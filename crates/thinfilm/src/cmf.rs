//! CIE standard observers: colour-matching functions x̄, ȳ, z̄ at 1 nm, 360–830 nm.
//!
//! The tables are the CIE's (CIE 015:2018, ISO/CIE 11664-1), embedded from
//! `data/cie1931_2deg_cmf.csv` and `data/cie1964_10deg_cmf.csv`; see
//! `data/README.md` for their provenance.

use std::sync::OnceLock;

/// A CIE standard colorimetric observer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Observer {
    /// The CIE 1931 2° standard observer (x̄, ȳ, z̄).
    Cie1931,
    /// The CIE 1964 10° supplementary standard observer (x̄₁₀, ȳ₁₀, z̄₁₀).
    Cie1964,
}

const CIE1931_CSV: &str = include_str!("../data/cie1931_2deg_cmf.csv");
const CIE1964_CSV: &str = include_str!("../data/cie1964_10deg_cmf.csv");

/// Number of 1 nm rows from [`Observer::MIN_NM`] to [`Observer::MAX_NM`] inclusive.
const ROWS: usize = 471;

impl Observer {
    /// Shortest tabulated wavelength.
    pub const MIN_NM: f64 = 360.0;
    /// Longest tabulated wavelength.
    pub const MAX_NM: f64 = 830.0;
    /// Both observers.
    pub const ALL: [Observer; 2] = [Observer::Cie1931, Observer::Cie1964];

    /// `[x̄, ȳ, z̄]` at `wavelength_nm`, linearly interpolated between the 1 nm
    /// samples; zero outside [`Observer::MIN_NM`, `Observer::MAX_NM`] (and for NaN).
    pub fn cmf(self, wavelength_nm: f64) -> [f64; 3] {
        let table = self.table_1nm();
        let t = wavelength_nm - Self::MIN_NM;
        // Also rejects NaN, which fails every comparison.
        if !(t >= 0.0 && t <= (ROWS - 1) as f64) {
            return [0.0; 3];
        }
        let i = (t.floor() as usize).min(ROWS - 2);
        let f = t - i as f64;
        let (a, b) = (table[i], table[i + 1]);
        std::array::from_fn(|c| (1.0 - f) * a[c] + f * b[c])
    }

    /// The observer named `"1931"` or `"1964"` (also `"cie1931"`, `"2"`, `"cie1964"`, `"10"`).
    pub fn from_name(s: &str) -> Option<Observer> {
        match s.trim().to_ascii_lowercase().as_str() {
            "1931" | "cie1931" | "2" => Some(Observer::Cie1931),
            "1964" | "cie1964" | "10" => Some(Observer::Cie1964),
            _ => None,
        }
    }

    /// The observer's short name, `"1931"` or `"1964"`.
    pub fn name(self) -> &'static str {
        match self {
            Observer::Cie1931 => "1931",
            Observer::Cie1964 => "1964",
        }
    }

    /// The published table: `[x̄, ȳ, z̄]` at `MIN_NM + i` nm for `i` in `0..471`.
    pub fn table_1nm(self) -> &'static [[f64; 3]] {
        static CIE1931: OnceLock<Vec<[f64; 3]>> = OnceLock::new();
        static CIE1964: OnceLock<Vec<[f64; 3]>> = OnceLock::new();
        match self {
            Observer::Cie1931 => CIE1931.get_or_init(|| parse_table(CIE1931_CSV)),
            Observer::Cie1964 => CIE1964.get_or_init(|| parse_table(CIE1964_CSV)),
        }
    }
}

/// Parses an embedded `wavelength_nm,x_bar,y_bar,z_bar` table.
///
/// # Panics
/// If the embedded file is malformed or not 1 nm from 360 to 830 nm; the
/// crate's tests load both tables, so a release cannot panic here.
fn parse_table(csv: &str) -> Vec<[f64; 3]> {
    let rows: Vec<[f64; 3]> = csv
        .lines()
        .skip(1)
        .enumerate()
        .map(|(i, line)| {
            let v: Vec<f64> = line
                .split(',')
                .map(|f| f.parse().expect("embedded CMF table is numeric"))
                .collect();
            assert!(
                v.len() == 4 && v[0] == Observer::MIN_NM + i as f64,
                "embedded CMF table row {i} is not at 1 nm spacing"
            );
            [v[1], v[2], v[3]]
        })
        .collect();
    assert_eq!(rows.len(), ROWS, "embedded CMF table must span 360–830 nm");
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cmf_interpolates_between_table_rows() {
        let o = Observer::Cie1931;
        let t = o.table_1nm();
        assert_eq!(o.cmf(555.0), t[195]);
        let mid = o.cmf(555.5);
        for c in 0..3 {
            assert!((mid[c] - 0.5 * (t[195][c] + t[196][c])).abs() < 1e-15);
        }
        assert_eq!(o.cmf(830.0), t[470]);
        assert_eq!(o.cmf(359.99), [0.0; 3]);
        assert_eq!(o.cmf(830.01), [0.0; 3]);
        assert_eq!(o.cmf(f64::NAN), [0.0; 3]);
    }

    #[test]
    fn names_round_trip() {
        for o in Observer::ALL {
            assert_eq!(Observer::from_name(o.name()), Some(o));
        }
        assert_eq!(Observer::from_name("1976"), None);
    }
}

//! CIE standard illuminants and a low-pressure sodium lamp.
//!
//! D65, D50, F2 and F11 are the CIE tables at 5 nm (CIE 015:2018), embedded from
//! `data/`; A is its defining closed form (Planck at 2856 K); E is equal energy;
//! the sodium lamp is its two D lines. See `data/README.md` for provenance.

use std::fmt;
use std::sync::OnceLock;

use crate::spectrum::Spectrum;

/// A named light source.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Illuminant {
    /// CIE standard illuminant D65 (noon daylight, 6504 K), 300–780 nm.
    D65,
    /// CIE illuminant D50 (horizon daylight, 5003 K), 300–780 nm.
    D50,
    /// CIE standard illuminant A (tungsten, Planck at 2856 K), 300–830 nm.
    A,
    /// Equal-energy illuminant E, 300–830 nm.
    E,
    /// CIE fluorescent illuminant F2 (cool white), 380–780 nm.
    F2,
    /// CIE fluorescent illuminant F11 (narrow triband), 380–780 nm.
    F11,
    /// Low-pressure sodium lamp: the D2 (589.0 nm) and D1 (589.6 nm) lines, 2:1.
    Sodium,
}

/// A name that is not one of [`Illuminant::ALL`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownIlluminant {
    /// The name that was given.
    pub name: String,
}

impl fmt::Display for UnknownIlluminant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let valid: Vec<&str> = Illuminant::ALL.iter().map(|i| i.name()).collect();
        write!(
            f,
            "unknown illuminant `{}`; valid names: {}",
            self.name,
            valid.join(", ")
        )
    }
}

impl std::error::Error for UnknownIlluminant {}

/// The radiation constant c₂ = hc/k in illuminant A's definition, in nm·K
/// (the 1948 value; today's is 1.4388×10⁷).
const C2_NM_K: f64 = 1.435e7;
/// The temperature in illuminant A's definition: 2848 K with the old c₂ is the
/// same curve as "2856 K" with today's c₂ (the ratio c₂/T is what matters).
const A_TEMPERATURE_K: f64 = 2848.0;

impl Illuminant {
    /// Every illuminant, in the order of their names' listing.
    pub const ALL: [Illuminant; 7] = [
        Illuminant::D65,
        Illuminant::D50,
        Illuminant::A,
        Illuminant::E,
        Illuminant::F2,
        Illuminant::F11,
        Illuminant::Sodium,
    ];

    /// The lower-case name: `"d65"`, `"d50"`, `"a"`, `"e"`, `"f2"`, `"f11"`, `"sodium"`.
    pub fn name(self) -> &'static str {
        match self {
            Illuminant::D65 => "d65",
            Illuminant::D50 => "d50",
            Illuminant::A => "a",
            Illuminant::E => "e",
            Illuminant::F2 => "f2",
            Illuminant::F11 => "f11",
            Illuminant::Sodium => "sodium",
        }
    }

    /// The illuminant called `s` (case-insensitive, surrounding spaces ignored).
    ///
    /// # Errors
    /// [`UnknownIlluminant`], whose message lists the valid names.
    pub fn from_name(s: &str) -> Result<Illuminant, UnknownIlluminant> {
        let wanted = s.trim().to_ascii_lowercase();
        Illuminant::ALL
            .into_iter()
            .find(|i| i.name() == wanted)
            .ok_or_else(|| UnknownIlluminant { name: s.to_owned() })
    }

    /// The relative spectral power distribution.
    pub fn spectrum(self) -> Spectrum {
        static CACHE: [OnceLock<Spectrum>; 7] = [const { OnceLock::new() }; 7];
        let index = Illuminant::ALL
            .iter()
            .position(|&i| i == self)
            .unwrap_or_default();
        CACHE[index].get_or_init(|| self.build()).clone()
    }

    /// Builds the spectrum (uncached).
    fn build(self) -> Spectrum {
        match self {
            Illuminant::D65 => table(include_str!("../data/illuminant_d65.csv")),
            Illuminant::D50 => table(include_str!("../data/illuminant_d50.csv")),
            Illuminant::F2 => table(include_str!("../data/illuminant_f2.csv")),
            Illuminant::F11 => table(include_str!("../data/illuminant_f11.csv")),
            Illuminant::A => sampled_1nm(illuminant_a),
            Illuminant::E => sampled_1nm(|_| 100.0),
            Illuminant::Sodium => Spectrum::from_lines(vec![(589.0, 2.0), (589.6, 1.0)])
                .expect("the sodium D lines are valid"),
        }
    }
}

/// CIE illuminant A's defining formula (CIE 015:2018 eq. 4.1): Planck's law
/// with c₂ = 1.435×10⁷ nm·K at 2848 K (nominally 2856 K on today's
/// temperature scale), normalised to 100 at 560 nm.
pub fn illuminant_a(wavelength_nm: f64) -> f64 {
    let planck = |l: f64| l.powi(-5) / (C2_NM_K / (A_TEMPERATURE_K * l)).exp_m1();
    100.0 * planck(wavelength_nm) / planck(560.0)
}

/// `f` sampled at 1 nm from 300 to 830 nm.
fn sampled_1nm(f: impl Fn(f64) -> f64) -> Spectrum {
    let wavelength_nm: Vec<f64> = (300..=830).map(f64::from).collect();
    let value = wavelength_nm.iter().map(|&w| f(w)).collect();
    Spectrum::try_from_samples(wavelength_nm, value).expect("closed-form illuminants are valid")
}

/// Parses an embedded `wavelength_nm,value` table.
///
/// # Panics
/// If the embedded file is malformed; the crate's tests load every table, so a
/// release cannot panic here.
fn table(csv: &str) -> Spectrum {
    Spectrum::from_csv_str(csv).expect("embedded illuminant table is valid")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_lists_valid_names() {
        for i in Illuminant::ALL {
            assert_eq!(Illuminant::from_name(i.name()), Ok(i));
            assert_eq!(Illuminant::from_name(&i.name().to_uppercase()), Ok(i));
        }
        let e = Illuminant::from_name("d75").unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown illuminant `d75`; valid names: d65, d50, a, e, f2, f11, sodium"
        );
    }

    #[test]
    fn every_illuminant_builds() {
        for i in Illuminant::ALL {
            let s = i.spectrum();
            assert!(
                !s.wavelengths_nm().is_empty() || !s.lines().is_empty(),
                "{i:?}"
            );
        }
    }
}

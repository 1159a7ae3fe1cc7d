//! Refractive index against wavelength: constant, Cauchy, Sellmeier, and liquid water.
//!
//! Wavelengths are in vacuum, in nm; indices are absolute (relative to vacuum).

use crate::fresnel::OpticsError;

/// The range (nm) that [`RefractiveIndex::cauchy`] and [`RefractiveIndex::sellmeier`] give
/// a model when no range is named: the range of the CIE colour-matching data.
pub const VALIDATED_RANGE_NM: [f64; 2] = [360.0, 830.0];

/// Wavelengths (nm) a constant index covers: from the far ultraviolet to the far infrared,
/// where a wavelength-independent index is a fair model of a transparent medium.
pub const CONSTANT_RANGE_NM: [f64; 2] = [100.0, 100_000.0];

/// Wavelengths (nm) over which the IAPWS water formulation is valid (its release's range).
pub const WATER_RANGE_NM: [f64; 2] = [200.0, 1100.0];

/// Temperature (K) of [`RefractiveIndex::Water`]: 20 °C.
pub const WATER_TEMPERATURE_K: f64 = 293.15;

/// Density (kg/m³) of liquid water at 20 °C and 0.101325 MPa, used by [`RefractiveIndex::Water`].
pub const WATER_DENSITY_KG_PER_M3: f64 = 998.207;

/// A refractive index as a function of vacuum wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RefractiveIndex {
    /// The same index at every wavelength.
    Constant(f64),
    /// Cauchy's formula `n = a + b/λ² + c/λ⁴`, with λ in nm, over `range_nm`.
    Cauchy {
        /// Constant term.
        a: f64,
        /// Coefficient of `1/λ²`, in nm².
        b_nm2: f64,
        /// Coefficient of `1/λ⁴`, in nm⁴.
        c_nm4: f64,
        /// The wavelengths (nm) where the fit holds: `[lo, hi]`.
        range_nm: [f64; 2],
    },
    /// Three-term Sellmeier formula `n² = 1 + Σ B_i λ²/(λ² − C_i)`, with λ in nm, over `range_nm`.
    Sellmeier {
        /// Oscillator strengths `B_i` (dimensionless).
        b: [f64; 3],
        /// Squared resonance wavelengths `C_i`, in nm².
        c_nm2: [f64; 3],
        /// The wavelengths (nm) where the fit holds: `[lo, hi]`.
        range_nm: [f64; 2],
    },
    /// Pure liquid water at 20 °C and atmospheric pressure: the IAPWS R9-97 formulation
    /// (Harvey, Gallagher & Levelt Sengers, J. Phys. Chem. Ref. Data 27, 761 (1998)), valid
    /// over [`WATER_RANGE_NM`]. It gives n(589.3 nm) = 1.33335 relative to vacuum, which is
    /// the handbook n_D = 1.3330 once divided by the index of air (1.00027).
    Water,
}

impl RefractiveIndex {
    /// The soap-film default: a constant 1.33.
    pub const SOAP: RefractiveIndex = RefractiveIndex::Constant(1.33);

    /// A constant index.
    ///
    /// # Guarantees
    /// `n` is finite and `> 0`.
    pub fn constant(n: f64) -> Result<RefractiveIndex, OpticsError> {
        RefractiveIndex::Constant(n).validated()
    }

    /// A Cauchy model `a + b_nm2/λ² + c_nm4/λ⁴` over [`VALIDATED_RANGE_NM`].
    ///
    /// # Guarantees
    /// As [`RefractiveIndex::cauchy_over`] with that range.
    pub fn cauchy(a: f64, b_nm2: f64, c_nm4: f64) -> Result<RefractiveIndex, OpticsError> {
        RefractiveIndex::cauchy_over(a, b_nm2, c_nm4, VALIDATED_RANGE_NM)
    }

    /// A Cauchy model `a + b_nm2/λ² + c_nm4/λ⁴` valid over `range_nm` = `[lo, hi]`.
    ///
    /// # Guarantees
    /// `0 < lo ≤ hi` are finite, all coefficients are finite and the index is finite and
    /// `> 0` over the whole range.
    pub fn cauchy_over(
        a: f64,
        b_nm2: f64,
        c_nm4: f64,
        range_nm: [f64; 2],
    ) -> Result<RefractiveIndex, OpticsError> {
        RefractiveIndex::Cauchy {
            a,
            b_nm2,
            c_nm4,
            range_nm,
        }
        .validated()
    }

    /// A three-term Sellmeier model `n² = 1 + Σ b[i] λ²/(λ² − c_nm2[i])` over [`VALIDATED_RANGE_NM`].
    ///
    /// # Guarantees
    /// As [`RefractiveIndex::sellmeier_over`] with that range.
    pub fn sellmeier(b: [f64; 3], c_nm2: [f64; 3]) -> Result<RefractiveIndex, OpticsError> {
        RefractiveIndex::sellmeier_over(b, c_nm2, VALIDATED_RANGE_NM)
    }

    /// A three-term Sellmeier model valid over `range_nm` = `[lo, hi]`.
    ///
    /// # Guarantees
    /// `0 < lo ≤ hi` are finite, all `b[i] ≥ 0` and `c_nm2[i] ≥ 0` are finite, no resonance
    /// `sqrt(c_nm2[i])` lies in the range, and the index is finite and `> 0` over it.
    pub fn sellmeier_over(
        b: [f64; 3],
        c_nm2: [f64; 3],
        range_nm: [f64; 2],
    ) -> Result<RefractiveIndex, OpticsError> {
        RefractiveIndex::Sellmeier { b, c_nm2, range_nm }.validated()
    }

    /// The wavelengths (nm) this model covers, `[lo, hi]`.
    pub fn range_nm(&self) -> [f64; 2] {
        match *self {
            RefractiveIndex::Constant(_) => CONSTANT_RANGE_NM,
            RefractiveIndex::Cauchy { range_nm, .. }
            | RefractiveIndex::Sellmeier { range_nm, .. } => range_nm,
            RefractiveIndex::Water => WATER_RANGE_NM,
        }
    }

    /// Checks a model built directly from its variant, with the guarantees of its constructor.
    pub fn validate(&self) -> Result<(), OpticsError> {
        match *self {
            RefractiveIndex::Constant(n) => {
                crate::fresnel::check_real_index("constant refractive index", n)
            }
            RefractiveIndex::Cauchy {
                a,
                b_nm2,
                c_nm4,
                range_nm,
            } => check_range(range_nm).and_then(|()| validate_cauchy(a, b_nm2, c_nm4, range_nm)),
            RefractiveIndex::Sellmeier { b, c_nm2, range_nm } => {
                check_range(range_nm).and_then(|()| validate_sellmeier(b, c_nm2, range_nm))
            }
            RefractiveIndex::Water => Ok(()),
        }
    }

    fn validated(self) -> Result<RefractiveIndex, OpticsError> {
        self.validate().map(|()| self)
    }

    /// The index at `wavelength_nm`, or an error if the wavelength is not finite and
    /// positive, lies outside the model's [`RefractiveIndex::range_nm`], or the model gives
    /// no finite positive index there.
    pub fn try_n_at(&self, wavelength_nm: f64) -> Result<f64, OpticsError> {
        crate::fresnel::check_wavelength(wavelength_nm)?;
        check_in_range(self.name(), self.range_nm(), wavelength_nm)?;
        let n = match *self {
            RefractiveIndex::Constant(n) => n,
            RefractiveIndex::Cauchy {
                a, b_nm2, c_nm4, ..
            } => {
                let inv_l2 = 1.0 / (wavelength_nm * wavelength_nm);
                a + inv_l2 * (b_nm2 + inv_l2 * c_nm4)
            }
            RefractiveIndex::Sellmeier { b, c_nm2, .. } => {
                sellmeier_n2(b, c_nm2, wavelength_nm).sqrt()
            }
            RefractiveIndex::Water => {
                water_iapws(wavelength_nm, WATER_TEMPERATURE_K, WATER_DENSITY_KG_PER_M3)?
            }
        };
        if n.is_finite() && (crate::fresnel::MIN_INDEX..=crate::fresnel::MAX_INDEX).contains(&n) {
            Ok(n)
        } else {
            Err(OpticsError::IndexAtWavelength {
                wavelength_nm,
                value: n,
            })
        }
    }

    /// The index at `wavelength_nm`.
    ///
    /// # Panics
    /// Where [`RefractiveIndex::try_n_at`] fails; never for a validated model inside its
    /// [`RefractiveIndex::range_nm`].
    pub fn n_at(&self, wavelength_nm: f64) -> f64 {
        self.try_n_at(wavelength_nm)
            .unwrap_or_else(|err| panic!("{err}"))
    }

    /// The model's name in messages.
    pub fn name(&self) -> &'static str {
        match self {
            RefractiveIndex::Constant(_) => "constant index",
            RefractiveIndex::Cauchy { .. } => "Cauchy model",
            RefractiveIndex::Sellmeier { .. } => "Sellmeier model",
            RefractiveIndex::Water => "water (IAPWS R9-97)",
        }
    }
}

/// Checks a model's wavelength range: finite, `0 < lo ≤ hi`.
pub(crate) fn check_range(range_nm: [f64; 2]) -> Result<(), OpticsError> {
    let [lo, hi] = range_nm;
    if lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi {
        Ok(())
    } else {
        Err(dispersion_error(format!(
            "wavelength range [{lo}, {hi}] nm is not finite with 0 < lo <= hi"
        )))
    }
}

/// Checks that `wavelength_nm` lies in a model's `range_nm`.
pub(crate) fn check_in_range(
    model: &'static str,
    range_nm: [f64; 2],
    wavelength_nm: f64,
) -> Result<(), OpticsError> {
    let [lo, hi] = range_nm;
    if (lo..=hi).contains(&wavelength_nm) {
        Ok(())
    } else {
        Err(OpticsError::OutOfRange {
            model,
            wavelength_nm,
            range_nm,
        })
    }
}

impl Default for RefractiveIndex {
    fn default() -> Self {
        RefractiveIndex::SOAP
    }
}

fn sellmeier_n2(b: [f64; 3], c_nm2: [f64; 3], wavelength_nm: f64) -> f64 {
    let l2 = wavelength_nm * wavelength_nm;
    1.0 + b
        .iter()
        .zip(c_nm2)
        .map(|(b_i, c_i)| b_i * l2 / (l2 - c_i))
        .sum::<f64>()
}

fn dispersion_error(reason: String) -> OpticsError {
    OpticsError::Dispersion { reason }
}

fn validate_cauchy(a: f64, b_nm2: f64, c_nm4: f64, range_nm: [f64; 2]) -> Result<(), OpticsError> {
    for (name, value) in [("a", a), ("b_nm2", b_nm2), ("c_nm4", c_nm4)] {
        if !value.is_finite() {
            return Err(dispersion_error(format!(
                "Cauchy {name} = {value} is not finite"
            )));
        }
    }
    // n is a quadratic in x = 1/λ²: its minimum over the range is at an end or the vertex.
    let [lo, hi] = range_nm;
    let (x_lo, x_hi) = (1.0 / (hi * hi), 1.0 / (lo * lo));
    let n_of = |x: f64| a + x * (b_nm2 + x * c_nm4);
    let mut candidates = vec![x_lo, x_hi];
    if c_nm4 != 0.0 {
        let vertex = -b_nm2 / (2.0 * c_nm4);
        if (x_lo..=x_hi).contains(&vertex) {
            candidates.push(vertex);
        }
    }
    for x in candidates {
        let n = n_of(x);
        if n.is_nan() || n <= 0.0 {
            let wavelength_nm = 1.0 / x.sqrt();
            return Err(dispersion_error(format!(
                "Cauchy model gives n = {n} at {wavelength_nm} nm, inside its range [{lo}, {hi}] nm"
            )));
        }
    }
    Ok(())
}

fn validate_sellmeier(b: [f64; 3], c_nm2: [f64; 3], range_nm: [f64; 2]) -> Result<(), OpticsError> {
    let [lo, hi] = range_nm;
    for i in 0..3 {
        if !(b[i].is_finite() && b[i] >= 0.0) {
            return Err(dispersion_error(format!(
                "Sellmeier b[{i}] = {} is not finite and >= 0",
                b[i]
            )));
        }
        if !(c_nm2[i].is_finite() && c_nm2[i] >= 0.0) {
            return Err(dispersion_error(format!(
                "Sellmeier c_nm2[{i}] = {} is not finite and >= 0",
                c_nm2[i]
            )));
        }
        let resonance_nm = c_nm2[i].sqrt();
        if b[i] > 0.0 && (lo..=hi).contains(&resonance_nm) {
            return Err(dispersion_error(format!(
                "Sellmeier resonance sqrt(c_nm2[{i}]) = {resonance_nm} nm lies inside [{lo}, {hi}] nm"
            )));
        }
    }
    // With b, c ≥ 0 every term falls as λ grows between resonances, so n² is smallest at
    // the long end of the range.
    let n2 = sellmeier_n2(b, c_nm2, hi);
    if n2 > 0.0 && n2.is_finite() {
        Ok(())
    } else {
        Err(dispersion_error(format!(
            "Sellmeier model gives n² = {n2} at {hi} nm"
        )))
    }
}

/// IAPWS R9-97 coefficients `a0..a7`.
const IAPWS_A: [f64; 8] = [
    0.244257733,
    9.74634476e-3,
    -3.73234996e-3,
    2.68678472e-4,
    1.58920570e-3,
    2.45934259e-3,
    0.900704920,
    -1.66626219e-2,
];
/// IAPWS R9-97 reduced ultraviolet and infrared resonance wavelengths.
const IAPWS_LAMBDA_UV: f64 = 0.229202;
const IAPWS_LAMBDA_IR: f64 = 5.432937;

/// Refractive index of liquid water or steam, IAPWS R9-97 ("Release on the Refractive
/// Index of Ordinary Water Substance as a Function of Wavelength, Temperature and
/// Pressure", 1997): the Lorentz–Lorenz function fitted in reduced density, temperature
/// and wavelength. Valid for 200–1100 nm, 261.15–773.15 K, 0–1060 kg/m³.
///
/// Errors if an argument is outside that domain.
pub fn water_iapws(
    wavelength_nm: f64,
    temperature_k: f64,
    density_kg_per_m3: f64,
) -> Result<f64, OpticsError> {
    let [lo, hi] = WATER_RANGE_NM;
    if !(lo..=hi).contains(&wavelength_nm) {
        return Err(OpticsError::Wavelength { wavelength_nm });
    }
    if !(261.15..=773.15).contains(&temperature_k) {
        return Err(dispersion_error(format!(
            "water temperature {temperature_k} K is outside 261.15–773.15 K"
        )));
    }
    if !(0.0..=1060.0).contains(&density_kg_per_m3) {
        return Err(dispersion_error(format!(
            "water density {density_kg_per_m3} kg/m³ is outside 0–1060 kg/m³"
        )));
    }
    let a = IAPWS_A;
    let rho = density_kg_per_m3 / 1000.0;
    let t = temperature_k / 273.15;
    let l2 = (wavelength_nm / 589.0).powi(2);
    let lorentz_lorenz_per_rho = a[0]
        + a[1] * rho
        + a[2] * t
        + a[3] * l2 * t
        + a[4] / l2
        + a[5] / (l2 - IAPWS_LAMBDA_UV * IAPWS_LAMBDA_UV)
        + a[6] / (l2 - IAPWS_LAMBDA_IR * IAPWS_LAMBDA_IR)
        + a[7] * rho * rho;
    // (n² − 1)/(n² + 2) = A  ⇒  n² = (1 + 2A)/(1 − A).
    let ll = lorentz_lorenz_per_rho * rho;
    Ok(((1.0 + 2.0 * ll) / (1.0 - ll)).sqrt())
}

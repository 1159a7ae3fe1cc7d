//! Validated scalar and vector types for scene files.
//!
//! Validation happens inside deserialisation, so a bad value is reported by the TOML
//! parser with its line and column (and [`super::Scene::from_toml_str`] adds the key).
//! Every number carries the physical range its key accepts (a [`Bounds`] type): inside
//! it the whole pipeline, f64 solver and f32 renderer alike, stays finite.

use serde::{Deserialize, Deserializer, de::Error as _};
use std::fmt;
use std::marker::PhantomData;

/// The closed range `MIN..=MAX` one kind of scene number may take, and its unit.
pub trait Bounds {
    /// Smallest accepted value.
    const MIN: f64;
    /// Largest accepted value.
    const MAX: f64;
    /// Unit written after the range in messages (may be empty).
    const UNIT: &'static str;
}

/// A finite `f64` inside `B`'s range.
///
/// # Guarantees
/// The value is finite and `B::MIN <= value <= B::MAX`.
pub struct Num<B>(f64, PhantomData<B>);

/// Three finite components, each inside `B`'s range.
///
/// # Guarantees
/// Every component is finite and `B::MIN <= c <= B::MAX`.
pub struct Num3<B>([f64; 3], PhantomData<B>);

/// A direction: three components in `-1e6..=1e6`, of length at least `1e-6`.
///
/// # Guarantees
/// Every component is finite with `|c| <= 1e6`, and the length is `>= 1e-6`, so the
/// direction normalises without overflow in f32.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction([f64; 3]);

/// A direction on the horizontal XZ plane: two components in `-1e6..=1e6`, of length at
/// least `1e-6` (normalised where it is used).
///
/// # Guarantees
/// Both components are finite with `|c| <= 1e6`, and the length is `>= 1e-6`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction2([f64; 2]);

/// A whole number inside `B`'s range.
///
/// # Guarantees
/// `B::MIN <= value <= B::MAX`.
pub struct Count<B>(u32, PhantomData<B>);

/// `MIN..=MAX UNIT`, with the short forms Rust prints (`0.0001`, `1e30`).
pub fn range_text<B: Bounds>() -> String {
    let unit = if B::UNIT.is_empty() {
        String::new()
    } else {
        format!(" {}", B::UNIT)
    };
    format!("{}..={}{unit}", B::MIN, B::MAX)
}

impl<B: Bounds> Num<B> {
    /// Checks `value`, returning `None` outside the range or when not finite.
    pub fn new(value: f64) -> Option<Self> {
        (value.is_finite() && (B::MIN..=B::MAX).contains(&value))
            .then_some(Self(value, PhantomData))
    }

    /// Like [`Num::new`], with the message a user reads when `value` is refused.
    pub fn try_new(value: f64) -> Result<Self, String> {
        Self::new(value).ok_or_else(|| format!("{} is outside {}", plain(value), range_text::<B>()))
    }

    /// The checked value.
    pub fn get(self) -> f64 {
        self.0
    }
}

impl<B: Bounds> Num3<B> {
    /// Checks every component, returning `None` when one breaks the guarantee.
    pub fn new(value: [f64; 3]) -> Option<Self> {
        let ok = |c: &f64| c.is_finite() && (B::MIN..=B::MAX).contains(c);
        value.iter().all(ok).then_some(Self(value, PhantomData))
    }

    /// The checked components.
    pub fn get(self) -> [f64; 3] {
        self.0
    }
}

impl<B: Bounds> Count<B> {
    /// Checks `value`, returning `None` outside the range.
    pub fn new(value: u32) -> Option<Self> {
        (B::MIN <= f64::from(value) && f64::from(value) <= B::MAX)
            .then_some(Self(value, PhantomData))
    }

    /// The checked value.
    pub fn get(self) -> u32 {
        self.0
    }
}

impl Direction {
    /// Checks `value`, returning `None` when it breaks the guarantee.
    pub fn new(value: [f64; 3]) -> Option<Self> {
        let finite = value.iter().all(|c| c.is_finite() && c.abs() <= 1e6);
        let length_sq: f64 = value.iter().map(|c| c * c).sum();
        (finite && length_sq >= 1e-12).then_some(Self(value))
    }

    /// The checked components.
    pub fn get(self) -> [f64; 3] {
        self.0
    }
}

impl Direction2 {
    /// Checks `value`, returning `None` when it breaks the guarantee.
    pub fn new(value: [f64; 2]) -> Option<Self> {
        let finite = value.iter().all(|c| c.is_finite() && c.abs() <= 1e6);
        let length_sq: f64 = value.iter().map(|c| c * c).sum();
        (finite && length_sq >= 1e-12).then_some(Self(value))
    }

    /// The checked components.
    pub fn get(self) -> [f64; 2] {
        self.0
    }
}

// Manual impls: derives would demand `B: Clone` etc. of the marker types.
macro_rules! plain_value_impls {
    ($name:ident) => {
        impl<B> Clone for $name<B> {
            fn clone(&self) -> Self {
                *self
            }
        }
        impl<B> Copy for $name<B> {}
        impl<B> PartialEq for $name<B> {
            fn eq(&self, other: &Self) -> bool {
                self.0 == other.0
            }
        }
        impl<B> fmt::Debug for $name<B> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Debug::fmt(&self.0, f)
            }
        }
    };
}

plain_value_impls!(Num);
plain_value_impls!(Num3);
plain_value_impls!(Count);

impl<'de, B: Bounds> Deserialize<'de> for Num<B> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Self::try_new(f64::deserialize(d)?).map_err(D::Error::custom)
    }
}

impl<'de, B: Bounds> Deserialize<'de> for Num3<B> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value: [f64; 3] = exact(d)?;
        Self::new(value).ok_or_else(|| {
            D::Error::custom(format!(
                "{} has a component outside {}",
                numbers(&value),
                range_text::<B>()
            ))
        })
    }
}

impl<'de, B: Bounds> Deserialize<'de> for Count<B> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value = i64::deserialize(d)?;
        u32::try_from(value)
            .ok()
            .and_then(Self::new)
            .ok_or_else(|| D::Error::custom(format!("{value} is outside {}", range_text::<B>())))
    }
}

impl<'de> Deserialize<'de> for Direction {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value: [f64; 3] = exact(d)?;
        Self::new(value).ok_or_else(|| {
            D::Error::custom(format!(
                "{} is not a direction: components in -1e6..=1e6, length at least 1e-6",
                numbers(&value)
            ))
        })
    }
}

impl<'de> Deserialize<'de> for Direction2 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value: [f64; 2] = exact(d)?;
        Self::new(value).ok_or_else(|| {
            D::Error::custom(format!(
                "[{}, {}] is not a direction: components in -1e6..=1e6, length at least 1e-6",
                plain(value[0]),
                plain(value[1])
            ))
        })
    }
}

/// Deserialises an array of exactly `N` elements, refusing a longer or shorter one
/// (serde's own arrays ignore extra elements in TOML); for `deserialize_with`.
pub fn exact<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let items = Vec::<T>::deserialize(d)?;
    let len = items.len();
    items
        .try_into()
        .map_err(|_| D::Error::custom(format!("an array of {len} elements where {N} are expected")))
}

/// `[a, b, c]` as [`plain`] numbers.
pub fn numbers(v: &[f64; 3]) -> String {
    format!("[{}, {}, {}]", plain(v[0]), plain(v[1]), plain(v[2]))
}

/// A number as a user reads it: the shortest round-trip decimal between 1e-4 and 1e7,
/// scientific (`1e300`, `1e-300`) outside, never hundreds of digits.
pub fn plain(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e7).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// [`plain`] for an `f32` (an image texel): its own shortest decimal, not its f64 widening.
pub fn plain_f32(v: f32) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e7).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

macro_rules! bounds {
    ($($(#[$doc:meta])* $name:ident: $min:expr, $max:expr, $unit:literal;)*) => {
        $(
            $(#[$doc])*
            #[derive(Debug)]
            pub enum $name {}
            impl Bounds for $name {
                const MIN: f64 = $min;
                const MAX: f64 = $max;
                const UNIT: &'static str = $unit;
            }
        )*
    };
}

// Ranges wide enough for any soap-bubble scene, narrow enough that products of them
// (radiance × luminance × exposure, positions squared in f32) stay far from overflow.
bounds! {
    /// A coordinate of a position: within 10 km of the origin.
    Coordinate: -1e4, 1e4, "m";
    /// Simulated time.
    Seconds: 0.0, 3600.0, "s";
    /// Vertical field of view.
    FieldOfView: 0.1, 179.0, "degrees";
    /// Radiance of a sky, environment or sun, per channel.
    Radiance: 0.0, 1e6, "";
    /// Albedo or specular colour, per channel.
    Reflectance: 0.0, 1.0, "";
    /// A scale factor on image radiance.
    Intensity: 0.0, 1e6, "";
    /// Side of a checker square or texture repeat.
    PatternScale: 1e-4, 1e4, "m";
    /// Blinn-Phong exponent.
    Shininess: 1.0, 1e4, "";
    /// Radius of an opaque sphere.
    ObjectRadius: 1e-4, 1e4, "m";
    /// Uniform scale of an OBJ mesh.
    MeshScale: 1e-6, 1e6, "";
    /// A bubble's initial per-axis stretch: a squash or stretch, never a collapse.
    InitialScale: 0.5, 2.0, "";
    /// Radius of a light sphere.
    LightRadius: 1e-4, 100.0, "m";
    /// Luminance of a light's surface, relative to white 1.
    Luminance: 0.0, 1e6, "";
    /// Rest radius of a soap bubble.
    BubbleRadius: 1e-3, 1.0, "m";
    /// A velocity component (bubble or wind).
    Speed: -100.0, 100.0, "m/s";
    /// A gust amplitude.
    GustSpeed: 0.0, 100.0, "m/s";
    /// Soap-film thickness.
    FilmThickness: 1.0, 1e4, "nm";
    /// Thickness at which a film bursts.
    RuptureThickness: 0.0, 1e4, "nm";
    /// Icosphere subdivision level.
    Subdivisions: 0.0, crate::limits::MAX_SUBDIVISIONS as f64, "";
    /// Surface tension.
    SurfaceTension: 1e-3, 1.0, "N/m";
    /// Velocity damping rate.
    Damping: 0.0, 1e3, "1/s";
    /// Gibbs film elasticity.
    Elasticity: 0.0, 10.0, "N/m";
    /// Effective drainage viscosity (a model parameter: the default is 5e-8).
    Viscosity: 1e-12, 10.0, "Pa·s";
    /// Relative thickness variation.
    Variation: 0.0, 0.99, "";
    /// Film flow speed.
    SloshSpeed: 0.0, 10.0, "m/s";
    /// Film-flow grid cells along a cube face (0: off; the solver checks it halves to 8).
    FilmGrid: 0.0, bubble_dynamics::MAX_FILM_GRID as f64, "cells";
    /// Viscosity of the film liquid.
    FilmViscosity: 0.0, 10.0, "Pa·s";
    /// Rate of spontaneous holes in black film.
    NucleationRate: 0.0, 1e9, "1/(m²·s)";
    /// Evaporative thinning rate.
    Evaporation: 0.0, 1e4, "nm/s";
    /// How much warmer the air at a bubble's bottom is than at its top.
    Warming: -bubble_dynamics::MAX_WARMING_K, bubble_dynamics::MAX_WARMING_K, "K";
    /// Height of a meniscus's contact line over the bubble's radius.
    ContactHeight: -0.95, 0.95, "";
    /// Thin-film patches a meniscus regenerates per metre of contact line.
    RegenerationRate: 0.0, 1e4, "1/(m·s)";
    /// A regenerated patch's thickness over the film's.
    RegeneratedFraction: 0.01, 1.0, "";
    /// Radius of a regenerated patch.
    PatchRadius: 1e-4, 0.1, "m";
    /// Molar mass of the gas inside.
    MolarMass: 1e-3, 1.0, "kg/mol";
    /// Film refractive index.
    FilmIndex: 1.0, 4.0, "";
    /// Solver time step.
    TimeStep: 1e-6, 0.1, "s";
    /// A gravity component.
    Acceleration: -1e3, 1e3, "m/s²";
    /// Exposure multiplier.
    Exposure: 1e-6, 1e6, "";
    /// Cube-map face size.
    CubeMapSize: 1.0, crate::limits::MAX_CUBE_MAP_SIZE as f64, "texels";
    /// Film-table columns over thickness.
    LutThicknessSamples: 2.0, crate::limits::MAX_LUT_THICKNESS_SAMPLES as f64, "columns";
    /// Film-table rows over cos θ.
    LutAngleSamples: 2.0, crate::limits::MAX_LUT_ANGLE_SAMPLES as f64, "rows";
    /// Anti-aliasing samples (1, 4, 8, 9 or 16; the set is checked later).
    Samples: 1.0, 16.0, "";
    /// Water grid slices along one side.
    WaterSlices: 1.0, crate::limits::MAX_WATER_SLICES as f64, "";
    /// Refractive index of the water (air is 1).
    WaterIndex: 1.0, 4.0, "";
    /// Depth of the pool floor below the water's rest plane.
    WaterDepth: 1e-4, 1e4, "m";
    /// Beer–Lambert absorption of the water, per channel.
    Absorption: 0.0, 1e4, "1/m";
    /// Amplitude of a wave or ripple (with at most `MAX_WATER_PERTURBATIONS` of them,
    /// the surface stays within the scene's coordinates).
    WaveAmplitude: 0.0, 10.0, "m";
    /// Wavelength of a wave or ripple.
    Wavelength: 1e-3, 1e4, "m";
    /// Angular frequency of a wave or ripple.
    AngularSpeed: 1e-6, 1e4, "rad/s";
    /// A ripple's fading with distance from its centre.
    DecayPerMetre: 0.0, 1e4, "1/m";
    /// A ripple's fading with time.
    DecayPerSecond: 0.0, 1e4, "1/s";
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_what_the_guarantees_exclude() {
        assert!(Num::<BubbleRadius>::new(0.0).is_none());
        assert!(Num::<BubbleRadius>::new(1e-300).is_none());
        assert!(Num::<BubbleRadius>::new(1e300).is_none());
        assert!(Num::<BubbleRadius>::new(f64::NAN).is_none());
        assert!(Num::<Seconds>::new(-1e-300).is_none());
        assert!(Num::<Coordinate>::new(f64::INFINITY).is_none());
        assert!(Num3::<Radiance>::new([0.1, -0.1, 0.0]).is_none());
        assert!(Direction::new([0.0; 3]).is_none());
        assert!(Direction::new([1e30, 0.0, 0.0]).is_none());
        assert!(Count::<Subdivisions>::new(7).is_none());
        assert_eq!(Num::<BubbleRadius>::new(0.05).map(Num::get), Some(0.05));
    }

    #[test]
    fn plain_numbers_stay_short() {
        assert_eq!(plain(1e-300), "1e-300");
        assert_eq!(plain(1e300), "1e300");
        assert_eq!(plain(-0.5), "-0.5");
        assert_eq!(plain(4294967295.0), "4.294967295e9");
        assert_eq!(plain_f32(1e34), "1e34");
        assert_eq!(plain_f32(3.4e38), "3.4e38");
    }

    #[test]
    fn range_edges_are_accepted() {
        assert!(Num::<FilmIndex>::new(1.0).is_some());
        assert!(Num::<FilmIndex>::new(4.0).is_some());
        assert!(Count::<Subdivisions>::new(0).is_some());
    }

    #[test]
    fn refusal_names_value_and_range() {
        let msg = Num::<BubbleRadius>::try_new(1e300).err().unwrap();
        assert_eq!(msg, "1e300 is outside 0.001..=1 m");
    }
}

//! What the user tells the inverse: the viewing geometry, how the camera's exposure and
//! white balance are fixed, anchors and masks.

use crate::error::{InverseError, short};

/// The most grazing view the inverse accepts: cos θ below this is excluded (the film's
/// colours there change faster with angle than any angle map is accurate).
pub const MIN_COS: f64 = 0.1;
/// cos θ rows of the colour table when the angle varies across the photo.
pub const ANGLE_ROWS: usize = 128;

/// How the film is seen.
#[derive(Clone, Debug, PartialEq)]
pub enum Viewing {
    /// Every pixel at one angle of incidence (degrees, 0 = head-on).
    Angle(f64),
    /// cos θ per pixel, row-major (values below [`MIN_COS`] are excluded).
    CosMap(Vec<f32>),
    /// A sphere (a bubble) of `radius_px` centred at `centre_px`, seen from far away: cos θ
    /// is `√(1 − r²/R²)` inside the disc; pixels outside are excluded.
    Sphere {
        /// Centre of the disc, in pixels (x right, y down).
        centre_px: [f64; 2],
        /// Radius of the disc in pixels.
        radius_px: f64,
    },
}

/// An axis-aligned region of the photo, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width (≥ 1).
    pub w: u32,
    /// Height (≥ 1).
    pub h: u32,
}

impl Rect {
    /// Checks that the region is non-empty and inside a `width × height` photo.
    pub(crate) fn check(
        &self,
        what: &'static str,
        width: u32,
        height: u32,
    ) -> Result<(), InverseError> {
        let inside = self.w > 0
            && self.h > 0
            && u64::from(self.x) + u64::from(self.w) <= u64::from(width)
            && u64::from(self.y) + u64::from(self.h) <= u64::from(height);
        if inside {
            Ok(())
        } else {
            Err(InverseError::Outside {
                what,
                value: format!("{},{},{},{}", self.x, self.y, self.w, self.h),
                width,
                height,
            })
        }
    }

    /// The pixel indices inside, row-major, for a photo `width` wide.
    pub(crate) fn pixels(&self, width: u32) -> impl Iterator<Item = usize> + '_ {
        (self.y..self.y + self.h).flat_map(move |y| {
            (self.x..self.x + self.w).map(move |x| y as usize * width as usize + x as usize)
        })
    }
}

/// How exposure and white balance are fixed.
#[derive(Clone, Debug, PartialEq)]
pub enum Calibration {
    /// Known: the photo's linear value is `exposure · gains[c]` times the film's
    /// white-balanced reflectance.
    Given(crate::Camera),
    /// A region showing the light itself in a perfect mirror (reflectance 1): its mean is
    /// the camera's response to white.
    White(Rect),
    /// A region of film of known thickness (nm).
    Known(Rect, f64),
    /// Estimated from the photo: the exposure and white balance under which the film's
    /// colours lie closest to the model's colour curve.
    Auto,
}

/// A pixel whose thickness the user knows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anchor {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// Thickness there (nm).
    pub thickness_nm: f64,
}

/// Everything [`crate::recover`] needs besides the photo and the film model.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The viewing geometry.
    pub viewing: Viewing,
    /// How exposure and white balance are fixed.
    pub calibration: Calibration,
    /// Known thicknesses, which fix the fringe order of the region around them.
    pub anchors: Vec<Anchor>,
    /// Pixels to use (`true`) and to leave out, row-major; `None` uses all.
    pub mask: Option<Vec<bool>>,
    /// A fitted pixel whose re-rendered colour is further than this ΔE2000 from the
    /// photo is reported as unexplained.
    pub max_residual_de: f64,
    /// The thickness change (nm) between neighbouring pixels the continuity prior
    /// expects; larger steps are allowed but cost more.
    pub smoothness_nm: f64,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            viewing: Viewing::Angle(0.0),
            calibration: Calibration::Auto,
            anchors: Vec::new(),
            mask: None,
            max_residual_de: 8.0,
            smoothness_nm: 30.0,
        }
    }
}

impl Settings {
    /// Checks every setting against a `width × height` photo.
    pub(crate) fn check(
        &self,
        width: u32,
        height: u32,
        thickness_max_nm: f64,
    ) -> Result<(), InverseError> {
        let n = width as usize * height as usize;
        let setting = |name, v: f64, allowed: &str| InverseError::Setting {
            name,
            value: short(v),
            allowed: allowed.into(),
        };
        match &self.viewing {
            Viewing::Angle(a) if !(0.0..=84.0).contains(a) => {
                return Err(setting("angle_deg", *a, "0 to 84 degrees (cos θ ≥ 0.1)"));
            }
            Viewing::CosMap(m) if m.len() != n => {
                return Err(InverseError::Size {
                    what: "angle map",
                    len: m.len(),
                    expected: n,
                });
            }
            Viewing::CosMap(m) => {
                if let Some(i) = m.iter().position(|c| !(0.0..=1.0).contains(c)) {
                    return Err(InverseError::Photo(format!(
                        "the angle map's cos θ at ({}, {}) is {}: it must lie in [0, 1]",
                        i % width as usize,
                        i / width as usize,
                        m[i]
                    )));
                }
            }
            Viewing::Sphere {
                centre_px,
                radius_px,
            } => {
                if !(radius_px.is_finite() && *radius_px >= 1.0 && *radius_px <= 1e6) {
                    return Err(setting("sphere radius_px", *radius_px, "1 to 1e6 pixels"));
                }
                if !centre_px.iter().all(|c| c.is_finite() && c.abs() <= 1e6) {
                    return Err(setting(
                        "sphere centre",
                        centre_px[0],
                        "finite, within 1e6 pixels",
                    ));
                }
            }
            Viewing::Angle(_) => {}
        }
        if let Some(mask) = &self.mask
            && mask.len() != n
        {
            return Err(InverseError::Size {
                what: "mask",
                len: mask.len(),
                expected: n,
            });
        }
        if !(self.max_residual_de.is_finite()
            && self.max_residual_de > 0.0
            && self.max_residual_de <= 100.0)
        {
            return Err(setting(
                "max_residual_de",
                self.max_residual_de,
                "above 0, at most 100",
            ));
        }
        if !(self.smoothness_nm.is_finite() && (1.0..=500.0).contains(&self.smoothness_nm)) {
            return Err(setting("smoothness_nm", self.smoothness_nm, "1 to 500 nm"));
        }
        for a in &self.anchors {
            if a.x >= width || a.y >= height {
                return Err(InverseError::Outside {
                    what: "anchor",
                    value: format!("{},{}={}", a.x, a.y, short(a.thickness_nm)),
                    width,
                    height,
                });
            }
            if !(0.0..=thickness_max_nm).contains(&a.thickness_nm) {
                return Err(setting(
                    "anchor thickness_nm",
                    a.thickness_nm,
                    &format!("0 to the model's thickness_max_nm {thickness_max_nm}"),
                ));
            }
        }
        match &self.calibration {
            Calibration::Given(camera) => camera.check(),
            Calibration::White(r) => r.check("white region", width, height),
            Calibration::Known(r, nm) => {
                r.check("reference region", width, height)?;
                if (0.0..=thickness_max_nm).contains(nm) {
                    Ok(())
                } else {
                    Err(setting(
                        "reference thickness_nm",
                        *nm,
                        "0 to thickness_max_nm",
                    ))
                }
            }
            Calibration::Auto => Ok(()),
        }
    }

    /// cos θ of each pixel, `None` where the geometry excludes it.
    pub(crate) fn cos_of(&self, width: u32, height: u32) -> Vec<Option<f32>> {
        let n = width as usize * height as usize;
        let keep = |c: f64| (c >= MIN_COS).then_some(c as f32);
        match &self.viewing {
            Viewing::Angle(a) => vec![keep(a.to_radians().cos()); n],
            Viewing::CosMap(m) => m.iter().map(|&c| keep(f64::from(c))).collect(),
            Viewing::Sphere {
                centre_px,
                radius_px,
            } => (0..n)
                .map(|i| {
                    let x = (i % width as usize) as f64 + 0.5 - centre_px[0];
                    let y = (i / width as usize) as f64 + 0.5 - centre_px[1];
                    let s2 = (x * x + y * y) / (radius_px * radius_px);
                    if s2 < 1.0 {
                        keep((1.0 - s2).sqrt())
                    } else {
                        None
                    }
                })
                .collect(),
        }
    }
}

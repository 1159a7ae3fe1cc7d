//! Small validation helpers: each names the parameter and its value on failure.

use glam::DVec3;

use crate::error::ParamError;

pub(crate) fn positive(name: &str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, v, "must be positive and finite"))
    }
}

pub(crate) fn non_negative(name: &str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, v, "must be non-negative and finite"))
    }
}

pub(crate) fn unit_interval(name: &str, v: f64) -> Result<(), ParamError> {
    if (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(ParamError::new(name, v, "must lie in [0, 1]"))
    }
}

pub(crate) fn finite_vec(name: &str, v: DVec3) -> Result<(), ParamError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ParamError::new(name, v.to_array(), "must be finite"))
    }
}

pub(crate) fn nonzero_vec(name: &str, v: DVec3) -> Result<(), ParamError> {
    if v.is_finite() && v.length_squared() > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            name,
            v.to_array(),
            "must be finite and non-zero",
        ))
    }
}

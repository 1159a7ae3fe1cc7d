//! Errors: invalid parameters (before a world exists) and failures while stepping.

use std::fmt;

/// A parameter that fails validation, named with its value and what it must satisfy.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    name: String,
    value: String,
    requirement: String,
}

impl ParamError {
    /// A new error for parameter `name` holding `value`, which `requirement` explains.
    pub fn new(
        name: impl Into<String>,
        value: impl fmt::Debug,
        requirement: impl Into<String>,
    ) -> Self {
        Self {
            name: name.into(),
            value: format!("{value:?}"),
            requirement: requirement.into(),
        }
    }

    /// The parameter's path, e.g. `bubbles[1].radius_m`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The offending value as written by `Debug`.
    pub fn value(&self) -> &str {
        &self.value
    }

    /// What the value must satisfy.
    pub fn requirement(&self) -> &str {
        &self.requirement
    }

    /// The same error with `prefix.` in front of the name (for nested parameters).
    pub(crate) fn within(mut self, prefix: &str) -> Self {
        self.name = format!("{prefix}.{}", self.name);
        self
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {} {}", self.name, self.value, self.requirement)
    }
}

impl std::error::Error for ParamError {}

/// Why a bubble's state was judged diverged.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Divergence {
    /// A position or velocity became NaN or infinite.
    NonFinite {
        /// The vertex index.
        vertex: usize,
    },
    /// A vertex moved faster than the configured limit (default: the speed of sound in
    /// air, which a soap film cannot reach; only energy blow-up gets there).
    Speed {
        /// The vertex index.
        vertex: usize,
        /// Its speed.
        speed_m_per_s: f64,
        /// The limit (`WorldParams::max_speed_m_per_s`).
        limit_m_per_s: f64,
    },
    /// The enclosed volume left [1/100, 100]× its rest value, or turned inside out.
    Volume {
        /// Current volume over rest volume.
        ratio: f64,
    },
}

impl fmt::Display for Divergence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { vertex } => {
                write!(f, "vertex {vertex} has a non-finite position or velocity")
            }
            Self::Speed {
                vertex,
                speed_m_per_s,
                limit_m_per_s,
            } => {
                write!(
                    f,
                    "vertex {vertex} moves at {speed_m_per_s:.4e} m/s, above the {limit_m_per_s} m/s limit (energy blow-up)"
                )
            }
            Self::Volume { ratio } => write!(f, "volume is {ratio:.4e} × its rest value"),
        }
    }
}

/// A failure while stepping a world. After one, the world refuses to step further.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SimError {
    /// The integration blew up.
    Diverged {
        /// The step that failed, counting from 1.
        step: u64,
        /// The substep within it, counting from 0.
        substep: u32,
        /// Simulated time at the start of that substep.
        time_s: f64,
        /// The bubble (`Bubble::id`).
        bubble_id: u64,
        /// What went wrong.
        reason: Divergence,
    },
    /// The stability bound asked for more substeps than `WorldParams::max_substeps`.
    TooManySubsteps {
        /// The step that failed, counting from 1.
        step: u64,
        /// The bubble with the tightest bound.
        bubble_id: u64,
        /// Substeps the bound asked for.
        needed: u64,
        /// The configured limit.
        limit: u32,
    },
    /// `advance`/`advance_to` was given a negative or non-finite duration.
    BadDuration {
        /// The duration in seconds.
        seconds: f64,
    },
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Diverged {
                step,
                substep,
                time_s,
                bubble_id,
                reason,
            } => write!(
                f,
                "simulation diverged at step {step} (substep {substep}, t = {time_s:.6} s), bubble {bubble_id}: {reason}"
            ),
            Self::TooManySubsteps {
                step,
                bubble_id,
                needed,
                limit,
            } => write!(
                f,
                "step {step}: bubble {bubble_id} needs {needed} substeps for stability, above max_substeps = {limit} (lower dt_s)"
            ),
            Self::BadDuration { seconds } => {
                write!(f, "duration {seconds} s must be finite and non-negative")
            }
        }
    }
}

impl std::error::Error for SimError {}

//! Progress bars on stderr: frames for `animate`, solver steps for `render` and `simulate`.
//!
//! indicatif draws nothing when stderr is not a terminal, so pipes, logs and tests stay
//! quiet without a flag.

use bubble_dynamics::{Event, SimError, World};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::{Duration, Instant};

/// Solver runs shorter than this show no bar (it would only flash).
const STEP_BAR_DELAY: Duration = Duration::from_secs(1);

/// A progress bar that may stay hidden until the work has taken a while.
pub struct Progress {
    bar: ProgressBar,
    started: Instant,
    hidden_until: Option<Duration>,
}

impl Progress {
    /// A bar over `len` frames, shown at once, with frames done, frames per second and ETA.
    pub fn frames(len: u64) -> Self {
        Self::new(len, "frames", None)
    }

    /// A bar over `len` solver steps that appears only once a second has passed.
    pub fn steps(len: u64) -> Self {
        Self::new(len, "steps", Some(STEP_BAR_DELAY))
    }

    /// A bar that never shows.
    pub fn off() -> Self {
        Self {
            bar: ProgressBar::hidden(),
            started: Instant::now(),
            hidden_until: None,
        }
    }

    fn new(len: u64, unit: &str, hidden_until: Option<Duration>) -> Self {
        let template = format!(
            "{{bar:40}} {{pos}}/{{len}} {unit}  {{per_sec}}  ETA {{eta}}  (elapsed {{elapsed}})"
        );
        let style = ProgressStyle::with_template(&template)
            .expect("the template is valid (tested)")
            .progress_chars("=> ");
        let target = if hidden_until.is_some() {
            ProgressDrawTarget::hidden()
        } else {
            ProgressDrawTarget::stderr()
        };
        let bar = ProgressBar::with_draw_target(Some(len), target).with_style(style);
        Self {
            bar,
            started: Instant::now(),
            hidden_until,
        }
    }

    /// Records `n` more units done.
    pub fn inc(&mut self, n: u64) {
        if let Some(delay) = self.hidden_until
            && self.started.elapsed() >= delay
        {
            self.hidden_until = None;
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        self.bar.inc(n);
    }

    /// Records units that were already done (resumed frames), without counting them in the rate.
    pub fn skip(&mut self, n: u64) {
        self.bar.set_position(self.bar.position() + n);
        self.bar.reset_eta();
    }

    /// Removes the bar from the terminal.
    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}

/// Steps `world` until its step count is `round(time_s / dt)`, exactly as
/// [`World::advance_to`], counting each step on `progress`.
///
/// # Errors
/// [`SimError::BadDuration`] for a negative or non-finite target; otherwise the first
/// step's error.
pub fn advance_world(
    world: &mut World,
    time_s: f64,
    progress: &mut Progress,
) -> Result<Vec<Event>, SimError> {
    if !(time_s.is_finite() && time_s >= 0.0) {
        return Err(SimError::BadDuration { seconds: time_s });
    }
    advance_world_steps(world, steps_to(world, time_s), progress)
}

/// Steps `world` until its step count is `target`, counting each step on `progress`.
///
/// # Errors
/// The first step's error.
pub fn advance_world_steps(
    world: &mut World,
    target: u64,
    progress: &mut Progress,
) -> Result<Vec<Event>, SimError> {
    let mut events = Vec::new();
    // A signal stops the loop early; the caller's `signals::check` reports it.
    while world.steps() < target && !crate::signals::interrupted() {
        events.extend(world.step()?);
        progress.inc(1);
    }
    Ok(events)
}

/// The step count at which `world` reaches `time_s` (the rule of [`World::advance_to`]).
pub fn steps_to(world: &World, time_s: f64) -> u64 {
    (time_s / world.dt_s()).round() as u64
}

/// The count of the last step that ends at or before `time_s` (a step that ends within
/// a billionth of a step after it counts: `time_s` computed from a frame number lands
/// on a step only to rounding).
pub fn steps_by(world: &World, time_s: f64) -> u64 {
    (time_s / world.dt_s() + 1e-9).floor() as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bars_build_without_a_terminal() {
        let mut p = Progress::frames(3);
        p.skip(1);
        p.inc(2);
        p.finish();
        let mut s = Progress::steps(5);
        s.inc(5);
        s.finish();
    }
}

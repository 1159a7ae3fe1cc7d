//! Adaptive internal resolution: render fewer pixels when frames are too slow to hold the
//! target rate, and upscale for presentation.

/// Smallest internal scale (a quarter of the window's width and height).
pub const MIN_SCALE: f32 = 0.25;
/// How far each update moves towards the estimated right scale (damps oscillation).
const GAIN: f32 = 0.5;
/// Frames within this fraction of the budget leave the scale alone (no hunting).
const DEAD_BAND: f32 = 0.1;

/// The internal resolution scale in (MIN_SCALE, 1], updated from measured frame times.
///
/// # Guarantees
/// `scale()` is always in `[MIN_SCALE, 1]`, and stays 1 when fixed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResolutionScale {
    scale: f32,
    budget_s: f32,
    fixed: bool,
}

impl ResolutionScale {
    /// Starts at full resolution, aiming at `target_fps`; `fixed` turns adaptation off.
    /// A non-finite or non-positive target is treated as fixed.
    pub fn new(target_fps: f32, fixed: bool) -> ResolutionScale {
        let ok = target_fps.is_finite() && target_fps > 0.0;
        ResolutionScale {
            scale: 1.0,
            budget_s: if ok { 1.0 / target_fps } else { 1.0 },
            fixed: fixed || !ok,
        }
    }

    /// The current scale.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// Whether adaptation is off.
    pub fn is_fixed(&self) -> bool {
        self.fixed
    }

    /// Folds in the time the last frame took to render at the current scale. The render
    /// cost is taken as proportional to the pixel count, i.e. to scale².
    pub fn update(&mut self, render_s: f32) {
        if self.fixed || !(render_s.is_finite() && render_s > 0.0) {
            return;
        }
        let ratio = self.budget_s / render_s;
        if (ratio - 1.0).abs() < DEAD_BAND {
            return;
        }
        let wanted = self.scale * ratio.sqrt();
        let next = self.scale + GAIN * (wanted - self.scale);
        self.scale = next.clamp(MIN_SCALE, 1.0);
    }

    /// The internal size for a window of `width`×`height` (at least 1×1).
    pub fn internal_size(&self, width: usize, height: usize) -> (usize, usize) {
        let s = |n: usize| ((n as f32 * self.scale).round() as usize).clamp(1, n.max(1));
        (s(width), s(height))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A renderer whose cost is `full_s` at scale 1 and proportional to the pixel count.
    fn settle(full_s: f32, fixed: bool) -> f32 {
        let mut r = ResolutionScale::new(60.0, fixed);
        for _ in 0..50 {
            r.update(full_s * r.scale() * r.scale());
        }
        r.scale()
    }

    #[test]
    fn a_renderer_four_times_too_slow_settles_near_half_scale() {
        let s = settle(4.0 / 60.0, false);
        // Cost at s is 4 s² / 60: within the dead band of the budget means s² · 4 ∈ [0.9, 1.1].
        assert!((0.9..=1.1).contains(&(4.0 * s * s)), "scale {s}");
    }

    #[test]
    fn a_fast_renderer_stays_at_full_scale_and_fixed_never_moves() {
        assert_eq!(settle(0.2 / 60.0, false), 1.0);
        assert_eq!(settle(10.0 / 60.0, true), 1.0);
    }

    proptest! {
        #[test]
        fn the_scale_stays_in_range(times in proptest::collection::vec(-1.0f32..10.0, 1..40)) {
            let mut r = ResolutionScale::new(60.0, false);
            for t in times {
                r.update(t);
                prop_assert!((MIN_SCALE..=1.0).contains(&r.scale()));
                let (w, h) = r.internal_size(640, 480);
                prop_assert!((1..=640).contains(&w) && (1..=480).contains(&h));
            }
        }
    }
}

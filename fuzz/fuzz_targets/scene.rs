//! Scenes end to end: generated TOML → parse and validate → solver (a few steps) →
//! tables → renderer at 24 × 16. Every outcome is an input error (exit code 2), a solver
//! divergence (exit code 1, reported by the solver), or a frame without a NaN, infinite
//! or negative pixel.
#![no_main]
use bubbles_fuzz::frame::{FrameJob, Options};
use bubbles_fuzz::scenegen::{FuzzScene, files};
use bubbles_fuzz::scene::Scene;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|fuzz: FuzzScene| {
    let text = fuzz.toml();
    let Ok(scene) = Scene::from_toml_str(&text, "fuzz.toml", files()) else {
        return;
    };
    let options = Options {
        width: Some(24),
        height: Some(16),
        samples: Some(1),
        cube_map_size: Some(8),
        ..Options::default()
    };
    let mut job = match FrameJob::from_scene(scene, &options) {
        Ok(job) => job,
        Err(e) => {
            assert_eq!(e.exit_code(), 2, "{e}\n{text}");
            return;
        }
    };
    let time_s = job.scene_time_s().min(3.0 * job.dt_s());
    if let Err(e) = job.advance_to(time_s, false) {
        assert!(e.exit_code() == 2 || e.to_string().contains("diverged"), "{e}\n{text}");
        return;
    }
    match job.render() {
        Ok(frame) => {
            let bad = frame
                .rgb()
                .iter()
                .flatten()
                .find(|c| !(c.is_finite() && **c >= 0.0));
            assert!(bad.is_none(), "pixel {bad:?}\n{text}");
        }
        Err(e) => assert_eq!(e.exit_code(), 2, "{e}\n{text}"),
    }
});

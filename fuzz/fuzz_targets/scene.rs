//! Scenes end to end: generated TOML → parse and validate → solver (a few steps) →
//! tables → renderer at 24 × 16. Every outcome is an input error (exit code 2), a solver
//! divergence (exit code 1, reported by the solver), or a frame without a NaN or
//! infinite pixel (slightly negative linear values are legal: out-of-gamut colours).
//! Every 500 inputs it prints how far they got, to show the renderer is reached.
#![no_main]
use bubbles_fuzz::frame::{FrameJob, Options};
use bubbles_fuzz::scenegen::{FuzzScene, files};
use bubbles_fuzz::scene::Scene;
use libfuzzer_sys::fuzz_target;
use std::sync::atomic::{AtomicU64, Ordering};

/// Inputs that stopped at parsing, at the checks/solver set-up, while stepping, or rendered.
static STAGES: [AtomicU64; 4] = [const { AtomicU64::new(0) }; 4];

fn reached(stage: usize) {
    STAGES[stage].fetch_add(1, Ordering::Relaxed);
    let total: u64 = STAGES.iter().map(|s| s.load(Ordering::Relaxed)).sum();
    if total % 500 == 0 {
        let [p, s, a, r] = STAGES.each_ref().map(|s| s.load(Ordering::Relaxed));
        eprintln!("stages: parse-refused {p}, prepare-refused {s}, step-refused {a}, rendered {r}");
    }
}

fuzz_target!(|fuzz: FuzzScene| {
    let text = fuzz.toml();
    let Ok(scene) = Scene::from_toml_str(&text, "fuzz.toml", files()) else {
        reached(0);
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
            reached(1);
            return;
        }
    };
    let time_s = job.scene_time_s().min(3.0 * job.dt_s());
    if let Err(e) = job.advance_to(time_s, false) {
        assert!(e.exit_code() == 2 || e.to_string().contains("diverged"), "{e}\n{text}");
        reached(2);
        return;
    }
    match job.render() {
        Ok(frame) => {
            let bad = frame
                .rgb()
                .iter()
                .flatten()
                .find(|c| !c.is_finite());
            assert!(bad.is_none(), "pixel {bad:?}\n{text}");
            reached(3);
        }
        Err(e) => assert_eq!(e.exit_code(), 2, "{e}\n{text}"),
    }
});

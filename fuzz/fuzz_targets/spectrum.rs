//! Spectrum CSVs: the scene's check, then thinfilm's reader and the integration the
//! bake and the lights do. A spectrum that passes the check either fails with an error
//! or integrates to a finite white.
#![no_main]
use libfuzzer_sys::fuzz_target;
use thinfilm::cmf::Observer;
use thinfilm::integrate::{DEFAULT_STEP_NM, SpectralIntegrator};
use thinfilm::spectrum::Spectrum;

fuzz_target!(|text: &str| {
    let dir = std::env::temp_dir().join(format!("bubbles-fuzz-spectrum-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("s.csv");
    if std::fs::write(&path, text).is_err() {
        return;
    }
    if bubbles_fuzz::scene::check_spectrum_file(&path).is_err() {
        return;
    }
    let Ok(spectrum) = Spectrum::from_csv_str(text) else {
        return;
    };
    if let Ok(integrator) = SpectralIntegrator::new(Observer::Cie1931, &spectrum, DEFAULT_STEP_NM) {
        let xyz = integrator.white_xyz();
        assert!(xyz.iter().all(|c| c.is_finite()), "white {xyz:?} from {text:?}");
    }
});

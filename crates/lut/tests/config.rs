//! `BakeConfig` validation: every refusal names the bad value.

use lut::{BakeConfig, ConfigError, Light};
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::illuminant::Illuminant;

fn refused(builder: lut::BakeConfigBuilder) -> ConfigError {
    builder.build().expect_err("should be refused")
}

#[test]
fn defaults_are_the_documented_ones() {
    let config = BakeConfig::default();
    assert_eq!((config.width(), config.height()), (4096, 128));
    assert_eq!(config.thickness_max_nm(), 4000.0);
    assert_eq!(config.step_nm(), 5.0);
    assert_eq!(*config.film_index(), RefractiveIndex::SOAP);
    assert_eq!(config.reference().name(), "d65");
    let names: Vec<_> = config.lights().iter().map(Light::name).collect();
    assert_eq!(names, ["sodium"]);
}

#[test]
fn refuses_bad_resolutions() {
    for (w, h) in [
        (0, 8),
        (1, 8),
        (8, 0),
        (16385, 8),
        (8, 16385),
        (16384, 16384),
    ] {
        let err = refused(BakeConfig::builder().resolution(w, h));
        assert_eq!(
            err,
            ConfigError::Resolution {
                width: w,
                height: h
            }
        );
        assert!(err.to_string().contains(&format!("{w}x{h}")), "{err}");
    }
}

#[test]
fn refuses_bad_thickness_ranges() {
    for d in [0.0, -5.0, f32::NAN, f32::INFINITY, 1e6] {
        let err = refused(BakeConfig::builder().thickness_max_nm(d));
        assert!(matches!(err, ConfigError::ThicknessMax(_)), "{err:?}");
        assert!(err.to_string().contains(&format!("{d}")), "{err}");
    }
}

#[test]
fn refuses_bad_steps() {
    for step in [0.0, 0.5, -1.0, 51.0, f64::NAN] {
        let err = refused(BakeConfig::builder().step_nm(step));
        assert!(matches!(err, ConfigError::Step(_)), "{err:?}");
        assert!(err.to_string().contains(&format!("{step}")), "{err}");
    }
}

#[test]
fn refuses_bad_film_indices() {
    let err = refused(BakeConfig::builder().film_index(RefractiveIndex::Constant(0.8)));
    assert!(err.to_string().contains("0.8"), "{err}");
    let err = refused(BakeConfig::builder().film_index(RefractiveIndex::Constant(f64::NAN)));
    assert!(matches!(err, ConfigError::FilmIndex(_)), "{err:?}");
    let cauchy = RefractiveIndex::Cauchy {
        a: 1.0,
        b_nm2: -1e6,
        c_nm4: 0.0,
    };
    assert!(matches!(
        refused(BakeConfig::builder().film_index(cauchy)),
        ConfigError::FilmIndex(_)
    ));
}

#[test]
fn refuses_a_coloured_reference_white_and_repeated_or_unsafe_lights() {
    let err = refused(BakeConfig::builder().reference(Light::illuminant(Illuminant::Sodium)));
    assert!(matches!(err, ConfigError::ReferenceWhite { .. }), "{err:?}");
    assert!(err.to_string().contains("sodium"), "{err}");

    let twice = vec![
        Light::illuminant(Illuminant::A),
        Light::illuminant(Illuminant::A),
    ];
    let err = refused(BakeConfig::builder().lights(twice));
    assert_eq!(err, ConfigError::DuplicateLight("a".into()));

    let spectrum = Illuminant::E.spectrum();
    for name in ["", "../x", "a b", &"x".repeat(65)] {
        let err = Light::try_new(name, spectrum.clone()).expect_err("unsafe name");
        assert_eq!(err, ConfigError::LightName(name.into()));
    }
    assert!(Light::try_new("my-lamp_2", spectrum).is_ok());
}

#[test]
fn csv_lights_are_named_after_their_file_and_report_bad_lines() {
    let dir = tempfile::tempdir().expect("temp dir");
    let good = dir.path().join("warm lamp.csv");
    std::fs::write(&good, "wavelength_nm,value\n400,1\n500,2\n600,3\n700,2\n").expect("write");
    let light = Light::try_from_csv_path(&good).expect("valid CSV");
    assert_eq!(light.name(), "warm_lamp");
    let config = BakeConfig::builder()
        .lights(vec![light])
        .build()
        .expect("valid");
    assert_eq!(config.lights()[0].name(), "warm_lamp");

    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "wavelength_nm,value\n400,1\n500,oops\n").expect("write");
    let err = Light::try_from_csv_path(&bad).expect_err("malformed");
    let message = err.to_string();
    assert!(
        message.contains("bad.csv") && message.contains("line 3"),
        "{message}"
    );

    let dark = dir.path().join("infrared.csv");
    std::fs::write(&dark, "wavelength_nm,value\n900,1\n1000,1\n").expect("write");
    let light = Light::try_from_csv_path(&dark).expect("parses");
    let err = refused(BakeConfig::builder().lights(vec![light]));
    assert!(matches!(err, ConfigError::Light { .. }), "{err:?}");
    assert!(err.to_string().contains("infrared"), "{err}");
}

//! Saving and loading: EXR is bit-exact, the 16-bit PNG decodes as documented in
//! `lut.json`, and a wrong version, a corrupt or truncated file, a tampered description
//! or a failed save are refused cleanly.

use std::path::Path;

use lut::{BakeConfig, Format, Light, LoadError, Lut, LutSet, SaveError};
use thinfilm::illuminant::Illuminant;

fn baked() -> LutSet {
    let config = BakeConfig::builder()
        .resolution(40, 9)
        .lights(
            [Illuminant::Sodium, Illuminant::F11]
                .map(Light::illuminant)
                .to_vec(),
        )
        .build()
        .expect("valid config");
    lut::bake(&config)
}

fn saved(formats: &[Format]) -> (tempfile::TempDir, LutSet) {
    let dir = tempfile::tempdir().expect("temp dir");
    let set = baked();
    set.save(dir.path(), formats).expect("save");
    (dir, set)
}

fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .expect("readable")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("lut.json")).expect("lut.json"))
        .expect("valid JSON")
}

fn write_json(dir: &Path, value: &serde_json::Value) {
    std::fs::write(dir.join("lut.json"), value.to_string()).expect("write");
}

#[test]
fn exr_round_trip_is_bit_exact_including_negative_and_extreme_values() {
    let (dir, mut set) = saved(&[Format::Exr]);
    // Out-of-gamut negatives, subnormals and large values must survive untouched too.
    let odd = Lut::try_new(
        3,
        2,
        2000.0,
        vec![
            [-0.25, 1e-40, 3.5e7],
            [f32::MIN_POSITIVE, -0.0, 1.0 + f32::EPSILON],
            [0.1, 0.2, 0.3],
            [f32::MAX, -f32::MAX, 0.5],
            [1.0, 0.0, -1.0],
            [0.04, 0.04, 0.04],
        ],
    )
    .expect("valid table");
    set.save(dir.path(), &[Format::Exr]).expect("save");
    let back = LutSet::load(dir.path()).expect("load");
    for (a, b) in set
        .reflectivity
        .texels()
        .iter()
        .zip(back.reflectivity.texels())
    {
        assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits));
    }
    assert_eq!(back, set);

    set.reflectivity = odd.clone();
    set.transmittance = odd.clone();
    set.lights = vec![("odd".into(), odd.clone())];
    set.meta.thickness_max_nm = 2000.0;
    set.save(dir.path(), &[Format::Exr]).expect("save");
    let back = LutSet::load(dir.path()).expect("load");
    for (a, b) in odd.texels().iter().zip(back.reflectivity.texels()) {
        assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits));
    }
}

#[test]
fn png16_only_set_loads_within_the_stated_quantisation() {
    let (dir, set) = saved(&[Format::Png16]);
    let back = LutSet::load(dir.path()).expect("load");
    let doc = json(dir.path());
    for (k, (name, table)) in set.named_tables().into_iter().enumerate() {
        let entry = &doc["textures"][k];
        assert_eq!(entry["name"], name.as_str());
        let scale = entry["png16"]["scale"].as_f64().expect("scale");
        let offset = entry["png16"]["offset"].as_f64().expect("offset");
        assert!(
            offset <= 0.0 && offset + scale >= 1.0,
            "range must cover 0..1"
        );
        let loaded = back.named_tables()[k].1;
        for (a, b) in table.texels().iter().zip(loaded.texels()) {
            for c in 0..3 {
                let err = f64::from((a[c] - b[c]).abs());
                let bound = scale / 65535.0 / 2.0 + 1e-6 * scale;
                assert!(
                    err <= bound,
                    "{name}: |{} - {}| = {err:e} > {bound:e}",
                    a[c],
                    b[c]
                );
            }
        }
    }
}

#[test]
fn lut_json_states_axes_mapping_and_provenance() {
    let (dir, set) = saved(&Format::ALL);
    let doc = json(dir.path());
    assert_eq!(doc["format_version"], lut::FORMAT_VERSION);
    assert_eq!(doc["width"], 40);
    assert_eq!(doc["height"], 9);
    assert_eq!(
        doc["axes"]["u"]["max"],
        f64::from(lut::config::DEFAULT_THICKNESS_MAX_NM)
    );
    let u = doc["axes"]["u"]["texture_coordinate"]
        .as_str()
        .expect("string");
    assert!(
        u.contains("(d / max * (samples - 1) + 0.5) / samples"),
        "{u}"
    );
    assert!(
        doc["axes"]["v"]["texel"]
            .as_str()
            .expect("string")
            .contains("top")
    );
    assert_eq!(doc["meta"]["reference_illuminant"], "d65");
    assert_eq!(doc["meta"]["observer"], "CIE 1931 2-degree");
    assert!(
        doc["meta"]["color_space"]
            .as_str()
            .expect("string")
            .contains("linear sRGB")
    );
    let names: Vec<_> = doc["textures"]
        .as_array()
        .expect("array")
        .iter()
        .map(|t| t["name"].as_str().expect("name").to_owned())
        .collect();
    assert_eq!(
        names,
        ["reflectivity", "transmittance", "light_sodium", "light_f11"]
    );
    assert_eq!(
        file_names(dir.path()).len(),
        1 + 3 * 4,
        "{:?}",
        file_names(dir.path())
    );
    assert_eq!(set.light("f11"), Some(&set.lights[1].1));
}

#[test]
fn save_leaves_no_temporary_files_and_replaces_an_older_set() {
    let (dir, _) = saved(&[Format::Exr, Format::Png16]);
    let second = {
        let config = BakeConfig::builder()
            .resolution(17, 5)
            .build()
            .expect("valid config");
        lut::bake(&config)
    };
    second.save(dir.path(), &[Format::Exr]).expect("save");
    assert!(file_names(dir.path()).iter().all(|n| !n.ends_with(".tmp")));
    assert_eq!(LutSet::load(dir.path()).expect("load"), second);
}

#[test]
fn a_save_that_fails_part_way_leaves_nothing_new_behind() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A directory squatting on one target name makes its rename fail after others succeeded.
    std::fs::create_dir(dir.path().join("transmittance.png")).expect("mkdir");
    let err = baked()
        .save(dir.path(), &[Format::Exr, Format::Png16])
        .expect_err("rename onto a directory fails");
    assert!(matches!(err, SaveError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("transmittance.png"), "{err}");
    assert_eq!(file_names(dir.path()), ["transmittance.png"]);
}

#[test]
fn save_refuses_an_unwritable_directory_and_an_inconsistent_set() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("plain-file");
    std::fs::write(&file, b"x").expect("write");
    let err = baked()
        .save(&file.join("sub"), &Format::DEFAULT)
        .expect_err("not a dir");
    assert!(err.to_string().contains("plain-file"), "{err}");

    let mut set = baked();
    set.lights[0].1 = Lut::try_new(2, 2, 2000.0, vec![[0.0; 3]; 4]).expect("valid");
    let err = set
        .save(dir.path(), &Format::DEFAULT)
        .expect_err("inconsistent");
    assert!(
        matches!(err, SaveError::Inconsistent { ref table } if table == "light_sodium"),
        "{err:?}"
    );
    let mut set = baked();
    set.lights[1].0 = "../escape".into();
    assert!(matches!(
        set.save(dir.path(), &Format::DEFAULT),
        Err(SaveError::BadLightName(_))
    ));
    assert!(matches!(
        baked().save(dir.path(), &[]),
        Err(SaveError::NoFormats)
    ));
    assert_eq!(file_names(dir.path()), ["plain-file"]);
}

#[test]
fn load_refuses_another_format_version() {
    let (dir, _) = saved(&[Format::Exr]);
    let mut doc = json(dir.path());
    doc["format_version"] = serde_json::json!(2);
    write_json(dir.path(), &doc);
    let err = LutSet::load(dir.path()).expect_err("version 2");
    assert!(matches!(err, LoadError::Version { .. }), "{err:?}");
    assert!(err.to_string().contains("format_version 2"), "{err}");
}

#[test]
fn load_refuses_a_truncated_exr() {
    let (dir, _) = saved(&[Format::Exr]);
    let path = dir.path().join("light_f11.exr");
    let bytes = std::fs::read(&path).expect("read");
    for keep in [bytes.len() - 100, bytes.len() / 2, 20] {
        std::fs::write(&path, &bytes[..keep]).expect("write");
        let err = LutSet::load(dir.path()).expect_err("truncated");
        assert!(err.to_string().contains("light_f11.exr"), "{err}");
        assert!(
            matches!(err, LoadError::Corrupt { .. } | LoadError::Checksum { .. }),
            "{err:?}"
        );
    }
}

#[test]
fn load_refuses_a_flipped_bit_the_decoder_cannot_see() {
    let (dir, _) = saved(&[Format::Exr, Format::Png16]);
    let path = dir.path().join("reflectivity.exr");
    let mut bytes = std::fs::read(&path).expect("read");
    // Uncompressed EXR: the last bytes are pixel data.
    let last = bytes.len() - 3;
    bytes[last] ^= 0x10;
    std::fs::write(&path, bytes).expect("write");
    let err = LutSet::load(dir.path()).expect_err("flipped bit");
    assert!(matches!(err, LoadError::Checksum { .. }), "{err:?}");
    assert!(err.to_string().contains("reflectivity.exr"), "{err}");
}

#[test]
fn load_refuses_a_corrupt_png16() {
    let (dir, _) = saved(&[Format::Png16]);
    let path = dir.path().join("transmittance.png");
    let mut bytes = std::fs::read(&path).expect("read");
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0xff;
    std::fs::write(&path, &bytes).expect("write");
    let err = LutSet::load(dir.path()).expect_err("corrupt");
    assert!(err.to_string().contains("transmittance.png"), "{err}");
}

#[test]
fn load_refuses_tampered_or_missing_descriptions() {
    let (dir, _) = saved(&[Format::Exr]);
    let original = json(dir.path());

    let mut doc = original.clone();
    doc["textures"][0]["exr"] = serde_json::json!("../reflectivity.exr");
    write_json(dir.path(), &doc);
    let err = LutSet::load(dir.path()).expect_err("path escape");
    assert!(matches!(err, LoadError::Inconsistent { .. }), "{err:?}");

    let mut doc = original.clone();
    doc["width"] = serde_json::json!(41);
    write_json(dir.path(), &doc);
    assert!(matches!(
        LutSet::load(dir.path()),
        Err(LoadError::Inconsistent { .. })
    ));

    let mut doc = original.clone();
    doc["textures"][0]["texels_fnv1a64"] = serde_json::json!("0000000000000000");
    write_json(dir.path(), &doc);
    assert!(matches!(
        LutSet::load(dir.path()),
        Err(LoadError::Checksum { .. })
    ));

    std::fs::write(
        dir.path().join("lut.json"),
        "{\"format\": \"bubbles-lut\", ",
    )
    .expect("write");
    let err = LutSet::load(dir.path()).expect_err("truncated json");
    assert!(matches!(err, LoadError::Json { .. }), "{err:?}");

    std::fs::remove_file(dir.path().join("lut.json")).expect("remove");
    let err = LutSet::load(dir.path()).expect_err("missing");
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("lut.json"), "{err}");
}

#[test]
fn load_refuses_a_missing_texture_file() {
    let (dir, _) = saved(&[Format::Exr]);
    std::fs::remove_file(dir.path().join("light_sodium.exr")).expect("remove");
    let err = LutSet::load(dir.path()).expect_err("missing file");
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("light_sodium.exr"), "{err}");
}

#[test]
fn png16_refuses_a_range_too_wide_for_f32_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut set = baked();
    set.reflectivity = {
        let mut texels = set.reflectivity.texels().to_vec();
        texels[0] = [f32::MAX, -f32::MAX, 0.0];
        Lut::try_new(40, 9, lut::config::DEFAULT_THICKNESS_MAX_NM, texels).expect("finite")
    };
    let err = set
        .save(dir.path(), &[Format::Exr, Format::Png16])
        .expect_err("too wide");
    assert!(matches!(err, SaveError::Encode { .. }), "{err:?}");
    assert!(
        file_names(dir.path()).is_empty(),
        "{:?}",
        file_names(dir.path())
    );
}

#[test]
fn metadata_of_a_dispersive_bake_round_trips_exactly() {
    let config = BakeConfig::builder()
        .resolution(8, 3)
        .film_index(thinfilm::dispersion::RefractiveIndex::Water)
        .build()
        .expect("valid config");
    let set = lut::bake(&config);
    let dir = tempfile::tempdir().expect("temp dir");
    set.save(dir.path(), &[Format::Exr]).expect("save");
    assert_eq!(LutSet::load(dir.path()).expect("load").meta, set.meta);
}

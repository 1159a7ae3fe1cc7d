//! Scenes: the TOML format (`schema`), its validated values (`values`), the built-in
//! scenes, and the conversions to the solver and the renderer.

mod check;
mod film;
pub mod schema;
mod to_dynamics;
mod to_raster;
pub(crate) use to_raster::bubble_film;
mod to_reference;
mod to_water;
pub mod values;

use crate::error::CliError;
pub use check::{check_memory, check_spectrum_file};
use schema::SceneFile;
use std::path::{Path, PathBuf};
pub use to_dynamics::sim_error;
pub(crate) use to_dynamics::{bubble_params, default_film_grid};
pub use to_raster::bubble_meshes;

/// Built-in scenes, by name, with their TOML source.
pub const BUILTINS: [(&str, &str); 12] = [
    ("paper", include_str!("../../scenes/paper.toml")),
    ("crowd", include_str!("../../scenes/crowd.toml")),
    ("crowd-100", include_str!("../../scenes/crowd-100.toml")),
    (
        "white-furnace",
        include_str!("../../scenes/white-furnace.toml"),
    ),
    ("wind", include_str!("../../scenes/wind.toml")),
    (
        "plane-collision",
        include_str!("../../scenes/plane-collision.toml"),
    ),
    (
        "bubble-collision",
        include_str!("../../scenes/bubble-collision.toml"),
    ),
    ("demo", include_str!("../../scenes/demo.toml")),
    ("demo-white", include_str!("../../scenes/demo-white.toml")),
    ("pond", include_str!("../../scenes/pond.toml")),
    ("swirl", include_str!("../../scenes/swirl.toml")),
    ("dome", include_str!("../../scenes/dome.toml")),
];

/// Name of the scene used when none is given.
pub const DEFAULT_SCENE: &str = "paper";

/// A parsed, validated scene and the directory its relative paths resolve against.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The scene's contents.
    pub file: SceneFile,
    /// Directory that relative paths in the file are resolved against.
    pub base_dir: PathBuf,
    /// Where the scene came from (a path or `builtin:NAME`), for messages.
    pub origin: String,
}

impl Scene {
    /// Parses TOML `text`; `origin` names it in errors.
    pub fn from_toml_str(text: &str, origin: &str, base_dir: &Path) -> Result<Self, CliError> {
        let file: SceneFile = toml::from_str(text).map_err(|e| {
            let (place, key) = match e.span() {
                Some(span) => {
                    let (line, column) = line_column(text, span.start);
                    let key = key_of_value(text, span.clone(), e.message())
                        .or_else(|| key_at(text, span.start))
                        .filter(|k| !e.message().contains(k.as_str()))
                        .map(|k| format!(" {k}:"))
                        .unwrap_or_default();
                    (format!(":{line}:{column}"), key)
                }
                None => (String::new(), String::new()),
            };
            CliError::input(format!("{origin}{place}:{key} {}", e.message()))
        })?;
        Ok(Self {
            file,
            base_dir: base_dir.to_path_buf(),
            origin: origin.to_string(),
        })
    }

    /// Reads and parses the scene file at `path`.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let text = crate::input::read_text(path, "scene")?;
        let base_dir = path.parent().unwrap_or(Path::new("."));
        Self::from_toml_str(&text, &path.display().to_string(), base_dir)
    }

    /// The built-in scene called `name`, if there is one.
    pub fn builtin(name: &str) -> Option<Self> {
        let (_, text) = BUILTINS.iter().find(|(n, _)| *n == name)?;
        let scene = Self::from_toml_str(text, &format!("builtin:{name}"), Path::new("."))
            .expect("built-in scenes parse (tested)");
        Some(scene)
    }

    /// A built-in scene name or a path to a TOML file; `None` gives the default scene.
    pub fn resolve(arg: Option<&str>) -> Result<Self, CliError> {
        let name = arg.unwrap_or(DEFAULT_SCENE);
        if let Some(scene) = Self::builtin(name) {
            return Ok(scene);
        }
        let path = Path::new(name);
        if path.exists() || name.ends_with(".toml") {
            return Self::load(path);
        }
        let names: Vec<&str> = BUILTINS.iter().map(|(n, _)| *n).collect();
        Err(CliError::input(format!(
            "unknown scene {name:?}: give a .toml path or one of: {}",
            names.join(", ")
        )))
    }

    /// Resolves a path written in the scene file.
    pub fn path(&self, relative: &str) -> PathBuf {
        self.base_dir.join(relative)
    }
}

/// The dotted key whose value starts at byte `offset`: the table header above it and
/// the last `key =` before it on its line (`bubbles.radius_m`, `ground.scale_m`).
fn key_at(text: &str, offset: usize) -> Option<String> {
    let offset = (0..=offset.min(text.len()))
        .rev()
        .find(|&i| text.is_char_boundary(i))?;
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[line_start..offset];
    let key = before
        .rsplit('=')
        .nth(1)?
        .rsplit([',', '{', ' ', '\t'])
        .find(|k| !k.is_empty())?
        .trim_matches('"');
    if key.is_empty() || !key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return None;
    }
    let table = text[..line_start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    Some(match table {
        Some(t) if !t.is_empty() => format!("{t}.{key}"),
        _ => key.to_string(),
    })
}

/// Inside a table the parser reports as a whole (a tagged `kind = …` table), the key
/// whose literal holds the number that `message` starts with.
fn key_of_value(text: &str, span: std::ops::Range<usize>, message: &str) -> Option<String> {
    let wanted = numbers_at_start(message)?;
    let region = text.get(span.clone())?;
    let mut offset = 0;
    while let Some(eq) = region[offset..].find('=') {
        let value_start = offset + eq + 1;
        if numbers_at_start(region[value_start..].trim_start()) == Some(wanted.clone()) {
            return key_at(text, span.start + value_start);
        }
        offset = value_start;
    }
    None
}

/// The number (`1e300 …`) or array of numbers (`[1e300, 0.5, 1] …`) `text` starts with.
fn numbers_at_start(text: &str) -> Option<Vec<f64>> {
    let parse = |s: &str| s.trim().replace('_', "").parse::<f64>().ok();
    if let Some(rest) = text.strip_prefix('[') {
        let inner = &rest[..rest.find(']')?];
        inner.split(',').map(parse).collect()
    } else {
        let end = text.find([' ', ',', '}', '\n', '#']).unwrap_or(text.len());
        Some(vec![parse(&text[..end])?])
    }
}

/// 1-based line and column of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.chars().rev().take_while(|c| *c != '\n').count() + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_parse() {
        for (name, _) in BUILTINS {
            let scene = Scene::builtin(name).unwrap();
            assert!(!scene.file.bubbles.is_empty(), "{name} has bubbles");
        }
    }

    #[test]
    fn unknown_field_names_line_and_column() {
        let text = "[camera]\neye_m = [0.0, 0.0, 1.0]\ntarget_m = [0.0, 0.0, 0.0]\nfov = 3\n";
        let err = Scene::from_toml_str(text, "t.toml", Path::new(".")).unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("t.toml:4:1"), "{msg}");
        assert!(msg.contains("fov"), "{msg}");
        assert_eq!(err.exit_code(), 2);
    }

    #[test]
    fn invalid_value_names_line_and_value() {
        let text = "[camera]\neye_m = [0.0, 0.0, 1.0]\ntarget_m = [0.0, 0.0, 0.0]\n\
                    [[bubbles]]\ncenter_m = [0.0, 0.0, 0.0]\nradius_m = -0.5\n";
        let msg = Scene::from_toml_str(text, "t.toml", Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(msg.starts_with("t.toml:6:"), "{msg}");
        assert!(msg.contains("-0.5"), "{msg}");
    }

    #[test]
    fn out_of_range_value_names_key_line_and_value() {
        let text = "[camera]\neye_m = [0.0, 0.0, 1.0]\ntarget_m = [0.0, 0.0, 0.0]\n\
                    [[bubbles]]\ncenter_m = [0.0, 0.0, 0.0]\nradius_m = 1e300\n";
        let msg = Scene::from_toml_str(text, "t.toml", Path::new("."))
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            "t.toml:6:12: bubbles.radius_m: 1e300 is outside 0.001..=1 m"
        );
    }

    #[test]
    fn vector_key_inside_a_tagged_table_is_found() {
        let text = "[camera]\neye_m = [0.0, 0.0, 1.0]\ntarget_m = [0.0, 0.0, 0.0]\n\
                    [environment]\nkind = \"uniform\"\nrgb = [1e300, 0.5, 1]\n";
        let msg = Scene::from_toml_str(text, "t.toml", Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("environment.rgb: [1e300, 0.5, 1]"), "{msg}");
    }

    #[test]
    fn key_inside_an_inline_table_is_found() {
        let text = "[ground]\nmaterial = { kind = \"checker\", scale_m = 1e-300 }\n";
        let offset = text.find("1e-300").unwrap();
        assert_eq!(key_at(text, offset).as_deref(), Some("ground.scale_m"));
        assert_eq!(key_at("time_s = 5", 9).as_deref(), Some("time_s"));
        assert_eq!(key_at("fov = 3", 0), None);
    }

    #[test]
    fn unknown_scene_lists_builtins() {
        let msg = Scene::resolve(Some("nope")).unwrap_err().to_string();
        assert!(
            msg.contains("paper") && msg.contains("white-furnace"),
            "{msg}"
        );
    }

    #[test]
    fn line_column_counts_from_one() {
        assert_eq!(line_column("ab\ncd", 0), (1, 1));
        assert_eq!(line_column("ab\ncd", 4), (2, 2));
    }
}

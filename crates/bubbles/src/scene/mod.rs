//! Scenes: the TOML format (`schema`), its validated values (`values`), the built-in
//! scenes, and the conversions to the solver and the renderer.

mod film;
pub mod schema;
mod to_dynamics;
mod to_raster;
pub mod values;

use crate::error::CliError;
use schema::SceneFile;
use std::path::{Path, PathBuf};
pub(crate) use to_dynamics::bubble_params;
pub use to_raster::bubble_meshes;

/// Built-in scenes, by name, with their TOML source.
pub const BUILTINS: [(&str, &str); 2] = [
    ("paper", include_str!("../../scenes/paper.toml")),
    (
        "white-furnace",
        include_str!("../../scenes/white-furnace.toml"),
    ),
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
            let place = e
                .span()
                .map(|span| {
                    let (line, column) = line_column(text, span.start);
                    format!(":{line}:{column}")
                })
                .unwrap_or_default();
            CliError::input(format!("{origin}{place}: {}", e.message()))
        })?;
        Ok(Self {
            file,
            base_dir: base_dir.to_path_buf(),
            origin: origin.to_string(),
        })
    }

    /// Reads and parses the scene file at `path`.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError::input(format!("cannot read scene {}: {e}", path.display())))?;
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

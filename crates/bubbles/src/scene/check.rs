//! Checks a scene against the limits of [`crate::limits`] before any work: counts,
//! the files it names (size, image pixels), solver steps and the planned memory.

use super::Scene;
use super::schema::{EnvironmentSpec, MaterialSpec, ObjectSpec};
use super::values::plain;
use crate::error::CliError;
use crate::{input, limits};

/// Triangles of an opaque sphere after tessellation (48 × 24 quads).
const SPHERE_TRIANGLES: u64 = 48 * 24 * 2;
/// Triangles of a box.
const BOX_TRIANGLES: u64 = 12;

impl Scene {
    /// Refuses a scene whose counts or files exceed the limits (exit code 2).
    pub fn check_limits(&self) -> Result<(), CliError> {
        let f = &self.file;
        self.check_count("bubbles", f.bubbles.len(), limits::MAX_BUBBLES)?;
        self.check_count("objects", f.objects.len(), limits::MAX_OBJECTS)?;
        self.check_count("lights", f.lights.len(), limits::MAX_LIGHTS)?;
        let vertices: usize = f
            .bubbles
            .iter()
            .map(|b| limits::icosphere_vertices(b.subdivisions.get()))
            .sum();
        if vertices > limits::MAX_BUBBLE_VERTICES {
            return Err(self.error(format!(
                "the bubbles have {vertices} vertices in all, above the limit of {} (lower subdivisions; see --help)",
                limits::MAX_BUBBLE_VERTICES
            )));
        }
        let film_cells = super::to_dynamics::given_film_cells(&f.bubbles);
        if film_cells > limits::MAX_FILM_CELLS {
            return Err(self.error(format!(
                "the bubbles' film grids have {film_cells} cells in all, above the limit of {} (lower film_grid; see --help)",
                limits::MAX_FILM_CELLS
            )));
        }
        self.check_environment_files()?;
        let mut triangles = 0;
        for object in &f.objects {
            triangles += self.check_object(object)?;
        }
        if let Some(g) = &f.ground {
            self.check_material(&g.material)?;
        }
        if let Some(w) = &f.water {
            self.check_material(&w.floor)?;
        }
        if triangles > limits::MAX_OPAQUE_TRIANGLES {
            return Err(self.error(format!(
                "the objects have {triangles} triangles in all, above the limit of {} (see --help)",
                limits::MAX_OPAQUE_TRIANGLES
            )));
        }
        for light in &f.lights {
            self.check_spectrum(&light.spectrum)?;
        }
        self.check_spectrum(&f.film.illuminant)
    }

    /// Refuses advancing from `from_s` to `to_s` when that takes more than
    /// `MAX_SOLVER_STEPS` steps of `dt_s`; `what` names the request in messages.
    pub fn check_steps(
        &self,
        what: &str,
        from_s: f64,
        to_s: f64,
        dt_s: f64,
    ) -> Result<(), CliError> {
        let steps = ((to_s - from_s) / dt_s).ceil();
        if steps > limits::MAX_SOLVER_STEPS as f64 {
            return Err(CliError::input(format!(
                "{what} needs {steps:.3e} solver steps of dynamics.dt_s = {} s, above the limit of {} (see --help)",
                plain(dt_s),
                limits::MAX_SOLVER_STEPS
            )));
        }
        Ok(())
    }

    fn error(&self, message: String) -> CliError {
        CliError::input(format!("{}: {message}", self.origin))
    }

    fn check_count(&self, key: &str, count: usize, limit: usize) -> Result<(), CliError> {
        if count > limit {
            return Err(self.error(format!(
                "{count} {key}, above the limit of {limit} (see --help)"
            )));
        }
        Ok(())
    }

    fn check_environment_files(&self) -> Result<(), CliError> {
        match &self.file.environment {
            EnvironmentSpec::Equirect { path, .. } => {
                self.image(path, "environment.path")?;
            }
            EnvironmentSpec::Cube { faces, .. } => {
                for face in faces {
                    self.image(face, "environment.faces")?;
                }
            }
            EnvironmentSpec::Sky { .. } | EnvironmentSpec::Uniform { .. } => {}
        }
        Ok(())
    }

    /// Checks an object's files; returns its triangle count.
    fn check_object(&self, object: &ObjectSpec) -> Result<u64, CliError> {
        Ok(match object {
            ObjectSpec::Sphere { material, .. } => {
                self.check_material(material)?;
                SPHERE_TRIANGLES
            }
            ObjectSpec::Box { material, .. } => {
                self.check_material(material)?;
                BOX_TRIANGLES
            }
            ObjectSpec::Mesh {
                path,
                material,
                offset_m,
                scale,
            } => {
                self.check_material(material)?;
                let full = self.path(path);
                let key = format!("objects.path {path:?}");
                input::check_text_file(&full, "OBJ mesh")
                    .map_err(|e| self.error(format!("{key}: {e}")))?;
                let text = input::read_text(&full, "OBJ mesh")?;
                if let Some((line, c)) = obj_far_vertex(&text, offset_m.get(), scale.get()) {
                    return Err(self.error(format!(
                        "{key} line {line}: a vertex lands {} m from the origin after scale and offset_m, beyond the scene's 10000 m",
                        plain(c)
                    )));
                }
                obj_triangles(&text)
            }
        })
    }

    fn check_material(&self, material: &MaterialSpec) -> Result<(), CliError> {
        match material {
            MaterialSpec::Image { path, .. } => self.image(path, "material.path"),
            MaterialSpec::Checker { .. } | MaterialSpec::Solid { .. } => Ok(()),
        }
    }

    fn image(&self, path: &str, key: &str) -> Result<(), CliError> {
        input::check_image_file(&self.path(path), "image")
            .map_err(|e| self.error(format!("{key} {path:?}: {e}")))
    }

    fn check_spectrum(&self, spectrum: &str) -> Result<(), CliError> {
        if !spectrum.ends_with(".csv") {
            return Ok(());
        }
        check_spectrum_file(&self.path(spectrum))
            .map_err(|e| self.error(format!("spectrum {spectrum:?}: {e}")))
    }
}

/// Largest value of a spectrum CSV: spectra are relative, and larger values overflow
/// when integrated against the colour-matching functions.
pub const MAX_SPECTRUM_VALUE: f64 = 1e30;

/// Checks a spectrum CSV's size and that every value lies in `0..=MAX_SPECTRUM_VALUE`,
/// naming the file, line and value.
pub fn check_spectrum_file(path: &std::path::Path) -> Result<(), CliError> {
    input::check_text_file(path, "spectrum")?;
    let text = input::read_text(path, "spectrum")?;
    let rows = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .skip(1);
    for (i, line) in rows {
        let value = line
            .split(',')
            .nth(1)
            .and_then(|v| v.trim().parse::<f64>().ok());
        if let Some(v) = value
            && !(0.0..=MAX_SPECTRUM_VALUE).contains(&v)
        {
            return Err(CliError::input(format!(
                "spectrum {} line {}: value {} is outside 0..={} (spectra are relative: scale them down)",
                path.display(),
                i + 1,
                plain(v),
                plain(MAX_SPECTRUM_VALUE)
            )));
        }
    }
    Ok(())
}

/// The first vertex line (1-based) whose scaled, offset coordinate passes 1e4 m, and
/// that coordinate.
fn obj_far_vertex(text: &str, offset_m: [f64; 3], scale: f64) -> Option<(usize, f64)> {
    text.lines().enumerate().find_map(|(i, l)| {
        let rest = l.trim_start().strip_prefix("v ")?;
        rest.split_whitespace()
            .take(3)
            .zip(offset_m)
            .filter_map(|(v, o)| Some(v.parse::<f64>().ok()? * scale + o))
            .find(|c| c.is_nan() || c.abs() > 1e4)
            .map(|c| (i + 1, c))
    })
}

/// Triangles of an OBJ text: each face line `f a b c …` of n corners is n − 2.
fn obj_triangles(text: &str) -> u64 {
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix("f "))
        .map(|rest| rest.split_whitespace().count().saturating_sub(2) as u64)
        .sum()
}

/// Refuses render settings whose buffers would pass `MEMORY_BUDGET_BYTES`: one cube map
/// per bubble plus the frame buffers.
pub fn check_memory(
    bubbles: usize,
    cube_map_size: Option<usize>,
    width: usize,
    height: usize,
    samples: u32,
) -> Result<(), CliError> {
    let cubes = cube_map_size.map_or(0, |s| bubbles as u64 * limits::cube_map_bytes(s));
    let frame = limits::frame_bytes(width, height, samples);
    let total = cubes + frame;
    if total > limits::MEMORY_BUDGET_BYTES {
        let cube_text = match cube_map_size {
            Some(s) if cubes > 0 => format!(
                "{bubbles} bubble cube map(s) of cube_map_size = {s} take {:.2} GiB, ",
                gib(cubes)
            ),
            _ => String::new(),
        };
        return Err(CliError::input(format!(
            "this render needs about {:.2} GiB ({cube_text}a {width}x{height} frame at {samples} sample(s) {:.2} GiB), above the {} GiB limit (see --help): lower cube_map_size, the image size or samples",
            gib(total),
            gib(frame),
            limits::MEMORY_BUDGET_BYTES >> 30
        )));
    }
    Ok(())
}

fn gib(bytes: u64) -> f64 {
    bytes as f64 / f64::from(1u32 << 30)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_faces_count_as_fans() {
        assert_eq!(obj_triangles("v 0 0 0\nf 1 2 3\nf 1 2 3 4\n# f 1 2 3\n"), 3);
    }

    #[test]
    fn far_obj_vertices_are_found() {
        let text = "v 0 0 0\nv 1e30 0 0\n";
        assert_eq!(obj_far_vertex(text, [0.0; 3], 1.0), Some((2, 1e30)));
        assert_eq!(obj_far_vertex("v 1 2 3\n", [0.0; 3], 1.0), None);
        assert_eq!(
            obj_far_vertex("v 1 2 3\n", [9999.5, 0.0, 0.0], 1.0).map(|v| v.0),
            Some(1)
        );
    }

    #[test]
    fn memory_refusal_names_the_cube_maps() {
        let msg = check_memory(10_000, Some(128), 800, 600, 4)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("10000 bubble cube map(s) of cube_map_size = 128"),
            "{msg}"
        );
        assert!(check_memory(2, Some(128), 800, 600, 4).is_ok());
    }
}

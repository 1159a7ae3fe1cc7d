//! Scene → `raster::RenderScene`, and bubble meshes from the solver's state.

use super::Scene;
use super::schema::{EnvironmentSpec, MaterialSpec, ObjectSpec};
use crate::error::CliError;
use crate::scene::values::{plain, plain_f32};
use bubble_dynamics::World;
use raster::{
    BubbleFilm, BubbleMesh, Camera, Environment, FilmField, Ground, Irradiance, Material, Object,
    Pattern, RenderScene, Sky, Texture, TriMesh, Vec3,
};

impl Scene {
    /// The opaque part of the frame: camera, environment, ground and objects (no lights, no bubbles).
    pub fn render_scene(&self) -> Result<RenderScene, CliError> {
        let c = &self.file.camera;
        let camera = Camera::try_look_at(
            vec3(c.eye_m.get()),
            vec3(c.target_m.get()),
            vec3(c.up.get()),
            c.vfov_deg.get() as f32,
        )
        .map_err(|e| CliError::input(format!("{}: {e}", self.origin)))?;
        let mut scene = RenderScene::new(camera, self.environment()?);
        // The sky lights the ground and the objects, not only the point lights.
        scene.irradiance = Irradiance::from_environment(&scene.environment);
        scene.ground = match &self.file.ground {
            Some(g) => Some(Ground {
                height_m: g.height_m.get() as f32,
                material: self.material(&g.material)?,
            }),
            None => None,
        };
        scene.objects = self
            .file
            .objects
            .iter()
            .map(|o| self.object(o))
            .collect::<Result<_, _>>()?;
        Ok(scene)
    }

    fn environment(&self) -> Result<Environment, CliError> {
        let input = |e: raster::RenderError| CliError::input(format!("{}: {e}", self.origin));
        Ok(match &self.file.environment {
            EnvironmentSpec::Sky {
                zenith_rgb,
                horizon_rgb,
                ground_rgb,
                sun_direction,
                sun_rgb,
            } => Environment::Sky(Sky {
                zenith_rgb: rgb(zenith_rgb.get()),
                horizon_rgb: rgb(horizon_rgb.get()),
                nadir_rgb: rgb(ground_rgb.get()),
                sun_direction: vec3(sun_direction.get()).normalize(),
                sun_rgb: rgb(sun_rgb.get()),
                ..Sky::default()
            }),
            EnvironmentSpec::Uniform { rgb: c } => Environment::Uniform(rgb(c.get())),
            EnvironmentSpec::Equirect { path, intensity } => {
                let tex = Texture::load(self.path(path)).map_err(input)?;
                let k = intensity.get();
                self.check_texels(path, tex.texels(), tex.width(), k)?;
                Environment::Equirect(scale_texture(tex, k).map_err(input)?)
            }
            EnvironmentSpec::Cube { faces, intensity } => {
                let paths = faces.clone().map(|f| self.path(&f));
                let cube = raster::CubeMap::load_faces(paths).map_err(input)?;
                let n = cube.face_size();
                for (face, path) in faces.iter().enumerate() {
                    let texels: Vec<_> =
                        (0..n * n).map(|i| cube.texel(face, i % n, i / n)).collect();
                    self.check_texels(path, &texels, n, intensity.get())?;
                }
                Environment::CubeFaces(scale_cube(&cube, intensity.get() as f32).map_err(input)?)
            }
        })
    }

    pub(super) fn material(&self, spec: &MaterialSpec) -> Result<Material, CliError> {
        Ok(match spec {
            MaterialSpec::Checker { a, b, scale_m } => {
                Material::checker(rgb(a.get()), rgb(b.get()), scale_m.get() as f32)
            }
            MaterialSpec::Image { path, scale_m } => {
                let texture = Texture::load(self.path(path))
                    .map_err(|e| CliError::input(format!("{}: {e}", self.origin)))?;
                self.check_texels(path, texture.texels(), texture.width(), 1.0)?;
                Material {
                    pattern: Pattern::Textured {
                        texture,
                        scale_m: scale_m.get() as f32,
                    },
                    ..Material::matte([1.0; 3])
                }
            }
            MaterialSpec::Solid {
                albedo,
                specular,
                shininess,
            } => Material {
                pattern: Pattern::Solid(rgb(albedo.get())),
                specular: rgb(specular.get()),
                shininess: shininess.get() as f32,
            },
        })
    }

    fn object(&self, spec: &ObjectSpec) -> Result<Object, CliError> {
        Ok(match spec {
            ObjectSpec::Sphere {
                center_m,
                radius_m,
                material,
            } => Object::Sphere {
                center: vec3(center_m.get()),
                radius_m: radius_m.get() as f32,
                material: self.material(material)?,
            },
            ObjectSpec::Box {
                min_m,
                max_m,
                material,
            } => {
                let (lo, hi) = (vec3(min_m.get()), vec3(max_m.get()));
                if lo.cmpge(hi).any() {
                    return Err(CliError::input(format!(
                        "{}: box min_m {lo} must be below max_m {hi} on every axis",
                        self.origin
                    )));
                }
                Object::Box {
                    center: (lo + hi) * 0.5,
                    half_extents_m: (hi - lo) * 0.5,
                    material: self.material(material)?,
                }
            }
            ObjectSpec::Mesh {
                path,
                offset_m,
                scale,
                material,
            } => {
                let mut mesh = TriMesh::load_obj(self.path(path))
                    .map_err(|e| CliError::input(format!("{}: {e}", self.origin)))?;
                let (offset, s) = (vec3(offset_m.get()), scale.get() as f32);
                mesh.positions.iter_mut().for_each(|p| *p = *p * s + offset);
                Object::Mesh {
                    mesh,
                    material: self.material(material)?,
                }
            }
        })
    }
}

/// The solver's bubbles as renderable meshes (f32, outward normals, thickness in nm),
/// each with its film-flow field when it has one.
pub fn bubble_meshes(world: &World) -> Vec<BubbleMesh> {
    world
        .bubbles()
        .iter()
        .map(|b| BubbleMesh {
            positions: b.positions_m().iter().map(|p| p.as_vec3()).collect(),
            normals: b.vertex_normals().iter().map(|n| n.as_vec3()).collect(),
            thickness_nm: b.thickness_nm().iter().map(|&d| d as f32).collect(),
            triangles: b.triangles().to_vec(),
            film: bubble_film(b),
        })
        .collect()
}

/// The renderers' view of a bubble's film flow: its grid as a cube-map field (thickness
/// clamped to the field's range, as the film tables clamp it) and each vertex's material
/// direction.
pub(crate) fn bubble_film(b: &bubble_dynamics::Bubble) -> Option<BubbleFilm> {
    let field = b.film_field()?;
    let dirs = b.material_dirs()?;
    let max = raster::MAX_FILM_THICKNESS_NM;
    let thickness = field
        .thickness_nm
        .iter()
        .map(|&h| (h as f32).clamp(0.0, max))
        .collect();
    let coverage = field
        .coverage
        .iter()
        .map(|&c| (c as f32).clamp(0.0, 1.0))
        .collect();
    let field = FilmField::try_new(field.face_size, thickness, coverage)
        .expect("a film grid is a valid cube-map field (sizes from the solver, values clamped)");
    Some(BubbleFilm {
        field: std::sync::Arc::new(field),
        material_dirs: dirs.iter().map(|d| d.as_vec3()).collect(),
    })
}

impl Scene {
    /// Refuses an image with a texel whose value times `intensity` leaves
    /// `0..=MAX_TEXEL_RADIANCE`, naming the file, the texel and its value.
    fn check_texels(
        &self,
        path: &str,
        texels: &[[f32; 3]],
        width: usize,
        intensity: f64,
    ) -> Result<(), CliError> {
        let max = crate::limits::MAX_TEXEL_RADIANCE;
        let too_bright = |t: &[f32; 3]| t.iter().any(|&c| f64::from(c) * intensity > max);
        let Some(k) = texels.iter().position(too_bright) else {
            return Ok(());
        };
        let value = texels[k].iter().fold(0.0f32, |m, &c| m.max(c));
        Err(CliError::input(format!(
            "{}: image {path}: texel ({}, {}) = {} times intensity {} is outside 0..={} \
             (the radiance range a texel keeps finite through the renderer)",
            self.origin,
            k % width,
            k / width,
            plain_f32(value),
            plain(intensity),
            plain(max)
        )))
    }
}

fn scale_texture(tex: Texture, k: f64) -> Result<Texture, raster::RenderError> {
    if k == 1.0 {
        return Ok(tex);
    }
    let k = k as f32;
    let texels = tex.texels().iter().map(|t| t.map(|c| c * k)).collect();
    Texture::try_new(tex.width(), tex.height(), texels)
}

fn scale_cube(cube: &raster::CubeMap, k: f32) -> Result<raster::CubeMap, raster::RenderError> {
    let n = cube.face_size();
    let faces: [Vec<[f32; 3]>; 6] = std::array::from_fn(|face| {
        (0..n * n)
            .map(|i| cube.texel(face, i % n, i / n).map(|c| c * k))
            .collect()
    });
    raster::CubeMap::try_from_faces(n, faces)
}

/// The colour a light shades opaque surfaces with: `rgb` (linear sRGB, possibly negative
/// in a channel for a spectrum outside the sRGB gamut, e.g. sodium) moved towards the
/// white of equal luminance until no channel is negative.
///
/// # Guarantees
/// For finite `rgb` with luminance `Y >= 0`: every channel is finite and `>= 0`, the
/// luminance stays `Y`, and the chromaticity stays on the line from the white point
/// through the light's own (the same dominant wavelength); in-gamut colours are unchanged.
pub(super) fn in_gamut_rgb(rgb: [f64; 3]) -> [f64; 3] {
    let y = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    let min = rgb.iter().copied().fold(f64::INFINITY, f64::min);
    if min >= 0.0 {
        return rgb;
    }
    if y <= 0.0 {
        return [0.0; 3];
    }
    // rgb' = Y + s (rgb − Y) with s chosen so the smallest channel lands on 0.
    let s = y / (y - min);
    rgb.map(|c| (y + s * (c - y)).max(0.0))
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn rgb(v: [f64; 3]) -> [f32; 3] {
    v.map(|c| c as f32)
}

#[cfg(test)]
mod tests {
    use super::in_gamut_rgb;

    fn luminance(c: [f64; 3]) -> f64 {
        0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    }

    #[test]
    fn in_gamut_rgb_keeps_luminance_and_hue_line_and_clears_negatives() {
        // The sodium lamp at luminance 400 (the message of issue 8).
        let sodium = [1108.8159, 234.81322, -51.370678];
        let c = in_gamut_rgb(sodium);
        assert!(c.iter().all(|v| v.is_finite() && *v >= 0.0), "{c:?}");
        assert!(c[2].abs() < 1e-9, "smallest channel lands on 0: {c:?}");
        let dy = luminance(c) - luminance(sodium);
        assert!(dy.abs() < 1e-9, "luminance off by {dy}");
        // On the line through white: (c − Y) ∥ (sodium − Y).
        let (y, ys) = (luminance(c), luminance(sodium));
        let a = [c[0] - y, c[1] - y, c[2] - y];
        let b = [sodium[0] - ys, sodium[1] - ys, sodium[2] - ys];
        let cross = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let off = norm(cross) / (norm(a) * norm(b));
        assert!(off < 1e-9, "off the white line by sin {off}");
        assert_eq!(in_gamut_rgb([0.3, 0.5, 0.0]), [0.3, 0.5, 0.0]);
        assert_eq!(in_gamut_rgb([-1.0, 0.1, 0.0]), [0.0; 3]);
    }
}

//! Scene → `raster::RenderScene`, and bubble meshes from the solver's state.

use super::Scene;
use super::schema::{EnvironmentSpec, MaterialSpec, ObjectSpec};
use crate::error::CliError;
use bubble_dynamics::World;
use raster::{
    BubbleMesh, Camera, Environment, Ground, Material, Object, Pattern, RenderScene, Sky, Texture,
    TriMesh, Vec3,
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
                Environment::Equirect(scale_texture(tex, intensity.get()))
            }
            EnvironmentSpec::Cube { faces, intensity } => {
                let paths = faces.clone().map(|f| self.path(&f));
                let cube = raster::CubeMap::load_faces(paths).map_err(input)?;
                Environment::CubeFaces(scale_cube(&cube, intensity.get() as f32).map_err(input)?)
            }
        })
    }

    fn material(&self, spec: &MaterialSpec) -> Result<Material, CliError> {
        Ok(match spec {
            MaterialSpec::Checker { a, b, scale_m } => {
                Material::checker(rgb(a.get()), rgb(b.get()), scale_m.get() as f32)
            }
            MaterialSpec::Image { path, scale_m } => Material {
                pattern: Pattern::Textured {
                    texture: Texture::load(self.path(path))
                        .map_err(|e| CliError::input(format!("{}: {e}", self.origin)))?,
                    scale_m: scale_m.get() as f32,
                },
                ..Material::matte([1.0; 3])
            },
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

/// The solver's bubbles as renderable meshes (f32, outward normals, thickness in nm).
pub fn bubble_meshes(world: &World) -> Vec<BubbleMesh> {
    world
        .bubbles()
        .iter()
        .map(|b| BubbleMesh {
            positions: b.positions_m().iter().map(|p| p.as_vec3()).collect(),
            normals: b.vertex_normals().iter().map(|n| n.as_vec3()).collect(),
            thickness_nm: b.thickness_nm().iter().map(|&d| d as f32).collect(),
            triangles: b.triangles().to_vec(),
        })
        .collect()
}

fn scale_texture(tex: Texture, k: f64) -> Texture {
    if k == 1.0 {
        return tex;
    }
    let k = k as f32;
    let texels = tex.texels().iter().map(|t| t.map(|c| c * k)).collect();
    Texture::try_new(tex.width(), tex.height(), texels).expect("scaling keeps a valid texture")
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

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn rgb(v: [f64; 3]) -> [f32; 3] {
    v.map(|c| c as f32)
}

//! What a frame shows: [`RenderScene`] with its [`Ground`], [`Object`]s, [`Light`]s and
//! [`BubbleMesh`]es, and the [`FilmTables`] the bubbles are shaded with.

use glam::Vec3;
use lut::Lut;

use crate::environment::check_rgb;
use crate::mesh::{check_triangles, check_vertices};
use crate::{
    BubbleFilm, Camera, Environment, Irradiance, Material, RenderError, TriMesh, WaterSurface,
};

/// The infinite horizontal plane `y = height_m`, seen from both sides.
#[derive(Debug, Clone, PartialEq)]
pub struct Ground {
    /// Height of the plane in metres.
    pub height_m: f32,
    /// Its surface.
    pub material: Material,
}

/// An opaque object, rasterised as triangles.
#[derive(Debug, Clone, PartialEq)]
pub enum Object {
    /// A sphere (tessellated into 48 × 24 quads, normals exact per vertex).
    Sphere {
        /// Centre in metres.
        center: Vec3,
        /// Radius in metres.
        radius_m: f32,
        /// Surface.
        material: Material,
    },
    /// An axis-aligned box.
    Box {
        /// Centre in metres.
        center: Vec3,
        /// Half the edge lengths in metres.
        half_extents_m: Vec3,
        /// Surface.
        material: Material,
    },
    /// A triangle mesh, e.g. from [`TriMesh::load_obj`].
    Mesh {
        /// The triangles, in world space.
        mesh: TriMesh,
        /// Surface.
        material: Material,
    },
}

impl Object {
    /// The object's surface.
    pub fn material(&self) -> &Material {
        match self {
            Self::Sphere { material, .. }
            | Self::Box { material, .. }
            | Self::Mesh { material, .. } => material,
        }
    }
}

/// A small spherical light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    /// Centre in metres.
    pub position: Vec3,
    /// Radius in metres.
    pub radius_m: f32,
    /// Linear RGB radiance of its surface.
    pub radiance: [f32; 3],
    /// Index into [`FilmTables::lights`] of this light's source table, if it has one.
    ///
    /// A source table already holds the light's colour, scaled so the light itself has
    /// luminance 1 (seed 000's light-source texture), so its highlight on a bubble is
    /// `table(d, cos θ) × Y`, with `Y` the luminance of `radiance`. Without a table it is
    /// `reflectivity(d, cos θ) ⊙ radiance`.
    pub light_lut: Option<usize>,
}

impl Light {
    /// What the highlight table is multiplied by: the luminance of `radiance` when the
    /// light has its own (already coloured) table, else `radiance` itself.
    #[inline]
    pub fn highlight_gain(&self) -> [f32; 3] {
        match self.light_lut {
            Some(_) => [luminance(self.radiance); 3],
            None => self.radiance,
        }
    }
}

/// Luminance Y of a linear sRGB colour (Rec. 709 / sRGB primaries, D65 white).
fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// A bubble film: a closed triangle mesh with outward vertex normals and per-vertex thickness.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BubbleMesh {
    /// Vertex positions in metres.
    pub positions: Vec<Vec3>,
    /// Outward vertex normals (normalised per pixel, so any positive length works).
    pub normals: Vec<Vec3>,
    /// Film thickness at each vertex, in nanometres.
    pub thickness_nm: Vec<f32>,
    /// Vertex indices of each triangle (any winding).
    pub triangles: Vec<[u32; 3]>,
    /// The film's thickness and coverage as a field over the bubble's material sphere,
    /// read per pixel at the interpolated material direction. When present, the field's
    /// thickness replaces `thickness_nm` in shading, and its coverage `c` blends the film
    /// in: transmittance `1 − c·(1 − T)`, added radiance `c·add` (`c = 0`: no film there).
    pub film: Option<BubbleFilm>,
}

impl BubbleMesh {
    /// Mean of the vertex positions: the bubble's centre for sorting and cube maps.
    pub fn center(&self) -> Vec3 {
        if self.positions.is_empty() {
            return Vec3::ZERO;
        }
        let sum: glam::DVec3 = self.positions.iter().map(|p| p.as_dvec3()).sum();
        (sum / self.positions.len() as f64).as_vec3()
    }

    fn validate(&self, k: usize) -> Result<(), RenderError> {
        let what = format!("bubble {k}");
        let n = self.positions.len();
        if self.normals.len() != n || self.thickness_nm.len() != n {
            return Err(RenderError::scene(
                what,
                format!(
                    "{n} positions but {} normals and {} thicknesses",
                    self.normals.len(),
                    self.thickness_nm.len()
                ),
            ));
        }
        check_vertices(&what, &self.positions, &self.normals)?;
        if let Some(v) = self
            .thickness_nm
            .iter()
            .position(|d| !(d.is_finite() && *d >= 0.0))
        {
            return Err(RenderError::scene(
                format!("{what}, vertex {v}"),
                format!(
                    "thickness {} nm must be finite and >= 0",
                    self.thickness_nm[v]
                ),
            ));
        }
        check_triangles(&what, &self.triangles, n)?;
        if let Some(film) = &self.film {
            if film.material_dirs.len() != n {
                return Err(RenderError::scene(
                    format!("{what}, film"),
                    format!(
                        "{n} positions but {} material directions",
                        film.material_dirs.len()
                    ),
                ));
            }
            if let Some(v) = film
                .material_dirs
                .iter()
                .position(|d| !(d.is_finite() && d.length_squared() > 0.0))
            {
                return Err(RenderError::scene(
                    format!("{what}, film, vertex {v}"),
                    format!(
                        "material direction {} must be finite and non-zero",
                        film.material_dirs[v]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The baked film tables bubbles are shaded with.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmTables {
    /// RGB reflectivity `R(d, cos θ)` for environment light.
    pub reflectivity: Lut,
    /// RGB transmittance `T(d, cos θ)`; `None` means `1 − R` (lossless film).
    pub transmittance: Option<Lut>,
    /// Per-light source tables, indexed by [`Light::light_lut`].
    pub lights: Vec<Lut>,
}

impl FilmTables {
    /// Checks that every table `scene` names exists: each light's
    /// [`Light::light_lut`] indexes [`FilmTables::lights`].
    pub fn validate_for(&self, scene: &RenderScene) -> Result<(), RenderError> {
        for (k, l) in scene.lights.iter().enumerate() {
            if let Some(i) = l.light_lut {
                if i >= self.lights.len() {
                    return Err(RenderError::scene(
                        format!("light {k}"),
                        format!("light_lut {i} but only {} light tables", self.lights.len()),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Tables with only a reflectivity (`T = 1 − R`, highlights use `R`).
    pub fn from_reflectivity(reflectivity: Lut) -> FilmTables {
        FilmTables {
            reflectivity,
            transmittance: None,
            lights: Vec::new(),
        }
    }
}

/// Everything a frame shows.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderScene {
    /// The viewpoint.
    pub camera: Camera,
    /// Radiance from infinitely far away.
    pub environment: Environment,
    /// Ambient radiance lighting opaque surfaces (unoccluded), added to `irradiance`.
    pub ambient_rgb: [f32; 3],
    /// Environment light on opaque surfaces by their normal (unoccluded), e.g.
    /// [`Irradiance::from_environment`] of `environment`; zero from [`RenderScene::new`].
    pub irradiance: Irradiance,
    /// Optional ground plane.
    pub ground: Option<Ground>,
    /// Opaque objects.
    pub objects: Vec<Object>,
    /// Small spherical lights.
    pub lights: Vec<Light>,
    /// Bubble films, blended over the opaque scene.
    pub bubbles: Vec<BubbleMesh>,
    /// Optional water surface, drawn with the opaque scene.
    pub water: Option<WaterSurface>,
}

impl RenderScene {
    /// An empty scene: camera and environment only.
    pub fn new(camera: Camera, environment: Environment) -> RenderScene {
        RenderScene {
            camera,
            environment,
            ambient_rgb: [0.0; 3],
            irradiance: Irradiance::default(),
            ground: None,
            objects: Vec::new(),
            lights: Vec::new(),
            bubbles: Vec::new(),
            water: None,
        }
    }

    /// Checks every element for the renderer, naming the first bad one. The film tables
    /// are checked against the scene apart, by [`FilmTables::validate_for`].
    pub fn validate(&self) -> Result<(), RenderError> {
        self.environment.validate()?;
        check_rgb("ambient_rgb", self.ambient_rgb)?;
        if !self.irradiance.is_finite() {
            return Err(RenderError::scene(
                "irradiance",
                "the environment is too bright: its irradiance overflows f32".to_string(),
            ));
        }
        if let Some(g) = &self.ground {
            if !g.height_m.is_finite() {
                return Err(RenderError::scene(
                    "ground",
                    format!("height {} m is not finite", g.height_m),
                ));
            }
            g.material.validate("ground")?;
        }
        for (k, o) in self.objects.iter().enumerate() {
            let what = format!("object {k}");
            o.material().validate(&what)?;
            match o {
                Object::Sphere {
                    center, radius_m, ..
                } => {
                    if !(center.is_finite() && radius_m.is_finite() && *radius_m > 0.0) {
                        return Err(RenderError::scene(
                            what,
                            format!(
                                "sphere at {center} radius {radius_m} m must be finite and > 0"
                            ),
                        ));
                    }
                }
                Object::Box {
                    center,
                    half_extents_m,
                    ..
                } => {
                    if !(center.is_finite()
                        && half_extents_m.is_finite()
                        && half_extents_m.min_element() > 0.0)
                    {
                        return Err(RenderError::scene(
                            what,
                            format!(
                                "box at {center} half extents {half_extents_m} m must be finite and > 0"
                            ),
                        ));
                    }
                }
                Object::Mesh { mesh, .. } => mesh.validate(&what)?,
            }
        }
        for (k, l) in self.lights.iter().enumerate() {
            let what = format!("light {k}");
            check_rgb(&what, l.radiance)?;
            if !(l.position.is_finite() && l.radius_m.is_finite() && l.radius_m > 0.0) {
                return Err(RenderError::scene(
                    what,
                    format!(
                        "position {} and radius {} m must be finite, radius > 0",
                        l.position, l.radius_m
                    ),
                ));
            }
        }
        for (k, b) in self.bubbles.iter().enumerate() {
            b.validate(k)?;
        }
        if let Some(w) = &self.water {
            w.validate()?;
        }
        Ok(())
    }
}

//! The TOML scene schema: plain serde types, documented in `docs/scene-format.md`.
//!
//! Every table uses `deny_unknown_fields`, so a misspelt key is an error with its
//! line and column rather than a silently ignored setting.

use super::values::{
    Absorption, Acceleration, AngularSpeed, Bounds, BubbleRadius, ContactHeight, Coordinate, Count,
    CubeMapSize, Damping, DecayPerMetre, DecayPerSecond, Direction, Direction2, Elasticity,
    Evaporation, Exposure, FieldOfView, FilmGrid, FilmIndex, FilmThickness, FilmViscosity,
    GustSpeed, InitialScale, Intensity, LightRadius, Luminance, LutAngleSamples,
    LutThicknessSamples, MeshScale, MolarMass, NucleationRate, Num, Num3, ObjectRadius,
    PatchRadius, PatternScale, Radiance, Reflectance, RegeneratedFraction, RegenerationRate,
    RuptureThickness, Samples, Seconds, Shininess, SloshSpeed, Speed, Subdivisions, SurfaceTension,
    TimeStep, Variation, Viscosity, Warming, WaterDepth, WaterIndex, WaterSlices, WaveAmplitude,
    Wavelength, exact,
};
use serde::Deserialize;

/// A whole scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Simulated time to advance before rendering, in seconds.
    #[serde(default = "zero")]
    pub time_s: Num<Seconds>,
    /// The viewpoint.
    pub camera: CameraSpec,
    /// What surrounds the scene.
    #[serde(default)]
    pub environment: EnvironmentSpec,
    /// Optional ground plane.
    #[serde(default)]
    pub ground: Option<GroundSpec>,
    /// Opaque objects.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Small spherical lights.
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// Optional water surface (seed 002): a perturbed grid over a pool floor.
    #[serde(default)]
    pub water: Option<WaterSpec>,
    /// The soap bubbles.
    #[serde(default)]
    pub bubbles: Vec<BubbleSpec>,
    /// Wind acting on the bubbles.
    #[serde(default)]
    pub wind: WindSpec,
    /// Film optics shared by every bubble.
    #[serde(default)]
    pub film: FilmSpec,
    /// Solver settings shared by every bubble.
    #[serde(default)]
    pub dynamics: DynamicsSpec,
    /// Renderer defaults (CLI flags override them).
    #[serde(default)]
    pub render: RenderSpec,
}

/// A literal default, checked against its range by the tests of the built-in scenes.
fn num<B: Bounds>(v: f64) -> Num<B> {
    Num::new(v).expect("literal default is in range")
}

fn zero() -> Num<Seconds> {
    num(0.0)
}

/// A look-at camera.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position, m.
    pub eye_m: Num3<Coordinate>,
    /// Point looked at, m.
    pub target_m: Num3<Coordinate>,
    /// Up direction.
    #[serde(default = "y_up")]
    pub up: Direction,
    /// Vertical field of view, degrees.
    #[serde(default = "default_vfov")]
    pub vfov_deg: Num<FieldOfView>,
}

fn y_up() -> Direction {
    Direction::new([0.0, 1.0, 0.0]).expect("y is a direction")
}

fn default_vfov() -> Num<FieldOfView> {
    num(40.0)
}

/// The environment: what a ray that hits nothing sees.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "kebab-case")]
pub enum EnvironmentSpec {
    /// A procedural sky with a sun.
    Sky {
        /// Sky radiance straight up.
        #[serde(default = "zenith")]
        zenith_rgb: Num3<Radiance>,
        /// Sky radiance at the horizon.
        #[serde(default = "horizon")]
        horizon_rgb: Num3<Radiance>,
        /// Radiance below the horizon.
        #[serde(default = "below")]
        ground_rgb: Num3<Radiance>,
        /// Direction towards the sun.
        #[serde(default = "sun_dir")]
        sun_direction: Direction,
        /// Sun disc radiance (0 for none).
        #[serde(default = "sun_rgb")]
        sun_rgb: Num3<Radiance>,
    },
    /// The same radiance in every direction.
    Uniform {
        /// The radiance.
        rgb: Num3<Radiance>,
    },
    /// An equirectangular (latitude-longitude) image.
    Equirect {
        /// Image path, relative to the scene file.
        path: String,
        /// Radiance scale applied to the decoded linear values.
        #[serde(default = "one")]
        intensity: Num<Intensity>,
    },
    /// Six cube-map face images, in the order +x, −x, +y, −y, +z, −z.
    Cube {
        /// Face paths, relative to the scene file.
        #[serde(deserialize_with = "exact")]
        faces: [String; 6],
        /// Radiance scale applied to the decoded linear values.
        #[serde(default = "one")]
        intensity: Num<Intensity>,
    },
}

impl Default for EnvironmentSpec {
    fn default() -> Self {
        Self::Sky {
            zenith_rgb: zenith(),
            horizon_rgb: horizon(),
            ground_rgb: below(),
            sun_direction: sun_dir(),
            sun_rgb: sun_rgb(),
        }
    }
}

fn rgb<B: Bounds>(v: [f64; 3]) -> Num3<B> {
    Num3::new(v).expect("literal colour is in range")
}
fn zenith() -> Num3<Radiance> {
    rgb([0.25, 0.45, 0.9])
}
fn horizon() -> Num3<Radiance> {
    rgb([0.85, 0.9, 1.0])
}
fn below() -> Num3<Radiance> {
    rgb([0.3, 0.28, 0.25])
}
fn sun_dir() -> Direction {
    Direction::new([0.4, 0.8, 0.3]).expect("literal direction is valid")
}
fn sun_rgb() -> Num3<Radiance> {
    rgb([0.0, 0.0, 0.0])
}
fn one() -> Num<Intensity> {
    num(1.0)
}

/// An infinite horizontal ground plane (drawn and collided with).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundSpec {
    /// Height of the plane, m.
    #[serde(default = "finite_zero")]
    pub height_m: Num<Coordinate>,
    /// Surface appearance.
    #[serde(default)]
    pub material: MaterialSpec,
}

fn finite_zero() -> Num<Coordinate> {
    num(0.0)
}

/// How an opaque surface looks.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "kebab-case")]
pub enum MaterialSpec {
    /// Two alternating colours.
    Checker {
        /// First albedo.
        a: Num3<Reflectance>,
        /// Second albedo.
        b: Num3<Reflectance>,
        /// Side of one square, m.
        scale_m: Num<PatternScale>,
    },
    /// An image repeated every `scale_m`.
    Image {
        /// Image path, relative to the scene file.
        path: String,
        /// Side of one repeat, m.
        scale_m: Num<PatternScale>,
    },
    /// One colour with a Blinn-Phong highlight.
    Solid {
        /// Diffuse albedo.
        albedo: Num3<Reflectance>,
        /// Specular colour.
        #[serde(default = "no_specular")]
        specular: Num3<Reflectance>,
        /// Blinn-Phong exponent.
        #[serde(default = "shininess")]
        shininess: Num<Shininess>,
    },
}

impl Default for MaterialSpec {
    fn default() -> Self {
        Self::Checker {
            a: rgb([0.8, 0.8, 0.8]),
            b: rgb([0.15, 0.15, 0.18]),
            scale_m: num(0.05),
        }
    }
}

fn no_specular() -> Num3<Reflectance> {
    rgb([0.0, 0.0, 0.0])
}
fn shininess() -> Num<Shininess> {
    num(32.0)
}

/// An opaque object.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "kebab-case")]
pub enum ObjectSpec {
    /// A sphere.
    Sphere {
        /// Centre, m.
        center_m: Num3<Coordinate>,
        /// Radius, m.
        radius_m: Num<ObjectRadius>,
        /// Appearance.
        material: MaterialSpec,
    },
    /// An axis-aligned box.
    Box {
        /// Lowest corner, m.
        min_m: Num3<Coordinate>,
        /// Highest corner, m.
        max_m: Num3<Coordinate>,
        /// Appearance.
        material: MaterialSpec,
    },
    /// A Wavefront OBJ mesh.
    Mesh {
        /// OBJ path, relative to the scene file.
        path: String,
        /// Translation applied to the mesh, m.
        #[serde(default = "origin")]
        offset_m: Num3<Coordinate>,
        /// Uniform scale applied to the mesh.
        #[serde(default = "unit_scale")]
        scale: Num<MeshScale>,
        /// Appearance.
        material: MaterialSpec,
    },
}

fn origin<B: Bounds>() -> Num3<B> {
    Num3::new([0.0; 3]).expect("0 is in every vector range")
}
fn unit_scale() -> Num<MeshScale> {
    num(1.0)
}

/// A small spherical light.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Centre, m.
    pub position_m: Num3<Coordinate>,
    /// Radius of the emitting sphere, m.
    pub radius_m: Num<LightRadius>,
    /// Emission spectrum: an illuminant name (`d65`, `sodium`, …) or a CSV path.
    #[serde(default = "d65")]
    pub spectrum: String,
    /// Luminance of the emitting surface, relative to a white of 1.
    #[serde(default = "light_luminance")]
    pub luminance: Num<Luminance>,
}

fn d65() -> String {
    "d65".into()
}
fn light_luminance() -> Num<Luminance> {
    num(20.0)
}

/// A water surface: a grid on the XZ plane perturbed by waves and ripples, drawn with
/// reflection and refraction onto a floor, and a collider (its rest plane) for bubbles.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaterSpec {
    /// Corner of the grid with the smallest X and Z, m.
    #[serde(deserialize_with = "exact")]
    pub min_m: [Num<Coordinate>; 2],
    /// Corner of the grid with the largest X and Z, m.
    #[serde(deserialize_with = "exact")]
    pub max_m: [Num<Coordinate>; 2],
    /// Slices along X and along Z (each side has one vertex more).
    #[serde(default = "water_slices", deserialize_with = "exact")]
    pub slices: [Count<WaterSlices>; 2],
    /// Height of the unperturbed surface, m.
    #[serde(default = "finite_zero")]
    pub rest_height_m: Num<Coordinate>,
    /// Refractive index of the water.
    #[serde(default = "water_ior")]
    pub ior: Num<WaterIndex>,
    /// Depth of the floor below the rest plane, m.
    #[serde(default = "floor_depth")]
    pub floor_depth_m: Num<WaterDepth>,
    /// The floor's appearance (default: tiles).
    #[serde(default)]
    pub floor: MaterialSpec,
    /// Beer–Lambert absorption per metre of water, per channel (default: clear water).
    #[serde(default = "clear_water")]
    pub absorption_per_m: Num3<Absorption>,
    /// Directional sine waves.
    #[serde(default)]
    pub waves: Vec<WaveSpec>,
    /// Circular ripples.
    #[serde(default)]
    pub ripples: Vec<RippleSpec>,
}

fn water_slices() -> [Count<WaterSlices>; 2] {
    [Count::new(128).expect("128 slices are in range"); 2]
}
fn water_ior() -> Num<WaterIndex> {
    num(1.333)
}
fn floor_depth() -> Num<WaterDepth> {
    num(0.5)
}
fn clear_water() -> Num3<Absorption> {
    // Pure water absorbs red most: about 0.45, 0.06 and 0.02 per metre at 650, 550, 450 nm.
    rgb([0.45, 0.06, 0.02])
}

/// A directional wave `a·sin(k(x·i + z·j) − ωt)`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaveSpec {
    /// Amplitude, m.
    pub amplitude_m: Num<WaveAmplitude>,
    /// Wavelength `2π/k`, m.
    pub wavelength_m: Num<Wavelength>,
    /// Direction of travel `(i, j)` on the XZ plane (normalised).
    pub direction: Direction2,
    /// Angular frequency ω, rad/s (default: deep-water dispersion with surface tension).
    #[serde(default)]
    pub omega_rad_per_s: Option<Num<AngularSpeed>>,
}

/// A circular ripple `a·e^(−αr)·e^(−βt)·sin(kr − ωt)` around a centre.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RippleSpec {
    /// Amplitude at the centre at t = 0, m.
    pub amplitude_m: Num<WaveAmplitude>,
    /// Wavelength, m.
    pub wavelength_m: Num<Wavelength>,
    /// Centre (X, Z), m.
    #[serde(deserialize_with = "exact")]
    pub center_m: [Num<Coordinate>; 2],
    /// Fading with distance α, 1/m (0: none).
    #[serde(default)]
    pub decay_per_m: Option<Num<DecayPerMetre>>,
    /// Fading with time β, 1/s (0: none).
    #[serde(default)]
    pub decay_per_s: Option<Num<DecayPerSecond>>,
    /// Angular frequency ω, rad/s (default: deep-water dispersion with surface tension).
    #[serde(default)]
    pub omega_rad_per_s: Option<Num<AngularSpeed>>,
}

/// One soap bubble.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BubbleSpec {
    /// Centre at time 0, m.
    pub center_m: Num3<Coordinate>,
    /// Radius at rest, m.
    pub radius_m: Num<BubbleRadius>,
    /// Initial velocity, m/s.
    #[serde(default = "origin")]
    pub velocity_m_per_s: Num3<Speed>,
    /// Mean film thickness at rest, nm.
    #[serde(default = "mean_thickness")]
    pub mean_thickness_nm: Num<FilmThickness>,
    /// Icosphere subdivision level (3 gives 642 vertices, as in seed 000).
    #[serde(default = "subdivisions")]
    pub subdivisions: Count<Subdivisions>,
    /// Surface tension, N/m.
    #[serde(default)]
    pub sigma_n_per_m: Option<Num<SurfaceTension>>,
    /// Velocity damping rate γ/m, 1/s.
    #[serde(default)]
    pub damping_per_s: Option<Num<Damping>>,
    /// Seed of the thickness perturbation (sloshing).
    #[serde(default)]
    pub seed: u64,
    /// Gibbs film elasticity, N/m.
    #[serde(default)]
    pub gibbs_elasticity_n_per_m: Option<Num<Elasticity>>,
    /// Effective drainage viscosity, Pa·s.
    #[serde(default)]
    pub drainage_viscosity_pa_s: Option<Num<Viscosity>>,
    /// Thickness below which the film bursts, nm.
    #[serde(default)]
    pub rupture_thickness_nm: Option<Num<RuptureThickness>>,
    /// Relative amplitude of the initial random thickness variation, in [0, 1).
    #[serde(default)]
    pub thickness_variation: Option<Num<Variation>>,
    /// Typical speed of the swirling film flow (sloshing), m/s.
    #[serde(default)]
    pub slosh_speed_m_per_s: Option<Num<SloshSpeed>>,
    /// Evaporative thinning rate, nm/s.
    #[serde(default)]
    pub evaporation_nm_per_s: Option<Num<Evaporation>>,
    /// Molar mass of the gas inside, kg/mol (air 0.02896, helium 0.004).
    #[serde(default)]
    pub gas_molar_mass_kg_per_mol: Option<Num<MolarMass>>,
    /// Initial per-axis stretch of the rest bubble (its gas is the rest bubble's, so
    /// anything but 1 starts it out of equilibrium).
    #[serde(default)]
    pub initial_scale: Option<Num3<InitialScale>>,
    /// Cells along a face of the film-flow cube-sphere (0: no flow, the per-vertex film).
    #[serde(default)]
    pub film_grid: Option<Count<FilmGrid>>,
    /// Viscosity of the film liquid in the flow's viscous stress, Pa·s.
    #[serde(default)]
    pub film_viscosity_pa_s: Option<Num<FilmViscosity>>,
    /// Thickness under which the flowing film turns black, nm (0: never).
    #[serde(default)]
    pub black_threshold_nm: Option<Num<RuptureThickness>>,
    /// Thickness of the common black film, nm.
    #[serde(default)]
    pub black_film_nm: Option<Num<RuptureThickness>>,
    /// Rate of spontaneous holes per area of black film, 1/(m²·s).
    #[serde(default)]
    pub nucleation_per_m2_s: Option<Num<NucleationRate>>,
    /// How much warmer the air at the bubble's bottom is than at its top, K (film flow:
    /// thermal convection).
    #[serde(default)]
    pub bottom_warming_k: Option<Num<Warming>>,
    /// The film flow's discrete gradient (default `"two-point"`).
    #[serde(default)]
    pub film_gradient: Option<FilmGradientSpec>,
    /// Stands the bubble on a wet surface: no film below the contact line, a meniscus
    /// there that regenerates the film (film flow only).
    #[serde(default)]
    pub meniscus: Option<MeniscusSpec>,
}

/// A bubble's `[bubbles.meniscus]`: the wet surface it stands on (each field defaults
/// to `bubble_dynamics::Meniscus::hemisphere`'s).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeniscusSpec {
    /// Height of the contact line above the bubble's centre over its radius (0: a
    /// hemisphere).
    #[serde(default)]
    pub contact_height: Option<Num<ContactHeight>>,
    /// Thin-film patches the meniscus pulls out per metre of contact line per second.
    #[serde(default)]
    pub regeneration_per_m_s: Option<Num<RegenerationRate>>,
    /// A patch's thickness over the thickness of the film it replaces.
    #[serde(default)]
    pub regenerated_fraction: Option<Num<RegeneratedFraction>>,
    /// Radius of a patch, m.
    #[serde(default)]
    pub patch_radius_m: Option<Num<PatchRadius>>,
}

/// A bubble's `film_gradient`: the discrete gradient that drives its film flow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FilmGradientSpec {
    /// `"two-point"`: along the line of cell centres; one symmetric solve a film step,
    /// the wave speed within ~3 % (the default).
    TwoPoint,
    /// `"normal"`: along the edge's normal; second-order wave speed at ~2.3× a film
    /// step's cost.
    Normal,
}

fn mean_thickness() -> Num<FilmThickness> {
    num(500.0)
}
fn subdivisions() -> Count<Subdivisions> {
    Count::new(3).expect("3 subdivisions are in range")
}

/// Wind: a uniform velocity plus seeded gusts.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindSpec {
    /// Uniform air velocity, m/s.
    #[serde(default)]
    pub velocity_m_per_s: Option<Num3<Speed>>,
    /// Gust amplitude, m/s.
    #[serde(default)]
    pub gust_m_per_s: Option<Num<GustSpeed>>,
    /// Gust seed.
    #[serde(default)]
    pub seed: u64,
}

/// Film optics.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilmSpec {
    /// Film refractive index (ignored when `dispersion = "water"`).
    #[serde(default = "n_soap")]
    pub n_film: Num<FilmIndex>,
    /// `"none"` for a constant index, `"water"` for water's n(λ).
    #[serde(default = "no_dispersion")]
    pub dispersion: String,
    /// White reference illuminant for the environment reflectivity texture.
    #[serde(default = "d65")]
    pub illuminant: String,
}

impl Default for FilmSpec {
    fn default() -> Self {
        Self {
            n_film: n_soap(),
            dispersion: no_dispersion(),
            illuminant: d65(),
        }
    }
}

fn n_soap() -> Num<FilmIndex> {
    num(1.33)
}
fn no_dispersion() -> String {
    "none".into()
}

/// Solver settings.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSpec {
    /// Fixed time step, s.
    #[serde(default)]
    pub dt_s: Option<Num<TimeStep>>,
    /// Step of the film flow, s (default 1/60).
    #[serde(default)]
    pub film_dt_s: Option<Num<TimeStep>>,
    /// Gravity, m/s².
    #[serde(default)]
    pub gravity_m_per_s2: Option<Num3<Acceleration>>,
    /// `"symplectic-euler"` (default) or `"explicit-euler"` (seed 000).
    #[serde(default)]
    pub integrator: Option<String>,
}

/// Renderer defaults.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderSpec {
    /// `"dynamic"` cube maps (default), `"static"` environment, or `"sphere-map"`.
    #[serde(default)]
    pub reflection: Option<String>,
    /// Cube-map face size, texels.
    #[serde(default)]
    pub cube_map_size: Option<Count<CubeMapSize>>,
    /// Exposure multiplier before tone mapping.
    #[serde(default)]
    pub exposure: Option<Num<Exposure>>,
    /// `"aces"`, `"reinhard"` or `"clamp"`.
    #[serde(default)]
    pub tonemap: Option<String>,
    /// Anti-aliasing samples per pixel.
    #[serde(default)]
    pub samples: Option<Count<Samples>>,
    /// Film-table columns over thickness (default 4096).
    #[serde(default)]
    pub lut_thickness_samples: Option<Count<LutThicknessSamples>>,
    /// Film-table rows over cos θ (default 128).
    #[serde(default)]
    pub lut_angle_samples: Option<Count<LutAngleSamples>>,
}

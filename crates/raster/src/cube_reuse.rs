//! Reusing a bubble's dynamic cube map across frames while what it shows cannot have
//! moved by more than a set fraction of a texel.
//!
//! A bubble's cube map holds the scene without bubbles or light spheres (the environment,
//! the ground, the objects, lit by the lights) seen from the bubble's centre. When none of
//! that changed, moving the centre by `δ` turns the direction to a point at distance `r` by
//! at most `δ / r` radians, and a level-0 texel subtends at least `(2/N)/3^¾` radians (at a
//! face's corner, `cube_lod`'s formula). So a map stays within `k` texels of a fresh one
//! while `δ ≤ k · (2/N)/3^¾ · r_min`, with `r_min` the distance from the centre to the
//! nearest opaque content. The environment is infinitely far: it never moves.

use glam::Vec3;
use render_scene::{Environment, Ground, Irradiance, Light, Object, RenderScene};

/// How far a reused cube map may lag behind a fresh one, in level-0 texels.
///
/// # Guarantees
/// The value is finite and in `[0, MAX_TEXELS]`; 0 renders every map every frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CubeMapReuse {
    max_shift_texels: f32,
}

impl CubeMapReuse {
    /// The largest lag allowed: half a texel, the bilinear lookup's own scale.
    pub const MAX_TEXELS: f32 = 0.5;

    /// Every map rendered every frame (the default: exact frames).
    pub const OFF: CubeMapReuse = CubeMapReuse {
        max_shift_texels: 0.0,
    };

    /// A lag of at most `max_shift_texels`, if it is finite and in `[0, MAX_TEXELS]`.
    pub fn new(max_shift_texels: f32) -> Option<CubeMapReuse> {
        (0.0..=Self::MAX_TEXELS)
            .contains(&max_shift_texels)
            .then_some(CubeMapReuse { max_shift_texels })
    }

    /// The lag allowed, in level-0 texels.
    pub fn max_shift_texels(self) -> f32 {
        self.max_shift_texels
    }
}

/// Everything a bubble's cube map shows other than its centre.
#[derive(Debug, Clone, PartialEq)]
struct Content {
    environment: Environment,
    ambient_rgb: [f32; 3],
    irradiance: Irradiance,
    ground: Option<Ground>,
    objects: Vec<Object>,
    lights: Vec<Light>,
    face_size: usize,
}

impl Content {
    /// Whether `scene` shows the same at `face_size`, compared field by field.
    fn matches(&self, scene: &RenderScene, face_size: usize) -> bool {
        self.face_size == face_size
            && self.ambient_rgb == scene.ambient_rgb
            && self.irradiance == scene.irradiance
            && self.ground == scene.ground
            && self.lights == scene.lights
            && self.objects == scene.objects
            && self.environment == scene.environment
    }

    fn of(scene: &RenderScene, face_size: usize) -> Content {
        Content {
            environment: scene.environment.clone(),
            ambient_rgb: scene.ambient_rgb,
            irradiance: scene.irradiance,
            ground: scene.ground.clone(),
            objects: scene.objects.clone(),
            lights: scene.lights.clone(),
            face_size,
        }
    }
}

/// What the renderer remembers of the cube maps it rendered: the content and, per
/// bubble, the centre its map was rendered from.
#[derive(Debug, Default)]
pub(crate) struct CubeReuseState {
    content: Option<Content>,
    /// Per bubble: the centre its current map was rendered from.
    pub centres: Vec<Vec3>,
}

impl CubeReuseState {
    /// Per bubble of `scene`, whether its map must be rendered afresh at `face_size`;
    /// updates the remembered centres of those that are (the others keep the centre their
    /// map was rendered from, which the parallax correction must read it with).
    ///
    /// `objects_bounds` is the axis-aligned box of the objects' tessellated vertices.
    pub fn plan(
        &mut self,
        scene: &RenderScene,
        face_size: usize,
        reuse: CubeMapReuse,
        objects_bounds: Option<(Vec3, Vec3)>,
    ) -> Vec<bool> {
        let n = scene.bubbles.len();
        let reusable = reuse.max_shift_texels > 0.0 && procedural(&scene.environment);
        let same = reusable
            && self
                .content
                .as_ref()
                .is_some_and(|c| c.matches(scene, face_size));
        if !same {
            self.content = reusable.then(|| Content::of(scene, face_size));
        }
        self.centres.truncate(n);
        let texel_rad = 2.0 / face_size as f32 / 3f32.powf(0.75);
        let fresh: Vec<bool> = scene
            .bubbles
            .iter()
            .enumerate()
            .map(|(b, bubble)| {
                let centre = bubble.center();
                let Some(&from) = self.centres.get(b).filter(|_| same) else {
                    return true;
                };
                let r_min = nearest_content_m(centre, scene.ground.as_ref(), objects_bounds);
                (centre - from).length() > reuse.max_shift_texels * texel_rad * r_min
            })
            .collect();
        for (b, bubble) in scene.bubbles.iter().enumerate() {
            if b >= self.centres.len() {
                self.centres.push(bubble.center());
            } else if fresh[b] {
                self.centres[b] = bubble.center();
            }
        }
        fresh
    }
}

/// The axis-aligned box of `positions`, if any.
pub(crate) fn bounds(positions: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *positions.first()?;
    Some(
        positions
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
    )
}

/// Whether the environment is cheap to compare (the procedural kinds), as the renderer's
/// environment cube cache also requires.
fn procedural(env: &Environment) -> bool {
    matches!(env, Environment::Sky(_) | Environment::Uniform(_))
}

/// A lower bound on the distance from `p` to the ground plane and the objects (within
/// `objects_bounds`); infinity when there is neither.
fn nearest_content_m(
    p: Vec3,
    ground: Option<&Ground>,
    objects_bounds: Option<(Vec3, Vec3)>,
) -> f32 {
    let ground_m = ground.map_or(f32::INFINITY, |g| (p.y - g.height_m).abs());
    let objects_m = objects_bounds.map_or(f32::INFINITY, |(lo, hi)| {
        (lo - p).max(p - hi).max(Vec3::ZERO).length()
    });
    ground_m.min(objects_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reuse_accepts_only_lags_up_to_half_a_texel() {
        assert!(CubeMapReuse::new(0.25).is_some());
        assert!(CubeMapReuse::new(0.0).is_some());
        assert!(CubeMapReuse::new(0.51).is_none());
        assert!(CubeMapReuse::new(-0.1).is_none());
        assert!(CubeMapReuse::new(f32::NAN).is_none());
    }

    #[test]
    fn nearest_content_is_the_ground_or_the_objects_box() {
        let ground = Ground {
            height_m: 0.0,
            material: render_scene::Material::matte([0.5; 3]),
        };
        let p = Vec3::new(0.0, 0.3, 0.0);
        assert_eq!(nearest_content_m(p, Some(&ground), None), 0.3);
        let bounds = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0));
        assert_eq!(nearest_content_m(p, Some(&ground), Some(bounds)), 0.3);
        let q = Vec3::new(0.9, 0.5, 0.5);
        assert!((nearest_content_m(q, Some(&ground), Some(bounds)) - 0.1).abs() < 1e-6);
        assert_eq!(nearest_content_m(p, None, None), f32::INFINITY);
    }
}

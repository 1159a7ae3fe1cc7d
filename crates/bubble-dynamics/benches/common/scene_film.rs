//! The scene's film the film-step bench (`film_step/scene_n64`) and the `film_profile`
//! example (`FILM_SCENE=1`) both step: the first of `crowd`'s bubbles with a grid of 64,
//! one second after it was dropped onto the ground.

use bubble_dynamics::film_flow::FilmFlow;
use bubble_dynamics::{BubbleParams, Collider, DVec3, World, WorldParams};

/// The film of `crowd`'s first bubble with a grid of 64, one second after it was
/// dropped onto the ground.
pub fn scene_film() -> FilmFlow {
    let bubble = BubbleParams {
        center_m: DVec3::new(-0.240, 0.0692, -0.210),
        radius_m: 0.0267,
        mean_thickness_nm: 600.0,
        subdivisions: 3,
        film_grid: 64,
        seed: 1,
        // A scene file's default for a flowing film (`bubbles`' `scene::to_dynamics`):
        // the library's 5e-8 is the per-vertex film's, under which a flowing film drains
        // into a thick pool and its steps run about ten times longer.
        drainage_viscosity_pa_s: 1e-6,
        ..BubbleParams::default()
    };
    let params = WorldParams {
        colliders: vec![Collider::ground(0.0)],
        ..WorldParams::default()
    };
    let mut world = World::try_new(params, vec![bubble]).expect("crowd's first bubble");
    world
        .advance(1.0)
        .expect("one second of crowd's first bubble");
    world.bubbles()[0]
        .film_flow()
        .expect("a film grid of 64")
        .clone()
}

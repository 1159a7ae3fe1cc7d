//! Keeping bubbles' dynamic cube maps across frames (`Renderer::set_cube_map_reuse`): a map
//! is kept only while its bubble moved less than the bound and nothing else it shows
//! changed; every other frame is the fresh frame bit for bit.

mod common;

use common::{lossless_tables, paper_scene, settings};
use raster::{CubeMapReuse, Frame, ReflectionMode, RenderScene, Renderer, Vec3};

const FACE: usize = 32;

fn fresh(scene: &RenderScene) -> Frame {
    let st = settings(
        96,
        72,
        4,
        ReflectionMode::DynamicCubeMap { face_size: FACE },
    );
    Renderer::new()
        .render(scene, &lossless_tables(), &st)
        .unwrap()
        .clone()
}

fn reusing() -> Renderer {
    let mut r = Renderer::new();
    r.set_cube_map_reuse(CubeMapReuse::new(0.25).unwrap());
    r
}

fn render(r: &mut Renderer, scene: &RenderScene) -> Frame {
    let st = settings(
        96,
        72,
        4,
        ReflectionMode::DynamicCubeMap { face_size: FACE },
    );
    r.render(scene, &lossless_tables(), &st).unwrap().clone()
}

/// The largest move that keeps a map: a quarter of a corner texel's angle times the
/// distance to the nearest content (the paper scene's ground, under the bubble).
fn bound_m(scene: &RenderScene, bubble: usize) -> f32 {
    let height = scene.bubbles[bubble].center().y;
    0.25 * 2.0 / FACE as f32 / 3f32.powf(0.75) * height
}

fn moved(scene: &RenderScene, bubble: usize, by: Vec3) -> RenderScene {
    let mut scene = scene.clone();
    for p in &mut scene.bubbles[bubble].positions {
        *p += by;
    }
    scene
}

fn mean_abs_diff(a: &Frame, b: &Frame) -> f64 {
    let sum: f64 = a
        .rgb()
        .iter()
        .zip(b.rgb())
        .flat_map(|(p, q)| (0..3).map(move |k| f64::from((p[k] - q[k]).abs())))
        .sum();
    sum / (3 * a.rgb().len()) as f64
}

#[test]
fn a_map_is_kept_while_its_bubble_moves_less_than_the_bound() {
    let scene = paper_scene();
    let mut r = reusing();
    render(&mut r, &scene);
    assert_eq!(
        r.cube_maps_rendered(),
        2,
        "the first frame renders every map"
    );
    let kept_map = r.cube_map(0).unwrap().clone();
    let step = moved(&scene, 0, Vec3::new(0.9 * bound_m(&scene, 0), 0.0, 0.0));
    let frame = render(&mut r, &step);
    assert_eq!(r.cube_maps_rendered(), 0, "both bubbles within the bound");
    assert!(
        *r.cube_map(0).unwrap() == kept_map,
        "the map was rendered again"
    );
    // The kept map lags the fresh one by under a quarter texel: the frames barely differ.
    let fresh_frame = fresh(&step);
    let diff = mean_abs_diff(&frame, &fresh_frame);
    let mean: f64 = fresh_frame
        .rgb()
        .iter()
        .flatten()
        .map(|&c| f64::from(c))
        .sum::<f64>()
        / (3 * fresh_frame.rgb().len()) as f64;
    eprintln!("kept map: mean |Δ| {diff:.3e}, mean radiance {mean:.3e}");
    assert!(
        diff > 0.0 && diff < 2e-4 * mean,
        "mean |Δ| {diff:.3e} against mean radiance {mean:.3e}"
    );
}

#[test]
fn a_bubble_that_moved_past_the_bound_gets_a_fresh_map_and_the_fresh_frame() {
    let scene = paper_scene();
    let mut r = reusing();
    render(&mut r, &scene);
    let step = moved(&scene, 1, Vec3::new(0.0, 0.0, 1.1 * bound_m(&scene, 1)));
    let frame = render(&mut r, &step);
    assert_eq!(
        r.cube_maps_rendered(),
        1,
        "only the bubble that moved past its bound"
    );
    // Bubble 0 did not move, so its kept map is the fresh one: the whole frame is fresh.
    assert!(frame.rgb() == fresh(&step).rgb());
}

#[test]
fn small_moves_add_up_until_the_map_is_rendered_again() {
    let scene = paper_scene();
    let mut r = reusing();
    render(&mut r, &scene);
    let by = Vec3::new(0.0, 0.0, 0.4 * bound_m(&scene, 0));
    let once = moved(&scene, 0, by);
    render(&mut r, &once);
    assert_eq!(r.cube_maps_rendered(), 0);
    // Measured from where the map was rendered, not from the last frame: 0.8 then 1.2.
    let twice = moved(&once, 0, by);
    render(&mut r, &twice);
    assert_eq!(r.cube_maps_rendered(), 0);
    let thrice = moved(&twice, 0, by);
    let frame = render(&mut r, &thrice);
    assert_eq!(r.cube_maps_rendered(), 1);
    assert!(frame.rgb() == fresh(&thrice).rgb());
}

/// A named change to a scene.
type Change = (&'static str, fn(&mut RenderScene));

#[test]
fn any_change_to_what_the_maps_show_renders_them_again() {
    let scene = paper_scene();
    let changes: [Change; 4] = [
        ("ground", |s| s.ground.as_mut().unwrap().height_m += 1e-4),
        ("light", |s| s.lights[0].position.x += 1e-4),
        ("ambient", |s| s.ambient_rgb[0] += 1e-4),
        ("bubble removed", |s| {
            s.bubbles.remove(0);
        }),
    ];
    for (what, change) in changes {
        let mut r = reusing();
        render(&mut r, &scene);
        let mut changed = scene.clone();
        change(&mut changed);
        let frame = render(&mut r, &changed);
        assert_eq!(
            r.cube_maps_rendered(),
            changed.bubbles.len(),
            "{what}: every map again"
        );
        assert!(
            frame.rgb() == fresh(&changed).rgb(),
            "{what}: not the fresh frame"
        );
    }
}

#[test]
fn without_reuse_every_frame_renders_every_map() {
    let scene = paper_scene();
    let mut r = Renderer::new();
    render(&mut r, &scene);
    let step = moved(&scene, 0, Vec3::new(1e-6, 0.0, 0.0));
    let frame = render(&mut r, &step);
    assert_eq!(r.cube_maps_rendered(), 2);
    assert!(frame.rgb() == fresh(&step).rgb());
}

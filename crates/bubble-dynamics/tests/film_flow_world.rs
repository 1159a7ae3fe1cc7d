//! The film flow inside the world: conservation on a moving, deforming bubble, a
//! thickness field that follows the mesh's stretch, and determinism at any thread count.

use bubble_dynamics::{BubbleParams, DVec3, Wind, World, WorldParams};

fn world_with_flow(grid: u32) -> World {
    let bubble = BubbleParams {
        radius_m: 0.03,
        film_grid: grid,
        // Squashed: the bubble wobbles while it falls and drifts in the wind.
        initial_scale: DVec3::new(1.15, 0.9, 1.0),
        velocity_m_per_s: DVec3::new(0.2, 0.0, 0.1),
        seed: 7,
        // Slow drainage and no rupture: this bubble must keep its film for the test.
        drainage_viscosity_pa_s: 1e-6,
        rupture_thickness_nm: 0.0,
        black_threshold_nm: 0.0,
        ..BubbleParams::default()
    };
    let params = WorldParams {
        wind: Wind::uniform(DVec3::new(0.5, 0.0, 0.0)),
        ..WorldParams::default()
    };
    World::try_new(params, vec![bubble]).expect("valid world")
}

#[test]
fn film_volume_and_surfactant_are_conserved_on_a_moving_deforming_bubble() {
    let mut w = world_with_flow(32);
    let flow = w.bubbles()[0].film_flow().expect("flow on");
    let (v0, s0) = (flow.liquid_volume_m3(), flow.surfactant_amount_m2());
    let start = w.bubbles()[0].center_m();
    w.advance(1.0).expect("stable");
    let b = &w.bubbles()[0];
    assert!(
        (b.center_m() - start).length() > 0.05,
        "the bubble did not move"
    );
    let flow = b.film_flow().expect("flow on");
    let dv = (flow.liquid_volume_m3() - v0) / v0;
    let ds = (flow.surfactant_amount_m2() - s0) / s0;
    assert!(dv.abs() < 1e-12, "liquid volume drifted {dv:.3e} in 1 s");
    assert!(ds.abs() < 1e-12, "surfactant drifted {ds:.3e} in 1 s");
    let moving = flow
        .edge_velocity_m_per_s()
        .iter()
        .map(|u| u.abs())
        .fold(0.0, f64::max);
    assert!(moving > 1e-5, "the film never moved ({moving} m/s)");
}

#[test]
fn the_field_thickness_follows_the_mesh_stretch() {
    // At t = 0 the film has not flowed; the squashed mesh thins the film where it is
    // stretched: the field's mean thickness is the rest mean × rest area / current area.
    let w = world_with_flow(16);
    let b = &w.bubbles()[0];
    let field = b.film_field().expect("flow on");
    let flow = b.film_flow().expect("flow on");
    let areas = flow.grid().areas_sr();
    let mean_now: f64 = field
        .thickness_nm
        .iter()
        .zip(areas)
        .map(|(h, a)| h * a)
        .sum::<f64>()
        / areas.iter().sum::<f64>();
    let rest_area = 4.0 * std::f64::consts::PI * 0.03f64.powi(2);
    let expected = 500.0 * rest_area / b.area_m2();
    assert!(b.area_m2() > 1.005 * rest_area, "the mesh is not stretched");
    assert!(
        (mean_now - expected).abs() < 0.01 * expected,
        "mean field thickness {mean_now:.2} nm, expected {expected:.2} nm"
    );
}

#[test]
fn film_flow_is_identical_at_any_thread_count() {
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut w = world_with_flow(16);
            w.advance(0.25).expect("stable");
            w.bubbles()[0].film_field().expect("flow on").thickness_nm
        })
    };
    let one = run(1);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one), bits(&run(3)));
}

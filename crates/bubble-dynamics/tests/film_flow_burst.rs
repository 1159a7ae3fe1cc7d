//! Black film and bursting: the Taylor–Culick rim speed, black spots that conserve the
//! liquid they push aside, and a bubble the world removes once its film is swept away.

use std::sync::Arc;

use bubble_dynamics::film_flow::{CubeSphere, FilmFlow, FlowParams, Forcing, Hierarchy};
use bubble_dynamics::{BubbleParams, DVec3, Event, World, WorldParams};

fn flow(n: usize, p: FlowParams, h_m: impl Fn(DVec3) -> f64) -> FilmFlow {
    let grid = Arc::new(CubeSphere::new(n));
    let hierarchy = Arc::new(Hierarchy::new(&grid));
    FilmFlow::new(grid, hierarchy, p, h_m)
}

/// Geodesic radius of the open cap whose area the film's holes cover, m.
fn hole_radius_m(f: &FilmFlow) -> f64 {
    let open: f64 = f
        .coverage()
        .iter()
        .zip(f.grid().areas_sr())
        .map(|(c, a)| (1.0 - c) * a)
        .sum();
    // A cap of angular radius φ covers 2π(1 − cos φ) sr.
    (1.0 - open / std::f64::consts::TAU).acos() * f.params().radius_m
}

#[test]
fn a_hole_opens_at_the_taylor_culick_speed() {
    let p = FlowParams::water_film(0.05);
    for h_m in [500e-9, 100e-9] {
        let mut f = flow(64, p, |_| h_m);
        let v0 = f.liquid_volume_m3();
        f.nucleate(DVec3::Y);
        let speed = (2.0 * p.burst.sigma_n_per_m / (p.density_kg_per_m3 * h_m)).sqrt();
        // Time for the rim to cross a fifth of the way to the far pole.
        let t_end = 0.2 * std::f64::consts::PI * 0.05 / speed;
        let dt = t_end / 100.0;
        let mut samples = Vec::new();
        for k in 1..=100 {
            f.step(dt, &Forcing::default());
            if k == 20 || k == 100 {
                samples.push((k as f64 * dt, hole_radius_m(&f)));
            }
        }
        let measured = (samples[1].1 - samples[0].1) / (samples[1].0 - samples[0].0);
        let rel = (measured - speed) / speed;
        eprintln!(
            "h {:.0} nm: rim {measured:.4} m/s, Taylor–Culick {speed:.4} m/s",
            h_m * 1e9
        );
        assert!(
            rel.abs() < 0.05,
            "h {h_m:e} m: rim at {measured:.3} m/s, Taylor–Culick {speed:.3} m/s ({rel:+.3})"
        );
        assert!(f.coverage().contains(&1.0), "the hole took everything");
        // What the rim swept is accounted for, to rounding.
        let dv = (f.liquid_volume_m3() + f.burst_volume_m3() - v0) / v0;
        assert!(dv.abs() < 1e-12, "film + swept liquid drifted {dv:e}");
        assert!(f.burst_volume_m3() > 0.0);
    }
}

#[test]
fn thin_film_turns_black_and_pushes_its_liquid_into_the_rim() {
    let p = FlowParams::water_film(0.03);
    // A thin spot at the top (10 nm at its centre, under 30 nm over a few cells) in a
    // 400 nm film.
    let mut f = flow(32, p, |d| {
        let spot = (-(d - DVec3::Y).length_squared() / 0.05).exp();
        400e-9 - 390e-9 * spot
    });
    let v0 = f.liquid_volume_m3();
    let h0 = f.thickness_m().to_vec();
    for _ in 0..30 {
        f.step(1.0 / 60.0, &Forcing::default());
    }
    let top = f
        .grid()
        .centres()
        .iter()
        .position(|c| c.y > 0.999)
        .expect("a cell at the top");
    let h_top = f.thickness_m()[top];
    assert!(
        (h_top - 12e-9).abs() < 0.5e-9,
        "the spot should be black film (12 nm), is {:.2} nm",
        h_top * 1e9
    );
    let dv = (f.liquid_volume_m3() - v0) / v0;
    assert!(dv.abs() < 1e-12, "black film lost or made liquid: {dv:e}");
    // The film around the spot took the liquid: it is thicker than it started.
    let gain = f
        .thickness_m()
        .iter()
        .zip(&h0)
        .filter(|&(_, &before)| before >= 30e-9)
        .map(|(now, before)| now - before)
        .fold(0.0, f64::max);
    assert!(
        gain > 5e-9,
        "no thickened rim around the black spot (gain {gain:e} m)"
    );
}

#[test]
fn a_film_under_the_rupture_thickness_bursts_and_the_world_removes_the_bubble() {
    let bubble = BubbleParams {
        radius_m: 0.02,
        film_grid: 16,
        mean_thickness_nm: 50.0,
        thickness_variation: 0.9,
        rupture_thickness_nm: 40.0,
        black_threshold_nm: 0.0,
        ..BubbleParams::default()
    };
    let mut w = World::try_new(WorldParams::default(), vec![bubble]).expect("valid");
    let mut burst_at = None;
    for _ in 0..240 {
        let events = w.step().expect("stable");
        if events.iter().any(|e| matches!(e, Event::Burst { .. })) {
            burst_at = Some(w.time_s());
            break;
        }
        if let Some(flow) = w.bubbles().first().and_then(|b| b.film_flow()) {
            let open = flow.coverage().iter().filter(|&&c| c < 1.0).count();
            let total = flow.coverage().len();
            assert!(open == 0 || open < total || flow.fully_burst());
        }
    }
    assert!(burst_at.is_some(), "the bubble never burst");
    assert!(w.bubbles().is_empty());
}

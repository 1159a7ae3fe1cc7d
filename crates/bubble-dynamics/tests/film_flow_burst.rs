//! Black film and bursting: the Taylor–Culick rim speed, black spots that conserve the
//! liquid they push aside, and a bubble the world removes once its film is swept away.

use std::sync::Arc;

use bubble_dynamics::film_flow::{
    CubeSphere, FilmFlow, FlowParams, Forcing, Hierarchy, RIM_CELLS_PER_SUBSTEP,
};
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

/// Regression: black spots are uniform black film, their liquid in the thick film
/// around them. A film at rest between 25 and 45 nm (no gravity, no flow): after 1 s (20
/// relaxation times) every cell under the 30 nm threshold is black film (12 nm) and no
/// grey cell is left alone inside black film. Each black cell used to push its liquid
/// only into its own neighbours above the threshold, so the inside of a spot (no thick
/// neighbour) stayed at its starting 25–30 nm and marginal cells were pushed up into
/// grey islands: the `swirl` film's black region was a cell-by-cell checkerboard.
#[test]
fn black_film_spreads_as_uniform_spots_not_a_checkerboard() {
    let p = FlowParams::water_film(0.03);
    let mut f = flow(32, p, |d| {
        35e-9 + 10e-9 * (3.0 * d.x + 2.0 * d.y).sin() * (2.0 * d.z).cos()
    });
    let v0 = f.liquid_volume_m3();
    for _ in 0..60 {
        f.step(1.0 / 60.0, &Forcing::default());
    }
    let h = f.thickness_m();
    let black: Vec<bool> = h.iter().map(|h| *h < 30e-9).collect();
    let thickest_black = h
        .iter()
        .zip(&black)
        .filter(|(_, b)| **b)
        .map(|(h, _)| *h)
        .fold(0.0, f64::max);
    let mut grey_neighbours = vec![0u32; h.len()];
    for e in f.grid().edges() {
        let (a, b) = (e.a as usize, e.b as usize);
        grey_neighbours[a] += u32::from(!black[b]);
        grey_neighbours[b] += u32::from(!black[a]);
    }
    let islands = (0..h.len())
        .filter(|&k| !black[k] && grey_neighbours[k] == 0)
        .count();
    let black_cells = black.iter().filter(|b| **b).count();
    let dv = (f.liquid_volume_m3() - v0) / v0;
    eprintln!(
        "{black_cells} black cells, thickest {:.3} nm; grey islands {islands}; drift {dv:.1e}",
        thickest_black * 1e9
    );
    assert!(black_cells > 100, "the film has {black_cells} black cells");
    assert!(
        thickest_black < 12.5e-9,
        "a black cell is {:.2} nm, not black film",
        thickest_black * 1e9
    );
    assert_eq!(islands, 0, "grey cells alone inside black film");
    assert!(dv.abs() < 1e-12, "black film lost or made liquid: {dv:e}");
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

/// A 5 cm bubble whose 500 nm film (±2 %) is over its rupture thickness (499 nm) at its
/// thinnest cells, so a hole opens there at the first film step (t = 1/60 s).
fn bursting_world() -> World {
    bursting_world_of(1)
}

/// `count` such bubbles side by side, 15 cm apart, each with its own seed (0, 1, …).
fn bursting_world_of(count: u32) -> World {
    let bubble = |i: u32| BubbleParams {
        center_m: DVec3::new(0.15 * f64::from(i), 0.0, 0.0),
        seed: u64::from(i),
        radius_m: 0.05,
        film_grid: 32,
        mean_thickness_nm: 500.0,
        thickness_variation: 0.02,
        rupture_thickness_nm: 499.0,
        black_threshold_nm: 0.0,
        ..BubbleParams::default()
    };
    World::try_new(WorldParams::default(), (0..count).map(bubble).collect()).expect("valid")
}

/// Cells of the first bubble's film grid.
fn flow_cells(w: &World) -> usize {
    w.bubbles()[0].film_flow().expect("alive").grid().cells()
}

/// Steps `w` while the next step ends by `time_s`, then moves the rims to `time_s`.
fn advance_to_instant(w: &mut World, time_s: f64) -> Vec<Event> {
    let mut events = Vec::new();
    while (w.steps() + 1) as f64 * w.dt_s() <= time_s * (1.0 + 1e-12) {
        events.extend(w.step().expect("stable"));
    }
    w.advance_rims_to(time_s).expect("finite");
    events
}

#[test]
fn the_rim_advances_between_steps_at_the_taylor_culick_speed() {
    let mut w = bursting_world();
    let film_dt = WorldParams::default().film_dt_s;
    advance_to_instant(&mut w, film_dt);
    let flow = w.bubbles()[0].film_flow().expect("a film flow");
    assert_eq!(flow.holes().len(), 1, "one hole at the first film step");
    let p = *flow.params();
    let h = flow.thickness_m().iter().sum::<f64>() / flow.thickness_m().len() as f64;
    let speed = (2.0 * p.burst.sigma_n_per_m / (p.density_kg_per_m3 * h)).sqrt();
    // Every quarter of a world step (1/960 s, a sixteenth of a film step) for 8 ms: the
    // rim crosses half the bubble, 4.6 cells per sample.
    let dt_sample = w.dt_s() / 4.0;
    // From one sample on: the hole opens at a cell's centre, half of that cell covered.
    let mut radii = Vec::new();
    for k in 1..=8 {
        advance_to_instant(&mut w, film_dt + k as f64 * dt_sample);
        radii.push(hole_radius_m(w.bubbles()[0].film_flow().expect("alive")));
    }
    // The rims stop at the last of their sub-steps that ends by the instant asked for, so
    // each sample may lag the law by one sub-step's move (half a cell) and no more.
    let cell_m = (4.0 * std::f64::consts::PI / flow_cells(&w) as f64).sqrt() * p.radius_m;
    let lag_m = RIM_CELLS_PER_SUBSTEP * cell_m;
    for (k, r) in radii.iter().enumerate().skip(1) {
        let law_m = speed * k as f64 * dt_sample;
        let off = (r - radii[0]) - law_m;
        eprintln!(
            "sample {k}: rim {:.3} mm past sample 0, law {:.3} mm ({:+.2} cells)",
            1e3 * (r - radii[0]),
            1e3 * law_m,
            off / cell_m
        );
        assert!(
            off.abs() <= 0.03 * law_m + lag_m,
            "sample {k}: the rim is {:.3} mm off the Taylor–Culick {speed:.2} m/s",
            1e3 * off
        );
    }
    // The world removes the bubble at the end of the step in which the rim has swept the
    // far pole (πR at the Taylor–Culick speed after the hole opened).
    let mut burst_s = None;
    for _ in 0..40 {
        let events = w.step().expect("stable");
        if let Some(Event::Burst { time_s, .. }) = events.first() {
            burst_s = Some(*time_s);
            break;
        }
    }
    let expected_s = film_dt + std::f64::consts::PI * p.radius_m / speed;
    let burst_s = burst_s.expect("the bubble burst");
    assert!(
        (expected_s..expected_s + 2.0 * w.dt_s()).contains(&burst_s),
        "removed at {burst_s:.5} s, the rim reaches the far pole at {expected_s:.5} s"
    );
}

#[test]
fn stopping_the_rims_between_steps_leaves_the_steps_states_unchanged() {
    let (mut straight, mut peeked) = (bursting_world(), bursting_world());
    let film_dt = WorldParams::default().film_dt_s;
    let dt = straight.dt_s();
    straight.advance_to(film_dt + 3.0 * dt).expect("stable");
    advance_to_instant(&mut peeked, film_dt);
    for t in [0.3, 0.31, 0.9, 1.5, 2.0, 2.99] {
        advance_to_instant(&mut peeked, film_dt + t * dt);
    }
    peeked.advance_to(film_dt + 3.0 * dt).expect("stable");
    let (a, b) = (
        straight.bubbles()[0].film_flow().expect("alive"),
        peeked.bubbles()[0].film_flow().expect("alive"),
    );
    assert_eq!(a.holes(), b.holes());
    assert_eq!(a.coverage(), b.coverage());
    assert_eq!(a.thickness_m(), b.thickness_m());
    assert_eq!(a.burst_volume_m3(), b.burst_volume_m3());
}

#[test]
fn one_long_film_step_moves_the_rim_as_many_short_ones_do() {
    let p = FlowParams::water_film(0.05);
    // 100 nm within 0.5 rad of the hole's site (22 m/s), 500 nm beyond (10 m/s).
    let h = |d: DVec3| {
        if d.angle_between(DVec3::Y) < 0.5 {
            100e-9
        } else {
            500e-9
        }
    };
    let t_s = 4e-3;
    let mut long = flow(32, p, h);
    long.nucleate(DVec3::Y);
    long.step(t_s, &Forcing::default());
    let mut short = flow(32, p, h);
    short.nucleate(DVec3::Y);
    for _ in 0..100 {
        short.step(t_s / 100.0, &Forcing::default());
    }
    let (r_long, r_short) = (hole_radius_m(&long), hole_radius_m(&short));
    eprintln!("one step: {r_long:.5} m, 100 steps: {r_short:.5} m");
    assert!(
        ((r_long - r_short) / r_short).abs() < 0.02,
        "one {t_s} s step opened the hole to {r_long:.4} m, 100 short ones to {r_short:.4} m"
    );
}

#[test]
fn bursts_stopped_between_steps_are_identical_at_any_thread_count() {
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut w = bursting_world_of(2);
            let film_dt = WorldParams::default().film_dt_s;
            for k in 0..6 {
                advance_to_instant(&mut w, film_dt + k as f64 * 7e-4);
            }
            w.bubbles()
                .iter()
                .flat_map(|b| b.film_flow().expect("alive").coverage().to_vec())
                .map(f64::to_bits)
                .collect::<Vec<_>>()
        })
    };
    assert_eq!(run(1), run(3));
}

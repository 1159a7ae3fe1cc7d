//! Prints the measured figures quoted in docs/dynamics.md, each from the run that
//! measures it:
//!
//! ```text
//! cargo run --release -p bubble-dynamics --example dynamics_figures -- <figure>
//! ```
//!
//! `elasticity` (smallest triangle area ratio with E = 0, 0.02, 0.05 N/m in a two-bubble
//! collision), `breathing` (the gas mode's angular frequency), `explicit-euler` (where
//! seed 000's scheme diverges), `film-mass` (film mass drift under drainage and swirl),
//! or `all`.

use bubble_dynamics::{
    BubbleParams, Collider, DVec3, Gusts, Integrator, World, WorldParams, geometry,
};

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "all".into());
    let all = which == "all";
    let mut known = false;
    let figures: [(&str, fn()); 4] = [
        ("elasticity", elasticity),
        ("breathing", breathing),
        ("explicit-euler", explicit_euler),
        ("film-mass", film_mass),
    ];
    for (name, run) in figures {
        if all || which == name {
            known = true;
            run();
        }
    }
    if !known {
        eprintln!(
            "unknown figure `{which}`: elasticity, breathing, explicit-euler, film-mass, all"
        );
        std::process::exit(2);
    }
}

/// Two 5 cm bubbles thrown at each other at 1 m/s in 1 m/s gusts, then onto the ground
/// (level 3, 2 s): the smallest triangle's area over its rest area, per elasticity.
fn elasticity() {
    for e in [0.0, 0.02, 0.05] {
        let bubble = |x: f64, v: f64, seed| BubbleParams {
            center_m: DVec3::new(x, 0.12, 0.0),
            velocity_m_per_s: DVec3::new(v, 0.0, 0.0),
            gibbs_elasticity_n_per_m: e,
            seed,
            ..BubbleParams::default()
        };
        let params = WorldParams {
            colliders: vec![Collider::ground(0.0)],
            wind: bubble_dynamics::Wind::default().with_gusts(Gusts {
                amplitude_m_per_s: 1.0,
                ..Gusts::default()
            }),
            ..WorldParams::default()
        };
        let mut w = World::try_new(params, vec![bubble(-0.07, 1.0, 1), bubble(0.07, -1.0, 2)])
            .expect("valid scene");
        let rest: Vec<Vec<f64>> = w.bubbles().iter().map(face_areas).collect();
        let mut smallest = f64::INFINITY;
        let mut outcome = String::from("both intact");
        while w.time_s() < 2.0 {
            match w.step() {
                Ok(events) if !events.is_empty() => {
                    outcome = format!("burst: {events:?}");
                    break;
                }
                Ok(_) => {}
                Err(err) => {
                    outcome = format!("error: {err}");
                    break;
                }
            }
            for b in w.bubbles() {
                let ratio = face_areas(b)
                    .iter()
                    .zip(&rest[b.id() as usize])
                    .map(|(a, a0)| a / a0)
                    .fold(f64::INFINITY, f64::min);
                smallest = smallest.min(ratio);
            }
        }
        let thickest = w
            .bubbles()
            .iter()
            .map(|b| b.max_thickness_nm())
            .fold(0.0, f64::max);
        println!(
            "elasticity E = {e} N/m: smallest triangle {:.1} % of its rest area, thickest vertex {thickest:.0} nm, {outcome} at t = {:.3} s",
            100.0 * smallest,
            w.time_s()
        );
    }
}

fn face_areas(b: &bubble_dynamics::Bubble) -> Vec<f64> {
    let x = b.positions_m();
    b.triangles()
        .iter()
        .map(|t| {
            0.5 * geometry::double_area_vector(x[t[0] as usize], x[t[1] as usize], x[t[2] as usize])
                .length()
        })
        .collect()
}

/// A 5 cm level-3 bubble in air dilated by 1e-5: the volume rings at the gas mode.
fn breathing() {
    let params = WorldParams {
        gravity_m_per_s2: DVec3::ZERO,
        air_viscosity_pa_s: 0.0,
        drag_coefficient: 0.0,
        dt_s: 1e-6,
        ..WorldParams::default()
    };
    let bubble = BubbleParams {
        initial_scale: DVec3::splat(1.0 + 1e-5),
        deformation_damping_per_s: 0.0,
        thickness_variation: 0.0,
        slosh_speed_m_per_s: 0.0,
        ..BubbleParams::default()
    };
    let mut w = World::try_new(params, vec![bubble]).expect("valid scene");
    let mut volumes = vec![w.bubbles()[0].volume_m3()];
    while w.time_s() < 1e-3 {
        w.step().expect("stable");
        volumes.push(w.bubbles()[0].volume_m3());
    }
    let mean = volumes.iter().sum::<f64>() / volumes.len() as f64;
    let crossings: Vec<f64> = volumes
        .windows(2)
        .enumerate()
        .filter(|(_, v)| (v[0] - mean) * (v[1] - mean) < 0.0)
        .map(|(k, v)| (k as f64 + (mean - v[0]) / (v[1] - v[0])) * w.dt_s())
        .collect();
    let half_period =
        (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    println!(
        "breathing mode of a 5 cm level-3 bubble in air: ω = {:.3e} rad/s",
        std::f64::consts::PI / half_period
    );
}

/// Seed 000's explicit Euler on a wobbling 3 cm bubble at the default step.
fn explicit_euler() {
    let params = WorldParams {
        integrator: Integrator::ExplicitEuler,
        ..WorldParams::default()
    };
    let bubble = BubbleParams {
        initial_scale: DVec3::new(1.05, 0.97, 1.0),
        radius_m: 0.03,
        subdivisions: 2,
        thickness_variation: 0.0,
        slosh_speed_m_per_s: 0.0,
        ..BubbleParams::default()
    };
    let mut w = World::try_new(params, vec![bubble]).expect("valid scene");
    match w.advance(0.5) {
        Ok(_) => println!("explicit Euler: no divergence in 0.5 s"),
        Err(err) => println!("explicit Euler: {err}"),
    }
}

/// A 3 cm bubble on the ground draining and swirling for 3 s: relative film mass change.
fn film_mass() {
    let params = WorldParams {
        colliders: vec![Collider::ground(0.0)],
        ..WorldParams::default()
    };
    let bubble = BubbleParams {
        center_m: DVec3::new(0.0, 0.0306, 0.0),
        radius_m: 0.03,
        subdivisions: 3,
        ..BubbleParams::default()
    };
    let mut w = World::try_new(params, vec![bubble]).expect("valid scene");
    let m0 = w.bubbles()[0].film_mass_kg();
    w.advance(3.0).expect("stable");
    let b = &w.bubbles()[0];
    println!(
        "film mass after 3 s of drainage and swirl: relative change {:.1e} (thickness {:.0}..{:.0} nm)",
        (b.film_mass_kg() - m0).abs() / m0,
        b.min_thickness_nm(),
        b.max_thickness_nm()
    );
}

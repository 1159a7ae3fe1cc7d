//! World behaviour: integrators and divergence reports, determinism, validation,
//! bursting, stepping arithmetic.

mod common;

use bubble_dynamics::{
    BubbleParams, Collider, DVec3, Divergence, Event, Integrator, MassDistribution, SimError,
    World, WorldParams,
};
use common::{assert_rel, isolated, plain_bubble, world};

fn wobbly() -> BubbleParams {
    BubbleParams {
        initial_scale: DVec3::new(1.05, 0.97, 1.0),
        ..plain_bubble(0.03, 2)
    }
}

#[test]
fn explicit_euler_is_reported_as_diverging_where_symplectic_euler_is_stable() {
    let params = |integrator| WorldParams {
        integrator,
        ..WorldParams::default()
    };
    let mut stable = world(params(Integrator::SymplecticEuler), vec![wobbly()]);
    stable
        .advance(0.5)
        .expect("the default integrator is stable at this dt");
    assert!(
        stable.bubbles()[0]
            .positions_m()
            .iter()
            .all(|x| x.is_finite())
    );

    let mut explicit = world(params(Integrator::ExplicitEuler), vec![wobbly()]);
    let err = explicit
        .advance(0.5)
        .expect_err("explicit Euler should blow up");
    match &err {
        SimError::Diverged {
            step,
            bubble_id,
            reason,
            ..
        } => {
            assert_eq!(*bubble_id, 0);
            assert!(*step >= 1 && *step <= 120, "step {step}");
            assert!(matches!(
                reason,
                Divergence::Speed { .. } | Divergence::NonFinite { .. } | Divergence::Volume { .. }
            ));
        }
        other => panic!("expected a divergence, got {other}"),
    }
    let message = err.to_string();
    assert!(
        message.contains("step") && message.contains("bubble 0"),
        "message: {message}"
    );
    // The error sticks: no garbage steps after a blow-up.
    assert_eq!(explicit.step().expect_err("still failed"), err);
}

/// Three level-2 bubbles are 960 triangles, below the 8192 from which bubbles run on the
/// rayon pool: this checks that the sequential path keeps no state between runs and
/// none tied to the OS thread. The parallel path at 1, 2 and 3 threads is
/// `tests/threads.rs`.
#[test]
fn sequential_runs_on_two_os_threads_are_bit_identical() {
    let scene = || {
        let params = WorldParams {
            colliders: vec![Collider::ground(0.0)],
            ..WorldParams::default()
        };
        let bubbles = (0..3)
            .map(|i| BubbleParams {
                center_m: DVec3::new(0.07 * i as f64, 0.05 + 0.03 * i as f64, 0.0),
                velocity_m_per_s: DVec3::new(0.3 - 0.3 * i as f64, -0.5, 0.1),
                radius_m: 0.03,
                subdivisions: 2,
                seed: i,
                ..BubbleParams::default()
            })
            .collect();
        World::try_new(params, bubbles).expect("valid")
    };
    let run = move || {
        let mut w = scene();
        w.advance(0.25).expect("stable");
        w.bubbles()
            .iter()
            .map(|b| (b.positions_m().to_vec(), b.thickness_nm().to_vec()))
            .collect::<Vec<_>>()
    };
    let here = run();
    let there = std::thread::spawn(run).join().expect("thread");
    assert!(here == there, "states differ between runs");
}

#[test]
fn bad_parameters_are_rejected_by_name_and_value() {
    let cases: Vec<(WorldParams, Vec<BubbleParams>, &str)> = vec![
        (
            WorldParams {
                dt_s: f64::NAN,
                ..WorldParams::default()
            },
            vec![],
            "dt_s = NaN",
        ),
        (
            WorldParams {
                p_out_pa: -1.0,
                ..WorldParams::default()
            },
            vec![],
            "p_out_pa = -1.0",
        ),
        (
            WorldParams {
                colliders: vec![Collider::plane(DVec3::ZERO, DVec3::ZERO)],
                ..WorldParams::default()
            },
            vec![],
            "colliders[0].normal",
        ),
        (
            WorldParams::default(),
            vec![
                plain_bubble(0.03, 2),
                BubbleParams {
                    radius_m: -0.05,
                    ..BubbleParams::default()
                },
            ],
            "bubbles[1].radius_m = -0.05",
        ),
        (
            WorldParams::default(),
            vec![BubbleParams {
                bottom_warming_k: f64::NAN,
                ..BubbleParams::default()
            }],
            "bubbles[0].bottom_warming_k = NaN",
        ),
        (
            WorldParams::default(),
            vec![BubbleParams {
                bottom_warming_k: 31.0,
                ..BubbleParams::default()
            }],
            "bubbles[0].bottom_warming_k = 31.0",
        ),
        (
            WorldParams::default(),
            vec![BubbleParams {
                subdivisions: 12,
                ..BubbleParams::default()
            }],
            "bubbles[0].subdivisions = 12",
        ),
        (
            WorldParams::default(),
            vec![BubbleParams {
                rupture_thickness_nm: 600.0,
                ..BubbleParams::default()
            }],
            "bubbles[0].rupture_thickness_nm = 600.0",
        ),
        (
            WorldParams::default(),
            vec![BubbleParams {
                sigma_n_per_m: 0.0,
                ..BubbleParams::default()
            }],
            "bubbles[0].sigma_n_per_m = 0.0",
        ),
        (
            WorldParams::default(),
            vec![
                plain_bubble(0.05, 2),
                BubbleParams {
                    center_m: DVec3::new(0.05, 0.0, 0.0),
                    ..plain_bubble(0.05, 2)
                },
            ],
            "bubbles[1].center_m",
        ),
        (
            WorldParams {
                colliders: vec![Collider::ground(0.0)],
                ..WorldParams::default()
            },
            vec![BubbleParams {
                center_m: DVec3::new(0.0, 0.01, 0.0),
                ..plain_bubble(0.05, 2)
            }],
            "colliders[0]",
        ),
    ];
    for (params, bubbles, expected) in cases {
        let err = World::try_new(params, bubbles).expect_err(expected);
        assert!(
            err.to_string().contains(expected),
            "error `{err}` does not name `{expected}`"
        );
    }
}

#[test]
fn an_evaporating_bubble_bursts_when_its_film_reaches_the_rupture_thickness() {
    // 500 nm thinning at 1000 nm/s reaches 10 nm after 0.49 s.
    let bubble = BubbleParams {
        evaporation_nm_per_s: 1000.0,
        ..plain_bubble(0.02, 2)
    };
    let mut w = world(
        isolated(),
        vec![
            plain_bubble(0.02, 2),
            BubbleParams {
                center_m: DVec3::new(0.1, 0.0, 0.0),
                ..bubble
            },
        ],
    );
    let events = w.advance(0.6).expect("stable");
    assert_eq!(events.len(), 1, "events: {events:?}");
    let Event::Burst {
        bubble_id,
        time_s,
        min_thickness_nm,
        ..
    } = events[0].clone();
    assert_eq!(bubble_id, 1);
    assert!(
        (0.48..=0.50).contains(&time_s),
        "burst at {time_s} s, expected 0.49 s"
    );
    assert!(min_thickness_nm < 10.0, "burst at {min_thickness_nm} nm");
    assert_eq!(w.bubbles().len(), 1);
    assert_eq!(w.bubbles()[0].id(), 0, "the survivor keeps its id");
}

#[test]
fn advance_counts_whole_steps_and_rejects_bad_durations() {
    let mut w = world(isolated(), vec![plain_bubble(0.03, 1)]);
    w.advance(0.1).expect("stable");
    assert_eq!(w.steps(), 24, "0.1 s at 1/240 s");
    for _ in 0..3 {
        w.advance(1.0 / 30.0).expect("stable");
    }
    assert_eq!(w.steps(), 48, "three 1/30 s frames after 0.1 s");
    w.advance_to(0.5).expect("stable");
    assert_eq!(w.steps(), 120);
    assert!((w.time_s() - 0.5).abs() < 1e-15, "time {}", w.time_s());
    assert_eq!(
        w.advance(-1.0),
        Err(SimError::BadDuration { seconds: -1.0 })
    );
    assert!(matches!(
        w.advance(f64::NAN),
        Err(SimError::BadDuration { .. })
    ));
}

#[test]
fn a_step_too_stiff_for_the_substep_limit_is_an_error_naming_the_bubble() {
    let params = WorldParams {
        dt_s: 0.5,
        max_substeps: 10,
        ..isolated()
    };
    let mut w = world(
        params,
        vec![
            plain_bubble(0.05, 1),
            BubbleParams {
                center_m: DVec3::new(0.2, 0.0, 0.0),
                ..plain_bubble(0.005, 3)
            },
        ],
    );
    match w.step() {
        Err(SimError::TooManySubsteps {
            bubble_id,
            needed,
            limit,
            ..
        }) => {
            assert_eq!(bubble_id, 1, "the small, fine bubble is the stiff one");
            assert!(needed > u64::from(limit));
        }
        other => panic!("expected TooManySubsteps, got {other:?}"),
    }
}

#[test]
fn equal_particle_masses_keep_the_area_weighted_mean_thickness() {
    let bubble = BubbleParams {
        mass_distribution: MassDistribution::Equal,
        ..plain_bubble(0.03, 3)
    };
    let w = world(isolated(), vec![bubble]);
    let b = &w.bubbles()[0];
    let m = b.film_masses_kg();
    assert!(
        m.iter().all(|x| (x - m[0]).abs() <= 1e-15 * m[0]),
        "masses differ"
    );
    assert_rel(
        "area-weighted mean thickness",
        b.mean_thickness_nm(),
        500.0,
        1e-12,
    );
    // Seed 000's equal masses make the small triangles round the 12 icosahedron
    // corners thicker than the rest.
    assert!(
        b.max_thickness_nm() > 1.05 * b.min_thickness_nm(),
        "{}..{}",
        b.min_thickness_nm(),
        b.max_thickness_nm()
    );
}

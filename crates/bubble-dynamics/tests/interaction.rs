//! Changes from outside between steps (the viewer's blow, poke and wind controls),
//! judged against worlds built with the same bubbles or wind from the start and against
//! momentum conservation.

mod common;

use bubble_dynamics::{BubbleParams, DVec3, Wind, World, WorldParams};
use common::{isolated, plain_bubble, world};
use proptest::prelude::*;

fn at(center_m: DVec3) -> BubbleParams {
    BubbleParams {
        center_m,
        ..plain_bubble(0.03, 2)
    }
}

fn assert_same_state(a: &World, b: &World) {
    assert_eq!(a.bubbles().len(), b.bubbles().len(), "bubble counts differ");
    for (x, y) in a.bubbles().iter().zip(b.bubbles()) {
        assert_eq!(x.id(), y.id());
        assert_eq!(
            x.positions_m(),
            y.positions_m(),
            "bubble {} positions differ",
            x.id()
        );
        assert_eq!(
            x.thickness_nm(),
            y.thickness_nm(),
            "bubble {} films differ",
            x.id()
        );
    }
}

#[test]
fn an_added_bubble_moves_exactly_like_one_present_from_the_start() {
    let (a, b) = (at(DVec3::ZERO), at(DVec3::new(0.2, 0.0, 0.0)));
    let mut both = world(WorldParams::default(), vec![a.clone(), b.clone()]);
    let mut added = world(WorldParams::default(), vec![a]);
    assert_eq!(added.try_add_bubble(b), Ok(1));
    both.advance(0.05).unwrap();
    added.advance(0.05).unwrap();
    assert_same_state(&both, &added);
}

#[test]
fn an_added_bubble_that_overlaps_is_refused_naming_its_centre() {
    let mut w = world(WorldParams::default(), vec![at(DVec3::ZERO)]);
    let err = w
        .try_add_bubble(at(DVec3::new(0.04, 0.0, 0.0)))
        .expect_err("centres 4 cm apart with 3 cm radii overlap");
    assert_eq!(err.name(), "center_m");
    assert_eq!(w.bubbles().len(), 1, "a refused bubble must not be added");
    let bad = BubbleParams {
        radius_m: -1.0,
        ..at(DVec3::new(1.0, 0.0, 0.0))
    };
    assert_eq!(
        w.try_add_bubble(bad).expect_err("negative radius").name(),
        "radius_m"
    );
}

#[test]
fn ids_of_added_bubbles_are_never_reused() {
    let mut w = world(WorldParams::default(), vec![at(DVec3::ZERO)]);
    assert_eq!(w.try_add_bubble(at(DVec3::new(0.5, 0.0, 0.0))), Ok(1));
    assert_eq!(w.try_add_bubble(at(DVec3::new(-0.5, 0.0, 0.0))), Ok(2));
}

#[test]
fn setting_the_steady_wind_later_matches_a_world_built_with_it() {
    let wind = DVec3::new(0.3, 0.0, -0.1);
    let built = WorldParams {
        wind: Wind::uniform(wind),
        ..WorldParams::default()
    };
    let mut from_start = world(built, vec![at(DVec3::ZERO)]);
    let mut set_later = world(WorldParams::default(), vec![at(DVec3::ZERO)]);
    set_later.set_uniform_wind_m_per_s(wind).unwrap();
    assert_eq!(set_later.uniform_wind_m_per_s(), wind);
    from_start.advance(0.05).unwrap();
    set_later.advance(0.05).unwrap();
    assert_same_state(&from_start, &set_later);
    let err = set_later
        .set_uniform_wind_m_per_s(DVec3::new(f64::NAN, 0.0, 0.0))
        .expect_err("NaN wind");
    assert_eq!(err.name(), "uniform_m_per_s");
    assert_eq!(
        set_later.uniform_wind_m_per_s(),
        wind,
        "a refused wind must not be set"
    );
}

#[test]
fn poking_a_missing_bubble_or_with_nan_changes_nothing() {
    let mut w = world(isolated(), vec![at(DVec3::ZERO)]);
    let before = w.bubbles()[0].velocities_m_per_s().to_vec();
    assert!(!w.poke(7, DVec3::ZERO, DVec3::X));
    assert!(!w.poke(0, DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)));
    assert_eq!(w.bubbles()[0].velocities_m_per_s(), &before[..]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Newton: an impulse J changes the bubble's momentum by exactly J, wherever it lands.
    #[test]
    fn a_poke_changes_momentum_by_exactly_its_impulse(
        jx in -1e-4..1e-4f64, jy in -1e-4..1e-4f64, jz in -1e-4..1e-4f64,
        theta in 0.0..std::f64::consts::PI, phi in 0.0..std::f64::consts::TAU,
    ) {
        let mut w = world(isolated(), vec![at(DVec3::ZERO)]);
        let impulse = DVec3::new(jx, jy, jz);
        let point = 0.03 * DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
        let before = w.bubbles()[0].momentum_kg_m_per_s();
        prop_assert!(w.poke(0, point, impulse));
        let change = w.bubbles()[0].momentum_kg_m_per_s() - before;
        let error = (change - impulse).length();
        prop_assert!(error <= 1e-12 * impulse.length().max(1e-9),
            "momentum change {change} vs impulse {impulse}: difference {error:e}");
        // The push is local: the vertex farthest from the point does not move.
        let v = w.bubbles()[0].velocities_m_per_s();
        let far = w.bubbles()[0].positions_m().iter().enumerate()
            .max_by(|a, b| a.1.distance(point).total_cmp(&b.1.distance(point))).unwrap().0;
        prop_assert_eq!(v[far], DVec3::ZERO);
    }
}

//! External forces against closed forms: terminal velocity under gravity and drag,
//! buoyancy of a helium bubble, a bubble carried by the wind.

mod common;

use bubble_dynamics::{
    AIR_MOLAR_MASS_KG_PER_MOL, BubbleParams, DVec3, GAS_CONSTANT_J_PER_MOL_K, Gusts, Wind,
    WorldParams,
};
use common::{assert_rel, plain_bubble, world};
use std::f64::consts::PI;

const SIGMA: f64 = 0.025;

/// The terminal speed v solving ½ρC_d πR² v² + 6πμR v = |net weight|, where the net weight
/// is film + gas − displaced air, the gas an ideal gas at the Laplace pressure.
fn analytic_terminal_speed(p: &WorldParams, b: &BubbleParams) -> f64 {
    let r = b.radius_m;
    let volume = 4.0 / 3.0 * PI * r.powi(3);
    let film = b.film_density_kg_per_m3 * 4.0 * PI * r * r * b.mean_thickness_nm * 1e-9;
    let p_in = p.p_out_pa + 4.0 * SIGMA / r;
    let gas = p_in * b.gas_molar_mass_kg_per_mol / (GAS_CONSTANT_J_PER_MOL_K * b.gas_temperature_k)
        * volume;
    let weight = (film + gas - p.air_density_kg_per_m3 * volume) * p.gravity_m_per_s2.length();
    let quad = 0.5 * p.air_density_kg_per_m3 * p.drag_coefficient * PI * r * r;
    let lin = 6.0 * PI * p.air_viscosity_pa_s * p.linear_drag_factor * r;
    positive_root(quad, lin, weight.abs())
}

/// The positive v with quad·v² + lin·v = w.
fn positive_root(quad: f64, lin: f64, w: f64) -> f64 {
    if quad == 0.0 {
        w / lin
    } else {
        (-lin + (lin * lin + 4.0 * quad * w).sqrt()) / (2.0 * quad)
    }
}

#[test]
fn falling_bubble_reaches_the_analytic_terminal_velocity() {
    let params = WorldParams::default();
    let bubble = plain_bubble(0.012, 2);
    let v_t = analytic_terminal_speed(&params, &bubble);
    let mut w = world(WorldParams::default(), vec![bubble]);
    w.advance(1.6).expect("stable");
    let v = w.bubbles()[0].velocity_m_per_s();
    assert_rel("terminal fall speed", -v.y, v_t, 0.02);
    assert!(v.x.abs() + v.z.abs() < 1e-3 * v_t, "sideways drift {v:?}");
    // Still accelerating? The speed must have settled.
    w.advance(0.2).expect("stable");
    assert_rel(
        "speed 0.2 s later",
        -w.bubbles()[0].velocity_m_per_s().y,
        -v.y,
        0.005,
    );
}

#[test]
fn stokes_only_terminal_velocity() {
    // Quadratic drag off: v = W / (6πμR f); a thick air (f = 50) keeps it quick.
    let params = WorldParams {
        drag_coefficient: 0.0,
        linear_drag_factor: 50.0,
        ..WorldParams::default()
    };
    let bubble = plain_bubble(0.01, 2);
    let v_t = analytic_terminal_speed(&params, &bubble);
    let mut w = world(params, vec![bubble]);
    w.advance(1.0).expect("stable");
    assert_rel(
        "Stokes terminal speed",
        -w.bubbles()[0].velocity_m_per_s().y,
        v_t,
        0.02,
    );
}

#[test]
fn helium_bubble_rises_at_its_terminal_velocity() {
    let params = WorldParams::default();
    let bubble = BubbleParams {
        gas_molar_mass_kg_per_mol: 0.004_002_6,
        ..plain_bubble(0.02, 2)
    };
    let v_t = analytic_terminal_speed(&params, &bubble);
    let mut w = world(WorldParams::default(), vec![bubble]);
    w.advance(1.5).expect("stable");
    let v = w.bubbles()[0].velocity_m_per_s();
    assert!(v.y > 0.0, "helium bubble sinks: {v:?}");
    assert_rel("terminal rise speed", v.y, v_t, 0.02);
}

#[test]
fn without_buoyancy_only_the_film_weighs() {
    // Buoyancy off removes both the displaced air's lift and the gas's weight.
    let params = WorldParams {
        buoyancy: false,
        ..WorldParams::default()
    };
    let bubble = plain_bubble(0.012, 2);
    let r = bubble.radius_m;
    let weight = 1000.0 * 4.0 * PI * r * r * 500e-9 * params.gravity_m_per_s2.length();
    let quad = 0.5 * params.air_density_kg_per_m3 * params.drag_coefficient * PI * r * r;
    let lin = 6.0 * PI * params.air_viscosity_pa_s * r;
    let expected = positive_root(quad, lin, weight);
    let mut w = world(params, vec![bubble]);
    w.advance(1.6).expect("stable");
    assert_rel(
        "fall speed without buoyancy",
        -w.bubbles()[0].velocity_m_per_s().y,
        expected,
        0.02,
    );
}

/// A bubble at rest in a steady wind: the slip speed u = |w − v| obeys
/// M du/dt = −(c_q u² + c_l u) with M = film + gas + ½ρ_air V (added mass), whose
/// solution is u(t) = c_l u₀ e^(−c_l t/M) / (c_l + c_q u₀ (1 − e^(−c_l t/M))).
#[test]
fn bubble_in_a_steady_wind_follows_the_analytic_drag_law_with_added_mass() {
    let wind = DVec3::new(0.8, 0.0, -0.3);
    let params = WorldParams {
        gravity_m_per_s2: DVec3::ZERO,
        wind: Wind::uniform(wind),
        ..WorldParams::default()
    };
    let bubble = plain_bubble(0.01, 2);
    let r = bubble.radius_m;
    let volume = 4.0 / 3.0 * PI * r.powi(3);
    let film = 1000.0 * 4.0 * PI * r * r * 500e-9;
    let gas = (params.p_out_pa + 4.0 * SIGMA / r) * AIR_MOLAR_MASS_KG_PER_MOL
        / (GAS_CONSTANT_J_PER_MOL_K * 293.15)
        * volume;
    let mass = film + gas + 0.5 * params.air_density_kg_per_m3 * volume;
    let c_q = 0.5 * params.air_density_kg_per_m3 * params.drag_coefficient * PI * r * r;
    let c_l = 6.0 * PI * params.air_viscosity_pa_s * r;
    let u0 = wind.length();
    let mut w = world(params, vec![bubble]);
    for t in [0.1, 0.3, 0.6] {
        w.advance_to(t).expect("stable");
        let decay = (-c_l * t / mass).exp();
        let expected = c_l * u0 * decay / (c_l + c_q * u0 * (1.0 - decay));
        let slip = wind - w.bubbles()[0].velocity_m_per_s();
        assert_rel(
            &format!("slip speed at {t} s"),
            slip.length(),
            expected,
            0.02,
        );
        // The faceted mesh is not perfectly isotropic: allow a milliradian.
        assert!(
            slip.cross(wind).length() < 1e-3 * u0 * slip.length(),
            "slip {slip:?} not along the wind"
        );
    }
}

#[test]
fn user_wind_field_equals_the_same_uniform_wind() {
    let wind = DVec3::new(0.5, 0.1, 0.0);
    let uniform = WorldParams {
        wind: Wind::uniform(wind),
        ..WorldParams::default()
    };
    let closure = WorldParams {
        wind: Wind::default().with_field(move |_, _| wind),
        ..WorldParams::default()
    };
    let mut a = world(uniform, vec![plain_bubble(0.02, 2)]);
    let mut b = world(closure, vec![plain_bubble(0.02, 2)]);
    a.advance(0.1).expect("stable");
    b.advance(0.1).expect("stable");
    assert_eq!(a.bubbles()[0].positions_m(), b.bubbles()[0].positions_m());
}

#[test]
fn gusts_push_bubbles_around_smoothly_and_deterministically() {
    let gusty = || WorldParams {
        gravity_m_per_s2: DVec3::ZERO,
        wind: Wind::default().with_gusts(Gusts {
            amplitude_m_per_s: 1.0,
            timescale_s: 0.5,
            length_scale_m: 0.5,
            seed: 3,
        }),
        ..WorldParams::default()
    };
    let mut a = world(gusty(), vec![plain_bubble(0.02, 2)]);
    let mut b = world(gusty(), vec![plain_bubble(0.02, 2)]);
    a.advance(0.5).expect("stable");
    b.advance(0.5).expect("stable");
    let (va, vb) = (
        a.bubbles()[0].velocity_m_per_s(),
        b.bubbles()[0].velocity_m_per_s(),
    );
    assert_eq!(va, vb, "same seed, different result");
    assert!(
        va.length() > 0.05,
        "the gusts did not move the bubble: {va:?}"
    );
    // The bubble cannot outrun the air pushing it (RMS 1 m/s; peaks a few times that).
    assert!(va.length() < 4.0, "bubble outran the gusts: {va:?}");
}

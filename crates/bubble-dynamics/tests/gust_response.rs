//! A bubble in an unsteady wind against the drag law's time constant.
//!
//! With linear (Stokes) drag only, the centre of mass obeys M dv/dt = c(u(t) − v) with
//! c = 6πμR·f and M the film, gas and added air: a first-order lag of time constant
//! τ = M/c. For a sinusoidal gust u = U sin Ωt from rest,
//! v(t) = U/(1 + (Ωτ)²)·(sin Ωt − Ωτ cos Ωt + Ωτ e^(−t/τ)).

mod common;

use bubble_dynamics::{BubbleParams, DVec3, GAS_CONSTANT_J_PER_MOL_K, Wind, WorldParams};
use common::{plain_bubble, world};
use std::f64::consts::PI;

/// τ = M/c for `b` in `p`, with every mass from the parameters, s.
fn drag_time_constant_s(p: &WorldParams, b: &BubbleParams) -> f64 {
    let r = b.radius_m;
    let volume = 4.0 / 3.0 * PI * r.powi(3);
    let film = b.film_density_kg_per_m3 * 4.0 * PI * r * r * b.mean_thickness_nm * 1e-9;
    let p_in = p.p_out_pa + 4.0 * b.sigma_n_per_m / r;
    let gas = p_in * b.gas_molar_mass_kg_per_mol / (GAS_CONSTANT_J_PER_MOL_K * b.gas_temperature_k)
        * volume;
    let added = p.added_mass_coefficient * p.air_density_kg_per_m3 * volume;
    let c = 6.0 * PI * p.air_viscosity_pa_s * p.linear_drag_factor * r;
    (film + gas + added) / c
}

#[test]
fn sinusoidal_gust_lags_and_shrinks_as_a_first_order_drag_response() {
    let (u_m_per_s, linear_drag_factor) = (0.3, 200.0);
    let still = WorldParams {
        gravity_m_per_s2: DVec3::ZERO,
        drag_coefficient: 0.0,
        linear_drag_factor,
        // dt/τ = 0.01: the implicit drag update lags by about dt/2, 0.5 % of the signal.
        dt_s: 1.0 / 960.0,
        ..WorldParams::default()
    };
    let bubble = plain_bubble(0.03, 2);
    let tau = drag_time_constant_s(&still, &bubble);
    // Ωτ = 1: the response is 1/√2 of the gust, 45° behind.
    let omega = 1.0 / tau;
    let params = WorldParams {
        wind: Wind::default().with_field(move |_, t| DVec3::X * u_m_per_s * (omega * t).sin()),
        ..still
    };
    let mut w = world(params, vec![bubble]);
    let mut worst: f64 = 0.0;
    while w.time_s() < 4.0 * tau {
        w.step().expect("stable");
        let t = w.time_s();
        let wt = omega * t;
        let want = u_m_per_s / 2.0 * (wt.sin() - wt.cos() + (-t / tau).exp());
        let got = w.bubbles()[0].velocity_m_per_s().x;
        worst = worst.max((got - want).abs());
    }
    println!("τ = {tau:.4} s; worst |v − v_closed| = {worst:.3e} m/s of U = {u_m_per_s}");
    // Measured 1.3 % of U: the level-2 mesh's drag integral (the steady-wind test allows
    // 2 % too). A missing added mass or a factor 2 in the drag changes τ by a third or
    // more, and v by over 10 % of U.
    assert!(
        worst < 0.02 * u_m_per_s,
        "worst |v − v_closed| = {worst:.3e} m/s > 2 % of the gust's {u_m_per_s} m/s"
    );
}

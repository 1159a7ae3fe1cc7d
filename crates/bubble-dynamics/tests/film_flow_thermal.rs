//! The film's temperature against closed forms and independent data: its relaxation to
//! the air's, the evaporation's rise with the vapour pressure (Buck's empirical formula,
//! not the Clausius–Clapeyron law the flow uses), the surfactant gradient that holds the
//! thermal Marangoni stress, and thermal convection keeping a film stirred.

use std::sync::Arc;

use bubble_dynamics::DVec3;
use bubble_dynamics::film_flow::{
    CubeSphere, FilmFlow, FlowParams, Forcing, Hierarchy, ThermalParams,
};

const G: f64 = 9.80665;

fn flow(n: usize, p: FlowParams, h_m: impl Fn(DVec3) -> f64) -> FilmFlow {
    let grid = Arc::new(CubeSphere::new(n));
    let hierarchy = Arc::new(Hierarchy::new(&grid));
    FilmFlow::new(grid, hierarchy, p, h_m)
}

/// A 2 cm film warmed `warming_k` at its bottom (+Y up), with `dσ/dθ` given.
fn warmed(warming_k: f64, tension_per_kelvin: f64) -> FlowParams {
    let mut p = FlowParams::water_film(0.02);
    p.thermal = ThermalParams {
        bottom_warming_k: warming_k,
        tension_per_kelvin_n_per_m_k: tension_per_kelvin,
        ..ThermalParams::isothermal()
    };
    p
}

fn still(g: f64) -> Forcing {
    Forcing {
        g_eff_m_per_s2: DVec3::new(0.0, -g, 0.0),
        air_m_per_s: DVec3::ZERO,
    }
}

/// The index of the cell whose centre is lowest (−Y) and highest.
fn bottom_and_top(f: &FilmFlow) -> (usize, usize) {
    let c = f.grid().centres();
    let by_y = |a: &usize, b: &usize| c[*a].y.total_cmp(&c[*b].y);
    let bottom = (0..c.len()).min_by(by_y).unwrap();
    let top = (0..c.len()).max_by(by_y).unwrap();
    (bottom, top)
}

/// Saturated vapour pressure of water over liquid, Pa (Buck 1996, an empirical fit).
fn buck_pa(celsius: f64) -> f64 {
    611.21 * ((18.678 - celsius / 234.5) * (celsius / (257.14 + celsius))).exp()
}

/// With no Marangoni stress (dσ/dθ = 0) the film's lowest cell warms towards the air's
/// `ΔT (1 − y)/2` as `1 − exp(−2 h_c t/(ρ c_p h))`: a 600 nm water film with 5 W/(m²·K)
/// a face relaxes at 3.98 /s. In steps of 1/600 s (backward Euler's error 0.3 %).
#[test]
fn a_film_warms_to_the_air_at_the_heat_transfer_rate() {
    let mut f = flow(16, warmed(4.0, 0.0), |_| 600e-9);
    let (bottom, _) = bottom_and_top(&f);
    let air = 0.5 * 4.0 * (1.0 - f.grid().centres()[bottom].y);
    let rate = 2.0 * 5.0 / (1000.0 * 4186.0 * 600e-9);
    let dt = 1.0 / 600.0;
    for _ in 0..150 {
        f.step(dt, &still(0.0));
    }
    let t = 150.0 * dt;
    let want = air * (1.0 - (-rate * t).exp());
    let got = f.temperature_excess_k()[bottom];
    eprintln!("bottom cell after {t} s: {got:.4} K, closed form {want:.4} K (air {air:.4} K)");
    assert!(
        (got / want - 1.0).abs() < 0.01,
        "warmed to {got:.4} K, want {want:.4} K ({:+.2} %)",
        100.0 * (got / want - 1.0)
    );
}

/// Once the film has the air's temperature, its warm bottom thins faster than its top by
/// the ratio of water's vapour pressures at the two temperatures, which Buck's empirical
/// formula gives independently of the Clausius–Clapeyron law the flow uses (1.3555 for
/// 20 → 25 °C; within 1 %).
#[test]
fn warm_film_evaporates_faster_by_the_vapour_pressure_ratio() {
    let mut p = warmed(5.0, 0.0);
    p.evaporation_nm_per_s = 40.0;
    let mut f = flow(16, p, |_| 600e-9);
    let (bottom, top) = bottom_and_top(&f);
    for _ in 0..180 {
        f.step(1.0 / 60.0, &still(0.0));
    }
    let before = f.thickness_m().to_vec();
    f.step(1.0 / 60.0, &still(0.0));
    let thinning = |k: usize| before[k] - f.thickness_m()[k];
    let got = thinning(bottom) / thinning(top);
    let theta = f.temperature_excess_k();
    let ambient_c = 20.0;
    let want = buck_pa(ambient_c + theta[bottom]) / buck_pa(ambient_c + theta[top]);
    eprintln!(
        "bottom {:.3} K, top {:.3} K: thinning ratio {got:.4}, Buck {want:.4}",
        theta[bottom], theta[top]
    );
    assert!(
        (got / want - 1.0).abs() < 0.01,
        "thinning ratio {got:.4}, vapour pressure ratio {want:.4}"
    );
}

/// Without gravity, warm film's lower tension `2 (dσ/dθ) θ` is held by surfactant swept
/// towards the cold top until `E_f ln Γ` cancels it: `ln(Γ_bottom/Γ_top) = 2 (dσ/dθ)
/// (θ_bottom − θ_top)/E_f`, −3 % for 5 K on a water-like film. Within 5 % of that, the film
/// coming to rest (a sign error would sweep the surfactant down; a lost factor 2 would
/// halve the gradient).
#[test]
fn surfactant_swept_to_the_cold_top_holds_the_thermal_marangoni_stress() {
    let mut f = flow(16, warmed(5.0, -1.5e-4), |_| 600e-9);
    let (bottom, top) = bottom_and_top(&f);
    for _ in 0..240 {
        f.step(1.0 / 60.0, &still(0.0));
    }
    let theta = f.temperature_excess_k();
    let gamma = f.surfactant();
    let got = (gamma[bottom] / gamma[top]).ln();
    let want = 2.0 * -1.5e-4 * (theta[bottom] - theta[top]) / 0.05;
    let fastest = f
        .edge_velocity_m_per_s()
        .iter()
        .fold(0.0_f64, |m, u| m.max(u.abs()));
    eprintln!("ln Γ_bottom/Γ_top {got:.5}, closed form {want:.5}; fastest edge {fastest:.2e} m/s");
    assert!(
        (got / want - 1.0).abs() < 0.05,
        "ln Γ ratio {got:.5}, want {want:.5}"
    );
    assert!(fastest < 1e-4, "the film still moves at {fastest:.2e} m/s");
}

/// Liquid and surfactant stay conserved with the thermal stress on, in gravity, with
/// drainage (no evaporation, which removes liquid).
#[test]
fn thermal_convection_conserves_liquid_and_surfactant() {
    let mut p = warmed(5.0, -1.5e-4);
    p.drainage_viscosity_pa_s = 1e-6;
    let mut f = flow(16, p, |d| {
        600e-9 * (1.0 + 0.2 * (3.0 * d.x + 2.0 * d.z).sin())
    });
    let (v0, s0) = (f.liquid_volume_m3(), f.surfactant_amount_m2());
    for _ in 0..60 {
        f.step(1.0 / 60.0, &still(G));
    }
    let dv = (f.liquid_volume_m3() / v0 - 1.0).abs();
    let ds = (f.surfactant_amount_m2() / s0 - 1.0).abs();
    eprintln!("after 1 s of convection: liquid drift {dv:.2e}, surfactant drift {ds:.2e}");
    assert!(
        dv < 1e-12 && ds < 1e-12,
        "liquid {dv:.2e}, surfactant {ds:.2e}"
    );
}

/// The `swirl` film's physics on a 5 cm bubble (n = 32, 600 nm ± 20 %, drainage 1 µPa·s,
/// evaporation 40 nm/s): stirred films settle into drained bands, but one warmed 5 K at
/// its bottom keeps plumes of thin film rising, so the thickness varies along each
/// height band (the swirls' signature) more than in the isothermal film after 6 s.
#[test]
fn a_film_warmed_at_its_bottom_keeps_swirling_where_an_isothermal_one_settles() {
    let swirls_after = |warming_k: f64| {
        let mut p = warmed(warming_k, -1.5e-4);
        p.radius_m = 0.05;
        p.drainage_viscosity_pa_s = 1e-6;
        p.evaporation_nm_per_s = 40.0;
        p.burst.rupture_thickness_nm = 0.0;
        let mut f = flow(32, p, |d| {
            600e-9 * (1.0 + 0.2 * ((5.0 * d.x + 3.0 * d.z).sin() * (4.0 * d.y + d.x).cos()))
        });
        for _ in 0..360 {
            f.step(1.0 / 60.0, &still(G));
        }
        band_variation(&f)
    };
    let (cold, warm) = (swirls_after(0.0), swirls_after(5.0));
    eprintln!(
        "thickness variation along height bands after 6 s: isothermal {cold:.4}, warmed {warm:.4}"
    );
    assert!(
        warm > 1.5 * cold,
        "warmed {warm:.4} against isothermal {cold:.4}"
    );
}

/// The rms of the thickness's departure from its mean over each of 24 height bands, over
/// the mean thickness, above the bottom quarter (where the drained liquid pools).
fn band_variation(f: &FilmFlow) -> f64 {
    let c = f.grid().centres();
    let (h, areas) = (f.thickness_m(), f.grid().areas_sr());
    let band = |y: f64| (((y + 1.0) * 12.0) as usize).min(23);
    let mut sums = [(0.0, 0.0); 24];
    for ((d, h), a) in c.iter().zip(h).zip(areas) {
        let s = &mut sums[band(d.y)];
        *s = (s.0 + h * a, s.1 + a);
    }
    let (mut dev, mut mean, mut area) = (0.0, 0.0, 0.0);
    for ((d, h), a) in c.iter().zip(h).zip(areas) {
        if d.y > -0.5 {
            let (hs, w) = sums[band(d.y)];
            dev += (h - hs / w).powi(2) * a;
            mean += h * a;
            area += a;
        }
    }
    (dev / area).sqrt() / (mean / area)
}

/// The film carries its warmth with it: a film turning about Z at ω (no air drag, no
/// thermal Marangoni stress) under air warm at the bottom settles, for the linear part
/// `θ = c + a x + b y` of its temperature, where `da/dt = −ω b − k a` and
/// `db/dt = ω a + k (−ΔT/2 − b)` (the rotation turns the gradient, the air relaxes it at
/// `k = 2 h_c/(ρ c_p h)`): the warm side lags behind the air's by `a/(−b) = ω/k`, 0.502
/// for 2 rad/s on 600 nm. (Taken downwind, the warmth would lead instead; without the
/// transport, `a` would stay 0.)
#[test]
fn a_turning_film_carries_its_warmth_behind_the_airs() {
    let mut p = warmed(4.0, 0.0);
    p.air_viscosity_pa_s = 0.0;
    let omega = 2.0;
    let mut f = flow(32, p, |_| 600e-9);
    f.set_velocity(|d| DVec3::Z.cross(d) * (omega * p.radius_m));
    for _ in 0..480 {
        f.step(1.0 / 240.0, &still(0.0));
    }
    let (theta, grid) = (f.temperature_excess_k(), f.grid());
    let moment = |axis: fn(DVec3) -> f64| {
        let cells = theta.iter().zip(grid.centres()).zip(grid.areas_sr());
        let (num, den) = cells.fold((0.0, 0.0), |(n, d), ((t, c), area)| {
            (n + t * axis(*c) * area, d + axis(*c) * axis(*c) * area)
        });
        num / den
    };
    let (a, b) = (moment(|c| c.x), moment(|c| c.y));
    let k = 2.0 * 5.0 / (1000.0 * 4186.0 * 600e-9);
    let (got, want) = (a / -b, omega / k);
    eprintln!("a {a:.4} K, b {b:.4} K: lag {got:.4}, closed form {want:.4}");
    assert!(
        (got / want - 1.0).abs() < 0.1,
        "the warmth lags by {got:.4}, want {want:.4} ({:+.1} %)",
        100.0 * (got / want - 1.0)
    );
}

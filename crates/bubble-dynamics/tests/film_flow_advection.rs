//! The film's momentum advection against Haurwitz's exact solution of the Euler equations
//! on a sphere: a degree-l stream-function pattern riding a solid-body rotation ω turns
//! at `ω (1 − 2/(l(l+1)))`, not at ω (docs/dynamics.md, "Momentum advection").
//!
//! Derivation: the surface flow is nearly incompressible (Marangoni waves at 7 m/s
//! against 5 cm/s), so its vorticity ζ = ∇²ψ is carried, `∂ζ/∂t + J(ψ, ζ) = 0`. With
//! ψ = ψ₀ + ψ', ψ₀ = a cos θ the rotation (∇²ψ₀ = −2ψ₀/R²) and ψ' of degree l
//! (∇²ψ' = −l(l+1)ψ'/R²), the terms J(ψ₀, ζ₀) and J(ψ', ζ') vanish and what is left is
//! `∂ψ'/∂t = −(1 − 2/(l(l+1))) J(ψ₀, ψ')`: the rotation's advection slowed by that
//! factor. Without advection the pattern stands still; l = 1 (a tilted rotation added to
//! the first) is steady.

use std::sync::Arc;

use bubble_dynamics::DVec3;
use bubble_dynamics::film_flow::{CubeSphere, FilmFlow, FlowParams, Forcing, Hierarchy};

const RADIUS_M: f64 = 0.01;
const OMEGA_RAD_PER_S: f64 = 5.0;

/// A 1 µm film of a 1 cm sphere in a vacuum: no air, the liquid's own viscosity
/// (its l = 2 decay, 4ν/R² = 0.04/s, changes the amplitude, not the phase).
fn flow(n: usize) -> FilmFlow {
    let mut p = FlowParams::water_film(RADIUS_M);
    p.air_viscosity_pa_s = 0.0;
    let grid = Arc::new(CubeSphere::new(n));
    let hierarchy = Arc::new(Hierarchy::new(&grid));
    FilmFlow::new(grid, hierarchy, p, |_| 1e-6)
}

/// The velocity `d × ∇ψ` of stream function `ψ(d) = scale · f(d)` on the sphere, from
/// `f`'s gradient in space (its tangential part is the surface gradient).
fn velocity(grad_f: impl Fn(DVec3) -> DVec3, scale: f64) -> impl Fn(DVec3) -> DVec3 {
    move |d: DVec3| {
        let g = grad_f(d);
        d.cross(g - d * g.dot(d)) * scale
    }
}

/// Edge velocities of `field` on `f`'s grid.
fn edge_pattern(f: &FilmFlow, field: impl Fn(DVec3) -> DVec3) -> Vec<f64> {
    f.grid()
        .edges()
        .iter()
        .map(|e| field(e.midpoint).dot(e.normal))
        .collect()
}

/// Each edge's weight `l·d` in the kinetic energy `Σ l d u²` (and in projections).
fn energy_weights(f: &FilmFlow) -> Vec<f64> {
    f.grid()
        .edges()
        .iter()
        .map(|e| e.length * e.dual_length)
        .collect()
}

/// `Σ a b w / Σ b b w`.
fn projection(a: &[f64], b: &[f64], w: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).zip(w).map(|((x, y), w)| x * y * w).sum();
    let den: f64 = b.iter().zip(w).map(|(y, w)| y * y * w).sum();
    num / den
}

/// Turns a solid rotation about z plus a pattern `(1 − z²) cos mλ` of degree l = m for
/// `t_end` and returns (the angle the pattern turned, the kinetic energy's relative
/// change).
fn pattern_turn(n: usize, m: u32, t_end: f64, steps: u32) -> (f64, f64) {
    let mut f = flow(n);
    let rotation = velocity(|_| DVec3::Z, -OMEGA_RAD_PER_S * RADIUS_M);
    // Sectoral harmonics Re/Im (x + iy)^m: degree l = m.
    let (cos_m, sin_m) = sectoral_gradients(m);
    let amplitude = 0.3 * OMEGA_RAD_PER_S * RADIUS_M;
    let (vc, vs) = (velocity(cos_m, amplitude), velocity(sin_m, amplitude));
    f.set_velocity(|d| rotation(d) + vc(d));
    let (pc, ps) = (edge_pattern(&f, &vc), edge_pattern(&f, &vs));
    let w = energy_weights(&f);
    let energy = |u: &[f64]| -> f64 { u.iter().zip(&w).map(|(u, w)| u * u * w).sum() };
    let e0 = energy(f.edge_velocity_m_per_s());
    let dt = t_end / f64::from(steps);
    for _ in 0..steps {
        f.step(dt, &Forcing::default());
    }
    let u = f.edge_velocity_m_per_s();
    let (c, s) = (projection(u, &pc, &w), projection(u, &ps, &w));
    // Re (x+iy)^m rotated by α is cos mα Re + sin mα Im.
    let turned = s.atan2(c) / f64::from(m);
    (turned, energy(u) / e0 - 1.0)
}

/// Space gradients of Re and Im of `(x + iy)^m`.
fn sectoral_gradients(m: u32) -> (impl Fn(DVec3) -> DVec3, impl Fn(DVec3) -> DVec3) {
    // d/dx (x+iy)^m = m (x+iy)^(m−1), d/dy = i m (x+iy)^(m−1).
    let power = move |d: DVec3| {
        let (mut re, mut im) = (1.0, 0.0);
        for _ in 1..m {
            (re, im) = (re * d.x - im * d.y, re * d.y + im * d.x);
        }
        (f64::from(m) * re, f64::from(m) * im)
    };
    (
        move |d: DVec3| {
            let (re, im) = power(d);
            DVec3::new(re, -im, 0.0)
        },
        move |d: DVec3| {
            let (re, im) = power(d);
            DVec3::new(im, re, 0.0)
        },
    )
}

#[test]
fn a_haurwitz_pattern_turns_at_the_rotation_slowed_by_two_over_l_l_plus_one() {
    let t_end = 0.2;
    for m in [2u32, 3] {
        let l = f64::from(m);
        let want = OMEGA_RAD_PER_S * (1.0 - 2.0 / (l * (l + 1.0))) * t_end;
        let (turned, energy_change) = pattern_turn(32, m, t_end, 48);
        eprintln!(
            "l = {m}: turned {turned:.5} rad, Haurwitz {want:.5} rad ({:+.2} %), \
             kinetic energy {energy_change:+.3e}",
            100.0 * (turned / want - 1.0)
        );
        assert!(
            (turned / want - 1.0).abs() < 0.05,
            "l = {m}: the pattern turned {turned:.5} rad, Haurwitz says {want:.5}"
        );
        // The advection's rotation term does no work; what the film loses is the
        // perturbation's viscous decay and the Marangoni step's damping of the divergence
        // the advection stirs up. It may lose, never gain.
        assert!(
            (-0.1..1e-3).contains(&energy_change),
            "l = {m}: kinetic energy changed by {energy_change:+.3e}"
        );
    }
}

#[test]
fn a_solid_rotation_about_a_tilted_axis_keeps_its_axis_and_rate() {
    let mut f = flow(32);
    let spin = DVec3::new(1.0, 0.0, 1.0).normalize() * OMEGA_RAD_PER_S;
    f.set_velocity(|d| spin.cross(d) * RADIUS_M);
    let w = energy_weights(&f);
    // The rotation vector, read off as the amplitudes of the rotations about x, y and z.
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let patterns = axes.map(|a| edge_pattern(&f, |d| a.cross(d) * RADIUS_M));
    let read = |u: &[f64]| {
        let [x, y, z] = [0, 1, 2].map(|k| projection(u, &patterns[k], &w));
        DVec3::new(x, y, z)
    };
    let before = read(f.edge_velocity_m_per_s());
    for _ in 0..48 {
        f.step(0.2 / 48.0, &Forcing::default());
    }
    let after = read(f.edge_velocity_m_per_s());
    let tilt_deg = before.angle_between(after).to_degrees();
    let rate = after.length() / before.length() - 1.0;
    eprintln!("solid rotation after 0.2 s: axis moved {tilt_deg:.4}°, rate {rate:+.3e}");
    assert!(tilt_deg < 0.5, "the rotation axis moved {tilt_deg:.4}°");
    // It loses about (ω dt)² a step to the split with the Marangoni step (module
    // advect's docs): 3.4 % here.
    assert!(
        rate.abs() < 0.05,
        "the rotation rate changed by {rate:+.3e}"
    );
}

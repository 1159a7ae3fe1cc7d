//! How far the Gershgorin bound behind the substep count overestimates the film's true
//! fastest mode: ω_max of M⁻¹H (H the tension/elasticity Hessian, M the vertex masses)
//! by power iteration, independently of the solver (finite differences of the film
//! energy's exact gradient).
//!
//! `cargo run --release -p bubble-dynamics --example fastest_mode`

use bubble_dynamics::{BubbleParams, Collider, DVec3, World, WorldParams};

/// The film energy's parameters and rest face areas, m².
struct Film {
    sigma_n_per_m: f64,
    elasticity_n_per_m: f64,
    rest_area_m2: Vec<f64>,
}

/// ∂E/∂x of E = Σ 2σA + E(A − A⁰)²/(2A⁰): T ∂A/∂x with T = 2σ + E(A/A⁰ − 1), N.
fn gradient_n(film: &Film, x: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut g = vec![DVec3::ZERO; x.len()];
    for (t, a0) in triangles.iter().zip(&film.rest_area_m2) {
        let [ia, ib, ic] = t.map(|i| i as usize);
        let (a, b, c) = (x[ia], x[ib], x[ic]);
        let n2 = (b - a).cross(c - a);
        let len = n2.length();
        let tension = 2.0 * film.sigma_n_per_m + film.elasticity_n_per_m * (0.5 * len / a0 - 1.0);
        let n = n2 / len;
        for (i, opposite) in [(ia, c - b), (ib, a - c), (ic, b - a)] {
            g[i] += 0.5 * tension * n.cross(opposite);
        }
    }
    g
}

/// The Gershgorin bound the solver uses: max_i √(Σ_f (|T| + E)·Σ|e|²/(4A) / m_i), rad/s.
fn gershgorin_rad_per_s(film: &Film, x: &[DVec3], triangles: &[[u32; 3]], m: &[f64]) -> f64 {
    let mut rows = vec![0.0; x.len()];
    for (t, a0) in triangles.iter().zip(&film.rest_area_m2) {
        let [a, b, c] = t.map(|i| x[i as usize]);
        let len = (b - a).cross(c - a).length();
        let tension = 2.0 * film.sigma_n_per_m + film.elasticity_n_per_m * (0.5 * len / a0 - 1.0);
        let edges2 = (b - a).length_squared() + (c - b).length_squared() + (a - c).length_squared();
        for &i in t {
            rows[i as usize] += (tension.abs() + film.elasticity_n_per_m) * edges2 * 0.5 / len;
        }
    }
    rows.iter()
        .zip(m)
        .map(|(k, m)| k / m)
        .fold(0.0, f64::max)
        .sqrt()
}

/// The eigenvalue of M^-½ H M^-½ of largest magnitude (signed), rad²/s², by 3000 steps
/// of power iteration with H·u from central differences of the gradient.
fn dominant_eigenvalue(film: &Film, x: &[DVec3], triangles: &[[u32; 3]], m: &[f64]) -> f64 {
    let mut u: Vec<DVec3> = (0..x.len())
        .map(|i| {
            let f = i as f64;
            DVec3::new((1.3 * f).sin(), (2.7 * f).cos(), (0.37 * f).sin())
        })
        .collect();
    let h = 1e-7 * film.rest_area_m2[0].sqrt();
    let mut lambda = 0.0;
    for _ in 0..3000 {
        let norm = u.iter().map(|v| v.length_squared()).sum::<f64>().sqrt();
        u.iter_mut().for_each(|v| *v /= norm);
        let shifted = |sign: f64| -> Vec<DVec3> {
            x.iter()
                .zip(&u)
                .zip(m)
                .map(|((x, u), m)| *x + *u * (sign * h / m.sqrt()))
                .collect()
        };
        let plus = gradient_n(film, &shifted(1.0), triangles);
        let minus = gradient_n(film, &shifted(-1.0), triangles);
        let y: Vec<DVec3> = plus
            .iter()
            .zip(&minus)
            .zip(m)
            .map(|((p, q), m)| (*p - *q) / (2.0 * h * m.sqrt()))
            .collect();
        lambda = u.iter().zip(&y).map(|(a, b)| a.dot(*b)).sum();
        u = y;
    }
    lambda
}

fn report(name: &str, bubble: BubbleParams) {
    let params = || WorldParams {
        colliders: vec![Collider::ground(0.0)],
        ..WorldParams::default()
    };
    let at_rest = BubbleParams {
        initial_scale: DVec3::ONE,
        ..bubble.clone()
    };
    let rest = World::try_new(params(), vec![at_rest]).expect("valid scene");
    let r = &rest.bubbles()[0];
    let film = Film {
        sigma_n_per_m: bubble.sigma_n_per_m,
        elasticity_n_per_m: bubble.gibbs_elasticity_n_per_m,
        rest_area_m2: bubble_dynamics::geometry::face_areas_m2(r.positions_m(), r.triangles()),
    };
    let mut world = World::try_new(params(), vec![bubble]).expect("valid scene");
    world.step().expect("one step");
    let b = &world.bubbles()[0];
    let (x, t, m) = (b.positions_m(), b.triangles(), b.vertex_masses_kg());
    let bound = gershgorin_rad_per_s(&film, x, t, m);
    let lambda = dominant_eigenvalue(&film, x, t, m);
    let omega = lambda.abs().sqrt();
    println!(
        "{name:<34} Gershgorin {bound:>8.1} rad/s  true {omega:>8.1} rad/s (eigenvalue {lambda:+.3e})  ratio {:.3}  dt·ω_true at 1/240 s {:.3}  substeps {}",
        bound / omega,
        omega / 240.0,
        world.last_substeps()
    );
}

fn main() {
    let base = |radius_m: f64, subdivisions: u32| BubbleParams {
        center_m: DVec3::new(0.0, 1.0, 0.0),
        radius_m,
        subdivisions,
        ..BubbleParams::default()
    };
    let squeezed = |b: BubbleParams| BubbleParams {
        initial_scale: DVec3::new(1.3, 1.0 / 1.3, 1.0),
        rupture_thickness_nm: 0.0,
        ..b
    };
    report("bench: 5 cm, level 3", base(0.05, 3));
    report("5 cm, level 2", base(0.05, 2));
    report("2 cm, level 3", base(0.02, 3));
    report("1 cm, level 2", base(0.01, 2));
    let no_elasticity = BubbleParams {
        gibbs_elasticity_n_per_m: 0.0,
        ..base(0.05, 3)
    };
    report("5 cm, level 3, E = 0", no_elasticity);
    let elastic = BubbleParams {
        gibbs_elasticity_n_per_m: 10.0,
        ..base(0.01, 2)
    };
    report("1 cm, level 2, E = 10, squeezed 1.3", squeezed(elastic));
    report("1 cm, level 3, squeezed 1.3", squeezed(base(0.01, 3)));
}

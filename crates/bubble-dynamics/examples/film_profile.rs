//! Prints the film step's solver iterations, wall time, thinnest film and fastest edge
//! for `film_profile [n] [air m/s] [g m/s²]` (the bench's film, for profiling with perf).

use std::sync::Arc;

use bubble_dynamics::DVec3;
use bubble_dynamics::film_flow::{CubeSphere, FilmFlow, FlowParams, Forcing, Hierarchy};

fn film(n: usize) -> FilmFlow {
    let grid = Arc::new(CubeSphere::new(n));
    let hierarchy = Arc::new(Hierarchy::new(&grid));
    let mut params = FlowParams {
        drainage_viscosity_pa_s: 1e-6,
        evaporation_nm_per_s: 40.0,
        ..FlowParams::water_film(0.05)
    };
    // A film that keeps flowing through the measurement: no rupture.
    params.burst.rupture_thickness_nm = 0.0;
    params.burst.black_threshold_nm = 0.0;
    FilmFlow::new(grid, hierarchy, params, |d| {
        600e-9 * (1.0 + 0.05 * (4.0 * d.x + d.y).sin())
    })
}

fn main() {
    let arg = |k: usize, d: f64| std::env::args().nth(k).map_or(d, |s| s.parse().unwrap());
    let forcing = Forcing {
        g_eff_m_per_s2: DVec3::new(0.0, -arg(3, 9.81), 0.0),
        air_m_per_s: DVec3::new(arg(2, 0.3), 0.0, 0.0),
    };
    let n = arg(1, 64.0) as usize;
    let mut f = film(n);
    for k in 0..40 {
        let t = std::time::Instant::now();
        let r = f.step(1.0 / 60.0, &forcing);
        let hmin = f.thickness_m().iter().cloned().fold(1.0, f64::min);
        let umax = f
            .edge_velocity_m_per_s()
            .iter()
            .map(|u| u.abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{k} {} it {:.2} ms hmin {hmin:.3e} umax {umax:.3}",
            r.iterations,
            t.elapsed().as_secs_f64() * 1e3
        );
    }
}

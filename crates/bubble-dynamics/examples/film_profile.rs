use std::sync::Arc;

use bubble_dynamics::DVec3;
use bubble_dynamics::film_flow::{CubeSphere, FilmFlow, Forcing, FlowParams, Hierarchy};


fn film(n: usize) -> FilmFlow {
    let grid = Arc::new(CubeSphere::new(n));
    let hierarchy = Arc::new(Hierarchy::new(&grid));
    let params = FlowParams {
        drainage_viscosity_pa_s: 5e-8,
        ..FlowParams::water_film(0.05)
    };
    FilmFlow::new(grid, hierarchy, params, |d| 500e-9 * (1.0 + 0.2 * (4.0 * d.x + d.y).sin()))
}

fn main() {
    let forcing = Forcing { g_eff_m_per_s2: DVec3::new(0.0, -9.81, 0.0), air_m_per_s: DVec3::new(0.3, 0.0, 0.0) };
    let n: usize = std::env::args().nth(1).map_or(64, |s| s.parse().unwrap());
    let mut f = film(n);
    for k in 0..40 {
        let t = std::time::Instant::now();
        let r = f.step(1.0 / 60.0, &forcing);
        if k % 5 == 0 { eprintln!("{k} {:?} {:.2} ms", r, t.elapsed().as_secs_f64() * 1e3); }
    }
}

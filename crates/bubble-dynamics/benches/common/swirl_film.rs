//! The film the film-step bench and the `film_profile` example both step: the `swirl`
//! scene's film (drainage μ 1e-6 Pa·s, evaporation 40 nm/s) on a 5 cm bubble, 600 nm ± 5 %,
//! with bursting off so it keeps flowing through a measurement; the scene's warm bottom
//! (thermal convection) is `swirl_film_warmed`'s.

use std::sync::Arc;

use bubble_dynamics::film_flow::{
    CubeSphere, FilmFlow, FilmGradient, FlowParams, Hierarchy, ThermalParams,
};

/// That film on a grid of `n` cells a face, the air `warming_k` warmer at its bottom,
/// driven through `gradient`.
pub fn swirl_film(n: usize, warming_k: f64, gradient: FilmGradient) -> FilmFlow {
    let grid = Arc::new(CubeSphere::new(n));
    let hierarchy = Arc::new(Hierarchy::new(&grid));
    let mut params = FlowParams {
        drainage_viscosity_pa_s: 1e-6,
        evaporation_nm_per_s: 40.0,
        ..FlowParams::water_film(0.05)
    };
    params.burst.rupture_thickness_nm = 0.0;
    params.gradient = gradient;
    params.burst.black_threshold_nm = 0.0;
    params.thermal = ThermalParams {
        bottom_warming_k: warming_k,
        ..ThermalParams::isothermal()
    };
    FilmFlow::new(grid, hierarchy, params, |d| {
        600e-9 * (1.0 + 0.05 * (4.0 * d.x + d.y).sin())
    })
}

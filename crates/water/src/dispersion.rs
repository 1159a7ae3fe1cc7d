//! The deep-water dispersion relation with surface tension: `ω² = g k + σ k³ / ρ`.

/// Standard gravity, m/s².
pub const GRAVITY_M_PER_S2: f64 = 9.80665;
/// Surface tension of clean water at 20 °C, N/m.
pub const WATER_SURFACE_TENSION_N_PER_M: f64 = 0.0728;
/// Density of water at 20 °C, kg/m³.
pub const WATER_DENSITY_KG_PER_M3: f64 = 998.2;

/// Angular frequency of a deep-water wave of wavenumber `k_per_m` (rad/m): gravity plus
/// the capillary term, so short ripples run faster than gravity alone would give.
pub fn deep_water_omega_rad_per_s(k_per_m: f64) -> f64 {
    (GRAVITY_M_PER_S2 * k_per_m
        + WATER_SURFACE_TENSION_N_PER_M * k_per_m.powi(3) / WATER_DENSITY_KG_PER_M3)
        .sqrt()
}

//! Thermal convection: the film's temperature, and the two ways it moves the film.
//!
//! The air around the bubble is warmer at its bottom than at its top by
//! `bottom_warming_k` (a bubble over a warm floor or a hand; Seychelles et al. 2008, "Thermal
//! convection and emergence of isolated vortices in soap bubbles", PRL 101, 144501, heated
//! a half bubble at its equator), linearly in height. The film's temperature excess θ
//! over the ambient (the air at the top) moves with the surfaces and relaxes towards the
//! air's through both faces, `∂θ/∂t + u·∇θ = (2 h_c/(ρ c_p h)) (θ_air − θ)`: a 600 nm film
//! follows the air within a quarter second, so a film carried up keeps its warmth for a
//! centimetre or so.
//!
//! Warm film is weaker, `T = T₀ − E_f ln Γ + 2 (dσ/dθ) θ`: the thermal Marangoni stress
//! pulls the surfaces from the warm bottom towards the cold top, stretching and thinning
//! the film there. Warm film also evaporates faster, as the water's vapour pressure,
//! `e(θ) = e₀ exp((L M/R)(1/T_a − 1/(T_a + θ)))` (Clausius–Clapeyron; 6 % a kelvin at
//! 20 °C). Both make thin film at the bottom, and thin film is light: the tension that
//! holds the film against gravity, a gradient, lifts a thin patch faster than its weight
//! pulls it down. Thin film below thick film is the unstable stratification of
//! Rayleigh–Bénard convection in two dimensions; plumes of thin film rise and roll up
//! into vortices, the swirls of a real bubble.
//!
//! Left out: the evaporation's latent heat (the scene's rate is taken as the net rate at
//! the ambient temperature) and conduction along the film (10⁻⁷ m²/s, far below the
//! upwind transport's own smoothing).

use glam::DVec3;

use super::compare::{larger, smaller};
use super::face_geometry::to_face_frame;
use super::flow::{FilmFlow, FilmGradient, H_FLOOR_M};
use super::fluxes::{span_sides, span_sides_on_face, spread_x_volumes};
use super::grid::dot_at;
use super::sides::{EdgeBlock, INFLOW};
use crate::avx2::with_avx2;
use crate::params::GAS_CONSTANT_J_PER_MOL_K;

/// Specific heat of the film liquid (water), J/(kg·K).
pub const LIQUID_HEAT_CAPACITY_J_PER_KG_K: f64 = 4186.0;
/// Latent heat of vaporisation of water at 20 °C, J/kg.
pub const LATENT_HEAT_J_PER_KG: f64 = 2.454e6;
/// Molar mass of water, kg/mol.
pub const WATER_MOLAR_MASS_KG_PER_MOL: f64 = 0.018_015;
/// Most sub-steps the temperature's transport takes in one step.
const MAX_SUBSTEPS: u32 = 64;
/// Largest fraction of a cell's temperature difference one edge's inflow brings in a
/// sub-step: with four edges a cell the new value is then a convex mix of the old ones.
const MAX_INFLOW_FRACTION: f64 = 0.25;

/// What the film's temperature does: the warming it sees and how it answers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalParams {
    /// How much warmer the air at the bubble's bottom is than at its top, K (0: an
    /// isothermal film, no thermal effects and no temperature field).
    pub bottom_warming_k: f64,
    /// Temperature of the air at the bubble's top (the ambient), K.
    pub ambient_k: f64,
    /// `dσ/dθ` of one surface, N/(m·K): negative, warm film is weaker.
    pub tension_per_kelvin_n_per_m_k: f64,
    /// Heat transfer coefficient between the film and the air on each face, W/(m²·K).
    pub heat_transfer_w_per_m2_k: f64,
}

impl ThermalParams {
    /// No warming: water's `dσ/dθ` (−1.5e-4 N/(m·K)), 5 W/(m²·K) a face (free convection
    /// about a sphere of a few cm in still air), 20 °C.
    pub fn isothermal() -> Self {
        Self {
            bottom_warming_k: 0.0,
            ambient_k: 293.15,
            tension_per_kelvin_n_per_m_k: -1.5e-4,
            heat_transfer_w_per_m2_k: 5.0,
        }
    }

    /// Whether the film has a temperature field at all.
    pub fn is_active(&self) -> bool {
        self.bottom_warming_k != 0.0
    }

    /// The air's temperature excess over the ambient at direction `d` (unit), K, with
    /// `up` the unit direction against gravity: `bottom_warming_k` at the bottom, 0 at
    /// the top, linear in height between.
    pub fn air_excess_k(&self, d: DVec3, up: DVec3) -> f64 {
        self.air_excess_at_height(d.dot(up))
    }

    /// [`Self::air_excess_k`] at the height `d·up` (in radii above the centre).
    #[inline(always)]
    fn air_excess_at_height(&self, height: f64) -> f64 {
        0.5 * self.bottom_warming_k * (1.0 - height)
    }

    /// The evaporation rate of film `excess_k` warmer than the ambient over the
    /// ambient's (Clausius–Clapeyron), its exponential within 2 ulps
    /// (the crate's own `exp`, which a loop over cells vectorises).
    #[inline]
    pub fn evaporation_factor(&self, excess_k: f64) -> f64 {
        let per_kelvin_inverse =
            LATENT_HEAT_J_PER_KG * WATER_MOLAR_MASS_KG_PER_MOL / GAS_CONSTANT_J_PER_MOL_K;
        let t = self.ambient_k;
        crate::exp::exp(per_kelvin_inverse * (1.0 / t - 1.0 / (t + excess_k)))
    }

    /// The rate at which a film `h_m` thick relaxes towards the air's temperature, 1/s.
    pub fn relaxation_per_s(&self, h_m: f64, density_kg_per_m3: f64) -> f64 {
        let heat_per_kelvin = density_kg_per_m3 * LIQUID_HEAT_CAPACITY_J_PER_KG_K * h_m;
        2.0 * self.heat_transfer_w_per_m2_k / heat_per_kelvin.max(f64::MIN_POSITIVE)
    }
}

/// A cell's four sides as the temperature's upwind transport sees them.
struct Inflow {
    /// Each side's surface speed, m/s (positive from the edge's `a` cell to its `b`).
    u: [f64; 4],
    /// Each side's length, rad.
    length: [f64; 4],
    /// Each side's sign of a speed into the cell ([`INFLOW`] inside a face).
    inflow: [f64; 4],
}

impl Inflow {
    /// The cell's change of temperature over a sub-step: `(θ_up − θ)` times the fraction
    /// of the cell that flows in over each side (`scale_per_area` the sub-step over the
    /// radius and the cell's area), at most [`MAX_INFLOW_FRACTION`] a side.
    #[inline(always)]
    fn warming(&self, scale_per_area: f64, across: [f64; 4], own: f64) -> f64 {
        let side = |k: usize| {
            let inward = self.inflow[k] * self.u[k];
            let fraction = smaller(
                scale_per_area * inward * self.length[k],
                MAX_INFLOW_FRACTION,
            );
            if inward > 0.0 {
                fraction * (across[k] - own)
            } else {
                0.0
            }
        };
        (side(0) + side(1)) + (side(2) + side(3))
    }
}

/// The thermal Marangoni stress's change of an edge's velocity, `per·(θ_b − θ_a)/(d h)`
/// at its ends' temperatures `t` and thicknesses `h`, `per_d = 1/d`.
#[inline(always)]
fn push(per: f64, [ta, tb]: [f64; 2], [ha, hb]: [f64; 2], per_d: f64) -> f64 {
    let h_edge = larger(0.5 * (ha + hb), H_FLOOR_M);
    per * (tb - ta) * per_d / h_edge
}

/// Relaxes each cell's temperature `theta` towards the air's over `dt_s`, implicitly, a
/// face at a time: the centres as face 0's components in its frame (`centre`, the same
/// on every face: [`super::face_geometry`]) against `up` taken into each face's, so
/// [`ThermalParams::air_excess_k`] to rounding, four cells at a time.
#[inline(always)]
fn relax(
    theta: &mut [f64],
    h: &[f64],
    [x, y, z]: &[Vec<f64>; 3],
    (th, rho): (ThermalParams, f64),
    (dt_s, up): (f64, DVec3),
) {
    let m = x.len();
    let centres = [&x[..m], &y[..m], &z[..m]];
    let faces = theta.chunks_exact_mut(m).zip(h.chunks_exact(m));
    for (face, (theta, h)) in faces.enumerate() {
        let (theta, h, up) = (&mut theta[..m], &h[..m], to_face_frame(face, up));
        for i in 0..m {
            let r = dt_s * th.relaxation_per_s(h[i].max(H_FLOOR_M), rho);
            let air = th.air_excess_at_height(dot_at(up, centres, i));
            theta[i] = (theta[i] + r * air) / (1.0 + r);
        }
    }
}

/// The unit direction against `g` (+Y where there is no gravity).
pub(super) fn up_from(g_eff_m_per_s2: DVec3) -> DVec3 {
    (-g_eff_m_per_s2).try_normalize().unwrap_or(DVec3::Y)
}

impl FilmFlow {
    /// Moves the temperature with the surfaces' starting velocity (upwind, in sub-steps
    /// of at most a quarter of a cell an edge), then relaxes it towards the air's,
    /// implicitly per cell. `fastest` is the velocity's
    /// [`CubeSphere::fastest_crossing`](super::grid::CubeSphere::fastest_crossing), which
    /// the surfactant's transport takes too.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn exchange_heat(
        &mut self,
        (u_start, fastest): (&[f64], f64),
        scratch: (&mut Vec<f64>, &mut Vec<f64>),
        dt_s: f64,
        up: DVec3,
    ) {
        if self.temperature_k.is_empty() {
            return;
        }
        self.advect_temperature((u_start, fastest), scratch, dt_s);
        let (th, rho) = (self.params.thermal, self.params.density_kg_per_m3);
        let centres = &self.grid.face_geometry().centre;
        let (theta, h) = (&mut self.temperature_k, &self.h_m);
        with_avx2(
            #[inline(always)]
            || relax(theta, h, centres, (th, rho), (dt_s, up)),
        );
    }

    /// `∂θ/∂t + u·∇θ = 0`, upwind: each cell takes `(θ_up − θ)` times what flows in, in
    /// sub-steps from `fastest`, `u`'s fastest crossing.
    /// The faces' cells read face 0's lengths and inverse areas (the same on every face,
    /// [`super::face_geometry`]), the rim the grid's lengths and its own inverse areas.
    fn advect_temperature(
        &mut self,
        (u, fastest): (&[f64], f64),
        (before, x_u): (&mut Vec<f64>, &mut Vec<f64>),
        dt_s: f64,
    ) {
        let courant = fastest * dt_s / self.params.radius_m;
        if courant == 0.0 {
            return;
        }
        let substeps = (courant / MAX_INFLOW_FRACTION)
            .ceil()
            .clamp(1.0, f64::from(MAX_SUBSTEPS)) as u32;
        let scale = dt_s / (self.params.radius_m * f64::from(substeps));
        let (sides, ea) = (&self.sides, self.grid.edge_arrays());
        let fg = self.grid.face_geometry();
        // The x-edges' speeds one a cell, so that a face's read as slices (the lengths
        // are so already, `FaceGeometry::x_length`).
        spread_x_volumes(sides, u, x_u);
        let x_u = &x_u[..];
        for _ in 0..substeps {
            // Every cell is written below from `before`: the two buffers trade places
            // where the temperature was copied.
            before.resize(self.temperature_k.len(), 0.0);
            std::mem::swap(before, &mut self.temperature_k);
            let (theta, before) = (&mut self.temperature_k, &*before);
            // Each cell gathers what flows in over its four sides (the edges scattered
            // into their downwind cells before: the same terms, summed cell by cell).
            with_avx2(
                #[inline(always)]
                || {
                    // A face at a time ([`CellSpan`]); its rim cells are redone below.
                    for span in sides.face_spans() {
                        let len = span.len;
                        let u = span_sides(sides, &span, x_u, u);
                        let l = span_sides_on_face(&span, &fg.x_length, &fg.length.face);
                        let across: [&[f64]; 4] =
                            std::array::from_fn(|k| &before[span.neighbours(k)]);
                        let own = &before[span.cells()];
                        let pa = span.on_face(&fg.inverse_area_per_sr);
                        let out = &mut theta[span.cells()];
                        for i in 0..len {
                            let sides = Inflow {
                                u: u.map(|u| u[i]),
                                length: l.map(|l| l[i]),
                                inflow: INFLOW,
                            };
                            let across = across.map(|a| a[i]);
                            out[i] = own[i] + sides.warming(scale * pa[i], across, own[i]);
                        }
                    }
                    let rim = sides.rim();
                    for (i, &c) in rim.cells.iter().enumerate() {
                        let c = c as usize;
                        let inflow = Inflow {
                            u: rim.at_edges(i, u),
                            length: rim.at_edges(i, &ea.length),
                            inflow: rim.inflow(i),
                        };
                        let across = rim.at_neighbours(i, before);
                        let per_area = rim.inverse_area[i];
                        theta[c] = before[c] + inflow.warming(scale * per_area, across, before[c]);
                    }
                },
            );
        }
    }

    /// `u += dt·2(dσ/dθ)∇θ/(ρh)` on every edge: the thermal Marangoni stress, with the
    /// film's gradient ([`FilmGradient`]: with the normal one the surfactant's gradient
    /// can hold it; `at_vertex` is scratch).
    pub(super) fn thermal_stress(&mut self, dt_s: f64, at_vertex: &mut Vec<f64>) {
        if self.temperature_k.is_empty() {
            return;
        }
        let p = &self.params;
        let per = 2.0 * p.thermal.tension_per_kelvin_n_per_m_k * dt_s
            / (p.density_kg_per_m3 * p.radius_m);
        let g = &self.grid;
        let (ea, fg) = (g.edge_arrays(), g.face_geometry());
        let (theta, h) = (&self.temperature_k, &self.h_m);
        match p.gradient {
            FilmGradient::TwoPoint => {
                let (sides, u) = (&self.sides, &mut self.u_m_per_s);
                sides.for_each_edge_run(
                    #[inline(always)]
                    |run| {
                        let len = run.len;
                        let ((ta, tb), (ha, hb)) = (run.ends(theta), run.ends(h));
                        let (ta, tb, ha, hb) = (&ta[..len], &tb[..len], &ha[..len], &hb[..len]);
                        let id = &run.constant(&fg.inverse_dual_length)[..len];
                        let u = run.along_mut(u);
                        for i in 0..len {
                            u[i] += push(per, [ta[i], tb[i]], [ha[i], hb[i]], id[i]);
                        }
                    },
                );
                // The seams one by one (the thermal film's own pass, not worth gathering).
                let seams = sides.seams();
                let id = seams.constant(&fg.inverse_dual_length);
                let u = seams.values_mut(u);
                for (i, u) in u.iter_mut().enumerate() {
                    let (t, h) = (seams.ends(i, theta), seams.ends(i, h));
                    *u += push(per, t, h, id[i]);
                }
            }
            FilmGradient::Normal => {
                g.cells_to_vertices(theta, at_vertex);
                let edges = self.u_m_per_s.iter_mut().zip(&ea.cells).enumerate();
                for (e, (u, [a, b])) in edges {
                    let (a, b) = (*a as usize, *b as usize);
                    let h_edge = (0.5 * (h[a] + h[b])).max(H_FLOOR_M);
                    *u += per * g.normal_gradient(e, theta, at_vertex) / h_edge;
                }
            }
        }
    }
}

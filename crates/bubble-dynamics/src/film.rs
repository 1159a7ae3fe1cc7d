//! Film transport along the mesh: gravity drainage (lubrication theory), seeded swirling
//! (seed 001's "sloshing"), evaporation. Mass moves along edges with antisymmetric
//! fluxes, so drainage and sloshing conserve film mass exactly and momentum with it.

use std::f64::consts::TAU;

use glam::DVec3;

use crate::bubble::{Bubble, Scratch};
use crate::params::BubbleParams;
use crate::rng::SplitMix64;
use crate::topology::Edge;

/// Number of travelling waves in the swirl stream function.
const SLOSH_WAVES: usize = 6;
/// Largest fraction of a vertex's film that may leave it in one step (keeps masses
/// positive and the upwind scheme monotone).
const MAX_OUTFLOW_FRACTION: f64 = 0.5;

/// A seeded stream function ψ on the film, fixed to material points (face centroids of
/// the rest mesh) so the swirl pattern rides with the surface; its flow n × ∇ψ is
/// divergence-free, so on a uniform film it moves nothing and on a patterned one it
/// stirs the pattern.
#[derive(Clone, Debug)]
pub(crate) struct Slosh {
    omega_per_s: [f64; SLOSH_WAVES],
    /// Per face and wave: amplitude × (sin θ, cos θ) of the material phase θ, m²/s.
    basis: Vec<[[f64; 2]; SLOSH_WAVES]>,
}

impl Slosh {
    pub(crate) fn new(
        params: &BubbleParams,
        triangles: &[[u32; 3]],
        unit_positions: &[DVec3],
    ) -> Self {
        let mut rng = SplitMix64::new(params.seed ^ 0x51_05_11);
        let omega_0 = TAU / params.slosh_period_s;
        let mut omega_per_s = [0.0; SLOSH_WAVES];
        // A wave sin(κ d·u) has RMS surface-gradient κ/(R√3); equal shares of the
        // requested RMS speed U give amplitudes U R √(3/K)/κ.
        let waves: Vec<(DVec3, f64, f64, f64)> = (0..SLOSH_WAVES)
            .map(|k| {
                let direction = rng.unit_vector();
                let wavenumber = rng.range(1.5, 4.0);
                let phase = rng.range(0.0, TAU);
                omega_per_s[k] =
                    omega_0 * rng.range(0.5, 1.5) * if rng.next_f64() < 0.5 { -1.0 } else { 1.0 };
                let amplitude = params.slosh_speed_m_per_s
                    * params.radius_m
                    * (3.0 / SLOSH_WAVES as f64).sqrt()
                    / wavenumber;
                (direction, wavenumber, phase, amplitude)
            })
            .collect();
        let basis = triangles
            .iter()
            .map(|t| {
                let u = t
                    .iter()
                    .map(|&i| unit_positions[i as usize])
                    .sum::<DVec3>()
                    .normalize();
                std::array::from_fn(|k| {
                    let (d, kappa, phase, amp) = waves[k];
                    let (s, c) = (kappa * d.dot(u) + phase).sin_cos();
                    [amp * s, amp * c]
                })
            })
            .collect();
        Self { omega_per_s, basis }
    }

    /// ψ at every face at time `t_s` into `out`, m²/s: Σ_k a_k sin(θ_fk + ω_k t).
    fn stream_m2_per_s(&self, t_s: f64, out: &mut Vec<f64>) {
        let rot: [(f64, f64); SLOSH_WAVES] =
            std::array::from_fn(|k| (self.omega_per_s[k] * t_s).sin_cos());
        out.clear();
        out.extend(self.basis.iter().map(|waves| {
            waves
                .iter()
                .zip(&rot)
                .map(|(b, (s, c))| b[0] * c + b[1] * s)
                .sum::<f64>()
        }));
    }
}

impl Bubble {
    /// Moves film mass for one step of `dt_s` under effective gravity `g_eff` (gravity
    /// minus the bubble's acceleration) and the swirl at time `t_s`, evaporates, and
    /// refreshes the thickness.
    pub(crate) fn transport_film(&mut self, g_eff: DVec3, dt_s: f64, t_s: f64) {
        // The work buffers live in the bubble; take them so the bubble can be borrowed.
        let mut s = std::mem::take(&mut self.scratch);
        film_geometry_into(
            &self.positions_m,
            self.topology.triangles(),
            &mut s.vertex_area_m2,
            &mut s.corner_cot2,
        );
        let rho = self.film.density_kg_per_m3;
        s.film_thickness_m.clear();
        s.film_thickness_m.extend(
            self.film_mass_kg
                .iter()
                .zip(&s.vertex_area_m2)
                .map(|(m, a)| if *a > 0.0 { m / (rho * a) } else { 0.0 }),
        );
        let swirl = self.slosh.as_ref().map(|slosh| {
            slosh.stream_m2_per_s(t_s, &mut s.stream_m2_per_s);
            &s.stream_m2_per_s[..]
        });
        let mut flux = std::mem::take(&mut s.flux_kg_per_s);
        self.edge_fluxes_kg_per_s(g_eff, swirl, &s.film_thickness_m, &s.corner_cot2, &mut flux);
        s.flux_kg_per_s = flux;
        self.apply_fluxes(&mut s, dt_s);
        if self.evaporate(&s.vertex_area_m2, dt_s) {
            self.refresh_inertial_mass();
        }
        self.update_thickness_with_areas(&s.vertex_area_m2);
        self.scratch = s;
    }

    /// Signed mass flux along every edge into `out`, kg/s, positive from `vertices[0]`
    /// to `vertices[1]`.
    ///
    /// Drainage: q = ρ g_t h³/(3μ) per unit width (a film draining under gravity with
    /// lubrication theory), upwind thickness, through the dual-cell boundary across the
    /// edge. Per face, g_t is the projection of g on the face plane (the gradient of the
    /// linear function g·x), and its flux through the barycentric dual boundary is
    /// g·(x_j − x_i)·cot(opposite angle)/2: the cotangent weights, exact for any
    /// triangle shape. (A width of 2(A_left + A_right)/(3|e|) along the edge is exact
    /// only for equilateral triangles and drained 7 % too fast on the level-3 icosphere.)
    /// Swirl: film volume ψ_left − ψ_right per unit time across the dual edge (`swirl`
    /// holds ψ per face), upwind thickness.
    fn edge_fluxes_kg_per_s(
        &self,
        g_eff: DVec3,
        swirl: Option<&[f64]>,
        h: &[f64],
        corner_cot2: &[f64],
        out: &mut Vec<f64>,
    ) {
        let n = self.positions_m.len();
        let (x, h) = (&self.positions_m[..n], &h[..n]);
        let rho = self.film.density_kg_per_m3;
        // ρ·ρ h³/(3μ) times g·e·(cot α + cot β)/2, with 2 cot per corner at hand.
        let mobility = rho * rho / (12.0 * self.film.drainage_viscosity_pa_s);
        let edges = self.topology.edges();
        out.clear();
        out.extend(
            edges
                .iter()
                .zip(self.topology.opposite_corners())
                .map(|(e, corners)| {
                    let [i, j] = e.vertices.map(|v| v as usize);
                    // One check here lets the compiler drop the six at the accesses below.
                    assert!(i < n && j < n, "edge {:?} beyond {n} vertices", e.vertices);
                    let [ca, cb] = corners.map(|c| c as usize);
                    // The sign of a flux is as good as random: select the index, not the branch.
                    let upwind = |q: f64| h[if q > 0.0 { i } else { j }];
                    let g_dot_e = g_eff.dot(x[j] - x[i]);
                    let hu = upwind(g_dot_e);
                    let cot_sum = corner_cot2[ca] + corner_cot2[cb];
                    let mut q = mobility * g_dot_e * cot_sum * (hu * hu * hu);
                    if let Some(psi) = swirl {
                        let [fa, fb] = e.faces.map(|f| f as usize);
                        let volume_rate = psi[fa] - psi[fb];
                        q += rho * volume_rate * upwind(volume_rate);
                    }
                    q
                }),
        );
    }

    /// Moves `flux·dt` along the edges, each donor limited so it keeps at least half its
    /// film; the moved mass carries the donor's velocity (momentum is conserved).
    fn apply_fluxes(&mut self, s: &mut Scratch, dt_s: f64) {
        let edges = self.topology.edges();
        let n = self.film_mass_kg.len();
        let flux = &s.flux_kg_per_s;
        // Outflow per donor, then turned in place into the donor's limiting factor.
        let limit = &mut s.outflow_kg;
        limit.clear();
        limit.resize(n, 0.0);
        for (e, q) in edges.iter().zip(flux) {
            let (donor, _) = donor_and_receiver(e, *q, n);
            limit[donor] += q.abs() * dt_s;
        }
        for (l, m) in limit.iter_mut().zip(&self.film_mass_kg) {
            let out = *l;
            *l = if out > MAX_OUTFLOW_FRACTION * m {
                MAX_OUTFLOW_FRACTION * m / out
            } else {
                1.0
            };
        }
        let momentum = &mut s.momentum_kg_m_per_s;
        momentum.clear();
        momentum.extend(
            self.velocities_m_per_s
                .iter()
                .zip(&self.inertial_mass_kg)
                .map(|(v, m)| *v * *m),
        );
        let (mass, velocity) = (&mut self.film_mass_kg[..n], &self.velocities_m_per_s[..n]);
        let (limit, momentum) = (&limit[..n], &mut momentum[..n]);
        for (e, q) in edges.iter().zip(flux) {
            let (donor, receiver) = donor_and_receiver(e, *q, n);
            let dm = q.abs() * dt_s * limit[donor];
            mass[donor] -= dm;
            mass[receiver] += dm;
            let dp = velocity[donor] * dm;
            momentum[donor] -= dp;
            momentum[receiver] += dp;
        }
        self.refresh_inertial_mass();
        for ((v, p), m) in self
            .velocities_m_per_s
            .iter_mut()
            .zip(momentum.iter())
            .zip(&self.inertial_mass_kg)
        {
            *v = *p / *m;
        }
    }

    /// Removes ρ·rate·area·dt of film per vertex (vapour leaves with the film's velocity);
    /// false when the film does not evaporate and no mass changed.
    fn evaporate(&mut self, areas: &[f64], dt_s: f64) -> bool {
        let rate = self.film.evaporation_nm_per_s * 1e-9 * self.film.density_kg_per_m3;
        if rate == 0.0 {
            return false;
        }
        for (m, a) in self.film_mass_kg.iter_mut().zip(areas) {
            *m = (*m - rate * a * dt_s).max(0.0);
        }
        true
    }
}

/// The donor and the receiver of flux `q` along edge `e` (from `vertices[0]` when
/// positive), both checked to be below `n` once so the caller's indexing needs no checks.
#[inline]
fn donor_and_receiver(e: &Edge, q: f64, n: usize) -> (usize, usize) {
    let forward = usize::from(q <= 0.0);
    let (donor, receiver) = (
        e.vertices[forward] as usize,
        e.vertices[1 - forward] as usize,
    );
    assert!(
        (donor < n) & (receiver < n),
        "edge {:?} beyond {n} vertices",
        e.vertices
    );
    (donor, receiver)
}

/// One pass over the triangles: the barycentric vertex areas (a third of each face's
/// area to each corner) into `vertex_areas`, and twice the
/// cotangent of every corner (u·v/A for the corner's edge vectors u, v) into
/// `corner_cot2` at `3·face + slot`, for the drainage's cotangent weights.
///
/// Each value is computed exactly as the separate passes did (the dot products of
/// negated edge vectors are negated exactly), so the fusion changes no bit.
fn film_geometry_into(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    vertex_areas: &mut Vec<f64>,
    corner_cot2: &mut Vec<f64>,
) {
    let n = positions.len();
    vertex_areas.clear();
    vertex_areas.resize(n, 0.0);
    corner_cot2.clear();
    for t in triangles {
        let [ia, ib, ic] = t.map(|i| i as usize);
        // One check here (`&`, not `&&`: a single branch) drops the six at the accesses below.
        assert!(
            (ia < n) & (ib < n) & (ic < n),
            "triangle {t:?} beyond {n} vertices"
        );
        let (a, b, c) = (positions[ia], positions[ib], positions[ic]);
        let (ab, ac, bc) = (b - a, c - a, c - b);
        let area = 0.5 * ab.cross(ac).length();
        let third = area / 3.0;
        for i in [ia, ib, ic] {
            vertex_areas[i] += third;
        }
        // At b the edge vectors are a − b = −ab and bc; at c, −ac and −bc.
        corner_cot2.extend([ab.dot(ac) / area, -ab.dot(bc) / area, ac.dot(bc) / area]);
    }
}

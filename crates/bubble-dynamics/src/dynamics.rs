//! Forces (seed 000 eq. 1) and the velocity/position update of one substep.
//!
//! m_i ẍ_i = −T ∂A/∂x_i + Δp ∂V/∂x_i + m_i g + F_buoyancy + F_drag − γ m_i ẋ_i, with the
//! film tension T = 2σ + E(A_f/A_f⁰ − 1) per triangle and Δp from the isothermal gas.

use glam::{DMat3, DVec3};

use crate::bubble::Bubble;
use crate::params::{Integrator, WorldParams};
use crate::wind::WindField;

/// What one substep of one bubble needs from the world.
pub(crate) struct Substep<'a> {
    pub(crate) params: &'a WorldParams,
    pub(crate) wind: &'a WindField,
    pub(crate) dt_s: f64,
    pub(crate) t_s: f64,
}

impl Bubble {
    /// Advances velocities and positions by one substep (collisions come after).
    pub(crate) fn integrate(&mut self, ctx: &Substep<'_>) {
        self.prepare_scratch();
        self.sample_wind(ctx);
        let p_in_pa = self.accumulate_forces(ctx.params);
        match ctx.params.integrator {
            Integrator::SymplecticEuler => {
                self.symplectic_velocities(ctx.dt_s, p_in_pa);
                self.damp_deformation(ctx.dt_s);
                for (x, v) in self.positions_m.iter_mut().zip(&self.velocities_m_per_s) {
                    *x += *v * ctx.dt_s;
                }
            }
            Integrator::ExplicitEuler => {
                self.explicit_step(ctx.dt_s, p_in_pa);
                self.damp_deformation(ctx.dt_s);
            }
        }
    }

    fn prepare_scratch(&mut self) {
        let n = self.positions_m.len();
        let s = &mut self.scratch;
        for buf in [
            &mut s.force_n,
            &mut s.volume_gradient_m2,
            &mut s.wind_m_per_s,
            &mut s.solve,
        ] {
            buf.clear();
            buf.resize(n, DVec3::ZERO);
        }
        s.drag_n_s_per_m.clear();
        s.drag_n_s_per_m.resize(n, 0.0);
    }

    fn sample_wind(&mut self, ctx: &Substep<'_>) {
        if ctx.wind.is_still() {
            return;
        }
        // Gusts are metres across, a bubble centimetres: a first-order expansion about the
        // centre is exact to (R/L)², and saves trigonometry at every vertex.
        let c = self.center_m();
        let (w0, jacobian) = ctx.wind.smooth_part(c, ctx.t_s);
        let user = ctx.wind.user_field();
        for (w, x) in self.scratch.wind_m_per_s.iter_mut().zip(&self.positions_m) {
            *w = w0 + jacobian * (*x - c) + user.map_or(DVec3::ZERO, |f| f(*x, ctx.t_s));
        }
    }

    /// Fills the explicit forces, the volume gradient and the drag coefficients; updates
    /// the volume; returns the gas pressure.
    fn accumulate_forces(&mut self, params: &WorldParams) -> f64 {
        let o = self.positions_m.iter().copied().sum::<DVec3>() / self.positions_m.len() as f64;
        let drag = DragModel::new(params, self.rest_radius_m);
        // Air density outside minus gas density inside: the hydrostatic pressure gradients
        // carry both the air's buoyancy and the gas's weight to the film, along normals.
        let hydro = if params.buoyancy {
            params.air_density_kg_per_m3 - self.gas_mass_kg / self.volume_m3
        } else {
            0.0
        };
        let tension_0 = 2.0 * self.film.sigma_n_per_m;
        let elasticity = self.film.gibbs_elasticity_n_per_m;
        let s = &mut self.scratch;
        for (t, inv_rest_area) in self
            .topology
            .triangles()
            .iter()
            .zip(&self.inv_rest_face_area)
        {
            let [ia, ib, ic] = t.map(|i| i as usize);
            let (a, b, c) = (
                self.positions_m[ia],
                self.positions_m[ib],
                self.positions_m[ic],
            );
            let n2 = (b - a).cross(c - a);
            let share = n2 * (1.0 / 6.0);
            s.volume_gradient_m2[ia] += share;
            s.volume_gradient_m2[ib] += share;
            s.volume_gradient_m2[ic] += share;
            let len = n2.length();
            if len == 0.0 {
                continue;
            }
            // −T ∂A/∂x with ∂A/∂a = ½ n̂ × (c − b) = n2 × (c − b) / (2|n2|), cyclically.
            let area = 0.5 * len;
            let tension = tension_0 + elasticity * (area * inv_rest_area - 1.0);
            let coef = 0.5 * tension / len;
            s.force_n[ia] -= coef * n2.cross(c - b);
            s.force_n[ib] -= coef * n2.cross(a - c);
            s.force_n[ic] -= coef * n2.cross(b - a);
            if hydro != 0.0 {
                // Pressures vary with height as ρ g·x outside and inside: the net push
                // −(ρ_air − ρ_gas)(g·(x̄ − o)) A n̂ per face sums to exactly
                // (ρ_gas − ρ_air) V g (divergence theorem on the polyhedron).
                let depth = params.gravity_m_per_s2.dot((a + b + c) * (1.0 / 3.0) - o);
                let f = share * (-hydro * depth);
                s.force_n[ia] += f;
                s.force_n[ib] += f;
                s.force_n[ic] += f;
            }
            if drag.active {
                let v = &self.velocities_m_per_s;
                let w = &s.wind_m_per_s;
                let v_face = ((v[ia] + v[ib] + v[ic]) - (w[ia] + w[ib] + w[ic])) * (1.0 / 3.0);
                let (force, stiffness) = drag.face_force(n2, v_face);
                for i in [ia, ib, ic] {
                    s.force_n[i] += force;
                    s.drag_n_s_per_m[i] += stiffness;
                }
            }
        }
        // Euler's theorem for the degree-3 homogeneous volume: Σ (x_i − o)·∂V/∂x_i = 3V.
        let three_volume: f64 = self
            .positions_m
            .iter()
            .zip(&s.volume_gradient_m2)
            .map(|(x, g)| (*x - o).dot(*g))
            .sum();
        self.volume_m3 = three_volume / 3.0;
        self.add_gravity(params);
        self.gas_pv_j / self.volume_m3
    }

    /// The film's own weight, a body force. The gas's weight is not here: it reaches the
    /// film as the hydrostatic pressure gradient above (pulling the gas share of each
    /// vertex down would shear the film along its own plane).
    fn add_gravity(&mut self, params: &WorldParams) {
        for (f, m) in self.scratch.force_n.iter_mut().zip(&self.film_mass_kg) {
            *f += params.gravity_m_per_s2 * *m;
        }
    }

    /// Velocity update with the gas mode and the damping implicit, and the drag
    /// stabilised: (D + dt²(p/V) g gᵀ) v⁺ = M v + dt (F + Δp g + k v), D = M + dt(k + γM),
    /// solved in O(n) by Sherman–Morrison because the gas stiffness (p/V) g gᵀ has rank
    /// one. F holds the drag at the current velocity and k ≥ ‖∂F_drag/∂v‖ per vertex, so
    /// the drag part is a contraction at any dt and exact at steady state.
    fn symplectic_velocities(&mut self, dt: f64, p_in_pa: f64) {
        let dp = p_in_pa - self.p_out_pa;
        let beta = dt * dt * p_in_pa / self.volume_m3;
        let gamma = self.film.damping_per_s;
        let s = &mut self.scratch;
        let (mut gu, mut gz) = (0.0, 0.0);
        for i in 0..self.positions_m.len() {
            let m = self.inertial_mass_kg[i];
            let k = s.drag_n_s_per_m[i];
            let d = m + dt * (k + gamma * m);
            let g = s.volume_gradient_m2[i];
            let v = self.velocities_m_per_s[i];
            let u = (v * m + (s.force_n[i] + g * dp + v * k) * dt) / d;
            let z = g / d;
            gu += g.dot(u);
            gz += g.dot(z);
            self.velocities_m_per_s[i] = u;
            s.solve[i] = z;
        }
        let correction = beta * gu / (1.0 + beta * gz);
        for (v, z) in self.velocities_m_per_s.iter_mut().zip(&s.solve) {
            *v -= *z * correction;
        }
    }

    /// Seed 000: x⁺ = x + dt v, v⁺ = v + dt a(x, v), everything explicit.
    fn explicit_step(&mut self, dt: f64, p_in_pa: f64) {
        let dp = p_in_pa - self.p_out_pa;
        let gamma = self.film.damping_per_s;
        let s = &self.scratch;
        for i in 0..self.positions_m.len() {
            let m = self.inertial_mass_kg[i];
            let v = self.velocities_m_per_s[i];
            let f = s.force_n[i] + s.volume_gradient_m2[i] * dp - v * (gamma * m);
            self.positions_m[i] += v * dt;
            self.velocities_m_per_s[i] = v + f * (dt / m);
        }
    }

    /// Exact exponential decay of the velocity relative to the best-fit rigid motion
    /// (v_cm + ω × r): damps wobble, conserves linear and angular momentum.
    fn damp_deformation(&mut self, dt: f64) {
        let rate = self.film.deformation_damping_per_s;
        if rate == 0.0 {
            return;
        }
        let keep = (-rate * dt).exp();
        let (com, v_cm, omega) = self.rigid_motion();
        for (v, x) in self.velocities_m_per_s.iter_mut().zip(&self.positions_m) {
            let rigid = v_cm + omega.cross(*x - com);
            *v = rigid + (*v - rigid) * keep;
        }
    }

    /// Centre of mass, its velocity, and the angular velocity I⁻¹L about it.
    pub(crate) fn rigid_motion(&self) -> (DVec3, DVec3, DVec3) {
        let (mut mass, mut first, mut momentum) = (0.0, DVec3::ZERO, DVec3::ZERO);
        for ((x, v), m) in self
            .positions_m
            .iter()
            .zip(&self.velocities_m_per_s)
            .zip(&self.inertial_mass_kg)
        {
            mass += m;
            first += *x * *m;
            momentum += *v * *m;
        }
        let (com, v_cm) = (first / mass, momentum / mass);
        let mut l = DVec3::ZERO;
        let mut second = DMat3::ZERO;
        for ((x, v), m) in self
            .positions_m
            .iter()
            .zip(&self.velocities_m_per_s)
            .zip(&self.inertial_mass_kg)
        {
            let r = *x - com;
            l += r.cross(*v) * *m;
            second += outer(r, r * *m);
        }
        // I = tr(S)·1 − S for the second moment S = Σ m r rᵀ.
        let trace = second.col(0).x + second.col(1).y + second.col(2).z;
        let inertia = DMat3::from_diagonal(DVec3::splat(trace)) - second;
        let omega = if inertia.determinant() > 0.0 {
            inertia.inverse() * l
        } else {
            DVec3::ZERO
        };
        (com, v_cm, omega)
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Air drag as a pressure on the leading faces (n̂·v > 0, v relative to the wind):
/// p = c_lin·(n̂·v) + c_quad·(n̂·v)², acting along −n̂ (Newtonian impact theory). Over a
/// sphere ∫cos²θ dA = 2πR²/3 and ∫cos³θ dA = πR²/2, so c_lin = 9μf/R and c_quad = ρC_d
/// give exactly Stokes' 6πμRv·f plus the form drag ½ρC_d πR²|v|v. Pressure acts along
/// the normal only: no tangential (skin-friction) stress shears the film in its plane.
struct DragModel {
    active: bool,
    linear_pa_s_per_m: f64,
    quadratic_kg_per_m3: f64,
}

impl DragModel {
    fn new(params: &WorldParams, radius_m: f64) -> Self {
        let linear = 9.0 * params.air_viscosity_pa_s * params.linear_drag_factor / radius_m;
        let quadratic = params.air_density_kg_per_m3 * params.drag_coefficient;
        Self {
            active: linear > 0.0 || quadratic > 0.0,
            linear_pa_s_per_m: linear,
            quadratic_kg_per_m3: quadratic,
        }
    }

    /// Each corner's share of the drag force (N) on a face with double-area vector `n2`
    /// (= 2A n̂) moving at `v_rel`, and a bound (N·s/m) on that share's derivative with
    /// respect to a corner's velocity.
    fn face_force(&self, n2: DVec3, v_rel: DVec3) -> (DVec3, f64) {
        let lead2 = n2.dot(v_rel);
        if lead2 <= 0.0 {
            return (DVec3::ZERO, 0.0);
        }
        let inv_len = 1.0 / n2.length();
        let normal_speed = lead2 * inv_len;
        let pressure =
            (self.linear_pa_s_per_m + self.quadratic_kg_per_m3 * normal_speed) * normal_speed;
        // Force −p·A·n̂ = −p·n2/2, a third per corner.
        let force = n2 * (-pressure / 6.0);
        let stiffness = (self.linear_pa_s_per_m + 2.0 * self.quadratic_kg_per_m3 * normal_speed)
            / (6.0 * inv_len);
        (force, stiffness)
    }
}

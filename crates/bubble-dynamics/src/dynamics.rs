//! Forces (seed 000 eq. 1) and the velocity/position update of one substep.
//!
//! m_i ẍ_i = −T ∂A/∂x_i + Δp ∂V/∂x_i + m_i g + F_buoyancy + F_drag − γ m_i ẋ_i, with the
//! film tension T = 2σ + E(A_f/A_f⁰ − 1) per triangle and Δp from the isothermal gas.
//!
//! A substep is two halves: [`Bubble::accumulate_forces`] (one pass over the triangles
//! that yields every per-vertex sum the update needs, and on a step's first substep the
//! stiffness bound that sets the substep count) and [`Bubble::advance`] (three passes
//! over the vertices: implicit solve, rigid-motion fit, damping and positions).

use glam::{DMat3, DVec3};

use crate::bubble::{Bubble, VertexSums};
use crate::params::{Integrator, WorldParams};
use crate::wind::WindField;

impl Bubble {
    /// Samples the wind and fills the per-vertex force, volume-gradient and drag sums at
    /// the current state and time `t_s`. With `STIFFNESS` also returns an upper bound on
    /// the angular frequency of the explicit (film) forces, rad/s; else 0.
    ///
    /// The bound: row sums of the tension/elasticity Hessian (Gershgorin). Each triangle
    /// contributes at most (|T| + E)·Σ|e|²/(4A) to the stiffness of each corner, divided
    /// by the corner's mass. The gas mode is implicit and does not appear.
    pub(crate) fn accumulate_forces<const STIFFNESS: bool>(
        &mut self,
        params: &WorldParams,
        wind: &WindField,
        t_s: f64,
    ) -> f64 {
        let n = self.positions_m.len();
        let s = &mut self.scratch;
        s.sums.clear();
        s.sums.resize(n, VertexSums::default());
        let still = wind.is_still();
        if !still {
            self.sample_relative_velocity(wind, t_s);
        }
        let o = self.positions_m.iter().copied().sum::<DVec3>() / n as f64;
        // Air density outside minus gas density inside: the hydrostatic pressure gradients
        // carry both the air's buoyancy and the gas's weight to the film, along normals.
        let hydro = if params.buoyancy {
            params.air_density_kg_per_m3 - self.gas_mass_kg / self.volume_m3
        } else {
            0.0
        };
        let faces = FaceForces {
            tension_0: 2.0 * self.film.sigma_n_per_m,
            elasticity: self.film.gibbs_elasticity_n_per_m,
            hydro_g: params.gravity_m_per_s2 * -hydro,
            origin: o,
            drag: DragModel::new(params, self.rest_radius_m),
        };
        let relative = if still {
            &self.velocities_m_per_s
        } else {
            &self.scratch.relative_velocity_m_per_s
        };
        let mesh = (&self.positions_m[..], self.topology.triangles());
        let (rest, sums) = (&self.inv_rest_face_area[..], &mut self.scratch.sums[..]);
        // The drag switch picks a loop, so the loop body carries no branch for it.
        let six_volume = if faces.drag.active {
            faces.accumulate::<STIFFNESS, true>(mesh, relative, rest, sums)
        } else {
            faces.accumulate::<STIFFNESS, false>(mesh, relative, rest, sums)
        };
        self.scratch.volume_m3 = six_volume / 6.0;
        if STIFFNESS {
            self.frequency_from_stiffness()
        } else {
            0.0
        }
    }

    /// Vertex velocities relative to the air. Gusts are metres across, a bubble
    /// centimetres: a first-order expansion about the centre is exact to (R/L)², and
    /// saves trigonometry at every vertex.
    fn sample_relative_velocity(&mut self, wind: &WindField, t_s: f64) {
        let c = self.center_m();
        let (w0, jacobian) = wind.smooth_part(c, t_s);
        let user = wind.user_field();
        let out = &mut self.scratch.relative_velocity_m_per_s;
        out.clear();
        out.extend(
            self.positions_m
                .iter()
                .zip(&self.velocities_m_per_s)
                .map(|(x, v)| {
                    let w = w0 + jacobian * (*x - c) + user.map_or(DVec3::ZERO, |f| f(*x, t_s));
                    *v - w
                }),
        );
    }

    /// ω_max from the per-vertex stiffness row sums: max_i √(k_i / m_i); infinite when a
    /// row sum is not finite (a degenerate triangle), so the substep count reports it.
    fn frequency_from_stiffness(&self) -> f64 {
        let mut worst = 0.0_f64;
        let mut finite = true;
        for (s, m) in self.scratch.sums.iter().zip(&self.inertial_mass_kg) {
            finite &= s.stiffness_n_per_m.is_finite();
            worst = worst.max(s.stiffness_n_per_m / m);
        }
        if finite { worst.sqrt() } else { f64::INFINITY }
    }

    /// Advances velocities and positions by `dt_s` with the sums of the last
    /// [`Bubble::accumulate_forces`] (collisions come after).
    pub(crate) fn advance(&mut self, params: &WorldParams, dt_s: f64) {
        self.volume_m3 = self.scratch.volume_m3;
        let p_in_pa = self.gas_pv_j / self.volume_m3;
        match params.integrator {
            Integrator::SymplecticEuler => self.symplectic_step(params, dt_s, p_in_pa),
            Integrator::ExplicitEuler => {
                self.explicit_step(params, dt_s, p_in_pa);
                self.damp_deformation(dt_s);
            }
        }
    }

    /// Velocity update with the gas mode and the damping implicit, and the drag
    /// stabilised: (D + dt²(p/V) g gᵀ) v⁺ = M v + dt (F + Δp g + k v), D = M + dt(k + γM),
    /// solved in O(n) by Sherman–Morrison because the gas stiffness (p/V) g gᵀ has rank
    /// one. F holds the drag at the current velocity and k ≥ ‖∂F_drag/∂v‖ per vertex, so
    /// the drag part is a contraction at any dt and exact at steady state. Then the
    /// deformation damping and the position update x⁺ = x + dt v⁺.
    fn symplectic_step(&mut self, params: &WorldParams, dt: f64, p_in_pa: f64) {
        let dp = p_in_pa - self.p_out_pa;
        let beta = dt * dt * p_in_pa / self.volume_m3;
        let gamma = self.film.damping_per_s;
        let gravity = params.gravity_m_per_s2;
        let s = &mut self.scratch;
        s.solve.clear();
        s.solve.resize(self.positions_m.len(), DVec3::ZERO);
        let (mut gu, mut gz) = (0.0, 0.0);
        // The mass moments feed the rigid-motion fit of the damping below.
        let (mut mass, mut first) = (0.0, DVec3::ZERO);
        for ((((v, z), sum), x), (&m, &film)) in self
            .velocities_m_per_s
            .iter_mut()
            .zip(&mut s.solve)
            .zip(&s.sums)
            .zip(&self.positions_m)
            .zip(self.inertial_mass_kg.iter().zip(&self.film_mass_kg))
        {
            let k = sum.drag_n_s_per_m;
            let inv_d = 1.0 / (m + dt * (k + gamma * m));
            let g = sum.volume_gradient_m2;
            let force = sum.force_n + gravity * film + g * dp + *v * k;
            let u = (*v * m + force * dt) * inv_d;
            *z = g * inv_d;
            gu += g.dot(u);
            gz += g.dot(*z);
            *v = u;
            mass += m;
            first += *x * m;
        }
        let correction = beta * gu / (1.0 + beta * gz);
        let rate = self.film.deformation_damping_per_s;
        if rate == 0.0 {
            for ((x, v), z) in self
                .positions_m
                .iter_mut()
                .zip(&mut self.velocities_m_per_s)
                .zip(&s.solve)
            {
                *v -= *z * correction;
                *x += *v * dt;
            }
            return;
        }
        let com = first / mass;
        let mut moments = RigidMoments::default();
        for (((x, v), z), &m) in self
            .positions_m
            .iter()
            .zip(&mut self.velocities_m_per_s)
            .zip(&s.solve)
            .zip(&self.inertial_mass_kg)
        {
            *v -= *z * correction;
            moments.add(*x - com, *v, m);
        }
        let (v_cm, omega) = moments.motion(mass);
        damp_and_move(
            &mut self.positions_m,
            &mut self.velocities_m_per_s,
            (com, v_cm, omega),
            (-rate * dt).exp(),
            dt,
        );
    }

    /// Seed 000: x⁺ = x + dt v, v⁺ = v + dt a(x, v), everything explicit.
    fn explicit_step(&mut self, params: &WorldParams, dt: f64, p_in_pa: f64) {
        let dp = p_in_pa - self.p_out_pa;
        let gamma = self.film.damping_per_s;
        for (((x, v), sum), (&m, &film)) in self
            .positions_m
            .iter_mut()
            .zip(&mut self.velocities_m_per_s)
            .zip(&self.scratch.sums)
            .zip(self.inertial_mass_kg.iter().zip(&self.film_mass_kg))
        {
            let f = sum.force_n + params.gravity_m_per_s2 * film + sum.volume_gradient_m2 * dp
                - *v * (gamma * m);
            *x += *v * dt;
            *v += f * (dt / m);
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
        let (mut mass, mut first) = (0.0, DVec3::ZERO);
        for (x, m) in self.positions_m.iter().zip(&self.inertial_mass_kg) {
            mass += m;
            first += *x * *m;
        }
        let com = first / mass;
        let mut moments = RigidMoments::default();
        for ((x, v), &m) in self
            .positions_m
            .iter()
            .zip(&self.velocities_m_per_s)
            .zip(&self.inertial_mass_kg)
        {
            moments.add(*x - com, *v, m);
        }
        let (v_cm, omega) = moments.motion(mass);
        (com, v_cm, omega)
    }
}

/// v ← rigid + (v − rigid)·keep with rigid = v_cm + ω × (x − com), then x ← x + dt v.
fn damp_and_move(
    positions: &mut [DVec3],
    velocities: &mut [DVec3],
    (com, v_cm, omega): (DVec3, DVec3, DVec3),
    keep: f64,
    dt: f64,
) {
    for (x, v) in positions.iter_mut().zip(velocities) {
        let rigid = v_cm + omega.cross(*x - com);
        *v = rigid + (*v - rigid) * keep;
        *x += *v * dt;
    }
}

/// Momentum, angular momentum and the second mass moment about the centre of mass.
#[derive(Default)]
struct RigidMoments {
    momentum: DVec3,
    angular: DVec3,
    /// Σ m r rᵀ: diagonal (xx, yy, zz) and off-diagonal (xy, xz, yz).
    diagonal: DVec3,
    off_diagonal: DVec3,
}

impl RigidMoments {
    #[inline(always)]
    fn add(&mut self, r: DVec3, v: DVec3, m: f64) {
        self.momentum += v * m;
        self.angular += r.cross(v) * m;
        let mr = r * m;
        self.diagonal += mr * r;
        self.off_diagonal += DVec3::new(mr.x * r.y, mr.x * r.z, mr.y * r.z);
    }

    /// Centre-of-mass velocity and the angular velocity I⁻¹L (zero for a degenerate I).
    fn motion(&self, mass: f64) -> (DVec3, DVec3) {
        // I = tr(S)·1 − S for the second moment S = Σ m r rᵀ.
        let (d, o) = (self.diagonal, self.off_diagonal);
        let trace = d.x + d.y + d.z;
        let inertia = DMat3::from_cols(
            DVec3::new(trace - d.x, -o.x, -o.y),
            DVec3::new(-o.x, trace - d.y, -o.z),
            DVec3::new(-o.y, -o.z, trace - d.z),
        );
        let omega = if inertia.determinant() > 0.0 {
            inertia.inverse() * self.angular
        } else {
            DVec3::ZERO
        };
        (self.momentum / mass, omega)
    }
}

/// Everything the triangle pass needs besides the mesh.
struct FaceForces {
    tension_0: f64,
    elasticity: f64,
    /// −(ρ_air − ρ_gas)·g: the hydrostatic pressure per unit height, vector form.
    hydro_g: DVec3,
    origin: DVec3,
    drag: DragModel,
}

/// Faces per block of the triangle pass: a block's per-face values (7 KB) stay in L1.
const BLOCK: usize = 32;

/// Vectors of a block's faces, one array per coordinate, so the per-face arithmetic runs
/// on two (SSE2) or four (AVX2) faces per instruction.
#[derive(Default)]
struct Lanes3 {
    x: [f64; BLOCK],
    y: [f64; BLOCK],
    z: [f64; BLOCK],
}

impl Lanes3 {
    #[inline(always)]
    fn get(&self, k: usize) -> DVec3 {
        DVec3::new(self.x[k], self.y[k], self.z[k])
    }

    #[inline(always)]
    fn set(&mut self, k: usize, v: DVec3) {
        (self.x[k], self.y[k], self.z[k]) = (v.x, v.y, v.z);
    }
}

/// One block of faces: the corners and corner velocities gathered from the mesh, then
/// everything each face adds to its corners' sums.
#[derive(Default)]
struct FaceBlock {
    a: Lanes3,
    b: Lanes3,
    c: Lanes3,
    /// Sum of the corners' velocities relative to the air.
    v_sum: Lanes3,
    /// The force on each corner.
    force_a: Lanes3,
    force_b: Lanes3,
    force_c: Lanes3,
    /// ∂V/∂x of each corner (the same for all three).
    share: Lanes3,
    /// (a − o)·n2: six times the face's tetrahedron from the origin.
    six_volume: [f64; BLOCK],
    /// |n2| = 2A; 0 marks a degenerate face.
    double_area: [f64; BLOCK],
    drag_k: [f64; BLOCK],
    stiffness: [f64; BLOCK],
}

impl FaceForces {
    /// One pass over the triangles: tension, hydrostatics and (with `DRAG`, which must be
    /// `self.drag.active`) drag into the forces, the volume gradient, the drag stiffness
    /// and (with `STIFFNESS`) the Gershgorin row sums of the tension Hessian. Returns six
    /// times the enclosed volume.
    ///
    /// Blocks of faces go through three loops: gather the corners, compute each face on
    /// its own (vectorised across faces), scatter to the corners in face order. Every
    /// value is the same expression as a face-at-a-time loop, summed in the same order.
    fn accumulate<const STIFFNESS: bool, const DRAG: bool>(
        &self,
        mesh: (&[DVec3], &[[u32; 3]]),
        relative_velocities: &[DVec3],
        inv_rest_face_area: &[f64],
        sums: &mut [VertexSums],
    ) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe {
                self.accumulate_avx2::<STIFFNESS, DRAG>(
                    mesh,
                    relative_velocities,
                    inv_rest_face_area,
                    sums,
                )
            };
        }
        self.accumulate_body::<STIFFNESS, DRAG>(mesh, relative_velocities, inv_rest_face_area, sums)
    }

    /// [`FaceForces::accumulate`] with four faces per instruction. AVX2 without FMA:
    /// the same roundings as SSE2, so the same bits on any CPU.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn accumulate_avx2<const STIFFNESS: bool, const DRAG: bool>(
        &self,
        mesh: (&[DVec3], &[[u32; 3]]),
        relative_velocities: &[DVec3],
        inv_rest_face_area: &[f64],
        sums: &mut [VertexSums],
    ) -> f64 {
        self.accumulate_body::<STIFFNESS, DRAG>(mesh, relative_velocities, inv_rest_face_area, sums)
    }

    /// The triangle pass itself, inlined into each of the above.
    #[inline(always)]
    fn accumulate_body<const STIFFNESS: bool, const DRAG: bool>(
        &self,
        (positions, triangles): (&[DVec3], &[[u32; 3]]),
        relative_velocities: &[DVec3],
        inv_rest_face_area: &[f64],
        sums: &mut [VertexSums],
    ) -> f64 {
        let mut six_volume = 0.0;
        let mut block = FaceBlock::default();
        for (faces, inv_rest) in triangles
            .chunks(BLOCK)
            .zip(inv_rest_face_area.chunks(BLOCK))
        {
            block.gather::<DRAG>(positions, relative_velocities, faces);
            self.compute::<STIFFNESS, DRAG>(&mut block, inv_rest);
            six_volume = block.scatter::<STIFFNESS>(faces, sums, six_volume);
        }
        six_volume
    }

    /// Every face's contributions in `block`, for the faces with an `inv_rest` entry.
    #[inline(always)]
    fn compute<const STIFFNESS: bool, const DRAG: bool>(
        &self,
        block: &mut FaceBlock,
        inv_rest: &[f64],
    ) {
        for (k, inv_rest_area) in inv_rest.iter().enumerate().take(BLOCK) {
            let (a, b, c) = (block.a.get(k), block.b.get(k), block.c.get(k));
            let (ab, bc, ca) = (b - a, c - b, a - c);
            // n2 = (b − a) × (c − a) = 2A n̂.
            let n2 = ca.cross(ab);
            // ∂V/∂x = A n̂ / 3 per corner; V = Σ (a − o)·n2 / 6 (tetrahedra from o).
            let share = n2 * (1.0 / 6.0);
            block.six_volume[k] = (a - self.origin).dot(n2);
            let len = n2.length();
            // A degenerate face (len = 0) computes garbage here; the scatter skips it.
            let inv_len = 1.0 / len;
            let tension = self.tension_0 + self.elasticity * (0.5 * len * inv_rest_area - 1.0);
            // −T ∂A/∂x with ∂A/∂a = ½ n̂ × (c − b) = n2 × (c − b) / (2|n2|), cyclically.
            let coef = -0.5 * tension * inv_len;
            // Pressures vary with height as ρ g·x outside and inside: the net push
            // −(ρ_air − ρ_gas)(g·(x̄ − o)) A n̂ per face sums to exactly
            // (ρ_gas − ρ_air) V g (divergence theorem on the polyhedron).
            let centroid = (a + b + c) * (1.0 / 3.0) - self.origin;
            let mut common = share * self.hydro_g.dot(centroid);
            let mut drag_k = 0.0;
            if DRAG {
                let v_face = block.v_sum.get(k) * (1.0 / 3.0);
                let (force, stiffness) = self.drag.face_force(n2, len, inv_len, v_face);
                common += force;
                drag_k = stiffness;
            }
            if STIFFNESS {
                // Gershgorin: (|T| + E)·Σ|e|²/(4A) bounds the row sums of this triangle's
                // tension/elasticity Hessian at each corner.
                let edges2 = ab.length_squared() + bc.length_squared() + ca.length_squared();
                block.stiffness[k] = (tension.abs() + self.elasticity) * edges2 * 0.5 * inv_len;
            }
            block.force_a.set(k, n2.cross(bc) * coef + common);
            block.force_b.set(k, n2.cross(ca) * coef + common);
            block.force_c.set(k, n2.cross(ab) * coef + common);
            block.share.set(k, share);
            block.double_area[k] = len;
            block.drag_k[k] = drag_k;
        }
    }
}

impl FaceBlock {
    /// Loads the corners of `faces` (at most `BLOCK`) and, with `DRAG`, the sums of their
    /// relative velocities.
    #[inline(always)]
    fn gather<const DRAG: bool>(
        &mut self,
        positions: &[DVec3],
        relative_velocities: &[DVec3],
        faces: &[[u32; 3]],
    ) {
        let n = positions.len();
        let relative_velocities = &relative_velocities[..n];
        for (k, t) in faces.iter().enumerate().take(BLOCK) {
            let [ia, ib, ic] = t.map(|i| i as usize);
            // One check here (`&`, not `&&`: a single branch) drops the six at the accesses below.
            assert!(
                (ia < n) & (ib < n) & (ic < n),
                "triangle {t:?} beyond {n} vertices"
            );
            self.a.set(k, positions[ia]);
            self.b.set(k, positions[ib]);
            self.c.set(k, positions[ic]);
            if DRAG {
                self.v_sum.set(
                    k,
                    relative_velocities[ia] + relative_velocities[ib] + relative_velocities[ic],
                );
            }
        }
    }

    /// Adds the block's contributions to the corners of `faces`, face by face; returns
    /// `six_volume` plus the block's tetrahedra.
    #[inline(always)]
    fn scatter<const STIFFNESS: bool>(
        &self,
        faces: &[[u32; 3]],
        sums: &mut [VertexSums],
        mut six_volume: f64,
    ) -> f64 {
        let n = sums.len();
        for (k, t) in faces.iter().enumerate().take(BLOCK) {
            six_volume += self.six_volume[k];
            let [ia, ib, ic] = t.map(|i| i as usize);
            assert!(
                (ia < n) & (ib < n) & (ic < n),
                "triangle {t:?} beyond {n} vertices"
            );
            let share = self.share.get(k);
            if self.double_area[k] == 0.0 {
                // No area gradient exists; the stiffness bound turns infinite and the
                // substep count reports the broken mesh.
                for i in [ia, ib, ic] {
                    sums[i].volume_gradient_m2 += share;
                    if STIFFNESS {
                        sums[i].stiffness_n_per_m = f64::INFINITY;
                    }
                }
                continue;
            }
            let corners = [
                (ia, &self.force_a),
                (ib, &self.force_b),
                (ic, &self.force_c),
            ];
            for (i, force) in corners {
                let sum = &mut sums[i];
                sum.force_n += force.get(k);
                sum.volume_gradient_m2 += share;
                sum.drag_n_s_per_m += self.drag_k[k];
                if STIFFNESS {
                    sum.stiffness_n_per_m += self.stiffness[k];
                }
            }
        }
        six_volume
    }
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
    /// (= 2A n̂, of length `len`) moving at `v_rel`, and a bound (N·s/m) on that share's
    /// derivative with respect to a corner's velocity.
    #[inline]
    fn face_force(&self, n2: DVec3, len: f64, inv_len: f64, v_rel: DVec3) -> (DVec3, f64) {
        let lead2 = n2.dot(v_rel);
        if lead2 <= 0.0 {
            return (DVec3::ZERO, 0.0);
        }
        let normal_speed = lead2 * inv_len;
        let pressure =
            (self.linear_pa_s_per_m + self.quadratic_kg_per_m3 * normal_speed) * normal_speed;
        // Force −p·A·n̂ = −p·n2/2, a third per corner.
        let force = n2 * (pressure * (-1.0 / 6.0));
        let stiffness = (self.linear_pa_s_per_m + 2.0 * self.quadratic_kg_per_m3 * normal_speed)
            * len
            * (1.0 / 6.0);
        (force, stiffness)
    }
}

/// The AVX2 pass against the portable one (only x86-64 has both).
#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::geometry::face_areas_m2;
    use crate::icosphere::equilibrium_icosphere;

    /// Positions, velocities, triangles and inverse rest areas (1/m²) of a mesh.
    type Mesh = (Vec<DVec3>, Vec<DVec3>, Vec<[u32; 3]>, Vec<f64>);

    /// A level-3 icosphere stretched and swirling, and its forces with drag and buoyancy.
    fn wobbling_mesh() -> (Mesh, FaceForces) {
        let mesh = equilibrium_icosphere(3);
        let rest: Vec<DVec3> = mesh.positions.iter().map(|p| *p * 0.05).collect();
        let inv_rest = face_areas_m2(&rest, &mesh.triangles)
            .iter()
            .map(|a| 1.0 / a)
            .collect();
        let positions: Vec<DVec3> = rest
            .iter()
            .enumerate()
            .map(|(i, p)| *p * DVec3::new(1.1, 0.9, 1.0) * (1.0 + 0.01 * (i as f64).sin()))
            .collect();
        let velocities = positions
            .iter()
            .map(|p| DVec3::new(p.y, -p.x, 0.3 * p.z) * 20.0 + DVec3::X * 0.1)
            .collect();
        let faces = FaceForces {
            tension_0: 0.05,
            elasticity: 0.02,
            hydro_g: DVec3::new(0.0, -0.5, 0.0),
            origin: DVec3::new(0.001, -0.002, 0.0),
            drag: DragModel {
                active: true,
                linear_pa_s_per_m: 0.003,
                quadratic_kg_per_m3: 0.56,
            },
        };
        let triangles = mesh.triangles.clone();
        ((positions, velocities, triangles, inv_rest), faces)
    }

    /// Every bit of the sums and the volume after the portable and the AVX2 triangle pass.
    fn both_passes<const STIFFNESS: bool>(positions: &[DVec3]) -> [Vec<u64>; 2] {
        let ((_, velocities, triangles, inv_rest), faces) = wobbling_mesh();
        let run = |avx2: bool| {
            let mut sums = vec![VertexSums::default(); positions.len()];
            let mesh = (positions, &triangles[..]);
            let six_volume = if avx2 {
                // SAFETY: the caller checked that the CPU supports AVX2.
                unsafe {
                    faces.accumulate_avx2::<STIFFNESS, true>(
                        mesh,
                        &velocities,
                        &inv_rest,
                        &mut sums,
                    )
                }
            } else {
                faces.accumulate_body::<STIFFNESS, true>(mesh, &velocities, &inv_rest, &mut sums)
            };
            let mut bits = vec![six_volume.to_bits()];
            for s in &sums {
                let [fx, fy, fz] = s.force_n.to_array();
                let [gx, gy, gz] = s.volume_gradient_m2.to_array();
                bits.extend(
                    [
                        fx,
                        fy,
                        fz,
                        gx,
                        gy,
                        gz,
                        s.drag_n_s_per_m,
                        s.stiffness_n_per_m,
                    ]
                    .map(f64::to_bits),
                );
            }
            bits
        };
        [run(false), run(true)]
    }

    /// The AVX2 triangle pass rounds exactly as the portable one (no FMA), so results do
    /// not depend on the CPU; also with degenerate faces (a corner moved onto another).
    #[test]
    fn triangle_pass_gives_the_same_bits_with_and_without_avx2() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let ((mut positions, _, triangles, _), _) = wobbling_mesh();
        let [portable, avx2] = both_passes::<true>(&positions);
        assert!(portable == avx2, "first substep's pass differs");
        let [portable, avx2] = both_passes::<false>(&positions);
        assert!(portable == avx2, "later substeps' pass differs");
        let [a, b, _] = triangles[0].map(|i| i as usize);
        positions[b] = positions[a];
        let [portable, avx2] = both_passes::<true>(&positions);
        assert!(portable == avx2, "pass with a degenerate face differs");
        assert!(
            f64::from_bits(portable[1 + 8 * a + 7]).is_infinite(),
            "the degenerate face's corner has no infinite stiffness"
        );
    }
}

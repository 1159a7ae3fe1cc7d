//! [`Surface`]: a [`Grid`] and its perturbations, evaluated frame after frame into a
//! [`WaterMesh`] with analytic normals; and seed 002's face-averaged normals.
//!
//! Everything that does not change with time is tabulated once: a wave's phase
//! `k(x·i + z·j) − ωt` splits into a column part and a row part, so
//! `sin(A + B) = sin A cos B + cos A sin B` needs no per-vertex sine; a ripple's
//! `e^(−αr)·sin(kr)`, `e^(−αr)·cos(kr)` and radial unit vector are fixed per vertex, and
//! time only rotates them by `ωt`. A frame is then a few multiply-adds per vertex.

use glam::Vec3;

use crate::{Grid, Perturbation, Ripple, Wave};

/// A triangle mesh of the water surface, in metres.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WaterMesh {
    /// Vertex positions, row by row (Z outer, X inner).
    pub positions: Vec<Vec3>,
    /// Unit vertex normals (pointing up, +Y side).
    pub normals: Vec<Vec3>,
    /// Vertex indices, counter-clockwise seen from above.
    pub triangles: Vec<[u32; 3]>,
}

/// A wave's time-independent column factors.
#[derive(Debug, Clone)]
struct WaveTable {
    wave: Wave,
    /// `(sin, cos)` of `k·i·x` per column.
    columns: Vec<[f32; 2]>,
}

/// A ripple's time-independent per-vertex factors `[a e^(−αr) sin kr, a e^(−αr) cos kr, x̂, ẑ]`.
#[derive(Debug, Clone)]
struct RippleTable {
    ripple: Ripple,
    vertices: Vec<[f32; 4]>,
}

/// A perturbed water grid, evaluated at any time with [`Surface::evaluate`].
#[derive(Debug, Clone)]
pub struct Surface {
    grid: Grid,
    perturbations: Vec<Perturbation>,
    waves: Vec<WaveTable>,
    ripples: Vec<RippleTable>,
    /// One row's summed heights and slopes (scratch of [`Surface::evaluate`]).
    heights: Vec<f32>,
    slopes: Vec<[f32; 2]>,
    mesh: WaterMesh,
}

impl Surface {
    /// The grid with its perturbations; tabulates their time-independent parts.
    pub fn new(grid: Grid, perturbations: Vec<Perturbation>) -> Surface {
        let [nx, nz] = grid.vertices();
        let xs: Vec<f64> = (0..nx).map(|i| grid.x_m(i)).collect();
        let zs: Vec<f64> = (0..nz).map(|j| grid.z_m(j)).collect();
        let mut waves = Vec::new();
        let mut ripples = Vec::new();
        for p in &perturbations {
            match *p {
                Perturbation::Wave(wave) => waves.push(wave_table(wave, &xs)),
                Perturbation::Ripple(ripple) => ripples.push(ripple_table(ripple, &xs, &zs)),
            }
        }
        let mut positions = Vec::with_capacity(nx * nz);
        for &z in &zs {
            for &x in &xs {
                positions.push(Vec3::new(x as f32, grid.rest_height_m() as f32, z as f32));
            }
        }
        Surface {
            grid,
            perturbations,
            waves,
            ripples,
            heights: vec![0.0; nx],
            slopes: vec![[0.0; 2]; nx],
            mesh: WaterMesh {
                normals: vec![Vec3::Y; positions.len()],
                positions,
                triangles: grid.triangles(),
            },
        }
    }

    /// The flat grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The perturbations, in the order given.
    pub fn perturbations(&self) -> &[Perturbation] {
        &self.perturbations
    }

    /// Exact height of the surface at `(x, z)` and `t_s` (rest height plus every
    /// perturbation, seed 002 eq. 6), in f64.
    pub fn height_m(&self, x: f64, z: f64, t_s: f64) -> f64 {
        let sum: f64 = self
            .perturbations
            .iter()
            .map(|p| p.height_m(x, z, t_s))
            .sum();
        self.grid.rest_height_m() + sum
    }

    /// Exact slope `(∂y/∂x, ∂y/∂z)` of the summed surface.
    pub fn gradient(&self, x: f64, z: f64, t_s: f64) -> [f64; 2] {
        self.perturbations.iter().fold([0.0; 2], |acc, p| {
            let g = p.gradient(x, z, t_s);
            [acc[0] + g[0], acc[1] + g[1]]
        })
    }

    /// The mesh at time `t_s`: heights summed over the perturbations and analytic normals
    /// `normalize(−∂y/∂x, 1, −∂y/∂z)`, in f32. Reuses its buffers.
    ///
    /// Row by row: the sums of one row stay in a row-long scratch (in L1 cache) while
    /// every perturbation adds to it, then become that row's positions and normals.
    pub fn evaluate(&mut self, t_s: f64) -> &WaterMesh {
        let [nx, _] = self.grid.vertices();
        self.heights.resize(nx, 0.0);
        self.slopes.resize(nx, [0.0; 2]);
        let ripple_frames: Vec<RippleFrame> = self
            .ripples
            .iter()
            .map(|r| RippleFrame::at(r, t_s))
            .collect();
        let rest = self.grid.rest_height_m() as f32;
        let mesh = &mut self.mesh;
        let rows = mesh
            .positions
            .chunks_exact_mut(nx)
            .zip(mesh.normals.chunks_exact_mut(nx));
        for (j, (p_row, n_row)) in rows.enumerate() {
            let (heights, slopes) = (&mut self.heights[..], &mut self.slopes[..]);
            heights.fill(0.0);
            slopes.fill([0.0; 2]);
            for table in &self.waves {
                add_wave_row(table, self.grid.z_m(j), t_s, heights, slopes);
            }
            for (table, frame) in self.ripples.iter().zip(&ripple_frames) {
                let row = &table.vertices[j * nx..(j + 1) * nx];
                add_ripple_row(frame, row, heights, slopes);
            }
            for (((p, n), h), s) in p_row.iter_mut().zip(n_row).zip(&*heights).zip(&*slopes) {
                p.y = rest + h;
                *n = Vec3::new(-s[0], 1.0, -s[1]).normalize();
            }
        }
        &self.mesh
    }

    /// The mesh as last evaluated (flat at rest before the first [`Surface::evaluate`]).
    pub fn mesh(&self) -> &WaterMesh {
        &self.mesh
    }
}

fn wave_table(wave: Wave, xs: &[f64]) -> WaveTable {
    let ki = wave.k_per_m() * wave.direction()[0];
    let columns = xs
        .iter()
        .map(|&x| {
            let (s, c) = (ki * x).sin_cos();
            [s as f32, c as f32]
        })
        .collect();
    WaveTable { wave, columns }
}

fn ripple_table(ripple: Ripple, xs: &[f64], zs: &[f64]) -> RippleTable {
    let [cx, cz] = ripple.center_m();
    let mut vertices = Vec::with_capacity(xs.len() * zs.len());
    for &z in zs {
        for &x in xs {
            let (dx, dz) = (x - cx, z - cz);
            let r = dx.hypot(dz);
            let a = ripple.amplitude_m() * (-ripple.decay_per_m() * r).exp();
            let (s, c) = (ripple.k_per_m() * r).sin_cos();
            // The cone tip at the centre takes slope 0 (see `Perturbation::gradient`).
            let (ux, uz) = if r > 0.0 {
                (dx / r, dz / r)
            } else {
                (0.0, 0.0)
            };
            vertices.push([(a * s) as f32, (a * c) as f32, ux as f32, uz as f32]);
        }
    }
    RippleTable { ripple, vertices }
}

/// Adds one wave to the row at `z_m`: `B = k·j·z − ωt` once, then `sin(A + B)` from the
/// column table.
fn add_wave_row(
    table: &WaveTable,
    z_m: f64,
    t_s: f64,
    heights: &mut [f32],
    slopes: &mut [[f32; 2]],
) {
    let w = &table.wave;
    let [di, dj] = w.direction();
    let a = w.amplitude_m() as f32;
    let ak = (w.amplitude_m() * w.k_per_m()) as f32;
    let (aki, akj) = (ak * di as f32, ak * dj as f32);
    let b = w.k_per_m() * dj * z_m - w.omega_rad_per_s() * t_s;
    let (sb, cb) = b.sin_cos();
    let (sb, cb) = (sb as f32, cb as f32);
    for ((h, s), col) in heights
        .iter_mut()
        .zip(slopes.iter_mut())
        .zip(&table.columns)
    {
        let sin_phase = col[0] * cb + col[1] * sb;
        let cos_phase = col[1] * cb - col[0] * sb;
        *h += a * sin_phase;
        s[0] += aki * cos_phase;
        s[1] += akj * cos_phase;
    }
}

/// A ripple's factors at one time: the rotation by `ωt`, faded by `e^(−βt)`.
#[derive(Debug, Clone, Copy)]
struct RippleFrame {
    sin_wt: f32,
    cos_wt: f32,
    k: f32,
    alpha: f32,
}

impl RippleFrame {
    fn at(table: &RippleTable, t_s: f64) -> RippleFrame {
        let r = &table.ripple;
        let fade = (-r.decay_per_s() * t_s).exp();
        let (st, ct) = (r.omega_rad_per_s() * t_s).sin_cos();
        RippleFrame {
            sin_wt: (st * fade) as f32,
            cos_wt: (ct * fade) as f32,
            k: r.k_per_m() as f32,
            alpha: r.decay_per_m() as f32,
        }
    }
}

/// Adds one ripple to a row: rotates the tabulated `sin kr`, `cos kr` back by `ωt`.
fn add_ripple_row(f: &RippleFrame, row: &[[f32; 4]], heights: &mut [f32], slopes: &mut [[f32; 2]]) {
    let (st, ct) = (f.sin_wt, f.cos_wt);
    for ((h, s), v) in heights.iter_mut().zip(slopes.iter_mut()).zip(row) {
        let [a_sin_kr, a_cos_kr, ux, uz] = *v;
        let a_sin_phase = a_sin_kr * ct - a_cos_kr * st;
        let a_cos_phase = a_cos_kr * ct + a_sin_kr * st;
        *h += a_sin_phase;
        let dy_dr = f.k * a_cos_phase - f.alpha * a_sin_phase;
        s[0] += dy_dr * ux;
        s[1] += dy_dr * uz;
    }
}

/// Seed 002's vertex normals: the mean of the unit normals of the triangles sharing each
/// vertex, normalised (oriented by the winding: counter-clockwise faces point at the
/// viewer). Writes one normal per position into `out`; a vertex in no triangle gets +Y.
pub fn face_averaged_normals(positions: &[Vec3], triangles: &[[u32; 3]], out: &mut Vec<Vec3>) {
    out.clear();
    out.resize(positions.len(), Vec3::ZERO);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        for &i in t {
            out[i as usize] += n;
        }
    }
    for n in out.iter_mut() {
        *n = n.normalize_or(Vec3::Y);
    }
}

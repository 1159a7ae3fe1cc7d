//! Transport of the film's thickness: liquid moves with the surfaces and by the drainage
//! flux relative to them, each part upwind along its own characteristic (second order:
//! the upwind cell's Barth–Jespersen-limited gradient), in sub-steps under a Courant
//! bound, each donor's outflow limited to a fraction of its content.
//!
//! A sub-step walks the edges four times (the cells' gradients and their neighbours'
//! range; the gradients' limits; the volumes and each donor's outflow; the limited volumes
//! applied): the edge speeds are computed where the volumes are, from the thickness the
//! sub-step starts with, so no pass stores them.

use glam::DVec3;

use super::compare::{larger, smaller};
use super::flow::{FilmFlow, MAX_OUTFLOW_FRACTION, Scratch};

/// Most sub-steps one thickness transport takes.
const MAX_SUBSTEPS: u32 = 64;

impl FilmFlow {
    /// Moves liquid with the surfaces (upwind) and by the drainage flux relative to them,
    /// in sub-steps that keep each cell's outflow below half its content.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn transport_thickness(&mut self, s: &mut Scratch, dt_s: f64, g_eff: DVec3) {
        let p = self.params;
        let drain = if p.drainage_viscosity_pa_s.is_finite() && p.drainage_viscosity_pa_s > 0.0 {
            p.density_kg_per_m3 / (3.0 * p.drainage_viscosity_pa_s)
        } else {
            0.0
        };
        // The drainage flux's coefficient `c = drain·g_eff·n` of every edge, fixed over
        // the step: each sub-step's flux is `u·h + c·h³`.
        let ea = self.grid.edge_arrays();
        s.drain_rate.clear();
        s.drain_rate
            .extend(ea.normal.iter().map(|normal| drain * g_eff.dot(*normal)));
        let courant = self.courant_number(&s.drain_rate, dt_s);
        // A cell drains through at most two edges of a smooth flow: 2·courant per step, kept
        // within one sub-step's content; the outflow limit guards the rest.
        let substeps = (2.0 * courant).ceil().clamp(1.0, f64::from(MAX_SUBSTEPS)) as u32;
        let h_dt = dt_s / f64::from(substeps);
        for _ in 0..substeps {
            self.upwind_substep(s, h_dt);
        }
    }

    /// The largest fraction of a cell's width any edge's characteristic speed, `|u|` plus
    /// the drainage's `3|c|h²`, carries over `dt_s`.
    fn courant_number(&self, drain_rate: &[f64], dt_s: f64) -> f64 {
        let ea = self.grid.edge_arrays();
        let edges = ea
            .cells
            .iter()
            .zip(&ea.length_per_smaller_area)
            .zip(drain_rate);
        let fastest = edges
            .zip(&self.u_m_per_s)
            .map(|((([a, b], per_area), &c), &u)| {
                let (ha, hb) = (self.h_m[*a as usize], self.h_m[*b as usize]);
                let h = larger(hb, ha);
                (u.abs() + 3.0 * c.abs() * h * h) * per_area
            })
            // The fold skips a NaN speed as `max` does.
            .fold(0.0, |fastest, speed| larger(speed, fastest));
        fastest * dt_s / self.params.radius_m
    }

    /// One transport of `h` over `dt_s`: second-order upwind (the upwind cell's
    /// Green–Gauss gradient, limited to its neighbours' range, carried to the edge
    /// midpoint and clamped between the two cells' values), outflow-limited.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn upwind_substep(&mut self, s: &mut Scratch, dt_s: f64) {
        self.gradients_and_ranges(&mut s.gradient, &mut s.neighbour_range);
        self.limit_gradients(s);
        self.upwind_volumes(s, dt_s);
        let areas = self.grid.areas_sr();
        // Each donor's factor `budget/outflow` where it would give more than its budget
        // (1 elsewhere: multiplying by it then changes nothing).
        for ((ratio, a), h) in s.cell.iter_mut().zip(areas).zip(&self.h_m) {
            let budget = MAX_OUTFLOW_FRACTION * a * h;
            *ratio = if *ratio > budget {
                budget / *ratio
            } else {
                1.0
            };
        }
        let cells = &self.grid.edge_arrays().cells;
        let per_area = self.grid.inverse_areas_per_sr();
        let (h, ratio) = (&mut self.h_m[..], &s.cell[..]);
        for ([a, b], f) in cells.iter().zip(&s.edge2) {
            let (a, b) = (*a as usize, *b as usize);
            let donor = if *f >= 0.0 { a } else { b };
            let moved = f * ratio[donor];
            h[a] -= moved * per_area[a];
            h[b] += moved * per_area[b];
        }
    }

    /// Each cell's Green–Gauss gradient of `h` on the unit sphere, per radian, projected
    /// onto the sphere's tangent plane, and the least and greatest `h` of the cell and its
    /// edge neighbours (one pass: both read the same two cells of each edge).
    fn gradients_and_ranges(&self, gradient: &mut Vec<DVec3>, range: &mut Vec<[f64; 2]>) {
        let g = &self.grid;
        gradient.clear();
        gradient.resize(g.cells(), DVec3::ZERO);
        range.clear();
        range.extend(self.h_m.iter().map(|h| [*h, *h]));
        let ea = g.edge_arrays();
        // Slices, not the vectors: a store through a `&mut Vec` made every edge load the
        // vectors' pointers and lengths again.
        let (gradient, range) = (&mut gradient[..], &mut range[..]);
        for (([a, b], normal), l) in ea.cells.iter().zip(&ea.normal).zip(&ea.length) {
            let (a, b) = (*a as usize, *b as usize);
            let (ha, hb) = (self.h_m[a], self.h_m[b]);
            let flux = *normal * (0.5 * (ha + hb) * l);
            gradient[a] += flux;
            gradient[b] -= flux;
            range[a] = widened(range[a], hb);
            range[b] = widened(range[b], ha);
        }
        let per_area = g.inverse_areas_per_sr();
        for ((grad, ia), c) in gradient.iter_mut().zip(per_area).zip(g.centres()) {
            *grad *= *ia;
            *grad -= *c * grad.dot(*c);
        }
    }

    /// Each cell's factor into `s.limiter` by which its gradient carries the cell's
    /// thickness to no edge midpoint outside the range of the cell and its edge
    /// neighbours (Barth–Jespersen).
    ///
    /// Why: the edge's own clamp (between the two cells' values) let a thin cell beside a
    /// pool tens of µm thick take a face value near the pool's, since the unlimited
    /// gradient leans on the pool. Its outflow, `u·h` and above all the drainage's `c·h³`,
    /// was then hundreds of times its content: the outflow limit let it give half of what
    /// it had in each of up to 64 sub-steps, so film beside the pooled bottom of a bubble
    /// resting on the ground emptied to under a nanometre and burst within a second.
    ///
    /// Each edge's two rises (gradient · reach) are kept in `s.rise` for the volumes'
    /// pass, which scales them by the limiter: that pass then reads 16 bytes an edge
    /// instead of the 48 of both reaches and the two cells' gradients.
    fn limit_gradients(&self, s: &mut Scratch) {
        let ea = self.grid.edge_arrays();
        let (gradient, range) = (&s.gradient, &s.neighbour_range);
        // The limit is 1 wherever the range holds the whole rise: that test skips the
        // division in most edges of a smooth film (x ≥ y > 0 gives x/y ≥ 1 exactly, so
        // the factor is the same).
        let allowed = |h: f64, [lo, hi]: [f64; 2], rise: f64| {
            if rise > 0.0 {
                let room = hi - h;
                if room >= rise {
                    1.0
                } else {
                    smaller(room / rise, 1.0)
                }
            } else if rise < 0.0 {
                let room = lo - h;
                if room <= rise {
                    1.0
                } else {
                    smaller(room / rise, 1.0)
                }
            } else {
                1.0
            }
        };
        let (phi, rises) = (&mut s.limiter, &mut s.rise);
        phi.clear();
        phi.resize(self.h_m.len(), 1.0);
        rises.resize(ea.cells.len(), [0.0; 2]);
        let phi = &mut phi[..];
        for (([a, b], reach), kept) in ea.cells.iter().zip(&ea.reach).zip(rises.iter_mut()) {
            let (a, b) = (*a as usize, *b as usize);
            let rise = [gradient[a].dot(reach[0]), gradient[b].dot(reach[1])];
            let fa = allowed(self.h_m[a], range[a], rise[0]);
            let fb = allowed(self.h_m[b], range[b], rise[1]);
            phi[a] = smaller(fa, phi[a]);
            phi[b] = smaller(fb, phi[b]);
            *kept = rise;
        }
        for f in phi.iter_mut() {
            *f = f.max(0.0);
        }
    }

    /// The volume across each edge over `dt_s` per R² (m × sr) into `s.edge2`, and each
    /// donor's total outflow into `s.cell`.
    fn upwind_volumes(&self, s: &mut Scratch, dt_s: f64) {
        let dt_per_r = dt_s / self.params.radius_m;
        let ea = self.grid.edge_arrays();
        let (volume, outflow, phi) = (&mut s.edge2, &mut s.cell, &s.limiter);
        volume.resize(ea.cells.len(), 0.0);
        outflow.clear();
        outflow.resize(self.grid.cells(), 0.0);
        let outflow = &mut outflow[..];
        let edges = ea.cells.iter().zip(&s.rise).zip(&ea.length);
        let speeds = self.u_m_per_s.iter().zip(&s.drain_rate);
        for (((&u, &c), (([a, b], rise), l)), v) in speeds.zip(edges).zip(volume.iter_mut()) {
            let (a, b) = (*a as usize, *b as usize);
            let face = |forward: bool| face_thickness(&self.h_m, phi, [a, b], *rise, forward);
            // Each part upwind along its own characteristic: the surfaces carry h at u,
            // the drainage flux c·h³ travels at 3c·h², the sign of c. One upwind choice by
            // the sign of the summed speed runs downwind wherever the surfaces move up
            // against a film that drains down, and grew odd-even stripes there.
            let h_plug = face(u >= 0.0);
            let h_drain = if (c >= 0.0) == (u >= 0.0) {
                h_plug
            } else {
                face(c >= 0.0)
            };
            let f = (u * h_plug + c * h_drain * h_drain * h_drain) * l * dt_per_r;
            *v = f;
            let donor = if f >= 0.0 { a } else { b };
            outflow[donor] += f.abs();
        }
    }
}

/// The thickness the upwind cell (`a` going `forward`, else `b`) carries to the edge: its
/// own plus its limited rise, clamped between the two cells' values. A function, not a
/// closure, so that it is inlined at both its calls.
#[inline(always)]
fn face_thickness(
    h: &[f64],
    phi: &[f64],
    [a, b]: [usize; 2],
    rise: [f64; 2],
    forward: bool,
) -> f64 {
    let (up, down, rise) = if forward {
        (a, b, rise[0])
    } else {
        (b, a, rise[1])
    };
    let (h_up, h_down) = (h[up], h[down]);
    // The clamp by comparisons: `clamp`, `min` and `max` each tested for NaN (and
    // `clamp` its bounds' order), a dozen instructions an edge that pick the same value
    // from any thickness that is a number.
    let (lo, hi) = if h_down < h_up {
        (h_down, h_up)
    } else {
        (h_up, h_down)
    };
    let face = h_up + rise * phi[up];
    if face < lo {
        lo
    } else if face > hi {
        hi
    } else {
        face
    }
}

/// `range` widened to hold `h`: `[lo.min(h), hi.max(h)]` for a range that is numbers.
#[inline(always)]
fn widened([lo, hi]: [f64; 2], h: f64) -> [f64; 2] {
    [smaller(h, lo), larger(h, hi)]
}

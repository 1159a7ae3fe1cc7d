//! Transport of the film's thickness: liquid moves with the surfaces and by the drainage
//! flux relative to them, each part upwind along its own characteristic (second order:
//! the upwind cell's Barth–Jespersen-limited gradient), in sub-steps under a Courant
//! bound, each donor's outflow limited to a fraction of its content.
//!
//! A sub-step is one limited apply of the volumes, taken a band of face rows at a time
//! ([`super::upwind`], [`super::fluxes`]): each cell's limited rises to its sides, the
//! volume across each edge, each donor's outflow factor and each cell's gathered volumes,
//! the band's scratch never leaving the cache. Inside a face each stretch reads slices
//! and vectorises. The first sub-step takes the Courant number too ([`Fastest`]).

use glam::DVec3;

use super::capillary::{Mobility, Term};
use super::compare::larger;
use super::face_geometry::FaceGeometry;
use super::flow::{FilmFlow, Scratch};
use super::fluxes::{OutOfPlace, Thinned, apply_limited, apply_limited_to};
use super::grid::dot_at;
use super::sides::EdgeBlock;
use super::upwind;

/// What the transport's first sub-step joins: the capillary smoothing's one sub-step
/// (its [`Term`]'s mobility and step over R²) and, with it, the uniform evaporation.
#[derive(Clone, Copy)]
pub(super) struct Joined {
    /// The smoothing's term.
    pub(super) capillary: (Mobility, f64),
    /// The share of its stability bound the smoothing's one sub-step takes
    /// (its `rate·dt` over the smoothing's `STABLE_RATE_DT`): see [`joins`].
    pub(super) share: f64,
    /// The uniform evaporation, m, where there is one.
    pub(super) thin: Option<f64>,
}

/// How [`FilmFlow::upwind_substep`] runs.
#[derive(Clone, Copy)]
enum Substep {
    /// The first: out of place into `s.cell`, taking the Courant number, with the
    /// smoothing joined where given.
    First(Option<Joined>),
    /// One of several after it, in place.
    Another,
}

/// Whether the transport's one sub-step at `courant` takes the capillary smoothing's
/// whose share of its own stability bound is `share` ([`Joined::share`]): where the two
/// shares, the transport's `2·courant`, sum to at most 1, the forward Euler step of the
/// sum is a convex combination of stable steps of each ([`super::capillary::Term`]).
pub(super) fn joins(share: f64, courant: f64) -> bool {
    share + 2.0 * courant <= 1.0
}

/// Most sub-steps one thickness transport takes.
const MAX_SUBSTEPS: u32 = 64;

/// The sub-steps a transport at Courant number `courant` (its fastest edge's) takes: a
/// cell drains through at most two edges of a smooth flow, `2·courant` of its content a
/// step, kept within one sub-step's content; the outflow limit guards the rest.
fn substeps_at(courant: f64) -> u32 {
    (2.0 * courant).ceil().clamp(1.0, f64::from(MAX_SUBSTEPS)) as u32
}

impl FilmFlow {
    /// Moves liquid with the surfaces (upwind) and by the drainage flux relative to them,
    /// in sub-steps that keep each cell's outflow below half its content.
    ///
    /// The common case first: one sub-step, whose volumes' pass takes the Courant number
    /// too ([`Fastest`]), from the thickness it starts from, out of place into `s.cell`
    /// (free by now), then swapped in; should the Courant number ask for more sub-steps,
    /// they run from the thickness in `h_m`, untouched. Why: a pass of its own for the
    /// Courant number read the velocities, thicknesses and normals again (14 k cache lines
    /// a step at n = 64) for the one sub-step a film in the optics' range takes; and the
    /// thickness copied aside in case (0.2 MB a step) cost as much.
    ///
    /// Where `joined` (the smoothing's one sub-step, its Laplacian in `s.cell2`), the
    /// one sub-step takes the smoothing's volumes too ([`Term`]), and thins every cell by
    /// the uniform evaporation where there is one: returns whether it did (not where the
    /// Courant number asks for more sub-steps).
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    pub(super) fn transport_thickness(
        &mut self,
        s: &mut Scratch,
        (dt_s, g_eff): (f64, DVec3),
        joined: Option<Joined>,
    ) -> bool {
        let p = self.params;
        let drain = if p.drainage_viscosity_pa_s.is_finite() && p.drainage_viscosity_pa_s > 0.0 {
            p.density_kg_per_m3 / (3.0 * p.drainage_viscosity_pa_s)
        } else {
            0.0
        };
        let drain = Drain { drain, g_eff };
        if self.transport_substeps > 1 {
            match self.take_last_count(s, (dt_s, drain)) {
                None => return false,
                Some(asked) if asked > 1 => {
                    self.substeps_from_start(s, (dt_s, drain), asked);
                    return false;
                }
                // One sub-step: over the whole step, as below, where the smoothing may join.
                Some(_) => {}
            }
        }
        let courant =
            self.upwind_substep(s, dt_s, drain, Substep::First(joined)) * dt_s / p.radius_m;
        let substeps = substeps_at(courant);
        self.transport_substeps = substeps;
        if substeps == 1 {
            let joins = joined.is_some_and(|j| joins(j.share, courant));
            if joined.is_some() && !joins {
                // The sum would overdraw the step's stability: the transport alone, again
                // from `h_m` (untouched), and the smoothing after it.
                self.upwind_substep(s, dt_s, drain, Substep::First(None));
            }
            std::mem::swap(&mut self.h_m, &mut s.cell);
            return joins;
        }
        self.substeps_from_start(s, (dt_s, drain), substeps);
        false
    }

    /// `substeps` sub-steps of the transport over `dt_s`, in place from `h_m`.
    fn substeps_from_start(&mut self, s: &mut Scratch, (dt_s, drain): (f64, Drain), substeps: u32) {
        let h_dt = dt_s / f64::from(substeps);
        for _ in 0..substeps {
            self.upwind_substep(s, h_dt, drain, Substep::Another);
        }
    }

    /// Where the last transport took several sub-steps: the first of as many again, out of
    /// place, taking the Courant number; where that asks for the same count, the rest of
    /// them in place, and `None`. Else the count the Courant number asks for (noted as the
    /// last), `h_m` untouched: [`FilmFlow::transport_thickness`] then takes that many from
    /// the start, or its one sub-step over the whole step.
    ///
    /// Why: that start takes its first sub-step over the whole step to learn the Courant
    /// number, and a film that needs several sub-steps then throws it away; a film's flow
    /// changes little from one step to the next, so the last count is a good first guess
    /// (`dome`'s film needed 2–3 sub-steps in 358 of its 360 steps over 6 s). The speeds
    /// that make the Courant number do not depend on the sub-step's length, and both
    /// ways take the same sub-steps from the same thickness: the same bits.
    fn take_last_count(&mut self, s: &mut Scratch, (dt_s, drain): (f64, Drain)) -> Option<u32> {
        let last = self.transport_substeps;
        let h_dt = dt_s / f64::from(last);
        let speed = self.upwind_substep(s, h_dt, drain, Substep::First(None));
        let substeps = substeps_at(speed * dt_s / self.params.radius_m);
        self.transport_substeps = substeps;
        if substeps != last {
            return Some(substeps);
        }
        std::mem::swap(&mut self.h_m, &mut s.cell);
        for _ in 1..substeps {
            self.upwind_substep(s, h_dt, drain, Substep::Another);
        }
        None
    }

    /// One transport of `h` over `dt_s`: second-order upwind (the upwind cell's
    /// Green–Gauss gradient, limited to its neighbours' range, carried to the edge
    /// midpoint and clamped between the two cells' values), outflow-limited: one limited
    /// apply of the [`upwind::Volumes`], band by band. The first ([`Substep::First`]) out
    /// of place into `s.cell` (`h_m` unchanged), returning the fastest edge's
    /// characteristic speed over its smaller cell's width ([`Fastest`]), with the
    /// capillary [`Term`] where given; another in place, returning 0.
    #[inline(never)] // its own frame in a profile (perf report names the step's parts)
    fn upwind_substep(
        &mut self,
        s: &mut Scratch,
        dt_s: f64,
        drain: Drain,
        substep: Substep,
    ) -> f64 {
        let (courant, joined) = match substep {
            Substep::First(joined) => (true, joined),
            Substep::Another => (false, None),
        };
        let mut fastest = Fastest {
            speed: std::mem::take(&mut s.edge2),
            fastest: 0.0,
        };
        let mut volumes = upwind::Volumes {
            sides: &self.sides,
            geo: &self.transport,
            fg: self.grid.face_geometry(),
            speeds: upwind::EdgeSpeeds {
                u: &self.u_m_per_s,
                drain,
                dt_per_r: dt_s / self.params.radius_m,
            },
            rises: &mut s.rises,
            seam_ends: &mut s.seam_ends,
            fastest: courant.then_some(&mut fastest),
            capillary: joined.map(|j| Term::new(&s.cell2, j.capillary)),
        };
        let (sides, grid, gather) = (&self.sides, &self.grid, &mut s.gather);
        if courant {
            // Every cell of `after` is written: its length, not a fill.
            s.cell.resize(self.h_m.len(), 0.0);
            let after = &mut s.cell[..];
            let moved = &mut OutOfPlace {
                before: &self.h_m,
                after,
            };
            match joined.and_then(|j| j.thin) {
                None => apply_limited_to(sides, grid, &mut volumes, 1.0, moved, gather),
                Some(by) => {
                    let h = &mut Thinned { values: moved, by };
                    apply_limited_to(sides, grid, &mut volumes, 1.0, h, gather);
                }
            }
        } else {
            apply_limited(sides, grid, &mut volumes, 1.0, &mut self.h_m, gather);
        }
        s.edge2 = fastest.speed;
        fastest.fastest
    }
}

/// The Courant number's fastest edge, taken block by block alongside a pass: each
/// edge's characteristic speed, `|u|` plus the drainage's `3|c|h²` (`c` its coefficient,
/// [`DrainAlong::at`]), over its smaller cell's width ([`edge_speed`]), a block's into
/// `speed` by the volumes' loop ([`super::upwind`]) and their maximum taken while they
/// are in L1 (taken in that loop, the compiler vectorised neither).
pub(crate) struct Fastest {
    /// A block's speeds (scratch).
    pub(super) speed: Vec<f64>,
    /// The fastest so far, per s (0 before any).
    pub(super) fastest: f64,
}

impl Fastest {
    /// A block of `len` edges: `speeds` writes their speeds into a buffer `len` long,
    /// whose largest is then taken while it is in L1.
    #[inline(always)]
    pub(crate) fn take(&mut self, len: usize, speeds: impl FnOnce(&mut [f64])) {
        if self.speed.len() < len {
            self.speed.resize(len, 0.0);
        }
        let speed = &mut self.speed[..len];
        speeds(speed);
        self.fastest = largest_of(speed, self.fastest);
    }
}

/// The largest of `values` and `start` (NaN passed over, as `f64::max` does), in four
/// running maxima that vectorise (a maximum is exact in any order).
#[inline(always)]
fn largest_of(values: &[f64], start: f64) -> f64 {
    let mut lanes = [start; 4];
    let quads = values.chunks_exact(4);
    let rest = quads.remainder().iter().fold(start, |a, &b| larger(b, a));
    for quad in quads {
        for k in 0..4 {
            lanes[k] = larger(quad[k], lanes[k]);
        }
    }
    lanes.into_iter().fold(rest, |a, b| larger(b, a))
}

/// The drainage: its speed `c·h²` and flux `c·h³` along an edge's normal, with
/// `c = drain·g_eff·n` fixed over the step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Drain {
    /// `ρ/(3μ_d)`, s/m² (0 without drainage): times `g_eff·n`, the coefficient `c`.
    pub(crate) drain: f64,
    /// Gravity minus the bubble's acceleration, m/s².
    pub(crate) g_eff: DVec3,
}

/// [`Drain`]'s coefficients along a block of edges, from their normals in the block's
/// frame with gravity taken into it ([`EdgeBlock::frame`]).
#[derive(Clone, Copy)]
pub(crate) struct DrainAlong<'a> {
    /// `ρ/(3μ_d)`, s/m².
    drain: f64,
    /// Gravity in the block's frame.
    g: DVec3,
    /// The edges' normals' components in that frame.
    normal: [&'a [f64]; 3],
}

impl Drain {
    /// The coefficients along `block`.
    #[inline(always)]
    pub(crate) fn along<'a>(&self, block: &impl EdgeBlock, fg: &'a FaceGeometry) -> DrainAlong<'a> {
        let normal = block.vector(&fg.normal);
        let len = block.count();
        DrainAlong {
            drain: self.drain,
            g: block.frame(self.g_eff),
            normal: normal.map(|c| &c[..len]),
        }
    }
}

impl DrainAlong<'_> {
    /// Edge `i`'s `c = drain·g_eff·n`, s⁻¹·m⁻¹: each pass takes it from the normals where
    /// it read a per-edge array of them (the normals are face 0's, 0.2 MB at n = 64, and
    /// stay in L2; the array was 0.4 MB, written a step and read every sub-step).
    #[inline(always)]
    pub(crate) fn at(&self, i: usize) -> f64 {
        self.drain * dot_at(self.g, self.normal, i)
    }
}

/// An edge's characteristic speed over its smaller cell's width: `|u|` plus the
/// drainage's `3|c|h²` at the thicker end, times `length/smaller area` (NaN skipped by
/// the maximum that takes it, as `max` does).
#[inline(always)]
pub(crate) fn edge_speed(u: f64, c: f64, ha: f64, hb: f64, per_area: f64) -> f64 {
    let h = larger(hb, ha);
    (u.abs() + 3.0 * c.abs() * h * h) * per_area
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bits::differing_bits;
    use crate::film_flow::FlowParams;
    use crate::film_flow::flow::test_film;

    /// A draining film turning at 3 rad/s, fast enough for several sub-steps a 1/60 s
    /// step, and its parameters.
    fn fast_film() -> (FlowParams, FilmFlow) {
        let params = FlowParams {
            drainage_viscosity_pa_s: 1e-6,
            ..FlowParams::water_film(0.05)
        };
        let mut film = test_film(params);
        film.set_velocity(|d| DVec3::Y.cross(d) * 3.0);
        (params, film)
    }

    /// A film whose Courant number asks for several sub-steps takes them all from the
    /// thickness it started from: the speculative single sub-step's is put back.
    #[test]
    fn a_fast_film_takes_its_sub_steps_from_its_starting_thickness() {
        let (params, mut film) = fast_film();
        let (dt_s, g_eff) = (1.0 / 60.0, DVec3::new(0.0, -9.81, 0.0));
        let drain = Drain {
            drain: params.density_kg_per_m3 / (3.0 * params.drainage_viscosity_pa_s),
            g_eff,
        };
        let mut taken = film.clone();
        taken.transport_thickness(&mut Scratch::default(), (dt_s, g_eff), None);
        // The Courant number from a sub-step of its own, then the sub-steps from the start.
        let fastest =
            film.clone()
                .upwind_substep(&mut Scratch::default(), dt_s, drain, Substep::First(None));
        let substeps = (2.0 * fastest * dt_s / params.radius_m).ceil() as u32;
        assert!(substeps > 1, "{substeps} sub-step: the test is idle");
        let mut s = Scratch::default();
        for _ in 0..substeps {
            film.upwind_substep(&mut s, dt_s / f64::from(substeps), drain, Substep::Another);
        }
        assert_eq!(differing_bits(&taken.h_m, &film.h_m), 0);
    }

    /// The last transport's sub-step count, taken as the next one's first guess, changes
    /// no bit: right (its first sub-step kept), too few or too many (put back, and the
    /// count the Courant number asks for taken from the start), and unknown.
    #[test]
    fn the_last_sub_step_count_as_a_guess_gives_the_same_bits() {
        let (_, film) = fast_film();
        let step = (1.0 / 60.0, DVec3::new(0.0, -9.81, 0.0));
        let mut unknown = film.clone();
        unknown.transport_thickness(&mut Scratch::default(), step, None);
        let substeps = unknown.transport_substeps;
        assert!(substeps > 2, "{substeps} sub-steps: the test is idle");
        for guess in [substeps, substeps - 1, substeps + 1] {
            let mut guessed = film.clone();
            guessed.transport_substeps = guess;
            guessed.transport_thickness(&mut Scratch::default(), step, None);
            let differ = differing_bits(&guessed.h_m, &unknown.h_m);
            assert_eq!(differ, 0, "guess {guess}: {differ} cells differ");
            assert_eq!(guessed.transport_substeps, substeps, "guess {guess}");
        }
    }
}

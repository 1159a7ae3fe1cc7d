//! Black film and bursting.
//!
//! Black film, a threshold model of the disjoining pressure: a film thinner than
//! `black_threshold_nm` (about 30 nm, where the van der Waals attraction between the two
//! surfaces wins over the film's electrostatic repulsion) thins to the common black film
//! `black_film_nm` within [`BLACK_RELAX_S`], pushing its liquid into the thicker film
//! around it (conservatively, so a black spot grows a thick rim as real ones do).
//!
//! Rupture: a hole nucleates where the film is thinner than `rupture_thickness_nm`, or at
//! random on black film at `nucleation_per_m2_s` (a seeded Poisson process). Its rim
//! retracts at the Taylor–Culick speed `√(2σ/(ρh))` of the film it meets (the mean
//! thickness along the rim); the film behind the rim is gone (its liquid leaves as the
//! rim's droplets). A hole is a spherical cap about its site; cells the rim only partly
//! covers keep a fractional coverage, so renderers draw a sharp, anti-aliased rim.
//!
//! The rims run at 10–64 m/s and would cross a 5 cm bubble within one 1/60 s film step,
//! so they advance in their own sub-steps, in each of which the fastest rim moves
//! [`RIM_CELLS_PER_SUBSTEP`] of a mean cell width: the film they meet is sampled every
//! half cell whatever the step, and (on a bubble in a world) the hole grows between film
//! steps, at every world step and at any instant between two of them.

use glam::DVec3;

use super::FilmFlow;
use super::compare::smaller;
use super::grid::{CubeSphere, arc};
use crate::avx2::with_avx2;
use crate::rng::SplitMix64;

/// Time for a film that fell under the black threshold to reach the black film, s.
pub const BLACK_RELAX_S: f64 = 0.05;

/// How far the fastest rim moves in one of its sub-steps, in mean cell widths
/// (√(4π/cells)·R; the smallest cells, at the cube corners, are 2.3× narrower). Half a
/// cell: the thickness ahead of the rim, which sets its speed, is sampled over 1.5 cells,
/// so every cell the rim meets is sampled at least twice.
pub const RIM_CELLS_PER_SUBSTEP: f64 = 0.5;

/// A hole in the film: a spherical cap about `site`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hole {
    /// Unit direction of the nucleation site on the material sphere.
    pub site: DVec3,
    /// Geodesic radius of the hole on the material sphere, m.
    pub radius_m: f64,
}

/// Black-film and rupture constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BurstParams {
    /// Surface tension of one film surface, N/m (the rim's pull is 2σ).
    pub sigma_n_per_m: f64,
    /// Thickness under which the film turns black, nm (0: no black film).
    pub black_threshold_nm: f64,
    /// Thickness of the common black film, nm.
    pub black_film_nm: f64,
    /// Thickness under which the film ruptures at once, nm.
    pub rupture_thickness_nm: f64,
    /// Rate of spontaneous holes per black-film area, 1/(m²·s).
    pub nucleation_per_m2_s: f64,
}

impl FilmFlow {
    /// Runs `f` on the film's burst state and the film.
    pub(crate) fn with_burst<R>(&mut self, f: impl FnOnce(&mut BurstState, &mut Self) -> R) -> R {
        let mut burst = self
            .burst
            .take()
            .expect("a film always has its burst state");
        let result = f(&mut burst, self);
        self.burst = Some(burst);
        result
    }
}

/// The holes of a film and what bursting has removed.
#[derive(Clone, Debug)]
pub struct BurstState {
    params: BurstParams,
    holes: Vec<Hole>,
    rng: SplitMix64,
    /// Per cell: 1 where film is, 0 where a hole is, between on the rim.
    coverage: Vec<f64>,
    /// Per cell: never film (below a meniscus's contact line); empty when none is.
    closed: Vec<bool>,
    burst_volume_m3: f64,
    /// Thickness of the film where the first hole opened on its own, m.
    first_hole_thickness_m: Option<f64>,
    /// Whether the rims are advanced from outside (by the world, every world step and
    /// between them) rather than within [`BurstState::step`].
    rims_driven_outside: bool,
    /// The black film's per-cell buffers, kept from step to step (three cell arrays a
    /// step were a malloc and free each, 200 kB apiece at n = 64).
    black: BlackScratch,
}

/// Buffers of [`BurstState::blacken`].
#[derive(Clone, Debug, Default)]
struct BlackScratch {
    /// Per cell: its black spot's root cell (union–find), or itself where not black.
    spot: Vec<u32>,
    /// Per root cell: the volume its spot expels this step, m³ per R².
    expelled: Vec<f64>,
    /// Per root cell: the summed weight of the thick film bordering its spot.
    border_weight: Vec<f64>,
    /// Per cell: the thickness the spots around it give it this step, m.
    gain: Vec<f64>,
}

/// The least thickness `h` of a cell with film (`coverage > 0`; NaN skipped, infinite
/// where none), in four lanes that vectorise; with no `coverage`, of every cell.
fn thinnest_covered(h: &[f64], coverage: Option<&[f64]>) -> f64 {
    with_avx2(
        #[inline(always)]
        || match coverage {
            Some(coverage) => {
                let covered = |h: f64, c: f64| if c > 0.0 { h } else { f64::INFINITY };
                thinnest_of(h, &coverage[..h.len()], covered)
            }
            None => thinnest_of(h, h, |h, _| h),
        },
    )
}

/// The least `value(h, c)` over `h` and `c` alike (NaN skipped, infinite where empty), in
/// four lanes.
#[inline(always)]
fn thinnest_of(h: &[f64], c: &[f64], value: impl Fn(f64, f64) -> f64) -> f64 {
    let mut lanes = [f64::INFINITY; 4];
    for (h, c) in h.chunks_exact(4).zip(c.chunks_exact(4)) {
        for k in 0..4 {
            lanes[k] = smaller(value(h[k], c[k]), lanes[k]);
        }
    }
    let whole = h.len() / 4 * 4;
    let rest = h[whole..]
        .iter()
        .zip(&c[whole..])
        .map(|(&h, &c)| value(h, c));
    let least = rest.fold(f64::INFINITY, |a, b| smaller(b, a));
    lanes.into_iter().fold(least, |a, b| smaller(b, a))
}

/// The root of `cell`'s spot, halving the path to it on the way.
fn spot_root(spot: &mut [u32], mut cell: usize) -> usize {
    while spot[cell] as usize != cell {
        let parent = spot[cell] as usize;
        spot[cell] = spot[parent];
        cell = parent;
    }
    cell
}

/// The black film's threshold model over one step's film.
struct BlackFilm<'a> {
    /// Thickness under which film is black, m.
    threshold: f64,
    /// Thickness of the common black film, m.
    black: f64,
    /// Per cell: 1 where film is, 0 in a hole.
    coverage: &'a [f64],
}

impl BlackFilm<'_> {
    /// Whether cell `k` of `h` is black film.
    fn is_black(&self, h: &[f64], k: usize) -> bool {
        h[k] < self.threshold && self.coverage[k] > 0.0
    }

    /// How far cell `k`'s film stands above the threshold, at most the threshold again
    /// (0: black, a hole; small: marginal film). The cap keeps a cell that has taken
    /// liquid from drawing ever more: uncapped, a few cells inside a growing spot took
    /// all of it and stood as bright dots in the black film.
    fn above(&self, h: &[f64], k: usize) -> f64 {
        if self.coverage[k] > 0.0 {
            (h[k] - self.threshold).clamp(0.0, self.threshold)
        } else {
            0.0
        }
    }

    /// Joins touching black cells into spots (union–find; a root is its spot's smallest
    /// cell) and sums each spot's border weight, judged before anything moves.
    fn find_spots(&self, grid: &CubeSphere, h: &[f64], s: &mut BlackScratch) {
        let ea = grid.edge_arrays();
        s.spot.clear();
        s.spot.extend(0..grid.cells() as u32);
        for [a, b] in &ea.cells {
            let (a, b) = (*a as usize, *b as usize);
            if self.is_black(h, a) && self.is_black(h, b) {
                let (ra, rb) = (spot_root(&mut s.spot, a), spot_root(&mut s.spot, b));
                s.spot[ra.max(rb)] = ra.min(rb) as u32;
            }
        }
        s.border_weight.clear();
        s.border_weight.resize(grid.cells(), 0.0);
        for ([a, b], l) in ea.cells.iter().zip(&ea.length) {
            let (a, b) = (*a as usize, *b as usize);
            for (from, to) in [(a, b), (b, a)] {
                if self.is_black(h, from) {
                    s.border_weight[spot_root(&mut s.spot, from)] += l * self.above(h, to);
                }
            }
        }
    }

    /// Thins each black cell of a spot with thick film around it by `fraction` of its
    /// excess over the black film, and puts the spot's liquid into the cells bordering
    /// it by edge length times thickness above the threshold (judged before any
    /// arrives). A spot with no thick film around it (it covers all the film there is)
    /// has nowhere to put its liquid and waits.
    fn expel(&self, grid: &CubeSphere, fraction: f64, h: &mut [f64], s: &mut BlackScratch) {
        let (ea, areas) = (grid.edge_arrays(), grid.areas_sr());
        s.expelled.clear();
        s.expelled.resize(grid.cells(), 0.0);
        for k in 0..h.len() {
            let root = spot_root(&mut s.spot, k);
            if self.is_black(h, k) && h[k] > self.black && s.border_weight[root] > 0.0 {
                let give = (h[k] - self.black) * fraction;
                s.expelled[root] += give * areas[k];
                h[k] -= give;
            }
        }
        s.gain.clear();
        s.gain.resize(grid.cells(), 0.0);
        for ([a, b], l) in ea.cells.iter().zip(&ea.length) {
            let (a, b) = (*a as usize, *b as usize);
            for (from, to) in [(a, b), (b, a)] {
                let root = spot_root(&mut s.spot, from);
                if self.is_black(h, from) && s.expelled[root] > 0.0 {
                    let share = l * self.above(h, to) / s.border_weight[root];
                    s.gain[to] += s.expelled[root] * share;
                }
            }
        }
        for ((h, g), a) in h.iter_mut().zip(&s.gain).zip(areas) {
            *h += g / a;
        }
    }
}

impl BurstState {
    /// No holes yet, all film present.
    pub fn new(params: BurstParams, cells: usize, seed: u64) -> Self {
        Self {
            params,
            holes: Vec::new(),
            rng: SplitMix64::new(seed ^ 0xB1AC_F11E),
            coverage: vec![1.0; cells],
            closed: Vec::new(),
            burst_volume_m3: 0.0,
            first_hole_thickness_m: None,
            rims_driven_outside: false,
            black: BlackScratch::default(),
        }
    }

    /// Closes the cells marked in `cells` for good: their coverage is zero from now on.
    pub(crate) fn close(&mut self, cells: &[bool]) {
        self.closed = cells.to_vec();
        for (c, _) in self.coverage.iter_mut().zip(cells).filter(|x| *x.1) {
            *c = 0.0;
        }
    }

    /// Leaves the rims to [`BurstState::advance_rims`] calls from outside: a film step
    /// then only blackens, nucleates and sweeps (what its transport moved into a hole).
    pub(crate) fn drive_rims_outside(&mut self) {
        self.rims_driven_outside = true;
    }

    /// The holes.
    pub fn holes(&self) -> &[Hole] {
        &self.holes
    }

    /// Film coverage of each cell, in [0, 1].
    pub fn coverage(&self) -> &[f64] {
        &self.coverage
    }

    /// Liquid the rims have swept off the film (as droplets), m³.
    pub fn burst_volume_m3(&self) -> f64 {
        self.burst_volume_m3
    }

    /// Thickness of the film where the first hole opened on its own (under the rupture
    /// thickness, or by nucleation in black film), m.
    pub fn first_hole_thickness_m(&self) -> Option<f64> {
        self.first_hole_thickness_m
    }

    /// Whether the rims have swept the whole film.
    pub fn fully_burst(&self) -> bool {
        !self.holes.is_empty() && self.coverage.iter().all(|&c| c == 0.0)
    }

    /// Opens a hole at `site` (a unit direction), e.g. to burst a bubble on purpose.
    pub fn nucleate(&mut self, site: DVec3) {
        self.holes.push(Hole {
            site: site.normalize(),
            radius_m: 0.0,
        });
    }

    /// One step of `dt_s`: black film, nucleation, rim retraction (in sub-steps, unless
    /// the rims are driven from outside), coverage.
    pub(crate) fn step(&mut self, flow: &mut FilmFlow, dt_s: f64) {
        let thinnest = self.thinnest_covered(&flow.h_m);
        let thinnest = if self.blacken(flow, dt_s, thinnest) {
            self.thinnest_covered(&flow.h_m)
        } else {
            thinnest
        };
        self.nucleate_where_due(flow, dt_s, thinnest);
        if !self.rims_driven_outside {
            self.advance_rims(flow, 0.0, dt_s, dt_s);
        }
        self.sweep(flow);
    }

    /// Advances the rims from offset `from_s` towards `to_s` within an interval that ends
    /// at `end_s` (offsets from its start, s), in sub-steps in which the fastest rim moves
    /// [`RIM_CELLS_PER_SUBSTEP`] cells (the last one cut to end at `end_s`), sweeping
    /// after each. Stops at the last sub-step that ends by `to_s` and returns its end
    /// offset (`to_s` when there is nothing to move). The sub-steps depend only on the
    /// state and `end_s`, so stopping at an instant and going on later gives the same
    /// state at `end_s` as going there at once.
    pub(crate) fn advance_rims(
        &mut self,
        flow: &mut FilmFlow,
        from_s: f64,
        to_s: f64,
        end_s: f64,
    ) -> f64 {
        // Offsets this close to the end (relative) are the end, so a target computed
        // from absolute times does not leave a sliver of a sub-step.
        let slack_s = 1e-9 * end_s;
        let mut at_s = from_s;
        while !self.holes.is_empty() && !self.fully_burst() {
            let speeds = self.rim_speeds(flow);
            let sub_s = self.rim_substep_s(flow, &speeds);
            let last = at_s + sub_s >= end_s - slack_s;
            let next_s = if last { end_s } else { at_s + sub_s };
            if next_s > to_s + slack_s {
                return at_s;
            }
            self.retract(flow, &speeds, next_s - at_s);
            self.sweep(flow);
            at_s = next_s;
            if last {
                return at_s;
            }
        }
        to_s
    }

    /// The sub-step in which the fastest rim moves [`RIM_CELLS_PER_SUBSTEP`] mean cell
    /// widths, s (infinite when no rim has film ahead of it to move at a finite speed).
    fn rim_substep_s(&self, flow: &FilmFlow, speeds: &[Option<f64>]) -> f64 {
        let width_m =
            (4.0 * std::f64::consts::PI / flow.grid.cells() as f64).sqrt() * flow.params.radius_m;
        let fastest = speeds.iter().flatten().copied().fold(0.0, f64::max);
        if fastest.is_finite() && fastest > 0.0 {
            RIM_CELLS_PER_SUBSTEP * width_m / fastest
        } else {
            f64::INFINITY
        }
    }

    /// Thins black cells towards the black film; each black spot's expelled liquid goes
    /// to the thick film around the spot, each bordering cell in proportion to its edge's
    /// length times its thickness above the threshold.
    ///
    /// Why by spot, and weighted so: each black cell used to push its liquid into its own
    /// neighbours above the threshold. Marginal neighbours (a few nm above it) were pushed
    /// up and stayed grey while the cells beyond them went black, and a cell under the
    /// threshold with no thick neighbour kept its liquid: the `swirl` film's black region
    /// became a cell-by-cell checkerboard of 13–16 nm and 34–41 nm cells with some stuck
    /// near 21 nm, drawn as blocks in the renders
    /// (`black_film_spreads_as_uniform_spots_not_a_checkerboard`). Real black spots are
    /// uniform and gather their liquid into a rim in the thicker film around them.
    ///
    /// `thinnest` is the least covered thickness ([`Self::thinnest_covered`]); returns
    /// whether any cell was thinned (else the thickness is as it was).
    fn blacken(&mut self, flow: &mut FilmFlow, dt_s: f64, thinnest: f64) -> bool {
        let p = &self.params;
        if p.black_threshold_nm <= 0.0 {
            return false;
        }
        let film = BlackFilm {
            threshold: p.black_threshold_nm * 1e-9,
            black: p.black_film_nm * 1e-9,
            coverage: &self.coverage,
        };
        // Some cell is black exactly where the thinnest covered one is.
        if thinnest >= film.threshold {
            return false;
        }
        let fraction = 1.0 - (-dt_s / BLACK_RELAX_S).exp();
        let grid = std::sync::Arc::clone(&flow.grid);
        film.find_spots(&grid, &flow.h_m, &mut self.black);
        film.expel(&grid, fraction, &mut flow.h_m, &mut self.black);
        true
    }

    /// Opens holes where the film is under the rupture thickness (`thinnest`, the least
    /// covered thickness, tells whether any is), and at random on black film.
    fn nucleate_where_due(&mut self, flow: &FilmFlow, dt_s: f64, thinnest: f64) {
        let p = self.params;
        let r2 = flow.params.radius_m * flow.params.radius_m;
        let grid = &flow.grid;
        let inside = |holes: &[Hole], d: DVec3| {
            holes
                .iter()
                .any(|h| arc(h.site, d) * flow.params.radius_m <= h.radius_m)
        };
        // The search for the thinnest cell (the first of them) runs only where a pass
        // that vectorises finds one under the rupture thickness.
        let rupture_m = p.rupture_thickness_nm * 1e-9;
        if thinnest < rupture_m
            && let Some((i, h)) = self.thinnest_cell(flow)
            && h < rupture_m
            && !inside(&self.holes, grid.centres()[i])
        {
            self.first_hole_thickness_m.get_or_insert(h);
            self.nucleate(grid.centres()[i]);
        }
        if p.nucleation_per_m2_s <= 0.0 || p.black_threshold_nm <= 0.0 {
            return;
        }
        let black = p.black_threshold_nm * 1e-9;
        for (i, (&h, &a)) in flow.h_m.iter().zip(grid.areas_sr()).enumerate() {
            if h < black && self.coverage[i] > 0.0 {
                let chance = p.nucleation_per_m2_s * a * r2 * dt_s;
                if self.rng.next_f64() < chance && !inside(&self.holes, grid.centres()[i]) {
                    self.first_hole_thickness_m.get_or_insert(h);
                    self.nucleate(grid.centres()[i]);
                }
            }
        }
    }

    /// The least thickness of a cell with film (infinite where none): where no hole has
    /// opened and no cell is closed, every cell keeps the coverage of 1 it started with
    /// (only [`Self::close`] and a hole's [`Self::sweep`] write it), and the thickness
    /// alone is read.
    ///
    /// Why: the coverage (0.2 MB at n = 64) was read from beyond the core's 1 MB L2 every
    /// step, where the capillary smoothing has just written the thickness: without it,
    /// `film_profile 64 0 9.81`'s 40 steps took 12.63 M LL misses against 12.75 M (620.2 M
    /// instructions against 620.7 M). The blackening and the nucleation took the least
    /// apiece; they share it unless the first thinned a cell.
    fn thinnest_covered(&self, h: &[f64]) -> f64 {
        let all_covered = self.holes.is_empty() && self.closed.is_empty();
        thinnest_covered(h, (!all_covered).then_some(&self.coverage[..]))
    }

    /// The covered cell with the least thickness (the first of them), and its thickness.
    fn thinnest_cell(&self, flow: &FilmFlow) -> Option<(usize, f64)> {
        let covered = flow.h_m.iter().enumerate();
        let covered = covered.filter(|&(i, _)| self.coverage[i] > 0.0);
        covered
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, &h)| (i, h))
    }

    /// The Taylor–Culick speed of every rim over the mean thickness of the film within
    /// 1.5 mean cell widths outside it, m/s; `None` where no film is ahead of it.
    fn rim_speeds(&self, flow: &FilmFlow) -> Vec<Option<f64>> {
        let p = self.params;
        let r = flow.params.radius_m;
        let rho = flow.params.density_kg_per_m3;
        let grid = &flow.grid;
        let width = (4.0 * std::f64::consts::PI / grid.cells() as f64).sqrt() * r;
        self.holes
            .iter()
            .map(|hole| {
                let (mut sum, mut area) = (0.0, 0.0);
                for ((c, &h), &a) in grid.centres().iter().zip(&flow.h_m).zip(grid.areas_sr()) {
                    let d = arc(hole.site, *c) * r - hole.radius_m;
                    if (0.0..=1.5 * width).contains(&d) && h > 0.0 {
                        sum += h * a;
                        area += a;
                    }
                }
                (area > 0.0).then(|| (2.0 * p.sigma_n_per_m / (rho * sum / area)).sqrt())
            })
            .collect()
    }

    /// Moves every rim outwards at its speed for `dt_s`; a rim with no film ahead of it
    /// has closed over the far pole, and passed it by the widest cell's width, so that
    /// no cell there keeps part of its film (its coverage ramps over its own width).
    fn retract(&mut self, flow: &FilmFlow, speeds: &[Option<f64>], dt_s: f64) {
        let r = flow.params.radius_m;
        let widest_sr = flow.grid.areas_sr().iter().copied().fold(0.0, f64::max);
        let past_far_pole_m = std::f64::consts::PI * r + widest_sr.sqrt() * r;
        for (hole, speed) in self.holes.iter_mut().zip(speeds) {
            match speed {
                Some(v) => hole.radius_m += v * dt_s,
                None => hole.radius_m = past_far_pole_m,
            }
        }
    }

    /// Sets the coverage from the holes and removes the film behind the rims.
    fn sweep(&mut self, flow: &mut FilmFlow) {
        if self.holes.is_empty() {
            return;
        }
        let r = flow.params.radius_m;
        let r2 = r * r;
        let grid = std::sync::Arc::clone(&flow.grid);
        for (i, (c, &a)) in grid.centres().iter().zip(grid.areas_sr()).enumerate() {
            let width = a.sqrt() * r;
            let film = if self.closed.get(i) == Some(&true) {
                0.0
            } else {
                1.0
            };
            let open = self
                .holes
                .iter()
                .map(|h| ((arc(h.site, *c) * r - h.radius_m) / width + 0.5).clamp(0.0, 1.0))
                .fold(film, f64::min);
            self.coverage[i] = open;
            if open == 0.0 && flow.h_m[i] != 0.0 {
                self.burst_volume_m3 += flow.h_m[i] * a * r2;
                flow.h_m[i] = 0.0;
            }
        }
        // No flow into or out of the holes.
        for (u, e) in flow.u_m_per_s.iter_mut().zip(grid.edges()) {
            if self.coverage[e.a as usize] == 0.0 || self.coverage[e.b as usize] == 0.0 {
                *u = 0.0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film_flow::FlowParams;

    /// The least covered thickness passes over the cells without film, closed or swept
    /// by a rim, and is every cell's least where there are none (the thinnest among the
    /// cells after the last whole four, so the lanes' rest is taken too).
    #[test]
    fn the_thinnest_covered_cell_passes_over_cells_without_film() {
        let params = FlowParams::water_film(0.05).burst;
        let h = [3.0, 4.0, 2.0, 5.0, 6.0, 1.0];
        let fresh = || BurstState::new(params, h.len(), 0);
        assert_eq!(fresh().thinnest_covered(&h), 1.0, "every cell covered");
        let mut closed = fresh();
        closed.close(&[false, false, false, false, false, true]);
        assert_eq!(closed.thinnest_covered(&h), 2.0, "a closed cell");
        // A rim's sweep as it leaves the coverage.
        let mut swept = fresh();
        swept.nucleate(DVec3::X);
        swept.coverage[5] = 0.0;
        swept.coverage[2] = 0.0;
        assert_eq!(swept.thinnest_covered(&h), 3.0, "swept cells");
    }
}

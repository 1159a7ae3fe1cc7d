//! Folds. Where the colour curve turns back on itself (pale high orders: pink, grey,
//! green and back), a growing front cannot tell from one pixel whether the film
//! thickens or thins beyond the turn, and may carry on along the mirror branch. The two
//! branches differ by a little colour in every pixel beyond, so the region beyond, taken
//! whole, can tell: each stretch of the map between such turns (where one pixel's colour
//! pins its thickness to no better than [`WEAK_SIGMA_NM`]) is put to the order vote on
//! its own, moved if its colours fit clearly better, and the turns are then regrown
//! from both sides.

use crate::camera::speed2;
use crate::model::TABLE_STEP_NM;
use crate::unwrap::{AMBIGUOUS, FREE, Grower, LABELLED, QUEUED, UNEXPLAINED};
use std::cmp::Reverse;

/// A labelled pixel whose colour alone fixes its thickness no better than this (one
/// sigma, nm) lies on a turn of the colour curve.
const WEAK_SIGMA_NM: f32 = 10.0;
/// A stretch whose mean colour cost is this many times the best stretch's is lost.
const LOST_RATIO: f64 = 2.0;
/// ... and above this absolute cost (an RMS error of 1 % of full scale per encoded
/// channel), so that a nearly noiseless photo's tiny costs are not compared as ratios.
const LOST_FLOOR: f64 = 3.0 * 0.01 * 0.01;

/// What [`Grower::refold`] did.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FoldReport {
    /// Stretches moved to another branch.
    pub(crate) moved: usize,
    /// Stretches set aside as lost.
    pub(crate) lost: usize,
}

/// Half-width (nm) of the band of thicknesses around a turn of the colour curve.
const TURN_BAND_NM: f32 = 12.0;
/// Turns are widened by this many pixels each way, so that a turn that a noisy pixel
/// breaks still separates the stretches on either side.
const DILATE_PX: usize = 2;
/// Stretches smaller than this (pixels) are left as they are: too few to vote.
const MIN_STRETCH: usize = 64;
/// A stretch moves only if its mean colour cost falls below this fraction.
const CLEARLY_BETTER: f64 = 0.8;

impl Grower<'_> {
    /// Finds the stretches between turns, moves those whose colours fit another branch
    /// clearly better, regrows the turns, and sets aside stretches that fit far worse
    /// than the rest.
    pub(crate) fn refold(&mut self) -> FoldReport {
        let weak_sigma = WEAK_SIGMA_NM / TABLE_STEP_NM as f32;
        let threshold = self.noise2.max(1e-6) / (weak_sigma * weak_sigma);
        let turns = self.turn_bands();
        let weak: Vec<usize> = (0..self.state.len())
            .filter(|&p| self.state[p] == LABELLED)
            .filter(|&p| {
                let i = self.h[p] as usize;
                turns[usize::from(self.rows[p])][i]
                    || speed2(self.table.row(usize::from(self.rows[p])), i) < threshold
            })
            .collect();
        let is_weak = self.dilate(&weak, DILATE_PX);
        let mut loose: Vec<usize> = (0..self.state.len()).filter(|&p| is_weak[p]).collect();
        let mut seen = vec![false; self.state.len()];
        let mut stretches = Vec::new();
        for start in 0..self.state.len() {
            if self.state[start] != LABELLED || is_weak[start] || seen[start] {
                continue;
            }
            let stretch = self.stretch(start, &is_weak);
            stretch.iter().for_each(|&p| seen[p] = true);
            if stretch.len() < MIN_STRETCH {
                // Too small to vote: it follows whichever stretch reaches it.
                loose.extend_from_slice(&stretch);
            } else {
                stretches.push(stretch);
            }
        }
        let mut report = FoldReport::default();
        for stretch in &stretches {
            if self.move_if_better(stretch) {
                report.moved += 1;
            }
        }
        // Pixels the first growth reached with a poor prediction (typically in a turn)
        // are tried again now that the map around them is known.
        loose.extend((0..self.state.len()).filter(|&p| self.state[p] == UNEXPLAINED));
        self.regrow(&loose);
        report.lost = self.set_aside_lost(&stretches);
        report
    }

    /// Marks ambiguous every stretch whose colours fit [`LOST_RATIO`] times worse than
    /// the best-fitting stretch's: there the growth lost the film (colours too close to
    /// noise to follow), and no order is better than a guess. Returns how many.
    fn set_aside_lost(&mut self, stretches: &[Vec<usize>]) -> usize {
        let costs: Vec<f64> = stretches.iter().map(|s| self.mean_cost(s)).collect();
        let best = costs.iter().copied().fold(f64::INFINITY, f64::min);
        let mut lost = 0;
        for (stretch, cost) in stretches.iter().zip(&costs) {
            if *cost > LOST_RATIO * best && *cost > LOST_FLOOR {
                lost += 1;
                stretch.iter().for_each(|&p| self.state[p] = AMBIGUOUS);
            }
        }
        lost
    }

    /// Per table row, the thicknesses near a turn of the colour curve: within
    /// [`TURN_BAND_NM`] of a local minimum of its speed that is below a quarter of the
    /// row's median speed. A front that folds does so there.
    fn turn_bands(&self) -> Vec<Vec<bool>> {
        let len = self.table.len;
        let band = (TURN_BAND_NM / TABLE_STEP_NM as f32) as usize;
        (0..self.table.rows)
            .map(|r| {
                let row = self.table.row(r);
                let speed: Vec<f32> = (0..len).map(|i| speed2(row, i)).collect();
                let mut sorted = speed.clone();
                let median = *sorted.select_nth_unstable_by(len / 2, f32::total_cmp).1;
                let mut near = vec![false; len];
                for i in 1..len - 1 {
                    let turn = speed[i] <= speed[i - 1]
                        && speed[i] < speed[i + 1]
                        && speed[i] < 0.25 * median;
                    if turn {
                        near[i.saturating_sub(band)..(i + band + 1).min(len)].fill(true);
                    }
                }
                near
            })
            .collect()
    }

    /// The labelled pixels within `radius` steps (4-connected) of `seeds`.
    fn dilate(&self, seeds: &[usize], radius: usize) -> Vec<bool> {
        let mut out = vec![false; self.state.len()];
        let mut front: Vec<usize> = seeds.to_vec();
        front.iter().for_each(|&p| out[p] = true);
        for _ in 0..radius {
            let mut next = Vec::new();
            for &p in &front {
                for (q, _) in self.neighbours(p) {
                    if self.state[q] == LABELLED && !out[q] {
                        out[q] = true;
                        next.push(q);
                    }
                }
            }
            front = next;
        }
        out
    }

    /// The labelled, non-weak pixels 4-connected to `start`.
    fn stretch(&mut self, start: usize, is_weak: &[bool]) -> Vec<usize> {
        self.flood(start, |g, q| g.state[q] == LABELLED && !is_weak[q])
    }

    /// Moves `stretch` by the vote's shift if its colours then fit clearly better.
    fn move_if_better(&mut self, stretch: &[usize]) -> bool {
        let shift = self.vote(stretch).shift;
        if shift == 0 {
            return false;
        }
        let moved: Vec<f32> = stretch
            .iter()
            .map(|&p| {
                let minima = self.minima(p);
                let here = self.h[p] as usize;
                let j = minima
                    .iter()
                    .enumerate()
                    .min_by_key(|(_, m)| m.0.abs_diff(here))
                    .map_or(0, |(j, _)| j);
                usize::try_from(j as i64 + shift)
                    .ok()
                    .and_then(|k| minima.get(k))
                    .map_or(self.h[p], |m| m.0 as f32)
            })
            .collect();
        let before = self.mean_cost(stretch);
        let old: Vec<f32> = stretch.iter().map(|&p| self.h[p]).collect();
        for (&p, &h) in stretch.iter().zip(&moved) {
            self.h[p] = h;
        }
        if self.mean_cost(stretch) < CLEARLY_BETTER * before {
            return true;
        }
        for (&p, &h) in stretch.iter().zip(&old) {
            self.h[p] = h;
        }
        false
    }

    /// Frees the turns, the stretches too small to vote and the unexplained pixels, and
    /// grows them again from the stretches around them; a pixel no stretch reaches keeps
    /// its former state.
    fn regrow(&mut self, weak: &[usize]) {
        let old: Vec<(u8, f32)> = weak.iter().map(|&p| (self.state[p], self.h[p])).collect();
        for &p in weak {
            self.state[p] = FREE;
        }
        for &p in weak {
            let from = self.neighbours(p).find(|&(q, _)| self.state[q] == LABELLED);
            if let Some((q, _)) = from {
                let key = self.information_key(p, self.h[q] as usize);
                self.state[p] = QUEUED;
                self.heap.push(Reverse((u64::from(key) << 32) | p as u64));
            }
        }
        self.grow(&[]);
        for (&p, &(state, h)) in weak.iter().zip(&old) {
            if self.state[p] == FREE || self.state[p] == QUEUED {
                (self.state[p], self.h[p]) = (state, h);
            }
        }
    }
}

//! The fringe orders, resolved globally: quality-guided growth over the pixel grid (as in
//! quality-guided phase unwrapping, the quality being how fast the colour changes with
//! thickness), each pixel taking the minimum of its colour cost nearest the thickness its
//! labelled neighbours predict; each connected region starts from the pixel whose colour
//! names its thickness most clearly, and the region's order as a whole is then put to a
//! vote of the colour evidence of all its pixels.

use crate::camera::{EncodedTable, dist2, speed2};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Pixel states during growth.
pub(crate) const EXCLUDED: u8 = 0;
pub(crate) const SATURATED: u8 = 1;
pub(crate) const FREE: u8 = 2;
pub(crate) const LABELLED: u8 = 3;
pub(crate) const UNEXPLAINED: u8 = 4;
/// Free, and already waiting in the growth's queue (queued once, at its first key).
pub(crate) const QUEUED: u8 = 5;
/// Labelled, but in an isolated patch too small to fix its fringe order.
pub(crate) const AMBIGUOUS: u8 = 6;
/// A region grown from its own seed (no anchor) with fewer labelled pixels than this is
/// too small for continuity and the order vote to place it.
const MIN_REGION: usize = 64;

/// The least colour cost that stops the growth (an RMS error of 0.03 per encoded
/// channel, 8 levels of 8 bits); noisier photos raise it to 4 σ (see
/// [`noise_variance`]).
const MIN_UNEXPLAINED_RMS: f32 = 0.03;

/// The photo's noise variance per encoded channel: a neighbour difference has variance
/// 2σ² per channel, and the smoothest quarter of the photo is mostly noise. (The growth
/// stops at pixels whose colour cost exceeds 4 σ per channel, or an RMS error of
/// [`MIN_UNEXPLAINED_RMS`] in quiet photos.)
fn noise_variance(mut roughness: Vec<f32>) -> f32 {
    if roughness.is_empty() {
        return 0.0;
    }
    let mid = roughness.len() / 4;
    let (_, quarter, _) = roughness.select_nth_unstable_by(mid, f32::total_cmp);
    *quarter / 6.0
}

/// How much of a neighbour's slope carries into a prediction.
const SLOPE_WEIGHT: f32 = 1.0;
/// The largest slope (samples per pixel) carried on.
const MAX_SLOPE: f32 = 40.0;
/// Orders tried either side of a region's first guess.
const MAX_ORDER_SHIFT: i64 = 8;
/// Pixels of a region that vote on its order.
const VOTERS: usize = 1500;

/// The growth's inputs and state.
pub(crate) struct Grower<'a> {
    pub(crate) table: &'a EncodedTable,
    pub(crate) encoded: &'a [[f32; 3]],
    pub(crate) rows: &'a [u16],
    pub(crate) width: usize,
    pub(crate) state: Vec<u8>,
    /// Thickness as a table sample index, for labelled pixels.
    pub(crate) h: Vec<f32>,
    /// Weight of the continuity prior per squared sample of distance from the prediction.
    pub(crate) prior: f32,
    /// Colour cost above which a pixel is unexplained.
    unexplained: f32,
    /// The photo's noise variance per encoded channel, estimated from the quality map.
    pub(crate) noise2: f32,
    pub(crate) heap: BinaryHeap<Reverse<u64>>,
    /// Region-search marks: a pixel is visited when its mark equals `generation`.
    mark: Vec<u32>,
    generation: u32,
}

/// How clearly a pixel's matches name its thickness: the margin of the best match's
/// cost under the second best's (infinite for a single match), and the best match.
fn clearness(minima: &[(usize, f32)]) -> Option<(f32, usize)> {
    let mut costs: Vec<(f32, usize)> = minima.iter().map(|m| (m.1, m.0)).collect();
    costs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    match costs.as_slice() {
        [a, b, ..] => Some((b.0 - a.0, a.1)),
        [a] => Some((f32::INFINITY, a.1)),
        [] => None,
    }
}

/// Pixels sampled evenly over the photo as seed candidates for its large regions.
const SEED_SAMPLES: usize = 4096;

/// A seed candidate: how clearly its colour names its thickness, and its matches.
struct Clearest {
    margin: f32,
    pixel: usize,
    first: usize,
    minima: Vec<(usize, f32)>,
}

/// A region's order vote: the winning shift and Student's t of its lead per pixel over
/// the runner-up (a region whose winner leads by less than [`MIN_T`] is ambiguous).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vote {
    pub(crate) shift: i64,
    pub(crate) t: f64,
}

/// The least significance of a region's order (Student's t of the vote's lead).
const MIN_T: f64 = 5.0;

/// Student's t of the mean of `x` against zero (infinite for a positive mean with no
/// spread, zero for no samples).
fn t_statistic(x: &[f64]) -> f64 {
    if x.len() < 2 {
        return 0.0;
    }
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    if var <= 0.0 {
        return if mean > 0.0 { f64::INFINITY } else { 0.0 };
    }
    mean / (var / n).sqrt()
}

/// What a region's order vote decided.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegionReport {
    /// Regions grown.
    pub regions: usize,
    /// Regions grown from the user's anchors.
    pub anchored: usize,
    /// Regions whose first guess was moved by one or more orders by the vote.
    pub shifted: usize,
    /// Regions too small, or too pale, to place: their pixels are reported ambiguous.
    pub unplaced: usize,
    /// Stretches between turns of the colour curve moved to another branch (see
    /// docs/inverse.md, "Folds").
    pub refolded: usize,
    /// Stretches whose colours fit far worse than the rest (the growth lost the film
    /// there): their pixels are reported ambiguous.
    pub lost: usize,
}

impl<'a> Grower<'a> {
    /// A grower over `state` (each pixel [`EXCLUDED`], [`SATURATED`] or [`FREE`]).
    pub(crate) fn new(
        table: &'a EncodedTable,
        encoded: &'a [[f32; 3]],
        rows: &'a [u16],
        width: usize,
        state: Vec<u8>,
        prior: f32,
    ) -> Grower<'a> {
        let noise2 = noise_variance(roughness(encoded, &state, width));
        let unexplained = 3.0 * (16.0 * noise2).max(MIN_UNEXPLAINED_RMS * MIN_UNEXPLAINED_RMS);
        let n = encoded.len();
        Grower {
            table,
            encoded,
            rows,
            width,
            state,
            h: vec![0.0; n],
            prior,
            unexplained,
            noise2,
            heap: BinaryHeap::new(),
            mark: vec![0; n],
            generation: 0,
        }
    }

    /// Colour cost of pixel `p` at sample `i`.
    #[inline]
    fn cost(&self, p: usize, i: usize) -> f32 {
        dist2(
            self.encoded[p],
            self.table.row(usize::from(self.rows[p]))[i],
        )
    }

    /// The local minimum of cost + prior reached by descending from the prediction.
    fn descend(&self, p: usize, pred: f32) -> (usize, f32) {
        let last = self.table.len - 1;
        let row = self.table.row(usize::from(self.rows[p]));
        let e = self.encoded[p];
        let total = |i: usize| {
            let d = i as f32 - pred;
            dist2(e, row[i]) + self.prior * d * d
        };
        let mut i = (pred.round().max(0.0) as usize).min(last);
        let mut here = total(i);
        loop {
            let down = (i > 0).then(|| total(i - 1)).filter(|&t| t < here);
            let up = (i < last).then(|| total(i + 1)).filter(|&t| t < here);
            match (down, up) {
                (Some(a), Some(b)) if a <= b => (i, here) = (i - 1, a),
                (_, Some(b)) => (i, here) = (i + 1, b),
                (Some(a), None) => (i, here) = (i - 1, a),
                (None, None) => break,
            }
        }
        (i, self.cost(p, i))
    }

    /// The 4-neighbours of `p`.
    pub(crate) fn neighbours(&self, p: usize) -> impl Iterator<Item = (usize, isize)> + use<> {
        let (w, n) = (self.width, self.encoded.len());
        let (x, y) = (p % w, p / w);
        let left = (x > 0).then(|| (p - 1, -1));
        let right = (x + 1 < w).then(|| (p + 1, 1));
        let up = (y > 0).then(|| (p - w, -(w as isize)));
        let down = (p + w < n).then(|| (p + w, w as isize));
        [left, right, up, down].into_iter().flatten()
    }

    /// The thickness the labelled neighbours of `p` predict: each neighbour's value,
    /// carried on along its line by the slope to the pixel beyond it when that one is
    /// labelled too (so a front crossing a turn of the colour curve keeps the film's
    /// trend rather than folding back).
    fn predict(&self, p: usize) -> Option<f32> {
        let (mut sum, mut count) = (0.0f32, 0.0f32);
        for (q, step) in self.neighbours(p) {
            if self.state[q] != LABELLED {
                continue;
            }
            let beyond = q as isize + step;
            let on_line = beyond >= 0
                && (beyond as usize) < self.state.len()
                && (step.abs() != 1 || (beyond as usize) / self.width == q / self.width);
            let slope = if on_line && self.state[beyond as usize] == LABELLED {
                SLOPE_WEIGHT * (self.h[q] - self.h[beyond as usize]).clamp(-MAX_SLOPE, MAX_SLOPE)
            } else {
                0.0
            };
            sum += self.h[q] + slope;
            count += 1.0;
        }
        (count > 0.0).then(|| sum / count)
    }

    /// Labels `p` from `pred`, or marks it unexplained; queues its free neighbours.
    fn settle(&mut self, p: usize, pred: f32, touched: &mut Vec<usize>) {
        let (i, d) = self.descend(p, pred);
        touched.push(p);
        if d > self.unexplained {
            self.state[p] = UNEXPLAINED;
            return;
        }
        self.state[p] = LABELLED;
        self.h[p] = i as f32;
        for (q, _) in self.neighbours(p) {
            if self.state[q] == FREE {
                let key = self.information_key(q, i);
                self.state[q] = QUEUED;
                self.heap.push(Reverse((u64::from(key) << 32) | q as u64));
            }
        }
    }

    /// Priority of reaching `q` from a neighbour at sample `i`: pixels whose colour
    /// changes fast with thickness there are settled first, so that where colours barely
    /// change (pale high orders) the growth arrives last, from every side, rather than
    /// wandering through them (lower keys first).
    pub(crate) fn information_key(&self, q: usize, i: usize) -> u32 {
        let slope2 = speed2(self.table.row(usize::from(self.rows[q])), i);
        let key = 1.0 / (slope2 * 1e6 + 1e-3);
        (key * 1e3).min(u32::MAX as f32) as u32
    }

    /// Grows from `seeds` (pixel, predicted sample) until nothing reachable is free;
    /// returns every pixel it labelled or marked unexplained.
    pub(crate) fn grow(&mut self, seeds: &[(usize, f32)]) -> Vec<usize> {
        let mut touched = Vec::new();
        for &(p, pred) in seeds {
            if self.state[p] == FREE {
                self.settle(p, pred, &mut touched);
            }
        }
        while let Some(Reverse(key)) = self.heap.pop() {
            let p = (key & 0xFFFF_FFFF) as usize;
            if self.state[p] != QUEUED {
                continue;
            }
            if let Some(pred) = self.predict(p) {
                self.settle(p, pred, &mut touched);
            }
        }
        touched
    }

    /// Local minima of pixel `p`'s colour cost over the whole thickness range.
    pub(crate) fn minima(&self, p: usize) -> Vec<(usize, f32)> {
        let row = self.table.row(usize::from(self.rows[p]));
        let e = self.encoded[p];
        let d: Vec<f32> = row.iter().map(|t| dist2(e, *t)).collect();
        (0..d.len())
            .filter(|&i| (i == 0 || d[i] <= d[i - 1]) && (i + 1 == d.len() || d[i] < d[i + 1]))
            .map(|i| (i, d[i]))
            .collect()
    }

    /// Resolves every pixel: anchored regions first, then each remaining region from its
    /// smoothest pixel, its order chosen by vote.
    pub(crate) fn resolve(&mut self, anchors: &[(usize, f32)]) -> RegionReport {
        let mut report = RegionReport::default();
        if !anchors.is_empty() {
            let touched = self.grow(anchors);
            report.anchored = usize::from(!touched.is_empty());
        }
        // The large regions first, each from the clearest of an even sample of the
        // photo's pixels that it holds (no pass over a whole region to find its seed) ...
        for c in self.clear_samples() {
            if self.state[c.pixel] == FREE {
                self.grow_region(&c, &mut report);
            }
        }
        // ... then whatever the sample missed, each from its own clearest pixel.
        let mut cursor = 0;
        while let Some(start) = (cursor..self.state.len()).find(|&p| self.state[p] == FREE) {
            cursor = start;
            let seed = self.clearest_in_region(start);
            self.grow_region(&seed, &mut report);
        }
        report.regions += report.anchored;
        report
    }

    /// Grows one region from a seed at its best match, lets it vote on its order, and
    /// sets it aside if it cannot be placed.
    fn grow_region(&mut self, seed: &Clearest, report: &mut RegionReport) {
        let Clearest {
            pixel: seed,
            first,
            ref minima,
            ..
        } = *seed;
        if minima.is_empty() {
            self.state[seed] = UNEXPLAINED;
            return;
        }
        report.regions += 1;
        let touched = self.grow(&[(seed, first as f32)]);
        let (moved, region, vote) = self.revote(seed, minima, first, touched);
        report.shifted += usize::from(moved);
        self.set_aside_if_unplaced(&region, vote, report);
    }

    /// Up to [`SEED_SAMPLES`] free pixels spread evenly over the photo, clearest first,
    /// each with its matches and its best one.
    fn clear_samples(&self) -> Vec<Clearest> {
        let free: Vec<usize> = (0..self.state.len())
            .filter(|&p| self.state[p] == FREE)
            .collect();
        let stride = free.len().div_ceil(SEED_SAMPLES).max(1);
        let mut scored: Vec<Clearest> = free
            .iter()
            .step_by(stride)
            .filter_map(|&p| self.clearest_of(p))
            .collect();
        scored.sort_by(|a, b| b.margin.total_cmp(&a.margin).then(a.pixel.cmp(&b.pixel)));
        scored
    }

    /// Marks a just-grown region ambiguous if it is too small, or its colours too
    /// indifferent between orders (its final `vote`), to place.
    fn set_aside_if_unplaced(&mut self, region: &[usize], vote: Vote, report: &mut RegionReport) {
        let labelled = self.labelled_of(region);
        if labelled.len() >= MIN_REGION && vote.t >= MIN_T {
            return;
        }
        report.unplaced += 1;
        for p in labelled {
            self.state[p] = AMBIGUOUS;
        }
    }

    /// The pixel of `start`'s free region whose colour names its thickness most clearly:
    /// among up to [`VOTERS`] of its pixels, the one whose best colour match beats its
    /// second best by the widest margin (vivid low orders, black film), with that match.
    fn clearest_in_region(&mut self, start: usize) -> Clearest {
        let region = self.region(start);
        let stride = region.len().div_ceil(VOTERS).max(1);
        let mut best: Option<Clearest> = None;
        for &p in region.iter().step_by(stride) {
            let Some(c) = self.clearest_of(p) else {
                continue;
            };
            if best.as_ref().is_none_or(|b| c.margin > b.margin) {
                best = Some(c);
            }
        }
        best.unwrap_or(Clearest {
            margin: 0.0,
            pixel: start,
            first: 0,
            minima: Vec::new(),
        })
    }

    /// Pixel `p` as a seed candidate, or `None` if its colour matches no thickness.
    fn clearest_of(&self, pixel: usize) -> Option<Clearest> {
        let minima = self.minima(pixel);
        let (margin, first) = clearness(&minima)?;
        Some(Clearest {
            margin,
            pixel,
            first,
            minima,
        })
    }

    /// The free pixels 4-connected to `start` through free pixels.
    fn region(&mut self, start: usize) -> Vec<usize> {
        self.flood(start, |g, q| g.state[q] == FREE)
    }

    /// The pixels 4-connected to `start` through pixels that `inside` accepts.
    pub(crate) fn flood(
        &mut self,
        start: usize,
        inside: impl Fn(&Self, usize) -> bool,
    ) -> Vec<usize> {
        self.generation += 1;
        let generation = self.generation;
        self.mark[start] = generation;
        let mut seen = vec![start];
        let mut k = 0;
        while k < seen.len() {
            let p = seen[k];
            k += 1;
            for (q, _) in self.neighbours(p) {
                if self.mark[q] != generation && inside(self, q) {
                    self.mark[q] = generation;
                    seen.push(q);
                }
            }
        }
        seen
    }

    /// Lets the region just grown vote on its order; regrows it shifted if the vote and
    /// the regrown region's own cost both say so. Returns whether it moved, the pixels
    /// the region now holds, and the vote of its final labelling.
    fn revote(
        &mut self,
        seed: usize,
        minima: &[(usize, f32)],
        first: usize,
        touched: Vec<usize>,
    ) -> (bool, Vec<usize>, Vote) {
        let labelled = self.labelled_of(&touched);
        let vote = self.vote(&labelled);
        let j = minima.iter().position(|m| m.0 == first).unwrap_or(0) as i64;
        let target = usize::try_from(j + vote.shift)
            .ok()
            .and_then(|k| minima.get(k));
        let Some(&(moved, _)) = target.filter(|_| vote.shift != 0) else {
            return (false, touched, vote);
        };
        let before = self.mean_cost(&labelled);
        let saved: Vec<(usize, u8, f32)> = touched
            .iter()
            .map(|&p| (p, self.state[p], self.h[p]))
            .collect();
        for &p in &touched {
            self.state[p] = FREE;
        }
        let regrown = self.grow(&[(seed, moved as f32)]);
        let relabelled = self.labelled_of(&regrown);
        if self.mean_cost(&relabelled) < before {
            let vote = self.vote(&relabelled);
            return (true, regrown, vote);
        }
        for &p in &regrown {
            self.state[p] = FREE;
        }
        for (p, s, h) in saved {
            (self.state[p], self.h[p]) = (s, h);
        }
        (false, touched, vote)
    }

    /// The labelled ones of `pixels`.
    fn labelled_of(&self, pixels: &[usize]) -> Vec<usize> {
        pixels
            .iter()
            .copied()
            .filter(|&p| self.state[p] == LABELLED)
            .collect()
    }

    /// The order shift under which a sample of the region's pixels fit best, and how
    /// significant its lead over the runner-up is.
    pub(crate) fn vote(&self, labelled: &[usize]) -> Vote {
        let stride = labelled.len().div_ceil(VOTERS).max(1);
        let shifts = 2 * MAX_ORDER_SHIFT as usize + 1;
        let costs: Vec<Vec<f32>> = labelled
            .iter()
            .step_by(stride)
            .filter_map(|&p| self.shifted_costs(p, shifts))
            .collect();
        let score: Vec<f64> = (0..shifts)
            .map(|k| costs.iter().map(|c| f64::from(c[k])).sum())
            .collect();
        let offset = |k: usize| (k as i64 - MAX_ORDER_SHIFT).abs();
        let mut order: Vec<usize> = (0..shifts).collect();
        order.sort_by(|&a, &b| {
            score[a]
                .total_cmp(&score[b])
                .then(offset(a).cmp(&offset(b)))
        });
        let (best, runner_up) = (order[0], order[1]);
        let lead: Vec<f64> = costs
            .iter()
            .map(|c| f64::from(c[runner_up] - c[best]))
            .collect();
        Vote {
            shift: best as i64 - MAX_ORDER_SHIFT,
            t: t_statistic(&lead),
        }
    }

    /// Pixel `p`'s colour cost at the local minimum nearest its label, shifted by each of
    /// `shifts` orders (capped at the unexplained cost; off the table costs the cap).
    fn shifted_costs(&self, p: usize, shifts: usize) -> Option<Vec<f32>> {
        let minima = self.minima(p);
        let here = self.h[p] as usize;
        let (j, _) = minima
            .iter()
            .enumerate()
            .min_by_key(|(_, m)| m.0.abs_diff(here))?;
        Some(
            (0..shifts)
                .map(|k| {
                    let at = j as i64 + k as i64 - MAX_ORDER_SHIFT;
                    let d = usize::try_from(at)
                        .ok()
                        .and_then(|a| minima.get(a))
                        .map_or(self.unexplained, |m| m.1);
                    d.min(self.unexplained)
                })
                .collect(),
        )
    }

    /// Mean colour cost of labelled pixels (infinite for none).
    pub(crate) fn mean_cost(&self, labelled: &[usize]) -> f64 {
        if labelled.is_empty() {
            return f64::INFINITY;
        }
        let sum: f64 = labelled
            .iter()
            .map(|&p| f64::from(self.cost(p, self.h[p] as usize)))
            .sum();
        sum / labelled.len() as f64
    }
}

/// For free pixels spread evenly over the photo (at most [`ROUGHNESS_SAMPLES`]), the
/// mean squared colour step to their free 4-neighbours.
fn roughness(encoded: &[[f32; 3]], state: &[u8], width: usize) -> Vec<f32> {
    let n = encoded.len();
    let stride = n.div_ceil(ROUGHNESS_SAMPLES).max(1);
    (0..n)
        .step_by(stride)
        .filter(|&p| state[p] == FREE)
        .filter_map(|p| {
            let (x, y) = (p % width, p / width);
            let near = [
                (x > 0).then(|| p - 1),
                (x + 1 < width).then(|| p + 1),
                (y > 0).then(|| p - width),
                (p + width < n).then(|| p + width),
            ];
            let (sum, count) = near
                .iter()
                .flatten()
                .filter(|&&q| state[q] == FREE)
                .fold((0.0f32, 0u32), |(s, c), &q| {
                    (s + dist2(encoded[p], encoded[q]), c + 1)
                });
            (count > 0).then(|| sum / count as f32)
        })
        .collect()
}

/// Pixels whose roughness estimates the noise.
const ROUGHNESS_SAMPLES: usize = 1 << 20;

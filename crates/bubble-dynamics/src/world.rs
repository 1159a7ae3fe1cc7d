//! The world: bubbles, wind and colliders advanced with a fixed step and automatic substeps.

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::DVec3;
use rayon::prelude::*;

use crate::bubble::Bubble;
use crate::collide;
use crate::collider::Collider;
use crate::error::{Divergence, ParamError, SimError};
use crate::film_flow::Forcing;
use crate::geometry::enclosed_volume_m3;
use crate::icosphere::equilibrium_icosphere;
use crate::params::{BubbleParams, WorldParams};
use crate::topology::Topology;
use crate::wind::{Wind, WindField};

mod interact;

/// Fraction of the symplectic-Euler stability limit ω·dt < 2 that a substep may use.
/// The Gershgorin bound below overestimates the fastest mode 1.4–2× (power iteration,
/// `examples/fastest_mode.rs`), but at 1.5 the E = 10 N/m film diverges in its first
/// step at the bound (`tests/stability_at_substep_bound.rs`; docs/dynamics.md, Substeps).
const STABILITY_FRACTION: f64 = 0.75;
/// A substep count, once chosen, is kept while the stability bound asks for no more and
/// for at least 1/SUBSTEP_HYSTERESIS of it. A count that follows the bound exactly flips
/// between n and n + 1 in step with a wobble that sits at the boundary, and that
/// state-dependent step pumped a free bubble's energy up 66-fold in 2 s
/// (`tests/stability_at_substep_bound.rs`).
const SUBSTEP_HYSTERESIS: f64 = 1.25;
/// A bubble whose volume leaves [1/VOLUME_BLOWUP, VOLUME_BLOWUP]× its rest volume diverged.
const VOLUME_BLOWUP: f64 = 100.0;

/// Something that happened during a step.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// A bubble's film fell below its rupture thickness; the bubble was removed.
    Burst {
        /// The bubble (`Bubble::id`).
        bubble_id: u64,
        /// The step at whose end it burst, counting from 1.
        step: u64,
        /// Simulated time, s.
        time_s: f64,
        /// Where it was, m.
        center_m: DVec3,
        /// Its volume-equivalent radius, m.
        radius_m: f64,
        /// Its thinnest point, nm.
        min_thickness_nm: f64,
    },
}

/// Bubbles in air: advance with [`World::step`] or [`World::advance`].
///
/// Deterministic: identical inputs give bit-identical states at any thread count (no
/// hash-map iteration, no parallel reductions; bubbles are integrated in parallel, each
/// on its own, and contacts are resolved in a fixed order).
#[derive(Debug)]
pub struct World {
    params: WorldParams,
    wind: WindField,
    bubbles: Vec<Bubble>,
    steps: u64,
    last_substeps: u32,
    failed: Option<SimError>,
    /// The id the next added bubble gets (ids are never reused).
    next_id: u64,
    /// Wall time of the steps' film stages while some bubble's film flows, s: a
    /// measurement for `bubbles bench`, never read by the simulation.
    film_wall_s: f64,
}

impl Clone for World {
    fn clone(&self) -> Self {
        let p = &self.params;
        Self {
            params: WorldParams {
                wind: Wind::default(),
                colliders: p.colliders.clone(),
                ..*p
            },
            wind: self.wind.clone(),
            bubbles: self.bubbles.clone(),
            steps: self.steps,
            last_substeps: self.last_substeps,
            failed: self.failed.clone(),
            next_id: self.next_id,
            film_wall_s: self.film_wall_s,
        }
    }
}

impl World {
    /// Validates `params` and `bubbles` and builds the world at t = 0.
    ///
    /// # Guarantees
    /// On success every parameter is finite and in range, no two bubbles overlap and no
    /// bubble overlaps a collider; each bubble is at rest shape (unless `initial_scale`
    /// stretches it) with the gas pressure that holds the discrete mesh in equilibrium.
    ///
    /// # Errors
    /// A [`ParamError`] naming the first bad value (`bubbles[1].radius_m = -0.1 must be …`).
    pub fn try_new(
        mut params: WorldParams,
        bubbles: Vec<BubbleParams>,
    ) -> Result<World, ParamError> {
        params.validate()?;
        for (i, b) in bubbles.iter().enumerate() {
            b.validate()
                .map_err(|e| e.within(&format!("bubbles[{i}]")))?;
        }
        let meshes = unit_meshes(&bubbles);
        check_initial_overlaps(&bubbles, &params.colliders, |b| {
            meshes[&b.subdivisions].circumradius_per_radius
        })?;
        let built: Vec<Bubble> = bubbles
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let mesh = &meshes[&b.subdivisions];
                Bubble::new(
                    i as u64,
                    b,
                    &params,
                    Arc::clone(&mesh.topology),
                    &mesh.unit_positions,
                )
            })
            .collect();
        let wind = WindField::new(std::mem::take(&mut params.wind));
        let next_id = built.len() as u64;
        Ok(World {
            params,
            wind,
            bubbles: built,
            steps: 0,
            last_substeps: 0,
            failed: None,
            next_id,
            film_wall_s: 0.0,
        })
    }

    /// The living bubbles, in id order.
    pub fn bubbles(&self) -> &[Bubble] {
        &self.bubbles
    }

    /// Simulated time, s (steps × dt, without accumulated rounding).
    pub fn time_s(&self) -> f64 {
        self.steps as f64 * self.params.dt_s
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The fixed step, s.
    pub fn dt_s(&self) -> f64 {
        self.params.dt_s
    }

    /// Wall time the steps' film stages have taken while some bubble's film flows, s
    /// (the bubbles' films step in parallel: this is what they add to a step).
    pub fn film_wall_time_s(&self) -> f64 {
        self.film_wall_s
    }

    /// Substeps the last step used.
    pub fn last_substeps(&self) -> u32 {
        self.last_substeps
    }

    /// The static colliders.
    pub fn colliders(&self) -> &[Collider] {
        &self.params.colliders
    }

    /// Air velocity at `position_m` and `time_s`, m/s.
    pub fn wind_m_per_s(&self, position_m: DVec3, time_s: f64) -> DVec3 {
        self.wind.velocity(position_m, time_s)
    }

    /// Advances by `seconds`, rounded to whole steps (see [`World::advance_to`]).
    ///
    /// # Errors
    /// [`SimError::BadDuration`] for a negative or non-finite duration; otherwise the
    /// first step's error.
    pub fn advance(&mut self, seconds: f64) -> Result<Vec<Event>, SimError> {
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(SimError::BadDuration { seconds });
        }
        self.advance_to(self.time_s() + seconds)
    }

    /// Steps until the step count is `round(time_s / dt)`; returns all events on the way.
    /// Targets computed from absolute times do not drift.
    ///
    /// # Errors
    /// [`SimError::BadDuration`] for a non-finite or negative target; otherwise the first
    /// step's error.
    pub fn advance_to(&mut self, time_s: f64) -> Result<Vec<Event>, SimError> {
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(SimError::BadDuration { seconds: time_s });
        }
        let target = (time_s / self.params.dt_s).round() as u64;
        let mut events = Vec::new();
        while self.steps < target {
            events.extend(self.step()?);
        }
        Ok(events)
    }

    /// Advances the rims of the holes in every film-flow bubble to `time_s`, between
    /// this step and the next; the bubbles' shapes and film flows stay at this step. A
    /// rim crosses a bubble within a few steps (10–64 m/s), so this is how a burst is
    /// seen at any instant: the rims reach the last of their own sub-steps (each under a
    /// cell, `film_flow::RIM_CELLS_PER_SUBSTEP`) that ends by `time_s`, the very
    /// sub-steps the next step takes, so the states the steps reach do not depend on
    /// whether or where this was called. A `time_s` before the rims' is a no-op, and one
    /// from the next step on is taken as the next step's start.
    ///
    /// # Errors
    /// [`SimError::BadDuration`] for a non-finite time; the world's earlier error.
    pub fn advance_rims_to(&mut self, time_s: f64) -> Result<(), SimError> {
        if !time_s.is_finite() {
            return Err(SimError::BadDuration { seconds: time_s });
        }
        if let Some(err) = &self.failed {
            return Err(err.clone());
        }
        let dt = self.params.dt_s;
        let into_step_s = (time_s - self.time_s()).clamp(0.0, dt);
        for b in &mut self.bubbles {
            if let Some(film) = b.grid_film.as_mut() {
                film.advance_rims(into_step_s, dt);
            }
        }
        Ok(())
    }

    /// One fixed step of `dt_s`, split into the substeps the stability bound asks for.
    ///
    /// # Errors
    /// [`SimError::Diverged`] naming the step, substep and bubble when a state turns
    /// non-finite or blows up; [`SimError::TooManySubsteps`]. After an error the world
    /// keeps returning it.
    pub fn step(&mut self) -> Result<Vec<Event>, SimError> {
        if let Some(err) = &self.failed {
            return Err(err.clone());
        }
        let result = self.try_step();
        if let Err(err) = &result {
            self.failed = Some(err.clone());
        }
        result
    }

    fn try_step(&mut self) -> Result<Vec<Event>, SimError> {
        let step = self.steps + 1;
        let dt = self.params.dt_s;
        let t0 = self.time_s();
        let v_start: Vec<DVec3> = self.bubbles.iter().map(Bubble::velocity_m_per_s).collect();
        let (params, wind) = (&self.params, &self.wind);
        let parallel = worth_threads(&self.bubbles);
        // The first substep's forces do not depend on its length, so the pass that
        // computes them also gives the stiffness bound that sets the substep count.
        let mut omegas = vec![0.0; self.bubbles.len()];
        for_each_bubble(&mut self.bubbles, &mut omegas, parallel, |b, omega| {
            *omega = b.accumulate_forces::<true>(params, wind, t0);
        });
        let substeps = self.substeps_needed(step, &omegas)?;
        let h = dt / f64::from(substeps);
        for k in 0..substeps {
            let t_s = t0 + f64::from(k) * h;
            for_each_bubble(&mut self.bubbles, &mut omegas, parallel, |b, _| {
                if k > 0 {
                    b.accumulate_forces::<false>(params, wind, t_s);
                }
                b.advance(params, h);
            });
            collide::resolve_bubbles(
                &mut self.bubbles,
                self.params.bubble_restitution,
                self.params.bubble_friction,
            );
            for b in &mut self.bubbles {
                collide::resolve_static(b, &self.params.colliders, h);
                b.hold_at_anchor();
            }
            self.check_divergence(step, k, t_s)?;
        }
        self.steps = step;
        self.last_substeps = substeps;
        let gravity = self.params.gravity_m_per_s2;
        let film_dt = self.params.film_dt_s;
        let mut slots: Vec<(DVec3, DVec3)> = v_start
            .into_iter()
            .zip(&self.bubbles)
            .map(|(v0, b)| {
                (
                    v0,
                    self.wind.velocity(b.center_m(), t0) - b.velocity_m_per_s(),
                )
            })
            .collect();
        let flowing = self.bubbles.iter().any(|b| b.grid_film.is_some());
        let parallel = parallel || flowing;
        let film_start = std::time::Instant::now();
        for_each_bubble(&mut self.bubbles, &mut slots, parallel, |b, (v0, air)| {
            let acceleration = (b.velocity_m_per_s() - *v0) / dt;
            match b.grid_film.as_mut() {
                Some(film) => film.step(
                    dt,
                    film_dt,
                    &Forcing {
                        g_eff_m_per_s2: gravity - acceleration,
                        air_m_per_s: *air,
                    },
                ),
                None => b.transport_film(gravity - acceleration, dt, t0),
            }
        });
        if flowing {
            self.film_wall_s += film_start.elapsed().as_secs_f64();
        }
        Ok(self.remove_burst(step))
    }

    /// Substeps for the stiffest bubble (the largest ω_max in `omegas`, one per bubble):
    /// symplectic Euler needs ω·h < 2.
    fn substeps_needed(&self, step: u64, omegas: &[f64]) -> Result<u32, SimError> {
        let mut worst = (0.0_f64, 0);
        for (b, &omega) in self.bubbles.iter().zip(omegas) {
            // NaN wins, so a broken mesh is reported rather than stepped.
            if omega.is_nan() || omega > worst.0 {
                worst = (omega, b.id);
            }
        }
        let raw = self.params.dt_s * worst.0 / (2.0 * STABILITY_FRACTION);
        let needed = keep_within_band(f64::from(self.last_substeps), raw);
        if needed.is_nan() || needed > f64::from(self.params.max_substeps) {
            return Err(SimError::TooManySubsteps {
                step,
                bubble_id: worst.1,
                needed: if needed.is_finite() {
                    needed as u64
                } else {
                    u64::MAX
                },
                limit: self.params.max_substeps,
            });
        }
        Ok(needed as u32)
    }

    fn check_divergence(&self, step: u64, substep: u32, time_s: f64) -> Result<(), SimError> {
        for b in &self.bubbles {
            if let Some(reason) = b.divergence(self.params.max_speed_m_per_s) {
                return Err(SimError::Diverged {
                    step,
                    substep,
                    time_s,
                    bubble_id: b.id,
                    reason,
                });
            }
        }
        Ok(())
    }

    fn remove_burst(&mut self, step: u64) -> Vec<Event> {
        let time_s = self.time_s();
        let mut events = Vec::new();
        self.bubbles.retain(|b| {
            // With a film flow, the bubble is gone once the rims have swept its film.
            let (intact, min_thickness_nm) = match b.film_flow() {
                Some(flow) => (!flow.fully_burst(), flow_min_thickness_nm(flow)),
                None => {
                    let min = b.min_thickness_nm();
                    (min >= b.film.rupture_thickness_nm, min)
                }
            };
            if !intact {
                events.push(Event::Burst {
                    bubble_id: b.id,
                    step,
                    time_s,
                    center_m: b.center_m(),
                    radius_m: b.radius_m(),
                    min_thickness_nm,
                });
            }
            intact
        });
        events
    }
}

/// The film thickness where a flow's first hole opened on its own (0 when holes were
/// only opened by hand), nm: the thinnest film, which is where holes nucleate.
fn flow_min_thickness_nm(flow: &crate::film_flow::FilmFlow) -> f64 {
    1e9 * flow.first_hole_thickness_m().unwrap_or(0.0)
}

impl Bubble {
    /// Why this bubble's state is judged diverged, if it is.
    pub(crate) fn divergence(&self, max_speed_m_per_s: f64) -> Option<Divergence> {
        let ratio = self.volume_m3 / self.rest_volume_m3;
        let volume_ok = (1.0 / VOLUME_BLOWUP..=VOLUME_BLOWUP).contains(&ratio);
        // Fast screen: a speed within the limit is finite, and a finite sum of finite
        // coordinates clears the position; anything else is judged by the loop below.
        let limit2 = max_speed_m_per_s * max_speed_m_per_s;
        let clear = self
            .positions_m
            .iter()
            .zip(&self.velocities_m_per_s)
            .all(|(x, v)| (x.x + x.y + x.z).is_finite() & (v.length_squared() <= limit2));
        if clear && volume_ok {
            return None;
        }
        for (vertex, (x, v)) in self
            .positions_m
            .iter()
            .zip(&self.velocities_m_per_s)
            .enumerate()
        {
            if !(x.is_finite() && v.is_finite()) {
                return Some(Divergence::NonFinite { vertex });
            }
            if v.length_squared() > max_speed_m_per_s * max_speed_m_per_s {
                return Some(Divergence::Speed {
                    vertex,
                    speed_m_per_s: v.length(),
                    limit_m_per_s: max_speed_m_per_s,
                });
            }
        }
        (!volume_ok).then_some(Divergence::Volume { ratio })
    }
}

/// The substep count for a bound of `raw` substeps after a step that took `last`: at
/// least ⌈raw⌉ (stability), `last` itself while it lies within the hysteresis band, else
/// ⌈SUBSTEP_HYSTERESIS·raw⌉ (at least 1; NaN stays NaN for the caller to report).
fn keep_within_band(last: f64, raw: f64) -> f64 {
    let lower = raw.ceil().max(1.0);
    let upper = (SUBSTEP_HYSTERESIS * raw).ceil().max(1.0);
    if raw.is_nan() {
        raw
    } else if last < lower || last > upper {
        if last < lower { lower } else { upper }
    } else {
        last
    }
}

/// Triangles below which a step is too little work to share among threads. Waking the
/// pool costs tens of microseconds on a busy machine, a parallel section of 8192
/// triangles takes about a millisecond; two level-3 bubbles (2560) measured no faster
/// in parallel on the shared 2-core build machine.
const PARALLEL_MIN_TRIANGLES: usize = 8192;

/// Whether the bubbles' independent work is worth spreading over threads (the results
/// are the same either way).
fn worth_threads(bubbles: &[Bubble]) -> bool {
    bubbles.len() > 1
        && bubbles
            .iter()
            .map(|b| b.topology.triangles().len())
            .sum::<usize>()
            >= PARALLEL_MIN_TRIANGLES
}

/// Runs `f` on every bubble with its slot of `data`, on the rayon pool when `parallel`.
/// Each call touches only its own bubble and slot, so the outcome does not depend on
/// the thread count or the scheduling.
fn for_each_bubble<T: Send>(
    bubbles: &mut [Bubble],
    data: &mut [T],
    parallel: bool,
    f: impl Fn(&mut Bubble, &mut T) + Send + Sync,
) {
    if !parallel {
        bubbles.iter_mut().zip(data).for_each(|(b, d)| f(b, d));
        return;
    }
    // The calling thread takes its share instead of only waiting for the pool: a
    // hand-over to sleeping workers costs microseconds, a bubble's substep tens of them.
    let own = (bubbles.len() / (rayon::current_num_threads() + 1)).max(1);
    let (mine, pool_bubbles) = bubbles.split_at_mut(own);
    let (my_data, pool_data) = data.split_at_mut(own);
    let f = &f;
    rayon::in_place_scope(|scope| {
        scope.spawn(move |_| {
            pool_bubbles
                .par_iter_mut()
                .zip(pool_data.par_iter_mut())
                .for_each(|(b, d)| f(b, d));
        });
        mine.iter_mut().zip(my_data).for_each(|(b, d)| f(b, d));
    });
}

/// A unit icosphere shared by all bubbles of its level.
struct UnitMesh {
    topology: Arc<Topology>,
    unit_positions: Vec<DVec3>,
    /// Farthest vertex distance over radius once scaled to the sphere's volume (1.18 at level 0).
    circumradius_per_radius: f64,
}

fn unit_meshes(bubbles: &[BubbleParams]) -> BTreeMap<u32, UnitMesh> {
    let mut meshes = BTreeMap::new();
    for b in bubbles {
        meshes.entry(b.subdivisions).or_insert_with(|| {
            let mesh = equilibrium_icosphere(b.subdivisions);
            let volume = enclosed_volume_m3(&mesh.positions, &mesh.triangles);
            let n = mesh.positions.len();
            let farthest = mesh
                .positions
                .iter()
                .map(|p| p.length())
                .fold(0.0, f64::max);
            UnitMesh {
                topology: Arc::new(
                    Topology::try_new(mesh.triangles.clone(), n)
                        .expect("icospheres are closed manifolds"),
                ),
                unit_positions: mesh.positions.clone(),
                circumradius_per_radius: farthest
                    * (4.0 / 3.0 * std::f64::consts::PI / volume).cbrt(),
            }
        });
    }
    meshes
}

/// Rejects bubbles that start inside each other or inside a collider (their bounding
/// spheres, which contain the stretched rest mesh).
fn check_initial_overlaps(
    bubbles: &[BubbleParams],
    colliders: &[Collider],
    circumradius_per_radius: impl Fn(&BubbleParams) -> f64,
) -> Result<(), ParamError> {
    let reach =
        |b: &BubbleParams| circumradius_per_radius(b) * b.radius_m * b.initial_scale.max_element();
    for (j, bj) in bubbles.iter().enumerate() {
        for (i, bi) in bubbles[..j].iter().enumerate() {
            let gap = bi.center_m.distance(bj.center_m);
            if gap < reach(bi) + reach(bj) {
                return Err(ParamError::new(
                    format!("bubbles[{j}].center_m"),
                    bj.center_m.to_array(),
                    format!(
                        "overlaps bubbles[{i}] (centres {gap:.4} m apart, reach {:.4} m from \
                         their radius_m {} and {} and initial stretch)",
                        reach(bi) + reach(bj),
                        bi.radius_m,
                        bj.radius_m
                    ),
                ));
            }
        }
        for (k, c) in colliders.iter().enumerate() {
            let (d, _) = c.signed_distance_m(bj.center_m);
            if d < reach(bj) {
                return Err(ParamError::new(
                    format!("bubbles[{j}].center_m"),
                    bj.center_m.to_array(),
                    format!(
                        "is {d:.4} m from colliders[{k}], closer than the bubble's reach {:.4} m \
                         (its radius_m {} and initial stretch)",
                        reach(bj),
                        bj.radius_m
                    ),
                ));
            }
        }
    }
    Ok(())
}

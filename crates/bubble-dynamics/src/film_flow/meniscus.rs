//! A film standing on a wet surface (a dome on a soapy table or bath): below its contact
//! line there is no film, the surfaces are pinned to the meniscus there, the meniscus
//! takes up the liquid that drains into it, and it regenerates the film at its foot.
//!
//! Marginal regeneration (Mysels, Shinoda & Frankel 1959): where a film meets the
//! Plateau border of a meniscus, the border's low pressure sucks thick film in and
//! pulls thinner film out in patches a few border widths across. The patches are lighter
//! than the film around them and rise as plumes: the vivid, high-contrast swirls of a
//! bubble resting on a wet surface, which a hovering bubble's thermal convection alone
//! does not make (docs/film-flow-comparison.md).
//!
//! The model: cells whose centre lies below the contact line are the bath. Every edge
//! with a bath cell on either side is a wall the surfaces do not cross (their velocity
//! and the Marangoni step's change of it held at zero, which disconnects the bath from
//! the surfactant's system). The drainage flux relative to the surfaces still crosses the
//! contact line, into the meniscus, which keeps what it receives ([`FilmFlow::meniscus_volume_m3`]).
//! Patches open at random along the contact line at a settable rate per metre of it;
//! each thins the film within its radius to a settable fraction of the film's mean
//! thickness (where it is thicker), the liquid it gives going to the meniscus, its
//! surfactant concentration unchanged.

use glam::DVec3;

use super::flow::FilmFlow;
use super::grid::CubeSphere;
use crate::rng::SplitMix64;

/// How a film stands on a wet surface and how its meniscus regenerates it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Meniscus {
    /// Height of the contact line above the sphere's centre over its radius, in (−1, 1):
    /// 0 stands a hemisphere.
    pub contact_height: f64,
    /// Thin-film patches the meniscus pulls out per metre of contact line per second.
    pub regeneration_per_m_s: f64,
    /// A patch's thickness over the film's mean thickness, in (0, 1]: the film within
    /// the patch that is thicker is thinned to it.
    pub regenerated_fraction: f64,
    /// Radius of a patch, m.
    pub patch_radius_m: f64,
}

impl Meniscus {
    /// A hemisphere on a wet surface with Mysels' regeneration: 40 patches of 4 mm, at
    /// 40 % of the film's thickness, per metre of contact line per second.
    pub fn hemisphere() -> Self {
        Self {
            contact_height: 0.0,
            regeneration_per_m_s: 40.0,
            regenerated_fraction: 0.4,
            patch_radius_m: 4e-3,
        }
    }

    /// The first value out of range, named, or `None`.
    pub fn invalid(&self) -> Option<(&'static str, f64)> {
        let Self {
            contact_height: c,
            regeneration_per_m_s: rate,
            regenerated_fraction: f,
            patch_radius_m: r,
        } = *self;
        if !(c.is_finite() && c > -1.0 && c < 1.0) {
            Some(("contact_height", c))
        } else if !(rate.is_finite() && rate >= 0.0) {
            Some(("regeneration_per_m_s", rate))
        } else if !(f.is_finite() && f > 0.0 && f <= 1.0) {
            Some(("regenerated_fraction", f))
        } else if !(r.is_finite() && r > 0.0) {
            Some(("patch_radius_m", r))
        } else {
            None
        }
    }
}

/// A film's meniscus: where the bath is, its walls and foot, and what it holds.
#[derive(Clone, Debug)]
pub(super) struct MeniscusState {
    params: Meniscus,
    /// Unit vector up, in the film's material frame.
    up: DVec3,
    /// Per cell: below the contact line.
    bath: Vec<bool>,
    /// Edges with a bath cell on either side.
    walls: Vec<u32>,
    /// Length of the contact line, m.
    contact_length_m: f64,
    /// Liquid the meniscus has taken up, m³.
    volume_m3: f64,
    rng: SplitMix64,
}

impl MeniscusState {
    /// The meniscus of `params` on `grid` (a sphere of `radius_m`) with `up` the way up.
    pub(super) fn new(
        grid: &CubeSphere,
        params: Meniscus,
        up: DVec3,
        radius_m: f64,
        seed: u64,
    ) -> Self {
        let up = up.try_normalize().unwrap_or(DVec3::Y);
        let bath: Vec<bool> = grid
            .centres()
            .iter()
            .map(|c| c.dot(up) < params.contact_height)
            .collect();
        let walls = grid
            .edge_arrays()
            .cells
            .iter()
            .enumerate()
            .filter(|(_, [a, b])| bath[*a as usize] || bath[*b as usize])
            .map(|(e, _)| e as u32)
            .collect();
        let c = params.contact_height;
        Self {
            params,
            up,
            bath,
            walls,
            contact_length_m: std::f64::consts::TAU * (1.0 - c * c).sqrt() * radius_m,
            volume_m3: 0.0,
            rng: SplitMix64::new(seed ^ 0x3E21_5C05),
        }
    }

    /// Per cell: below the contact line.
    pub(super) fn bath(&self) -> &[bool] {
        &self.bath
    }

    /// Liquid the meniscus has taken up, m³.
    pub(super) fn volume_m3(&self) -> f64 {
        self.volume_m3
    }

    /// Pins the surfaces at the walls: their velocity zero, and the Marangoni step's
    /// implicit factor zero there, so that the step does not change it.
    pub(super) fn hold(&self, u_m_per_s: &mut [f64], implicit_factor: &mut [f64]) {
        self.pin(u_m_per_s);
        for &e in &self.walls {
            implicit_factor[e as usize] = 0.0;
        }
    }

    /// The surfaces' velocity at the walls set to zero.
    fn pin(&self, u_m_per_s: &mut [f64]) {
        for &e in &self.walls {
            u_m_per_s[e as usize] = 0.0;
        }
    }

    /// Takes up the liquid in the bath's cells.
    pub(super) fn absorb(&mut self, h_m: &mut [f64], areas_sr: &[f64], radius_m: f64) {
        let r2 = radius_m * radius_m;
        for ((h, &a), _) in h_m
            .iter_mut()
            .zip(areas_sr)
            .zip(&self.bath)
            .filter(|x| *x.1)
        {
            self.volume_m3 += *h * a * r2;
            *h = 0.0;
        }
    }

    /// Opens this step's patches along the contact line (a Poisson number of them, at
    /// most [`MAX_PATCHES_PER_STEP`], at uniformly random places).
    pub(super) fn regenerate(&mut self, grid: &CubeSphere, h_m: &mut [f64], dt_s: f64, r: f64) {
        let expected = self.params.regeneration_per_m_s * self.contact_length_m * dt_s;
        let count = poisson(&mut self.rng, expected);
        if count == 0 {
            return;
        }
        let target_m = self.params.regenerated_fraction * self.mean_film_thickness_m(grid, h_m);
        let (e1, e2) = self.up.any_orthonormal_pair();
        let c = self.params.contact_height;
        let ring = (1.0 - c * c).sqrt();
        for _ in 0..count {
            let phi = std::f64::consts::TAU * self.rng.next_f64();
            let site = self.up * c + (e1 * phi.cos() + e2 * phi.sin()) * ring;
            self.thin_patch(grid, h_m, (site, target_m), r);
        }
    }

    /// The area-weighted mean thickness of the film above the contact line, m.
    fn mean_film_thickness_m(&self, grid: &CubeSphere, h_m: &[f64]) -> f64 {
        let film = grid.areas_sr().iter().zip(h_m).zip(&self.bath);
        let (volume, area) = film
            .filter(|x| !*x.1)
            .fold((0.0, 0.0), |(v, s), ((a, h), _)| (v + a * h, s + a));
        if area > 0.0 { volume / area } else { 0.0 }
    }

    /// Thins the film within the patch radius of `site` to `target_m` where it is
    /// thicker (film pulled out of the border is as thin wherever it replaces).
    fn thin_patch(&mut self, grid: &CubeSphere, h_m: &mut [f64], patch: (DVec3, f64), r: f64) {
        let (site, target_m) = patch;
        let cos_reach = (self.params.patch_radius_m / r)
            .min(std::f64::consts::PI)
            .cos();
        let cells = grid.centres().iter().zip(grid.areas_sr()).zip(&self.bath);
        for (((centre, &a), &bath), h) in cells.zip(h_m.iter_mut()) {
            if !bath && *h > target_m && centre.dot(site) >= cos_reach {
                self.volume_m3 += (*h - target_m) * a * r * r;
                *h = target_m;
            }
        }
    }
}

/// Most patches one step opens: each walks every cell, and at rates that reach this the
/// patches cover the whole foot every step anyway.
const MAX_PATCHES_PER_STEP: u32 = 64;

/// A Poisson-distributed count of mean `mean` (Knuth's product of uniforms), at most
/// [`MAX_PATCHES_PER_STEP`].
fn poisson(rng: &mut SplitMix64, mean: f64) -> u32 {
    if mean <= 0.0 {
        return 0;
    }
    let limit = (-mean).exp();
    let (mut count, mut product) = (0, rng.next_f64());
    while product > limit && count < MAX_PATCHES_PER_STEP {
        count += 1;
        product *= rng.next_f64();
    }
    count
}

impl FilmFlow {
    /// Stands the film on a wet surface: no film below the contact line from now on (its
    /// liquid goes to the meniscus), the surfaces pinned there, and the meniscus
    /// regenerating the film at its foot. `up` is the way up in the film's material
    /// frame.
    ///
    /// # Panics
    /// If `meniscus` has a value out of range ([`Meniscus::invalid`]).
    pub fn stand_on_wet_surface(&mut self, meniscus: Meniscus, up: DVec3) {
        if let Some((name, value)) = meniscus.invalid() {
            panic!("meniscus {name} = {value} is out of range");
        }
        let r = self.params.radius_m;
        let mut state = MeniscusState::new(&self.grid, meniscus, up, r, self.params.seed);
        state.absorb(&mut self.h_m, self.grid.areas_sr(), r);
        state.pin(&mut self.u_m_per_s);
        self.with_burst(|burst, _| burst.close(state.bath()));
        self.meniscus = Some(Box::new(state));
    }

    /// Liquid the meniscus has taken up (drained into it, or given by the patches it
    /// regenerated), m³; zero for a film that does not stand on a wet surface.
    pub fn meniscus_volume_m3(&self) -> f64 {
        self.meniscus.as_ref().map_or(0.0, |m| m.volume_m3())
    }

    /// The meniscus's part of a step: the liquid drained into the bath taken up, then the
    /// patches of this step regenerated.
    pub(super) fn feed_meniscus(&mut self, dt_s: f64) {
        let Some(mut m) = self.meniscus.take() else {
            return;
        };
        let r = self.params.radius_m;
        m.absorb(&mut self.h_m, self.grid.areas_sr(), r);
        m.regenerate(&self.grid, &mut self.h_m, dt_s, r);
        self.meniscus = Some(m);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poisson_counts_have_the_mean_they_are_drawn_with_and_stop_at_the_cap() {
        let mut rng = SplitMix64::new(7);
        for mean in [0.05, 0.7, 3.0] {
            let draws = 200_000;
            let sum: u32 = (0..draws).map(|_| poisson(&mut rng, mean)).sum();
            let measured = f64::from(sum) / f64::from(draws);
            // The standard error of the mean is sqrt(mean / draws): 0.004 at 3.
            assert!(
                (measured - mean).abs() < 5.0 * (mean / 200_000.0_f64).sqrt(),
                "{mean}: {measured}"
            );
        }
        assert_eq!(poisson(&mut rng, 1e6), MAX_PATCHES_PER_STEP);
        assert_eq!(poisson(&mut rng, 0.0), 0);
    }
}

//! Prints the film step's solver iterations, wall time, thinnest film and fastest edge
//! for `film_profile [n] [air m/s] [g m/s²] [bottom warming K] [normal]` (the bench's
//! film, for profiling with perf; `normal` drives it through the normal gradient;
//! `FILM_STEPS` sets the number of steps, 40 unless set; `FILM_REPEATS` runs those steps
//! that many times, each from a copy of the same starting film, so a profile of a small
//! grid is not dominated by building it; `FILM_EVICT_MB` writes a buffer of that many MB
//! before each step, outside its timing, so that the step finds the caches as a scene's
//! rendering leaves them: cold; `FILM_SCENE=1` steps `film_step/scene_n64`'s film, a
//! scene's, in place of the bench's, `n`, the warming and the gradient then unused).

#[path = "../benches/common/scene_film.rs"]
mod scene_film;
#[path = "../benches/common/swirl_film.rs"]
mod swirl_film;

use bubble_dynamics::DVec3;
use bubble_dynamics::film_flow::{FilmGradient, Forcing};

use swirl_film::swirl_film;

fn main() {
    let arg = |k: usize, d: f64| std::env::args().nth(k).map_or(d, |s| s.parse().unwrap());
    let forcing = Forcing {
        g_eff_m_per_s2: DVec3::new(0.0, -arg(3, 9.81), 0.0),
        air_m_per_s: DVec3::new(arg(2, 0.3), 0.0, 0.0),
    };
    let n = arg(1, 64.0) as usize;
    let gradient = match std::env::args().nth(5).as_deref() {
        Some("normal") => FilmGradient::Normal,
        _ => FilmGradient::TwoPoint,
    };
    let count = |name: &str, d: usize| std::env::var(name).map_or(d, |s| s.parse().expect(name));
    let start = if count("FILM_SCENE", 0) == 1 {
        scene_film::scene_film()
    } else {
        swirl_film(n, arg(4, 0.0), gradient)
    };
    let (steps, repeats) = (count("FILM_STEPS", 40), count("FILM_REPEATS", 1));
    let mut evict = vec![0u8; count("FILM_EVICT_MB", 0) << 20];
    for _ in 0..repeats {
        let mut f = start.clone();
        run(&mut f, steps, &forcing, &mut evict);
    }
}

/// Steps `f` `steps` times, printing each step's figures; writes every cache line of
/// `evict` before each step.
fn run(
    f: &mut bubble_dynamics::film_flow::FilmFlow,
    steps: usize,
    forcing: &Forcing,
    evict: &mut [u8],
) {
    for k in 0..steps {
        for (i, b) in evict.iter_mut().enumerate().step_by(64) {
            *b = b.wrapping_add(i as u8);
        }
        std::hint::black_box(&mut *evict);
        let t = std::time::Instant::now();
        let r = f.step(1.0 / 60.0, forcing);
        let hmin = f.thickness_m().iter().cloned().fold(1.0, f64::min);
        let umax = f
            .edge_velocity_m_per_s()
            .iter()
            .map(|u| u.abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{k} {} it {:.2} ms hmin {hmin:.3e} umax {umax:.3}",
            r.iterations,
            t.elapsed().as_secs_f64() * 1e3
        );
    }
}

//! Prints an FNV-1a hash of the film's state (every thickness, surfactant, temperature
//! and edge velocity, bit for bit, and each step's solve report) after stepping a few
//! films: `film_state_hash [n] [steps]`. Two builds that print the same hashes step the
//! film bit-identically (how the default gradient was checked against the code before
//! the normal gradient's option).

#[path = "../benches/common/swirl_film.rs"]
mod swirl_film;

use bubble_dynamics::film_flow::{FilmFlow, FilmGradient, Forcing};
use bubble_dynamics::{BubbleParams, DVec3, World, WorldParams};

use swirl_film::swirl_film;

struct Fnv(u64);

impl Fnv {
    fn add(&mut self, bits: u64) {
        for byte in bits.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn film(&mut self, f: &FilmFlow) {
        let fields = [
            f.thickness_m(),
            f.surfactant(),
            f.temperature_excess_k(),
            f.edge_velocity_m_per_s(),
        ];
        for x in fields.iter().flat_map(|v| v.iter()) {
            self.add(x.to_bits());
        }
    }
}

fn main() {
    let arg = |k: usize, d: usize| std::env::args().nth(k).map_or(d, |s| s.parse().unwrap());
    let (n, steps) = (arg(1, 32), arg(2, 40));
    for (what, warming_k, air, g) in [
        ("swirl film, isothermal", 0.0, 0.3, 9.81),
        ("swirl film, warmed 5 K", 5.0, 0.3, 9.81),
        ("swirl film, warmed 5 K, no gravity", 5.0, 0.0, 0.0),
    ] {
        let forcing = Forcing {
            g_eff_m_per_s2: DVec3::new(0.1, -g, 0.0),
            air_m_per_s: DVec3::new(air, 0.0, 0.1),
        };
        let mut f = swirl_film(n, warming_k, FilmGradient::TwoPoint);
        f.set_velocity(|d| DVec3::new(0.0, 0.02, 0.01).cross(d));
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        for _ in 0..steps {
            let r = f.step(1.0 / 60.0, &forcing);
            h.add(u64::from(r.iterations));
            h.add(r.relative_residual.to_bits());
        }
        h.film(&f);
        println!("{what}: {:016x}", h.0);
    }
    // A bubble of the world with a film flow (film_grid 16, warmed 3 K), 4 world steps a
    // film step.
    let bubble = BubbleParams {
        film_grid: 16,
        radius_m: 0.03,
        mean_thickness_nm: 60.0,
        rupture_thickness_nm: 30.0,
        seed: 7,
        bottom_warming_k: 3.0,
        ..BubbleParams::default()
    };
    let mut world = World::try_new(WorldParams::default(), vec![bubble]).unwrap();
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    for _ in 0..4 * steps {
        match world.step() {
            Ok(events) => h.add(events.len() as u64),
            Err(e) => {
                println!("world stopped: {e}");
                break;
            }
        }
    }
    let b = &world.bubbles()[0];
    if let Some(f) = b.film_flow() {
        h.film(f);
    }
    for p in b.positions_m() {
        h.add(p.x.to_bits());
        h.add(p.y.to_bits());
        h.add(p.z.to_bits());
    }
    println!("world bubble: {:016x}", h.0);
}

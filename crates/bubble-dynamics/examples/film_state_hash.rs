//! Prints an FNV-1a hash of the film's state (every thickness, surfactant, temperature
//! and edge velocity, bit for bit, and each step's solve report) after stepping a few
//! films: `film_state_hash [n] [steps]`. Two builds that print the same hashes step the
//! film bit-identically (how the default gradient was checked against the code before
//! the normal gradient's option).
//!
//! For a change meant to move only rounding: with `FILM_STATE_DUMP=dir` set, each swirl
//! film's fields are also written to `dir` (raw little-endian `f64`s), and
//! `film_state_hash compare dir_a dir_b` prints each field's largest difference between
//! two builds' dumps, relative to the field's largest magnitude, and its rms difference
//! relative to the field's rms.
//!
//! Two settings measure what such a difference is worth against the film's own
//! sensitivity and the step's own error (docs/performance.md, "Fifteenth round"):
//! `FILM_START_NUDGE=ε` scales the swirl films' starting rotation by `1 + ε`, and
//! `FILM_STEP_SPLIT=k` takes each 1/60 s step as `k` steps of 1/(60 k) s.

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

/// The films' fields, in the order they are hashed.
const FIELDS: [&str; 4] = ["thickness", "surfactant", "temperature", "velocity"];

/// Writes film `index`'s fields to `dir` (one file a field).
fn dump(dir: &str, index: usize, f: &FilmFlow) {
    let fields = [
        f.thickness_m(),
        f.surfactant(),
        f.temperature_excess_k(),
        f.edge_velocity_m_per_s(),
    ];
    for (name, values) in FIELDS.iter().zip(fields) {
        let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        std::fs::write(format!("{dir}/{index}_{name}.f64"), bytes).expect("writing a dump");
    }
}

/// Prints, per film and field, the largest difference of two dumps relative to the
/// field's largest magnitude.
fn compare(a: &str, b: &str) {
    let read = |dir: &str, name: &str| -> Vec<f64> {
        let bytes = std::fs::read(format!("{dir}/{name}.f64")).expect("reading a dump");
        let eight = |c: &[u8]| f64::from_le_bytes(c.try_into().expect("8 bytes"));
        bytes.chunks_exact(8).map(eight).collect()
    };
    for index in 0..3 {
        for field in FIELDS {
            let name = format!("{index}_{field}");
            let (x, y) = (read(a, &name), read(b, &name));
            assert_eq!(x.len(), y.len(), "{name}: the dumps differ in length");
            let largest = x.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
            let worst = x
                .iter()
                .zip(&y)
                .fold(0.0, |m: f64, (p, q)| m.max((p - q).abs()));
            let rms = |v: &mut dyn Iterator<Item = f64>| -> f64 {
                let (sum, count) = v.fold((0.0, 0usize), |(s, c), d| (s + d * d, c + 1));
                (sum / count.max(1) as f64).sqrt()
            };
            let rms_difference = rms(&mut x.iter().zip(&y).map(|(p, q)| p - q));
            let rms_field = rms(&mut x.iter().copied());
            let of = |d: f64, scale: f64| if scale > 0.0 { d / scale } else { d };
            println!(
                "film {index} {field}: largest difference {:.3e} of its largest, \
                 rms difference {:.3e} of its rms",
                of(worst, largest),
                of(rms_difference, rms_field)
            );
        }
    }
}

/// The environment's setting `name` as a number, else `default`.
///
/// # Panics
/// If the setting is there but not a number.
fn setting(name: &str, default: f64) -> f64 {
    std::env::var(name).map_or(default, |v| {
        v.parse()
            .unwrap_or_else(|_| panic!("{name}={v} is not a number"))
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("compare") {
        compare(&args[2], &args[3]);
        return;
    }
    let dump_dir = std::env::var("FILM_STATE_DUMP").ok();
    let arg = |k: usize, d: usize| std::env::args().nth(k).map_or(d, |s| s.parse().unwrap());
    let (n, steps) = (arg(1, 32), arg(2, 40));
    for (index, (what, warming_k, air, g)) in [
        ("swirl film, isothermal", 0.0, 0.3, 9.81),
        ("swirl film, warmed 5 K", 5.0, 0.3, 9.81),
        ("swirl film, warmed 5 K, no gravity", 5.0, 0.0, 0.0),
    ]
    .into_iter()
    .enumerate()
    {
        let forcing = Forcing {
            g_eff_m_per_s2: DVec3::new(0.1, -g, 0.0),
            air_m_per_s: DVec3::new(air, 0.0, 0.1),
        };
        let mut f = swirl_film(n, warming_k, FilmGradient::TwoPoint);
        let nudge = 1.0 + setting("FILM_START_NUDGE", 0.0);
        f.set_velocity(|d| DVec3::new(0.0, 0.02 * nudge, 0.01).cross(d));
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        let split = setting("FILM_STEP_SPLIT", 1.0) as usize;
        for _ in 0..steps * split {
            let r = f.step(1.0 / (60.0 * split as f64), &forcing);
            h.add(u64::from(r.iterations));
            h.add(r.relative_residual.to_bits());
        }
        h.film(&f);
        println!("{what}: {:016x}", h.0);
        if let Some(dir) = &dump_dir {
            dump(dir, index, &f);
        }
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

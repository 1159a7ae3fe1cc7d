//! Structure-aware scenes: `arbitrary` picks tables, keys and numbers (plausible,
//! scaled, extreme or raw), and [`FuzzScene::toml`] writes them as a scene file, so most
//! inputs parse and reach the solver and the renderer.

use arbitrary::Arbitrary;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A number for one key: left out, the key's plausible value scaled, an extreme, or raw.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Number {
    /// Leave the key out (its default applies) or write the plausible value.
    Default,
    /// The plausible value times 2^(k/16).
    Scaled(i8),
    /// One of the values that broke earlier versions.
    Extreme(u8),
    /// Any f64.
    Raw(f64),
}

const EXTREMES: [f64; 16] = [
    0.0,
    -0.0,
    1e-300,
    -1e-300,
    1e300,
    -1e300,
    1e39,
    -1e39,
    f64::MAX,
    f64::MIN_POSITIVE,
    1e-7,
    1e7,
    4294967295.0,
    -1.0,
    f64::NAN,
    f64::INFINITY,
];

impl Number {
    fn value(self, plausible: f64) -> f64 {
        match self {
            Self::Default => plausible,
            Self::Scaled(k) => plausible * 2f64.powf(f64::from(k) / 16.0),
            Self::Extreme(i) => EXTREMES[usize::from(i) % EXTREMES.len()],
            Self::Raw(v) => v,
        }
    }
}

/// A TOML literal for `v` (TOML spells the specials `nan`, `inf`, `-inf`).
fn lit(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v.is_infinite() {
        if v > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{v:?}")
    }
}

fn key(out: &mut String, name: &str, n: Number, plausible: f64) {
    if !matches!(n, Number::Default) {
        let _ = writeln!(out, "{name} = {}", lit(n.value(plausible)));
    }
}

fn triple(out: &mut String, name: &str, n: [Number; 3], plausible: [f64; 3]) {
    let v: Vec<String> = (0..3).map(|i| lit(n[i].value(plausible[i]))).collect();
    let _ = writeln!(out, "{name} = [{}]", v.join(", "));
}

fn inline_triple(n: [Number; 3], plausible: [f64; 3]) -> String {
    let v: Vec<String> = (0..3).map(|i| lit(n[i].value(plausible[i]))).collect();
    format!("[{}]", v.join(", "))
}

/// What surrounds the scene.
#[derive(Arbitrary, Debug)]
pub enum Env {
    Sky([Number; 3], [Number; 3], Option<[Number; 3]>),
    Uniform([Number; 3]),
    Equirect(u8, Number),
    Cube(u8, Number),
}

/// A material.
#[derive(Arbitrary, Debug)]
pub enum Mat {
    Checker([Number; 3], Number),
    Solid([Number; 3], Option<Number>),
    Image(u8, Number),
}

/// An opaque object.
#[derive(Arbitrary, Debug)]
pub enum Obj {
    Sphere([Number; 3], Number, Mat),
    Box([Number; 3], [Number; 3], Mat),
    Mesh(u8, [Number; 3], Number, Mat),
}

/// A light.
#[derive(Arbitrary, Debug)]
pub struct Light {
    position: [Number; 3],
    radius: Number,
    spectrum: u8,
    luminance: Number,
}

/// A bubble.
#[derive(Arbitrary, Debug)]
pub struct Bubble {
    center: [Number; 3],
    radius: Number,
    velocity: Option<[Number; 3]>,
    thickness: Number,
    subdivisions: Option<i64>,
    extra: [Number; 10],
    seed: u64,
    flow: Option<FilmFlow>,
}

/// A water wave: amplitude, wavelength, direction (X, Z), optional angular speed.
#[derive(Arbitrary, Debug)]
pub struct Wave(Number, Number, [Number; 2], Option<Number>);

/// A ripple: amplitude, wavelength, centre (X, Z), decays in r and t, angular speed.
#[derive(Arbitrary, Debug)]
pub struct Ripple(Number, Number, [Number; 2], Option<Number>, Option<Number>, Option<Number>);

/// A `[water]` section.
#[derive(Arbitrary, Debug)]
pub struct Pool {
    min: [Number; 2],
    max: [Number; 2],
    /// Slices per side; a third element must be refused (issue 28).
    slices: Option<(i64, i64, Option<i64>)>,
    rest_height: Number,
    ior: Number,
    floor_depth: Number,
    floor: Mat,
    absorption: Option<[Number; 3]>,
    waves: Vec<Wave>,
    ripples: Vec<Ripple>,
}

/// A bubble's living-film settings.
#[derive(Arbitrary, Debug)]
pub struct FilmFlow {
    grid: i64,
    viscosity: Number,
    black_threshold: Number,
    black_film: Number,
    initial_scale: Option<[Number; 3]>,
}

/// A whole scene.
#[derive(Arbitrary, Debug)]
pub struct FuzzScene {
    pool: Option<Pool>,
    film_dt_s: Number,
    illuminant: u8,
    time_s: Number,
    eye: [Number; 3],
    target: [Number; 3],
    up: Option<[Number; 3]>,
    vfov: Number,
    env: Env,
    ground: Option<(Number, Mat)>,
    objects: Vec<Obj>,
    lights: Vec<Light>,
    bubbles: Vec<Bubble>,
    wind: Option<([Number; 3], Number)>,
    n_film: Number,
    water: bool,
    dt_s: Number,
    gravity: Option<[Number; 3]>,
    explicit: bool,
    reflection: u8,
    cube_map_size: Option<i64>,
    exposure: Number,
    samples: Option<i64>,
}

/// Small input files the scenes point at, written once per process.
pub fn files() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("bubbles-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let small = image::RgbImage::from_pixel(4, 2, image::Rgb([200, 120, 40]));
        small.save(dir.join("small.png")).expect("small.png");
        std::fs::write(dir.join("bomb.png"), bomb_png()).expect("bomb.png");
        // Linear texels past the radiance range (issue 28: 3.4e38 gave NaN pixels, 1e34
        // times intensity 1e6 a panic) and one at its edge.
        for (name, texel) in [("max.exr", 3.4e38f32), ("hot.exr", 1e34), ("edge.exr", 1e6)] {
            let mut img = image::Rgb32FImage::from_pixel(4, 2, image::Rgb([0.5; 3]));
            img.put_pixel(1, 0, image::Rgb([texel, 0.5, texel]));
            img.save(dir.join(name)).expect(name);
        }
        std::fs::write(
            dir.join("tet.obj"),
            "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
        )
        .expect("tet.obj");
        std::fs::write(dir.join("huge.obj"), "v 1e30 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n")
            .expect("huge.obj");
        std::fs::write(dir.join("ok.csv"), "wavelength_nm,value\n400,1\n550,2\n700,1\n")
            .expect("ok.csv");
        std::fs::write(dir.join("big.csv"), "wavelength_nm,value\n400,1e308\n700,1e308\n")
            .expect("big.csv");
        dir
    })
}

/// A PNG header claiming 20000 × 20000 pixels (a decompression bomb's first bytes).
fn bomb_png() -> Vec<u8> {
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(20000u32.to_be_bytes());
    ihdr.extend(20000u32.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    png.extend(13u32.to_be_bytes());
    png.extend(&ihdr);
    png.extend(crc32(&ihdr).to_be_bytes());
    png
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

const IMAGES: [&str; 7] = [
    "small.png",
    "bomb.png",
    "missing.png",
    "/dev/zero",
    "max.exr",
    "hot.exr",
    "edge.exr",
];
const MESHES: [&str; 4] = ["tet.obj", "huge.obj", "/dev/zero", "missing.obj"];
const SPECTRA: [&str; 6] = ["d65", "sodium", "f11", "ok.csv", "big.csv", "nope"];

fn pick<'a>(list: &[&'a str], i: u8) -> &'a str {
    list[usize::from(i) % list.len()]
}

fn material(m: &Mat) -> String {
    match m {
        Mat::Checker(a, s) => format!(
            "{{ kind = \"checker\", a = {}, b = [0.1, 0.1, 0.1], scale_m = {} }}",
            inline_triple(*a, [0.8, 0.8, 0.8]),
            lit(s.value(0.05))
        ),
        Mat::Solid(a, sh) => format!(
            "{{ kind = \"solid\", albedo = {}, shininess = {} }}",
            inline_triple(*a, [0.5, 0.5, 0.5]),
            lit(sh.unwrap_or(Number::Default).value(32.0))
        ),
        Mat::Image(i, s) => format!(
            "{{ kind = \"image\", path = \"{}\", scale_m = {} }}",
            pick(&IMAGES, *i),
            lit(s.value(0.1))
        ),
    }
}

impl FuzzScene {
    /// The scene as TOML, with at most 3 bubbles, 3 objects and 2 lights.
    pub fn toml(&self) -> String {
        let mut o = String::new();
        key(&mut o, "time_s", self.time_s, 0.0);
        o.push_str("[camera]\n");
        triple(&mut o, "eye_m", self.eye, [0.0, 0.1, 0.4]);
        triple(&mut o, "target_m", self.target, [0.0, 0.05, 0.0]);
        if let Some(up) = self.up {
            triple(&mut o, "up", up, [0.0, 1.0, 0.0]);
        }
        key(&mut o, "vfov_deg", self.vfov, 40.0);
        self.environment(&mut o);
        if let Some((h, m)) = &self.ground {
            o.push_str("[ground]\n");
            key(&mut o, "height_m", *h, 0.0);
            let _ = writeln!(o, "material = {}", material(m));
        }
        for obj in self.objects.iter().take(3) {
            object(&mut o, obj);
        }
        for l in self.lights.iter().take(2) {
            o.push_str("[[lights]]\n");
            triple(&mut o, "position_m", l.position, [0.5, 0.8, 0.8]);
            let _ = writeln!(o, "radius_m = {}", lit(l.radius.value(0.05)));
            let _ = writeln!(o, "spectrum = \"{}\"", pick(&SPECTRA, l.spectrum));
            key(&mut o, "luminance", l.luminance, 100.0);
        }
        if let Some(pool) = &self.pool {
            water(&mut o, pool);
        }
        for (i, b) in self.bubbles.iter().take(3).enumerate() {
            bubble(&mut o, i, b);
        }
        self.rest(&mut o);
        o
    }

    fn environment(&self, o: &mut String) {
        o.push_str("[environment]\n");
        match &self.env {
            Env::Sky(z, h, sun) => {
                o.push_str("kind = \"sky\"\n");
                triple(o, "zenith_rgb", *z, [0.25, 0.45, 0.9]);
                triple(o, "horizon_rgb", *h, [0.85, 0.9, 1.0]);
                if let Some(s) = sun {
                    triple(o, "sun_rgb", *s, [10.0, 10.0, 10.0]);
                }
            }
            Env::Uniform(c) => {
                o.push_str("kind = \"uniform\"\n");
                triple(o, "rgb", *c, [0.5, 0.5, 0.5]);
            }
            Env::Equirect(i, k) => {
                o.push_str("kind = \"equirect\"\n");
                let _ = writeln!(o, "path = \"{}\"", pick(&IMAGES, *i));
                key(o, "intensity", *k, 1.0);
            }
            Env::Cube(i, k) => {
                o.push_str("kind = \"cube\"\n");
                let face = pick(&IMAGES, *i);
                let _ = writeln!(o, "faces = [{}]", vec![format!("\"{face}\""); 6].join(", "));
                key(o, "intensity", *k, 1.0);
            }
        }
    }

    fn rest(&self, o: &mut String) {
        if let Some((v, g)) = self.wind {
            o.push_str("[wind]\n");
            triple(o, "velocity_m_per_s", v, [0.1, 0.0, 0.0]);
            key(o, "gust_m_per_s", g, 0.05);
        }
        o.push_str("[film]\n");
        key(o, "n_film", self.n_film, 1.33);
        if self.water {
            o.push_str("dispersion = \"water\"\n");
        }
        let illuminants = ["d65", "d50", "a", "e", "f11", "sodium", "nope"];
        let _ = writeln!(o, "illuminant = \"{}\"", pick(&illuminants, self.illuminant));
        o.push_str("[dynamics]\n");
        key(o, "dt_s", self.dt_s, 1.0 / 240.0);
        key(o, "film_dt_s", self.film_dt_s, 1.0 / 240.0);
        if let Some(g) = self.gravity {
            triple(o, "gravity_m_per_s2", g, [0.0, -9.81, 0.0]);
        }
        if self.explicit {
            o.push_str("integrator = \"explicit-euler\"\n");
        }
        o.push_str("[render]\n");
        let reflection = ["dynamic", "static", "sphere-map", "mirror"];
        let _ = writeln!(o, "reflection = \"{}\"", pick(&reflection, self.reflection));
        if let Some(c) = self.cube_map_size {
            let _ = writeln!(o, "cube_map_size = {c}");
        }
        key(o, "exposure", self.exposure, 1.0);
        if let Some(s) = self.samples {
            let _ = writeln!(o, "samples = {s}");
        }
    }
}

fn object(o: &mut String, obj: &Obj) {
    o.push_str("[[objects]]\n");
    match obj {
        Obj::Sphere(c, r, m) => {
            o.push_str("kind = \"sphere\"\n");
            triple(o, "center_m", *c, [0.3, 0.05, -0.2]);
            let _ = writeln!(o, "radius_m = {}", lit(r.value(0.05)));
            let _ = writeln!(o, "material = {}", material(m));
        }
        Obj::Box(lo, hi, m) => {
            o.push_str("kind = \"box\"\n");
            triple(o, "min_m", *lo, [-0.4, 0.0, -0.4]);
            triple(o, "max_m", *hi, [-0.3, 0.1, -0.3]);
            let _ = writeln!(o, "material = {}", material(m));
        }
        Obj::Mesh(i, off, s, m) => {
            o.push_str("kind = \"mesh\"\n");
            let _ = writeln!(o, "path = \"{}\"", pick(&MESHES, *i));
            triple(o, "offset_m", *off, [0.3, 0.0, 0.2]);
            key(o, "scale", *s, 1.0);
            let _ = writeln!(o, "material = {}", material(m));
        }
    }
}

const BUBBLE_KEYS: [(&str, f64); 10] = [
    ("sigma_n_per_m", 0.025),
    ("damping_per_s", 0.1),
    ("gibbs_elasticity_n_per_m", 0.05),
    ("drainage_viscosity_pa_s", 5e-8),
    ("rupture_thickness_nm", 10.0),
    ("thickness_variation", 0.2),
    ("slosh_speed_m_per_s", 0.002),
    ("evaporation_nm_per_s", 1.0),
    ("gas_molar_mass_kg_per_mol", 0.029),
    ("sigma_n_per_m", 0.025),
];

fn bubble(o: &mut String, i: usize, b: &Bubble) {
    o.push_str("[[bubbles]]\n");
    let x = -0.15 + 0.15 * i as f64;
    triple(o, "center_m", b.center, [x, 0.08, 0.0]);
    let _ = writeln!(o, "radius_m = {}", lit(b.radius.value(0.04)));
    if let Some(v) = b.velocity {
        triple(o, "velocity_m_per_s", v, [0.0, 0.1, 0.0]);
    }
    key(o, "mean_thickness_nm", b.thickness, 500.0);
    // In-range levels above 3 are legal but slow a fuzz run; out-of-range ones stay.
    let subdivisions = match b.subdivisions.unwrap_or(2) {
        s @ 0..=6 => s.min(3),
        s => s,
    };
    let _ = writeln!(o, "subdivisions = {subdivisions}");
    // The last entry repeats a key: a duplicate key must be a parse error, not a panic.
    for (n, (name, plausible)) in b.extra.iter().zip(BUBBLE_KEYS).take(9) {
        key(o, name, *n, plausible);
    }
    let _ = writeln!(o, "seed = {}", b.seed);
    if let Some(flow) = &b.flow {
        film_flow(o, flow);
    }
}

fn film_flow(o: &mut String, f: &FilmFlow) {
    // In-range grids above 16 are legal but slow a fuzz run; out-of-range ones stay.
    let grid = match f.grid {
        g @ 0..=512 => g.min(16),
        g => g,
    };
    let _ = writeln!(o, "film_grid = {grid}");
    key(o, "film_viscosity_pa_s", f.viscosity, 1e-3);
    key(o, "black_threshold_nm", f.black_threshold, 20.0);
    key(o, "black_film_nm", f.black_film, 10.0);
    if let Some(s) = f.initial_scale {
        triple(o, "initial_scale", s, [1.0, 1.0, 1.0]);
    }
}

fn pair(n: [Number; 2], plausible: [f64; 2]) -> String {
    format!("[{}, {}]", lit(n[0].value(plausible[0])), lit(n[1].value(plausible[1])))
}

/// A `[water]` section with at most 2 waves and 2 ripples and a coarse grid.
fn water(o: &mut String, p: &Pool) {
    o.push_str("[water]\n");
    let _ = writeln!(o, "min_m = {}", pair(p.min, [-1.0, -1.0]));
    let _ = writeln!(o, "max_m = {}", pair(p.max, [1.0, 1.0]));
    if let Some((x, z, extra)) = p.slices {
        // In-range sizes above 32 are legal but slow a fuzz run.
        let small = |s: i64| if (1..=512).contains(&s) { s.min(32) } else { s };
        let extra = extra.map(|e| format!(", {e}")).unwrap_or_default();
        let _ = writeln!(o, "slices = [{}, {}{extra}]", small(x), small(z));
    }
    key(o, "rest_height_m", p.rest_height, 0.0);
    key(o, "ior", p.ior, 1.333);
    key(o, "floor_depth_m", p.floor_depth, 0.5);
    let _ = writeln!(o, "floor = {}", material(&p.floor));
    if let Some(a) = p.absorption {
        triple(o, "absorption_per_m", a, [0.45, 0.06, 0.02]);
    }
    for w in p.waves.iter().take(2) {
        o.push_str("[[water.waves]]\n");
        key_always(o, "amplitude_m", w.0, 0.01);
        key_always(o, "wavelength_m", w.1, 0.3);
        let _ = writeln!(o, "direction = {}", pair(w.2, [1.0, 0.0]));
        if let Some(omega) = w.3 {
            key_always(o, "omega_rad_per_s", omega, 10.0);
        }
    }
    for r in p.ripples.iter().take(2) {
        o.push_str("[[water.ripples]]\n");
        key_always(o, "amplitude_m", r.0, 0.005);
        key_always(o, "wavelength_m", r.1, 0.1);
        let _ = writeln!(o, "center_m = {}", pair(r.2, [0.0, 0.0]));
        for (name, n, plausible) in [
            ("decay_per_m", r.3, 1.0),
            ("decay_per_s", r.4, 0.5),
            ("omega_rad_per_s", r.5, 20.0),
        ] {
            if let Some(n) = n {
                key_always(o, name, n, plausible);
            }
        }
    }
}

/// Like [`key`], but a required key is written even for [`Number::Default`].
fn key_always(out: &mut String, name: &str, n: Number, plausible: f64) {
    let _ = writeln!(out, "{name} = {}", lit(n.value(plausible)));
}

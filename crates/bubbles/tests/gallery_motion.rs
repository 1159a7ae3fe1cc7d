//! Visible physics of the gallery scenes, judged on the simulated meshes that
//! `bubbles simulate --export-obj` writes (the same meshes `animate` renders): wind
//! deforms and carries a bubble, a dropped bubble flattens on the plane and rebounds
//! without crossing it, two thrown bubbles never interpenetrate, and films drain.

use std::path::Path;
use std::process::Command;

/// One bubble of one exported frame.
#[derive(Debug, Clone)]
struct Mesh {
    positions_m: Vec<[f64; 3]>,
    thickness_nm: Vec<f64>,
    triangles: Vec<[usize; 3]>,
}

impl Mesh {
    fn center_m(&self) -> [f64; 3] {
        let n = self.positions_m.len() as f64;
        [0, 1, 2].map(|i| self.positions_m.iter().map(|p| p[i]).sum::<f64>() / n)
    }

    fn extent_m(&self, axis: usize) -> f64 {
        let (lo, hi) = self
            .positions_m
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p[axis]), hi.max(p[axis]))
            });
        hi - lo
    }

    /// Mean thickness of the vertices whose direction from the centre is within ~45° of
    /// up (`up` true) or of down.
    fn cap_thickness_nm(&self, up: bool) -> f64 {
        let c = self.center_m();
        let sign = if up { 1.0 } else { -1.0 };
        let cap: Vec<f64> = self
            .positions_m
            .iter()
            .zip(&self.thickness_nm)
            .filter(|(p, _)| {
                let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                sign * d[1] > 0.7 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            })
            .map(|(_, t)| *t)
            .collect();
        assert!(!cap.is_empty(), "no vertex in the cap");
        cap.iter().sum::<f64>() / cap.len() as f64
    }

    /// Distance from `p` to the surface: to the nearest triangle whose plane `p` projects
    /// into, else to the nearest vertex.
    fn distance_m(&self, p: [f64; 3]) -> f64 {
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let to_vertex = self
            .positions_m
            .iter()
            .map(|v| dot(sub(p, *v), sub(p, *v)).sqrt())
            .fold(f64::MAX, f64::min);
        let to_face = self
            .triangles
            .iter()
            .filter_map(|t| {
                let [a, b, c] = t.map(|i| self.positions_m[i]);
                let (e1, e2, d) = (sub(b, a), sub(c, a), sub(p, a));
                let (d11, d12, d22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
                let (d1, d2) = (dot(d, e1), dot(d, e2));
                let det = d11 * d22 - d12 * d12;
                let u = (d22 * d1 - d12 * d2) / det;
                let v = (d11 * d2 - d12 * d1) / det;
                (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then(|| {
                    let q = [0, 1, 2].map(|i| a[i] + u * e1[i] + v * e2[i]);
                    dot(sub(p, q), sub(p, q)).sqrt()
                })
            })
            .fold(f64::MAX, f64::min);
        to_vertex.min(to_face)
    }

    /// Winding number of the closed surface around `p` (1 inside, 0 outside), by the
    /// solid angle of each triangle (Van Oosterom & Strackee 1983).
    fn winding_number(&self, p: [f64; 3]) -> f64 {
        let sub = |a: [f64; 3]| [a[0] - p[0], a[1] - p[1], a[2] - p[2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let norm = |a: [f64; 3]| dot(a, a).sqrt();
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let total: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| sub(self.positions_m[i]));
                let (la, lb, lc) = (norm(a), norm(b), norm(c));
                let num = dot(a, cross(b, c));
                let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
                2.0 * num.atan2(den)
            })
            .sum();
        total / (4.0 * std::f64::consts::PI)
    }
}

/// Simulates a built-in scene for `seconds`, exporting `fps` frames per second, and
/// reads every frame back.
fn simulate(scene: &str, seconds: f64, fps: f64) -> Vec<Vec<Mesh>> {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args(["simulate", scene, "--seconds", &seconds.to_string()])
        .args(["--fps", &fps.to_string(), "--export-obj"])
        .arg(dir.path())
        .output()
        .expect("bubbles runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    names.sort();
    assert!(names.len() >= 2, "too few frames: {}", names.len());
    names.iter().map(|p| read_obj(p)).collect()
}

fn read_obj(path: &Path) -> Vec<Mesh> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut meshes: Vec<Mesh> = Vec::new();
    let mut base = 1;
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let numbers = |w: std::str::SplitWhitespace| -> Vec<f64> {
            w.map(|s| s.split('/').next().unwrap().parse().unwrap())
                .collect()
        };
        match words.next() {
            Some("o") => {
                if let Some(last) = meshes.last() {
                    base += last.positions_m.len();
                }
                meshes.push(Mesh {
                    positions_m: Vec::new(),
                    thickness_nm: Vec::new(),
                    triangles: Vec::new(),
                });
            }
            Some("v") => {
                let v = numbers(words);
                meshes
                    .last_mut()
                    .unwrap()
                    .positions_m
                    .push([v[0], v[1], v[2]]);
            }
            Some("#thickness_nm") => meshes
                .last_mut()
                .unwrap()
                .thickness_nm
                .extend(numbers(words)),
            Some("f") => {
                let f = numbers(words);
                let t = [0, 1, 2].map(|i| f[i] as usize - base);
                meshes.last_mut().unwrap().triangles.push(t);
            }
            _ => {}
        }
    }
    for m in &meshes {
        assert_eq!(
            m.positions_m.len(),
            m.thickness_nm.len(),
            "{}",
            path.display()
        );
    }
    meshes
}

#[test]
fn wind_flattens_the_bubble_by_5_percent_and_carries_it_downwind() {
    let frames = simulate("wind", 1.2, 20.0);
    // Wind along +x: the extent along the wind against the extent across it (z).
    let aspect = |m: &Mesh| m.extent_m(0) / m.extent_m(2);
    let start = aspect(&frames[0][0]);
    let moved = frames
        .iter()
        .map(|f| (aspect(&f[0]) / start - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(
        moved >= 0.05,
        "the aspect ratio moved by only {:.1} %",
        100.0 * moved
    );
    let dx = frames.last().unwrap()[0].center_m()[0] - frames[0][0].center_m()[0];
    assert!(dx > 0.2, "the bubble drifted {dx:.3} m along the wind");
}

#[test]
fn dropped_bubble_flattens_on_the_plane_rebounds_and_never_crosses_it() {
    // Every solver step (dt = 1/240 s) through contact and rebound.
    let frames = simulate("plane-collision", 0.6, 240.0);
    let lowest = frames
        .iter()
        .flat_map(|f| f[0].positions_m.iter().map(|p| p[1]))
        .fold(f64::MAX, f64::min);
    assert!(
        lowest >= -1e-9,
        "a vertex went to y = {lowest:e} m, below the plane"
    );
    let flatness = |m: &Mesh| m.extent_m(1) / m.extent_m(0);
    let (contact, squashed) = frames
        .iter()
        .enumerate()
        .map(|(k, f)| (k, flatness(&f[0])))
        .fold((0, f64::MAX), |a, b| if b.1 < a.1 { b } else { a });
    assert!(
        squashed < 0.9,
        "height/width only fell to {squashed:.3} at contact"
    );
    let y_contact = frames[contact][0].center_m()[1];
    let y_after = frames[contact..]
        .iter()
        .map(|f| f[0].center_m()[1])
        .fold(f64::MIN, f64::max);
    // It leaves at the ground's restitution, 0.3 of its arrival speed, and a soap bubble
    // is nearly as light as the air it displaces: the centre rose 0.92 R (1.2 R when the
    // contact gave back 0.85 whatever the restitution).
    let radius = frames[0][0].extent_m(0) / 2.0;
    assert!(
        y_after - y_contact > 0.5 * radius,
        "no rebound: the centre rose {:.4} m after contact",
        y_after - y_contact
    );
}

#[test]
fn thrown_bubbles_squash_together_without_passing_through_each_other() {
    let frames = simulate("bubble-collision", 0.4, 240.0);
    let mut closest = f64::MAX;
    let mut deepest: f64 = 0.0;
    for f in &frames {
        let (a, b) = (&f[0], &f[1]);
        let (ca, cb) = (a.center_m(), b.center_m());
        let gap = (0..3).map(|i| (ca[i] - cb[i]).powi(2)).sum::<f64>().sqrt();
        closest = closest.min(gap / (a.extent_m(1) / 2.0 + b.extent_m(1) / 2.0));
        for (x, y) in [(a, b), (b, a)] {
            let c = y.center_m();
            let reach = y.extent_m(0).max(y.extent_m(1)).max(y.extent_m(2));
            for p in &x.positions_m {
                let d = (0..3).map(|i| (p[i] - c[i]).powi(2)).sum::<f64>().sqrt();
                if d < reach && y.winding_number(*p) > 0.5 {
                    deepest = deepest.max(y.distance_m(*p) / (y.extent_m(1) / 2.0));
                }
            }
        }
    }
    assert!(
        closest < 0.95,
        "the bubbles never pressed together ({closest:.3})"
    );
    // The solver resolves contacts to within 1 % of a radius (bubble-dynamics'
    // collision tests); passing through would put vertices far deeper.
    eprintln!("deepest vertex: {:.3} % of a radius", 100.0 * deepest);
    assert!(
        deepest <= 0.01,
        "a vertex went {:.2} % of a radius inside the other bubble",
        100.0 * deepest
    );
}

/// Gravity drains liquid from the top of every gallery bubble to its bottom: the top
/// cap's thickness falls against the bottom cap's. (With the film flow at its scene
/// drainage viscosity, 1e-6 Pa·s, the top itself thins only a few nm in these 1–2 s, and
/// the demo's breeze can stir a thick top a little thicker; the bottom gathers what
/// drains either way.)
#[test]
fn films_drain_from_top_to_bottom_over_every_gallery_animation() {
    for (scene, seconds) in [
        ("wind", 1.2),
        ("plane-collision", 1.2),
        ("bubble-collision", 1.0),
        ("demo", 2.0),
    ] {
        let frames = simulate(scene, seconds, 5.0);
        for (i, (first, last)) in frames[0].iter().zip(frames.last().unwrap()).enumerate() {
            let ratio = |m: &Mesh| m.cap_thickness_nm(true) / m.cap_thickness_nm(false);
            let (r0, r1) = (ratio(first), ratio(last));
            eprintln!("{scene} {i}: top/bottom {r0:.3} -> {r1:.3}");
            assert!(
                r1 < 0.97 * r0,
                "{scene}: bubble {i}'s top/bottom thickness went from {r0:.3} to {r1:.3}"
            );
        }
    }
}

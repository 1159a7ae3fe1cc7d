//! Path transport: every film hit splits a beam into its reflected and transmitted parts,
//! each traced on until the film depth runs out or its weight falls below the cut-off.
//!
//! A beam carries its s- and p-polarised factors per channel (a wavelength, or an RGB
//! channel in RGB mode) and the s axis they refer to. At a film the beam is re-expressed
//! in that film's s/p axes as intensities (`cos²φ` of the old s goes to the new s), which
//! is exact when the axes agree, as they do along any chord through a sphere, and drops
//! only the s–p coherence elsewhere.
//!
//! A ray also carries its differentials across the sample's footprint (Igehy 1999), so
//! the checkered ground and objects are box-filtered over the patch the sample stands
//! for, seen directly, through films or in a film's curved mirror, instead of being
//! point-sampled: most of the 16-ray reference's noise was the distant checker aliasing.

use glam::Vec3;
use thinfilm::{Response, ThinFilm};

use crate::geometry::{Geometry, Hit, blend};
use crate::spectral::{Grid, MAX_WAVELENGTHS};
use crate::upsample::Uplift;
use crate::{FilmSpec, ReferenceSettings, Reflections};
use render_scene::shading::{ground_albedo, lit, object_albedo};

/// Per-channel s and p factors of a beam and its s axis (`None`: unpolarised so far).
#[derive(Debug, Clone)]
pub(crate) struct Beam {
    s: [f64; MAX_WAVELENGTHS],
    p: [f64; MAX_WAVELENGTHS],
    s_axis: Option<Vec3>,
}

impl Beam {
    /// An unpolarised beam of factor 1.
    pub fn unit() -> Beam {
        Beam {
            s: [1.0; MAX_WAVELENGTHS],
            p: [1.0; MAX_WAVELENGTHS],
            s_axis: None,
        }
    }

    fn weight(&self, n: usize) -> f64 {
        self.s[..n]
            .iter()
            .chain(&self.p[..n])
            .fold(0.0, |m, &x| m.max(x.abs()))
    }

    /// Re-expresses the beam in axes whose s direction is `s_axis` (unit).
    fn rotate_to(&mut self, s_axis: Vec3, n: usize) {
        if let Some(old) = self.s_axis {
            let c2 = f64::from(old.dot(s_axis)).powi(2).min(1.0);
            for k in 0..n {
                let (s, p) = (self.s[k], self.p[k]);
                self.s[k] = c2 * s + (1.0 - c2) * p;
                self.p[k] = (1.0 - c2) * s + c2 * p;
            }
        }
        self.s_axis = Some(s_axis);
    }
}

/// A ray and how its origin and direction change across the sample's footprint, one
/// differential per image axis (Igehy 1999).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub d_origin: [Vec3; 2],
    pub d_dir: [Vec3; 2],
}

impl Ray {
    /// How the hit point at distance `t` on a plane of normal `n` moves (transfer).
    fn hit_differentials(&self, t: f32, n: Vec3) -> [Vec3; 2] {
        let cos = self.dir.dot(n);
        [0, 1].map(|k| {
            let q = self.d_origin[k] + self.d_dir[k] * t;
            let moved = q - self.dir * (q.dot(n) / cos);
            // A grazing plane: the footprint is unbounded; the filter then gives the mean.
            if moved.is_finite() {
                moved
            } else {
                Vec3::splat(1e9)
            }
        })
    }

    /// The ray continuing from `origin` along `dir` with differentials `d_origin`, `d_dir`.
    fn next(origin: Vec3, dir: Vec3, d_origin: [Vec3; 2], d_dir: [Vec3; 2]) -> Ray {
        Ray {
            origin,
            dir,
            d_origin,
            d_dir,
        }
    }
}

/// Per axis, the extent of the box bounding the parallelogram the two differentials span.
fn extent(d: [Vec3; 2]) -> Vec3 {
    (d[0].abs() + d[1].abs()).min(Vec3::splat(1e9))
}

/// The normal of triangle `[a, b, c]` (unit; any sign).
fn plane_normal([a, b, c]: [Vec3; 3]) -> Vec3 {
    (b - a).cross(c - a).normalize_or(Vec3::Y)
}

/// Barycentric `(du, dv)` of a move `dp` within triangle `[a, b, c]` (least squares).
fn barycentric_move([a, b, c]: [Vec3; 3], dp: Vec3) -> (f32, f32) {
    let (e1, e2) = (b - a, c - a);
    let (a11, a12, a22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (b1, b2) = (e1.dot(dp), e2.dot(dp));
    let det = a11 * a22 - a12 * a12;
    if det.abs() <= f32::MIN_POSITIVE {
        return (0.0, 0.0);
    }
    ((a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det)
}

/// A film's response per channel.
struct FilmFactors {
    r_s: [f64; MAX_WAVELENGTHS],
    r_p: [f64; MAX_WAVELENGTHS],
    t_s: [f64; MAX_WAVELENGTHS],
    t_p: [f64; MAX_WAVELENGTHS],
}

/// Everything a path needs, shared by all pixels.
pub(crate) struct Tracer<'a> {
    pub geo: Geometry<'a>,
    pub grid: Grid,
    pub uplift: Uplift,
    /// Per light, per grid wavelength: the linear RGB its emission adds (spectral mode).
    pub light_rgb: Vec<Vec<[f64; 3]>>,
    pub spec: &'a FilmSpec,
    pub settings: &'a ReferenceSettings,
    /// Sky irradiance plus the scene's ambient term, as the CPU backend lights surfaces.
    pub ambient: render_scene::Irradiance,
}

impl Tracer<'_> {
    /// Channels a beam carries: the wavelengths, or 3 in RGB mode.
    fn channels(&self) -> usize {
        if self.settings.spectral {
            self.grid.len()
        } else {
            3
        }
    }

    /// Adds the linear RGB radiance arriving along the ray to `out`, weighted by `beam`.
    pub fn trace(
        &self,
        ray: &Ray,
        beam: &Beam,
        films_left: u32,
        skip: Option<u32>,
        out: &mut [f64; 3],
    ) {
        let scene = self.geo.scene;
        let (origin, dir) = (ray.origin, ray.dir);
        match self.geo.closest(origin, dir, films_left > 0, skip) {
            None => self.add_rgb(scene.environment.radiance(dir), beam, out),
            Some(Hit::Light { light }) => self.add_light(light, beam, out),
            Some(Hit::Ground { t }) => {
                let d = extent(ray.hit_differentials(t, Vec3::Y));
                let rgb = self.shade_ground(origin + dir * t, dir, [d.x, d.z]);
                self.add_rgb(rgb, beam, out);
            }
            Some(Hit::Opaque { tri, t, u, v }) => {
                let n = plane_normal(self.geo.opaque_tris[tri as usize]);
                let d = extent(ray.hit_differentials(t, n));
                let rgb = self.shade_object(tri, origin + dir * t, dir, (u, v), d);
                self.add_rgb(rgb, beam, out);
            }
            Some(Hit::Film { tri, t, u, v }) => {
                self.film(tri, ray, t, (u, v), beam, films_left, out);
            }
        }
    }

    /// The film's shading normal at `(u, v)` facing the ray, and how it turns across the
    /// footprint when the hit point moves by `dp` (the blended vertex normals' derivative).
    fn film_normal(
        &self,
        tri: u32,
        (u, v): (f32, f32),
        dir: Vec3,
        dp: [Vec3; 2],
    ) -> (Vec3, [Vec3; 2]) {
        let (b, idx) = self.geo.bubble_owner[tri as usize];
        let normals = idx.map(|i| self.geo.scene.bubbles[b as usize].normals[i as usize]);
        let raw = blend(normals, u, v);
        let len = raw.length();
        let n = if len > 0.0 && len.is_finite() {
            raw / len
        } else {
            -dir
        };
        let sign = if dir.dot(n) > 0.0 { -1.0 } else { 1.0 };
        let corners = self.geo.bubble_tris[tri as usize];
        let dn = dp.map(|d| {
            let (du, dv) = barycentric_move(corners, d);
            let d_raw = (normals[1] - normals[0]) * du + (normals[2] - normals[0]) * dv;
            let turn = (d_raw - n * d_raw.dot(n)) / len.max(f32::MIN_POSITIVE);
            if turn.is_finite() {
                turn * sign
            } else {
                Vec3::ZERO
            }
        });
        (n * sign, dn)
    }

    #[allow(clippy::too_many_arguments)]
    fn film(
        &self,
        tri: u32,
        ray: &Ray,
        t: f32,
        (u, v): (f32, f32),
        beam: &Beam,
        films_left: u32,
        out: &mut [f64; 3],
    ) {
        let (b, idx) = self.geo.bubble_owner[tri as usize];
        let mesh = &self.geo.scene.bubbles[b as usize];
        let dir = ray.dir;
        let p = ray.origin + dir * t;
        let dp = ray.hit_differentials(t, plane_normal(self.geo.bubble_tris[tri as usize]));
        let (n, dn) = self.film_normal(tri, (u, v), dir, dp);
        let through = Ray::next(p, dir, dp, ray.d_dir);
        let cos_theta = f64::from(-dir.dot(n)).clamp(0.0, 1.0);
        // A film field gives thickness and coverage at the hit's material direction, read
        // through the same `FilmField::sample` as the real-time backends.
        let (thickness_nm, coverage) = match &mesh.film {
            None => (blend(idx.map(|i| mesh.thickness_nm[i as usize]), u, v), 1.0),
            Some(film) => {
                let dir_m = blend(idx.map(|i| film.material_dirs[i as usize]), u, v);
                let s = film.field.sample(dir_m);
                (s.thickness_nm, s.coverage)
            }
        };
        if coverage <= 0.0 {
            // A hole: the ray goes on as if this film were not there.
            self.trace(&through, beam, films_left, Some(tri), out);
            return;
        }
        let thickness_nm = f64::from(thickness_nm).max(0.0);
        let mut f = self.film_factors(thickness_nm, cos_theta);
        if coverage < 1.0 {
            // Coverage c blends the film in: R' = c·R, T' = 1 − c·(1 − T).
            let c = f64::from(coverage);
            for k in 0..MAX_WAVELENGTHS {
                f.r_s[k] *= c;
                f.r_p[k] *= c;
                f.t_s[k] = 1.0 - c * (1.0 - f.t_s[k]);
                f.t_p[k] = 1.0 - c * (1.0 - f.t_p[k]);
            }
        }
        let ch = self.channels();
        let mut beam = beam.clone();
        let s_axis = dir.cross(n).normalize_or_zero();
        if s_axis != Vec3::ZERO {
            beam.rotate_to(s_axis, ch);
        }
        let mut reflected = beam.clone();
        let mut transmitted = beam;
        for k in 0..ch {
            reflected.s[k] *= f.r_s[k];
            reflected.p[k] *= f.r_p[k];
            transmitted.s[k] *= f.t_s[k];
            transmitted.p[k] *= f.t_p[k];
        }
        let min = self.settings.min_weight;
        if reflected.weight(ch) >= min {
            let (origin, films, d_origin) = match self.settings.reflections {
                Reflections::Traced => (p, films_left - 1, dp),
                Reflections::NoFilms => (p, 0, dp),
                Reflections::FromCentre => (self.geo.centres[b as usize], 0, [Vec3::ZERO; 2]),
            };
            let mirror = reflect(ray, n, dn);
            let r = Ray::next(origin, mirror.dir, d_origin, mirror.d_dir);
            self.trace(&r, &reflected, films, Some(tri), out);
        }
        if transmitted.weight(ch) >= min {
            self.trace(&through, &transmitted, films_left - 1, Some(tri), out);
        }
    }

    /// The film's s/p reflectance and transmittance per channel.
    fn film_factors(&self, thickness_nm: f64, cos_theta: f64) -> FilmFactors {
        let film = ThinFilm::symmetric(self.spec.n_outside, self.spec.n_film, thickness_nm);
        let mut f = FilmFactors {
            r_s: [0.0; MAX_WAVELENGTHS],
            r_p: [0.0; MAX_WAVELENGTHS],
            t_s: [0.0; MAX_WAVELENGTHS],
            t_p: [0.0; MAX_WAVELENGTHS],
        };
        for (k, &w) in self.grid.wavelength_nm.iter().enumerate() {
            // The spec and grid were validated, so this cannot fail; a failure would show
            // as a transparent film rather than a NaN pixel.
            let r = film.try_response(w, cos_theta).unwrap_or(Response {
                r_s: 0.0,
                r_p: 0.0,
                t_s: 1.0,
                t_p: 1.0,
            });
            check_energy(&r, w, thickness_nm, cos_theta);
            let r = if self.settings.polarised {
                r
            } else {
                let (rr, tt) = (r.r(), r.t());
                Response {
                    r_s: rr,
                    r_p: rr,
                    t_s: tt,
                    t_p: tt,
                }
            };
            (f.r_s[k], f.r_p[k], f.t_s[k], f.t_p[k]) = (r.r_s, r.r_p, r.t_s, r.t_p);
        }
        if !self.settings.spectral {
            f = self.project_rgb(&f);
        }
        f
    }

    /// RGB mode: each factor projected to RGB as the LUT bakes it (reference-white weights).
    fn project_rgb(&self, f: &FilmFactors) -> FilmFactors {
        let project = |x: &[f64; MAX_WAVELENGTHS]| {
            let rgb = self.uplift.rgb_of(&x[..self.grid.len()]);
            let mut out = [0.0; MAX_WAVELENGTHS];
            out[..3].copy_from_slice(&rgb);
            out
        };
        FilmFactors {
            r_s: project(&f.r_s),
            r_p: project(&f.r_p),
            t_s: project(&f.t_s),
            t_p: project(&f.t_p),
        }
    }

    /// Adds RGB radiance (upsampled to a spectrum in spectral mode) through `beam`.
    fn add_rgb(&self, rgb: [f32; 3], beam: &Beam, out: &mut [f64; 3]) {
        if !self.settings.spectral {
            for c in 0..3 {
                out[c] += f64::from(rgb[c]) * 0.5 * (beam.s[c] + beam.p[c]);
            }
            return;
        }
        let mut s = [0.0; MAX_WAVELENGTHS];
        self.uplift.spectrum(rgb, &mut s);
        for (k, w) in self.grid.reference_rgb.iter().enumerate() {
            let f = s[k] * 0.5 * (beam.s[k] + beam.p[k]);
            for c in 0..3 {
                out[c] += w[c] * f;
            }
        }
    }

    /// Adds light `light`'s emission (its own spectrum in spectral mode) through `beam`.
    fn add_light(&self, light: usize, beam: &Beam, out: &mut [f64; 3]) {
        if !self.settings.spectral {
            let rgb = self.geo.scene.lights[light].radiance;
            self.add_rgb(rgb, beam, out);
            return;
        }
        for (k, w) in self.light_rgb[light].iter().enumerate() {
            let f = 0.5 * (beam.s[k] + beam.p[k]);
            for c in 0..3 {
                out[c] += w[c] * f;
            }
        }
    }

    /// The ground at `p`, its checker box-filtered over `footprint` (metres along x, z).
    fn shade_ground(&self, p: Vec3, dir: Vec3, footprint: [f32; 2]) -> [f32; 3] {
        let scene = self.geo.scene;
        let Some(g) = &scene.ground else {
            return [0.0; 3];
        };
        let footprint = if self.settings.filter_textures {
            footprint
        } else {
            [0.0; 2]
        };
        let albedo = ground_albedo(&g.material, p.x, p.z, footprint);
        lit(
            &g.material,
            albedo,
            p,
            Vec3::Y,
            dir,
            &self.ambient,
            &scene.lights,
        )
    }

    /// Opaque triangle `tri` at `p`, a checker box-filtered over `footprint` (metres per axis).
    fn shade_object(
        &self,
        tri: u32,
        p: Vec3,
        dir: Vec3,
        (u, v): (f32, f32),
        footprint: Vec3,
    ) -> [f32; 3] {
        let scene = self.geo.scene;
        let (o, idx) = self.geo.opaque_owner[tri as usize];
        let mesh = &self.geo.meshes[o as usize];
        let n = blend(idx.map(|i| mesh.normals[i as usize]), u, v).normalize_or(-dir);
        let uv = if mesh.uvs.len() == mesh.positions.len() {
            let [a, b, c] = idx.map(|i| glam::Vec2::from(mesh.uvs[i as usize]));
            blend([a, b, c], u, v).to_array()
        } else {
            [0.0; 2]
        };
        let material = scene.objects[o as usize].material();
        let footprint = if self.settings.filter_textures {
            footprint.to_array()
        } else {
            [0.0; 3]
        };
        let albedo = object_albedo(material, p, uv, footprint);
        lit(material, albedo, p, n, dir, &self.ambient, &scene.lights)
    }
}

/// The mirror direction of `ray` about unit normal `n` and its differentials, the normal
/// turning by `dn` across the footprint (Igehy 1999, eq. 14).
fn reflect(ray: &Ray, n: Vec3, dn: [Vec3; 2]) -> Ray {
    let d = ray.dir;
    let cos = d.dot(n);
    let dir = (d - n * (2.0 * cos)).normalize_or(-d);
    let d_dir = [0, 1].map(|k| {
        let dd = ray.d_dir[k];
        dd - (dn[k] * cos + n * (dd.dot(n) + d.dot(dn[k]))) * 2.0
    });
    Ray::next(ray.origin, dir, [Vec3::ZERO; 2], d_dir)
}

/// A lossless film conserves energy at every hit: `R + T = 1` for s and p (debug builds).
#[inline]
fn check_energy(r: &Response, wavelength_nm: f64, thickness_nm: f64, cos_theta: f64) {
    debug_assert!(
        (r.r_s + r.t_s - 1.0).abs() < 1e-9 && (r.r_p + r.t_p - 1.0).abs() < 1e-9,
        "film {thickness_nm} nm, cos θ {cos_theta}, {wavelength_nm} nm: R + T = {} (s), {} (p)",
        r.r_s + r.t_s,
        r.r_p + r.t_p
    );
}

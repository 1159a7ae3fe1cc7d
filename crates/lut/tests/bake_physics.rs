//! The baked tables against independent truth: the f64 Airy path of `thinfilm`, a
//! closed-form Airy reflectance written out here, energy conservation, and the limits
//! of grazing incidence and vanishing thickness.

use lut::{BakeConfig, Light, LutSet};
use num_complex::Complex64;
use proptest::prelude::*;
use thinfilm::airy::ThinFilm;
use thinfilm::cells::cell_threshold_nm;
use thinfilm::cmf::Observer;
use thinfilm::colorspace::{SRGB_FROM_XYZ, XYZ_FROM_SRGB, apply};
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::SpectralIntegrator;
use thinfilm::spectrum::Spectrum;

fn assert_close(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got}, want {want}, difference {:e} > {tol:e}",
        got - want
    );
}

fn small(builder: lut::BakeConfigBuilder) -> BakeConfig {
    builder.resolution(48, 12).build().expect("valid config")
}

fn film(config: &BakeConfig, thickness_nm: f32) -> ThinFilm {
    ThinFilm {
        n_outside: 1.0,
        n_film: *config.film_index(),
        n_substrate: Complex64::new(1.0, 0.0),
        thickness_nm: f64::from(thickness_nm),
    }
}

/// Linear sRGB of the film under `light` by the f64 path, `reflect` choosing R or T.
fn direct_rgb(config: &BakeConfig, light: &Light, d: f32, c: f32, reflect: bool) -> [f64; 3] {
    let integrator = SpectralIntegrator::new(config.observer(), light.spectrum(), config.step_nm())
        .expect("valid light");
    let film = film(config, d);
    let xyz = if reflect {
        integrator.film_xyz(&film, f64::from(c))
    } else {
        integrator.film_transmitted_xyz(&film, f64::from(c))
    };
    apply(&SRGB_FROM_XYZ, xyz)
}

fn reference_white_rgb(config: &BakeConfig) -> [f64; 3] {
    let integrator = SpectralIntegrator::new(
        config.observer(),
        config.reference().spectrum(),
        config.step_nm(),
    )
    .expect("valid light");
    apply(&SRGB_FROM_XYZ, integrator.white_xyz())
}

/// Every texel of every table against the f64 Airy path at the texel's (d, cos θ).
fn check_against_airy(config: &BakeConfig, set: &LutSet, tol: f64) {
    let white = reference_white_rgb(config);
    let lut = &set.reflectivity;
    for j in 0..lut.height() {
        for i in 0..lut.width() {
            let (d, c) = (lut.thickness_nm_at(i), lut.cos_theta_at(j));
            let r = direct_rgb(config, config.reference(), d, c, true);
            let t = direct_rgb(config, config.reference(), d, c, false);
            for k in 0..3 {
                let at = format!("texel ({i}, {j}) d={d} cos={c} channel {k}");
                let got = f64::from(set.reflectivity.texel(i, j)[k]);
                assert_close(&format!("R {at}"), got, r[k] / white[k], tol);
                let got = f64::from(set.transmittance.texel(i, j)[k]);
                assert_close(&format!("T {at}"), got, t[k] / white[k], tol);
            }
            for (light, (name, table)) in config.lights().iter().zip(&set.lights) {
                let want = direct_rgb(config, light, d, c, true);
                for (k, (got, want)) in table.texel(i, j).into_iter().zip(want).enumerate() {
                    let what = format!("light {name} texel ({i}, {j}) ch {k}");
                    assert_close(&what, f64::from(got), want, tol);
                }
            }
        }
    }
}

#[test]
fn default_settings_match_the_f64_airy_path_at_every_texel() {
    let config = small(BakeConfig::builder());
    check_against_airy(&config, &lut::bake(&config), 2e-5);
}

#[test]
fn dispersive_film_other_observer_and_lights_match_the_f64_airy_path() {
    let config = small(
        BakeConfig::builder()
            .film_index(RefractiveIndex::Water)
            .observer(Observer::Cie1964)
            .step_nm(10.0)
            .thickness_max_nm(1200.0)
            .reference(Light::illuminant(Illuminant::D50))
            .lights(
                [Illuminant::A, Illuminant::F11, Illuminant::Sodium]
                    .map(Light::illuminant)
                    .to_vec(),
            ),
    );
    check_against_airy(&config, &lut::bake(&config), 2e-5);
}

/// Unpolarised reflectance of a free film `1 | n | 1`, Airy's sum of all orders written
/// from the Fresnel coefficients: `R = F sin²(δ/2) / (1 + F sin²(δ/2))`, `F = 4ρ²/(1 − ρ²)²`.
fn airy_closed_form(n: f64, thickness_nm: f64, cos_theta: f64, wavelength_nm: f64) -> f64 {
    let sin2 = 1.0 - cos_theta * cos_theta;
    let n_cos_t = (n * n - sin2).sqrt();
    let rho_s = (cos_theta - n_cos_t) / (cos_theta + n_cos_t);
    let rho_p = (n * n * cos_theta - n_cos_t) / (n * n * cos_theta + n_cos_t);
    let half_delta = 2.0 * std::f64::consts::PI * n_cos_t * thickness_nm / wavelength_nm;
    let s2 = half_delta.sin().powi(2);
    let r = |rho: f64| {
        let f = 4.0 * rho * rho / (1.0 - rho * rho).powi(2);
        f * s2 / (1.0 + f * s2)
    };
    0.5 * (r(rho_s) + r(rho_p))
}

#[test]
fn a_single_line_light_gives_the_closed_form_airy_reflectance_as_luminance() {
    let wavelength_nm = 532.0;
    let line = Spectrum::from_lines(vec![(wavelength_nm, 1.0)]).expect("valid line");
    let config = BakeConfig::builder()
        .resolution(97, 23)
        .film_index(RefractiveIndex::Constant(1.38))
        .lights(vec![Light::try_new("laser", line).expect("valid name")])
        .build()
        .expect("valid config");
    let set = lut::bake(&config);
    let table = set.light("laser").expect("baked");
    for j in 1..table.height() {
        for i in 0..table.width() {
            let (d, c) = (table.thickness_nm_at(i), table.cos_theta_at(j));
            let y = apply(&XYZ_FROM_SRGB, table.texel(i, j).map(f64::from))[1];
            let want = airy_closed_form(1.38, f64::from(d), f64::from(c), wavelength_nm);
            assert_close(&format!("Y at d={d} cos={c}"), y, want, 2e-6);
        }
    }
}

/// The reflectivity weights rebuilt here from the integrator: linear sRGB per sample,
/// divided by the reference white, as f32 for the kernel.
fn reflectivity_weights(config: &BakeConfig) -> (Vec<f32>, Vec<f32>, Vec<[f32; 3]>) {
    let integrator = SpectralIntegrator::new(
        config.observer(),
        config.reference().spectrum(),
        config.step_nm(),
    )
    .expect("valid light");
    let white = reference_white_rgb(config);
    let mut out = (Vec::new(), Vec::new(), Vec::new());
    for (&l, w) in integrator.wavelengths_nm().iter().zip(integrator.weights()) {
        let rgb = apply(&SRGB_FROM_XYZ, *w);
        out.0.push(l as f32);
        out.1.push(config.film_index().n_at(l) as f32);
        out.2
            .push(std::array::from_fn(|k| (rgb[k] / white[k]) as f32));
    }
    out
}

#[test]
fn transmittance_table_matches_the_transmittance_formula_of_the_f32_kernel() {
    let config = BakeConfig::builder()
        .resolution(256, 64)
        .film_index(RefractiveIndex::Water)
        .build()
        .expect("valid config");
    let set = lut::bake(&config);
    let (wavelength_nm, n_film, weights) = reflectivity_weights(&config);
    let integrator = SpectralIntegrator::new(
        config.observer(),
        config.reference().spectrum(),
        config.step_nm(),
    )
    .expect("valid light");
    let cells = integrator.cells().expect("an even grid");
    let thickness_nm: Vec<f32> = (0..256)
        .map(|i| set.transmittance.thickness_nm_at(i))
        .collect();
    let mut worst = 0.0f32;
    for j in 0..64 {
        let mut r = vec![[0.0f32; 3]; 256];
        let mut t = vec![[0.0f32; 3]; 256];
        thinfilm::batch::try_weighted_response_row(
            1.0,
            set.transmittance.cos_theta_at(j),
            &wavelength_nm,
            &n_film,
            &weights,
            &thickness_nm,
            &mut r,
            &mut t,
        )
        .expect("valid row");
        // Films thick enough for cell means (near grazing) are integrated another way.
        let cos = f64::from(set.transmittance.cos_theta_at(j));
        let point_texels = cell_threshold_nm(cells, 1.0, config.film_index(), cos)
            .map_or(256, |t| thickness_nm.partition_point(|&d| f64::from(d) < t));
        for (i, own) in t.iter().enumerate().take(point_texels) {
            let baked = set.transmittance.texel(i, j);
            for k in 0..3 {
                worst = worst.max((own[k] - baked[k]).abs());
            }
        }
    }
    assert!(
        worst < 4e-6,
        "baked T differs from the kernel's own T formula by {worst:e}"
    );
}

#[test]
fn grazing_row_is_a_perfect_mirror_and_zero_thickness_column_is_invisible() {
    let config = small(
        BakeConfig::builder().lights(
            [Illuminant::Sodium, Illuminant::F11, Illuminant::A]
                .map(Light::illuminant)
                .to_vec(),
        ),
    );
    let set = lut::bake(&config);
    for i in 0..set.reflectivity.width() {
        for k in 0..3 {
            assert_close(
                "R at grazing",
                f64::from(set.reflectivity.texel(i, 0)[k]),
                1.0,
                2e-6,
            );
            assert_close(
                "T at grazing",
                f64::from(set.transmittance.texel(i, 0)[k]),
                0.0,
                2e-6,
            );
        }
        // Each light reflected by a perfect mirror is the light itself: Y = 1.
        for (name, table) in &set.lights {
            let y = apply(&XYZ_FROM_SRGB, table.texel(i, 0).map(f64::from))[1];
            assert_close(&format!("Y of {name} at grazing"), y, 1.0, 2e-6);
        }
    }
    for j in 1..set.reflectivity.height() {
        for k in 0..3 {
            assert_close(
                "R at d = 0",
                f64::from(set.reflectivity.texel(0, j)[k]),
                0.0,
                1e-7,
            );
            assert_close(
                "T at d = 0",
                f64::from(set.transmittance.texel(0, j)[k]),
                1.0,
                2e-6,
            );
        }
    }
}

#[test]
fn bake_is_bit_identical_at_any_thread_count() {
    let config = BakeConfig::builder()
        .resolution(300, 40)
        .build()
        .expect("valid config");
    let bake_on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| lut::bake(&config))
    };
    let one = bake_on(1);
    assert_eq!(one, bake_on(2));
    assert_eq!(one, bake_on(5));
}

#[test]
fn progress_reports_every_kernel_row() {
    let config = small(BakeConfig::builder());
    let rows = std::sync::atomic::AtomicUsize::new(0);
    let set = lut::bake_with_progress(&config, &|| {
        rows.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    });
    assert_eq!(rows.into_inner(), lut::progress_rows(&config));
    assert_eq!(set, lut::bake(&config));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Whatever the settings: finite texels, luminance of the reflection within [0, 1]
    /// (each R(λ) is, and the weights of Y are non-negative), and energy conserved: the
    /// transmittance texels (the bake's 1 − R) equal T integrated from the film's own
    /// transmittance spectrum, at the middle texel. (R + T = 1 of the tables alone would
    /// be an identity: the bake derives T from R.)
    #[test]
    fn any_valid_bake_is_finite_bounded_and_conserves_energy(
        width in 2usize..40,
        height in 2usize..12,
        thickness_max_nm in 1.0f32..20_000.0,
        step_nm in 1.0f64..50.0,
        n in 1.0f64..2.5,
        observer in prop::sample::select(Observer::ALL.to_vec()),
        reference in prop::sample::select(vec![Illuminant::D65, Illuminant::D50, Illuminant::E, Illuminant::F2]),
    ) {
        let config = BakeConfig::builder()
            .resolution(width, height)
            .thickness_max_nm(thickness_max_nm)
            .step_nm(step_nm)
            .film_index(RefractiveIndex::Constant(n))
            .observer(observer)
            .reference(Light::illuminant(reference))
            .build()
            .expect("valid config");
        let set = lut::bake(&config);
        let white = reference_white_rgb(&config);
        for (r, t) in set.reflectivity.texels().iter().zip(set.transmittance.texels()) {
            let absolute = std::array::from_fn(|k| f64::from(r[k]) * white[k]);
            let y = apply(&XYZ_FROM_SRGB, absolute)[1];
            prop_assert!((-1e-6..=1.0 + 1e-6).contains(&y), "Y = {y}");
            prop_assert!(r.iter().chain(t).all(|c| c.is_finite()));
        }
        let (i, j) = (width / 2, height / 2);
        let (d, c) = (set.transmittance.thickness_nm_at(i), set.transmittance.cos_theta_at(j));
        let t = direct_rgb(&config, config.reference(), d, c, false);
        for k in 0..3 {
            let got = f64::from(set.transmittance.texel(i, j)[k]);
            let want = t[k] / white[k];
            prop_assert!((got - want).abs() < 2e-5, "T[{}] at d={} cos={}: texel {} vs spectrum {}", k, d, c, got, want);
        }
    }
}

#[test]
fn an_index_matched_film_is_invisible_and_thick_films_stay_finite() {
    let config = small(BakeConfig::builder().film_index(RefractiveIndex::Constant(1.0)));
    let set = lut::bake(&config);
    for (r, t) in set
        .reflectivity
        .texels()
        .iter()
        .zip(set.transmittance.texels())
    {
        for k in 0..3 {
            assert_close("R of an index-matched film", f64::from(r[k]), 0.0, 1e-7);
            assert_close("T of an index-matched film", f64::from(t[k]), 1.0, 1e-7);
        }
    }
    let thick = small(BakeConfig::builder().thickness_max_nm(lut::config::MAX_THICKNESS_NM));
    let set = lut::bake(&thick);
    // 100 µm is ~450 periods of phase, and the kernel takes wavelengths in f32 (589.6 nm
    // is off by 2e-5 nm): ~2e-5 periods of phase, amplified near grazing by sharp fringes.
    check_against_airy(&thick, &set, 5e-4);
}

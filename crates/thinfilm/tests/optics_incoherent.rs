//! Incoherent layers against independent truth: the closed form of a bare slab, the phase
//! average of the coherent stack (an incoherent layer is a coherent one whose round-trip
//! phase is averaged away), Byrnes' 2×2 intensity matrices built here from separate
//! coherent stacks, Beer–Lambert, and energy conservation.

mod optics_common;

use num_complex::Complex64;
use optics_common::{assert_close, re};
use proptest::prelude::*;
use thinfilm::fresnel::Response;
use thinfilm::{Interface, Layer, OpticsError, Stack};

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 96,
        ..ProptestConfig::default()
    }
}

/// `(R_s, R_p)` and `(T_s, T_p)` of a response.
fn pols(resp: Response) -> [(f64, f64); 2] {
    [(resp.r_s, resp.t_s), (resp.r_p, resp.t_p)]
}

#[test]
fn bare_lossless_slab_is_the_closed_form_sum_of_intensities() {
    // A 1 mm glass slide in air: R = R1 + T1² R1 / (1 − R1²), T = T1² / (1 − R1²), with R1
    // the single air/glass interface's reflectance (the same from either side, lossless).
    let glass = 1.52;
    let slide = Stack::new(1.0, vec![Layer::incoherent(glass, 1e6)], 1.0).unwrap();
    let surface = Interface::new(1.0, re(glass)).unwrap();
    for cos in [1.0, 0.9, 0.5, 0.2, 0.01] {
        let one = surface.response(cos);
        let resp = slide.try_response(550.0, cos).unwrap();
        for ((r, t), (r1, _)) in pols(resp).into_iter().zip(pols(one)) {
            let t1 = 1.0 - r1;
            let expected_r = r1 + t1 * t1 * r1 / (1.0 - r1 * r1);
            assert_close(&format!("R at cos {cos}"), r, expected_r, 1e-15);
            assert_close(
                &format!("T at cos {cos}"),
                t,
                t1 * t1 / (1.0 - r1 * r1),
                1e-15,
            );
        }
        // Head-on: R = 2 R1 / (1 + R1), 8.2 % for a plate of n = 1.52.
        if cos == 1.0 {
            let r1 = one.r_s;
            assert_close("2 R1 / (1 + R1)", resp.r(), 2.0 * r1 / (1.0 + r1), 1e-15);
        }
    }
}

#[test]
fn a_lossless_incoherent_layer_ignores_its_thickness_and_wavelength() {
    let at = |d: f64, l: f64| {
        Stack::new(1.0, vec![Layer::incoherent(1.52, d)], 1.33)
            .unwrap()
            .try_response(l, 0.8)
            .unwrap()
    };
    let reference = at(1e6, 550.0);
    for (d, l) in [(0.0, 550.0), (123.4, 550.0), (3e6, 550.0), (1e6, 700.0)] {
        assert_eq!(at(d, l), reference, "d {d} nm, λ {l} nm");
    }
}

#[test]
fn absorbing_index_matched_slab_follows_beer_lambert() {
    // n = 1.5 + iκ between two n = 1.5 media: each interface reflects R1 = κ²/(4n² + κ²)
    // ≈ 1.1e-11, so T = (1 − R1)² exp(−4πκd/λ), and R ≤ 2 R1. Byrnes' power ratio into and
    // out of an absorbing medium counts the forward wave's flux alone, which is exact only
    // to O(κ²/n²) (here T_f T_b = 1 + κ²/2n² at an interface pair): that is the tolerance.
    let (n, kappa, l) = (1.5, 1e-5, 600.0);
    for d in [1e5, 1e6, 1e7] {
        let stack = Stack::new(n, vec![Layer::incoherent(Complex64::new(n, kappa), d)], n).unwrap();
        let resp = stack.try_response(l, 1.0).unwrap();
        let beer = (-4.0 * std::f64::consts::PI * kappa * d / l).exp();
        let r1 = kappa * kappa / (4.0 * n * n + kappa * kappa);
        let expected = (1.0 - r1) * (1.0 - r1) * beer;
        assert_close(
            &format!("T at {d} nm"),
            resp.t(),
            expected,
            kappa * kappa / (n * n),
        );
        assert!(resp.r() <= 2.0 * r1, "R = {}", resp.r());
    }
}

#[test]
fn absorbing_slab_on_a_mirror_loses_its_attenuation_twice() {
    // 1.5 | 1.5 + iκ (incoherent, one pass keeps P = e^{−1/(2 cos θ)}) | metal: the light crosses
    // the slab, reflects off the metal and crosses back, R = P² R_metal / (1 − R_b P² R_metal)
    // with R_b ≈ (κ/2n)² ≈ 1e-15, and R_metal the 1.5 | metal interface's to O(κ).
    let (n, kappa, l) = (1.5, 1e-7, 600.0);
    let d = 0.5 * l / (4.0 * std::f64::consts::PI * kappa);
    let metal = Complex64::new(0.2, 3.5);
    let stack = Stack::new(
        n,
        vec![Layer::incoherent(Complex64::new(n, kappa), d)],
        metal,
    )
    .unwrap();
    let mirror = Interface::new(n, metal).unwrap();
    for cos in [1.0f64, 0.7] {
        // Index-matched: the path inside the slab is d / cos θ.
        let pass = (-0.5 / cos).exp();
        let resp = stack.try_response(l, cos).unwrap();
        for ((r, _), (r_metal, _)) in pols(resp).into_iter().zip(pols(mirror.response(cos))) {
            assert_close(&format!("R at cos {cos}"), r, pass * pass * r_metal, 1e-6);
        }
    }
}

#[test]
fn opaque_incoherent_metal_reflects_like_its_front_face_and_transmits_nothing() {
    let metal = Complex64::new(0.2, 3.5);
    let stack = Stack::new(
        1.0,
        vec![Layer::new(1.38, 100.0), Layer::incoherent(metal, 1e6)],
        1.5,
    )
    .unwrap();
    let front = Stack::new(1.0, vec![Layer::new(1.38, 100.0)], metal).unwrap();
    for cos in [1.0, 0.5, 0.05] {
        let resp = stack.try_response(550.0, cos).unwrap();
        let expected = front.try_response(550.0, cos).unwrap();
        assert_eq!(resp.r_s, expected.r_s, "cos {cos}");
        assert_eq!(resp.r_p, expected.r_p, "cos {cos}");
        assert_eq!(resp.t(), 0.0, "cos {cos}");
    }
}

#[test]
fn amplitudes_of_an_incoherent_stack_are_an_error_naming_the_layer() {
    let stack = Stack::new(
        1.0,
        vec![Layer::new(1.38, 100.0), Layer::incoherent(1.52, 1e6)],
        1.0,
    )
    .unwrap();
    let err = stack.try_amplitudes(550.0, 1.0).unwrap_err();
    assert_eq!(err, OpticsError::Incoherent { layer: 2 });
    assert!(err.to_string().contains("layer 2 is incoherent"), "{err}");
}

#[test]
fn grazing_incidence_on_an_incoherent_stack_reflects_everything() {
    let stack = Stack::new(1.0, vec![Layer::incoherent(1.52, 1e6)], 1.0).unwrap();
    let resp = stack.try_response(550.0, 0.0).unwrap();
    assert_eq!((resp.r(), resp.t()), (1.0, 0.0));
}

#[test]
fn evanescent_incoherent_layer_totally_reflects_without_nan() {
    // Glass incidence at 60°: an incoherent air gap is beyond its critical angle.
    let stack = Stack::new(1.5, vec![Layer::incoherent(1.0, 1e5)], 1.5).unwrap();
    let resp = stack.try_response(550.0, 0.5).unwrap();
    assert_close("R", resp.r(), 1.0, 1e-15);
    assert_eq!(resp.t(), 0.0);
}

/// Thickness samples per period in [`phase_average`].
const SAMPLES: usize = 96;

/// The response of `before | incoherent layer (n, d) | after` computed coherently at [`SAMPLES`]
/// thicknesses spread over one period `λ / (2 n cos θ_n)` of its round-trip phase, averaged.
/// For a lossless layer the average of the coherent response over its phase is exactly the
/// incoherent sum; the samples converge geometrically (the Fourier series of a reflectance
/// in `e^{2iδ}` decays like `(R_b R')^m`).
fn phase_average(
    front: &[Layer],
    n: f64,
    d: f64,
    back: &[Layer],
    substrate: f64,
    wavelength_nm: f64,
    cos: f64,
) -> (f64, f64) {
    let count = SAMPLES;
    let sin = (1.0 - cos * cos).sqrt();
    let cos_n = (1.0 - (sin / n).powi(2)).sqrt();
    let period = wavelength_nm / (2.0 * n * cos_n);
    let (mut r, mut t) = (0.0, 0.0);
    for i in 0..count {
        let mut layers = front.to_vec();
        layers.push(Layer::new(n, d + period * i as f64 / count as f64));
        layers.extend_from_slice(back);
        let resp = Stack::new(1.0, layers, substrate)
            .unwrap()
            .try_response(wavelength_nm, cos)
            .unwrap();
        r += resp.r();
        t += resp.t();
    }
    (r / count as f64, t / count as f64)
}

fn coherent_layers(max: usize) -> impl Strategy<Value = Vec<Layer>> {
    prop::collection::vec((1.2..2.5f64, 0.0..400.0f64), 0..=max)
        .prop_map(|v| v.into_iter().map(|(n, d)| Layer::new(n, d)).collect())
}

/// Byrnes' intensity transfer matrix of one coherent block between two lossless media,
/// from that block's coherent responses seen from each side (separate `Stack`s).
fn block_matrix(
    front_n: f64,
    layers: &[Layer],
    back_n: f64,
    sin0: f64,
    wavelength_nm: f64,
) -> [[f64; 2]; 4] {
    let cos_in = |n: f64| (1.0 - (sin0 / n).powi(2)).sqrt();
    let fwd = Stack::new(front_n, layers.to_vec(), back_n)
        .unwrap()
        .try_response(wavelength_nm, cos_in(front_n))
        .unwrap();
    let reversed: Vec<Layer> = layers.iter().rev().cloned().collect();
    let bwd = Stack::new(back_n, reversed, front_n)
        .unwrap()
        .try_response(wavelength_nm, cos_in(back_n))
        .unwrap();
    let matrix = |(rf, tf): (f64, f64), (rb, tb): (f64, f64)| {
        [[1.0 / tf, -rb / tf], [rf / tf, (tf * tb - rf * rb) / tf]]
    };
    let [fs, fp] = pols(fwd);
    let [bs, bp] = pols(bwd);
    let [s0, s1] = matrix(fs, bs);
    let [p0, p1] = matrix(fp, bp);
    [s0, s1, p0, p1]
}

fn mat_mul(a: [[f64; 2]; 2], b: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let mut m = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            m[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    m
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn one_lossless_incoherent_layer_is_the_phase_average_of_the_coherent_stack(
        front in coherent_layers(2), back in coherent_layers(2),
        n in 1.3..3.5f64, d in 0.0..2e4f64, substrate in 1.0..2.0f64,
        l in 360.0..830.0f64, angle in 0.0..60.0f64,
    ) {
        let cos = angle.to_radians().cos();
        let mut layers = front.clone();
        layers.push(Layer::incoherent(n, d));
        layers.extend_from_slice(&back);
        let resp = Stack::new(1.0, layers, substrate).unwrap().try_response(l, cos).unwrap();
        let (r_avg, t_avg) = phase_average(&front, n, d, &back, substrate, l, cos);
        assert_close("R vs phase average", resp.r(), r_avg, 1e-13);
        assert_close("T vs phase average", resp.t(), t_avg, 1e-13);
    }

    #[test]
    fn two_incoherent_layers_equal_byrnes_intensity_matrices(
        b0 in coherent_layers(2), b1 in coherent_layers(2), b2 in coherent_layers(2),
        n1 in 1.2..3.5f64, n2 in 1.2..3.5f64, substrate in 1.0..2.0f64,
        l in 360.0..830.0f64, angle in 0.0..80.0f64,
    ) {
        let (sin0, cos) = angle.to_radians().sin_cos();
        let mut layers = b0.clone();
        layers.push(Layer::incoherent(n1, 1e6));
        layers.extend_from_slice(&b1);
        layers.push(Layer::incoherent(n2, 2e6));
        layers.extend_from_slice(&b2);
        let resp = Stack::new(1.0, layers, substrate).unwrap().try_response(l, cos).unwrap();
        // Lossless incoherent layers: the propagation matrices are the identity.
        let m0 = block_matrix(1.0, &b0, n1, sin0, l);
        let m1 = block_matrix(n1, &b1, n2, sin0, l);
        let m2 = block_matrix(n2, &b2, substrate, sin0, l);
        for (k, (r, t)) in pols(resp).into_iter().enumerate() {
            let pick = |m: [[f64; 2]; 4]| [m[2 * k], m[2 * k + 1]];
            let total = mat_mul(mat_mul(pick(m0), pick(m1)), pick(m2));
            assert_close("R vs matrices", r, total[1][0] / total[0][0], 1e-13);
            assert_close("T vs matrices", t, 1.0 / total[0][0], 1e-13);
        }
    }

    #[test]
    fn incoherent_stacks_conserve_energy(
        b0 in coherent_layers(2), b1 in coherent_layers(2),
        n1 in 1.2..3.5f64, k1 in 0.0..1e-4f64, d1 in 0.0..1e7f64,
        k2 in 0.0..1e-3f64, n2 in 1.0..3.5f64, d2 in 0.0..1e6f64,
        substrate in 1.0..2.0f64, l in 360.0..830.0f64, cos in 0.0..=1.0f64,
    ) {
        // R + T + A = 1 with 0 ≤ A ≤ 1; without absorption A = 0 to rounding. Incoherent
        // layers absorb weakly (κ ≤ 1e-3): Byrnes' forward-flux convention, which the model
        // follows, lets R + T exceed 1 by O(κ²) (measured up to 0.02 at κ = 0.01, and
        // R + T = 1.6 for an incoherent 10 nm metal; docs/physics.md).
        let mut layers = b0.clone();
        layers.push(Layer::incoherent(Complex64::new(n1, k1), d1));
        layers.extend_from_slice(&b1);
        layers.push(Layer::incoherent(Complex64::new(n2, k2), d2));
        let resp = Stack::new(1.0, layers.clone(), substrate).unwrap().try_response(l, cos).unwrap();
        for (r, t) in pols(resp) {
            prop_assert!((0.0..=1.0).contains(&r) && (0.0..=1.0).contains(&t), "R {r} T {t}");
            prop_assert!(r + t <= 1.0 + 1e-13 + 1e3 * (k1 * k1 + k2 * k2), "R + T = {}", r + t);
        }
        for layer in &mut layers {
            layer.index = Complex64::new(layer.index.as_constant().unwrap().re, 0.0).into();
        }
        let lossless = Stack::new(1.0, layers, substrate).unwrap().try_response(l, cos).unwrap();
        for (r, t) in pols(lossless) {
            assert_close("lossless R + T", r + t, 1.0, 1e-13);
        }
    }
}

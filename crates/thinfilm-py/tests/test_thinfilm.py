"""thinfilm's Python API against a from-scratch Airy sum, conservation, shapes and errors."""

import threading

import numpy as np
import pytest

import thinfilm


def airy_film(n0, n1, n2, d_nm, wl_nm, angle_deg):
    """Unpolarised (R, T) of n0 | n1 (d) | n2, all lossless, written out from the textbook."""
    th0 = np.radians(angle_deg)
    s = n0 * np.sin(th0)
    c0 = np.cos(th0)
    c1 = np.sqrt(1 - (s / n1) ** 2 + 0j)
    c2 = np.sqrt(1 - (s / n2) ** 2 + 0j)
    beta = 2 * np.pi * n1 * d_nm * c1 / wl_nm
    out_r, out_t = [], []
    for pol in "sp":
        if pol == "s":
            r01 = (n0 * c0 - n1 * c1) / (n0 * c0 + n1 * c1)
            r12 = (n1 * c1 - n2 * c2) / (n1 * c1 + n2 * c2)
            t01 = 2 * n0 * c0 / (n0 * c0 + n1 * c1)
            t12 = 2 * n1 * c1 / (n1 * c1 + n2 * c2)
        else:
            r01 = (n1 * c0 - n0 * c1) / (n1 * c0 + n0 * c1)
            r12 = (n2 * c1 - n1 * c2) / (n2 * c1 + n1 * c2)
            t01 = 2 * n0 * c0 / (n1 * c0 + n0 * c1)
            t12 = 2 * n1 * c1 / (n2 * c1 + n1 * c2)
        e = np.exp(2j * beta)
        r = (r01 + r12 * e) / (1 + r01 * r12 * e)
        t = t01 * t12 * np.exp(1j * beta) / (1 + r01 * r12 * e)
        flux = (n2 * c2).real if pol == "s" else (n2 * np.conj(c2)).real
        out_r.append(abs(r) ** 2)
        out_t.append(flux / (n0 * c0) * abs(t) ** 2)
    return 0.5 * (out_r[0] + out_r[1]), 0.5 * (out_t[0] + out_t[1])


GRID_D = np.linspace(0, 2000, 41)[:, None, None]
GRID_A = np.array([0.0, 30.0, 60.0, 85.0])[None, :, None]
GRID_L = np.array([360.0, 550.0, 830.0, 1550.0])[None, None, :]


def test_film_rt_matches_independent_airy():
    r, t = thinfilm.film_rt(GRID_D, GRID_A, GRID_L, n_film=1.33)
    r_ref, t_ref = airy_film(1.0, 1.33, 1.0, GRID_D, GRID_L, GRID_A)
    assert r.shape == (41, 4, 4)
    np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-12)
    np.testing.assert_allclose(t, t_ref, rtol=0, atol=1e-12)


def test_film_rt_fast_path_is_within_its_documented_5e_5_of_independent_airy():
    # Rounding the inputs to f32 moves the phase by up to 6e-8 of itself: measured worst
    # |dR| on this grid 1.3e-5 (n = 1.33), 2.7e-5 (0.95, near its critical angle), 2.0e-5 (2.4).
    rng = np.random.default_rng(7)
    d = np.concatenate([GRID_D.ravel(), rng.uniform(0, 5000, 4000), [0.0]])
    a = np.concatenate([np.full(41, 30.0), rng.uniform(0, 89.99, 4000), [89.9999]])
    l = np.concatenate([np.full(41, 550.0), rng.uniform(360, 1600, 4000), [500.0]])
    for n_film in (1.33, 1.0 / 1.33 + 0.2, 2.4):
        r, t = thinfilm.film_rt(d, a, l, n_film=n_film, fast=True)
        r_ref, t_ref = airy_film(1.0, n_film, 1.0, d, l, a)
        assert np.abs(r - r_ref).max() <= 5e-5, (np.abs(r - r_ref).max(), n_film)
        assert np.abs(t - t_ref).max() <= 5e-5, (np.abs(t - t_ref).max(), n_film)
        np.testing.assert_allclose(r + t, 1.0, rtol=0, atol=4e-7)


def test_film_rt_fast_path_hands_what_f32_cannot_hold_to_the_exact_path():
    # 1e9 nm (thinfilm's largest thickness) has a phase no f32 resolves; 1e-320 is
    # subnormal in f64 and zero in f32.
    d = np.array([1e9, 1e-320, 250.0])
    r, t = thinfilm.film_rt(d, 30.0, 550.0, fast=True)
    r_exact, t_exact = thinfilm.film_rt(d, 30.0, 550.0)
    np.testing.assert_array_equal(r[:2], r_exact[:2])
    np.testing.assert_array_equal(t[:2], t_exact[:2])


def test_stack_matches_airy_on_a_substrate_and_conserves_energy():
    wl = np.linspace(300, 1600, 27)
    ang = np.array([[0.0], [45.0], [80.0]])
    r, t = thinfilm.rt([1.0, 1.38, 1.52], [120.0], wl, ang)
    r_ref, t_ref = airy_film(1.0, 1.38, 1.52, 120.0, wl, ang)
    np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r + t, 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(t, t_ref, rtol=0, atol=1e-12)


def test_absorbing_stack_conserves_energy_and_polarisations_average():
    n = [1.0, 1.38, 0.2 + 3.5j, 1.5]
    rs, ts = thinfilm.rt(n, [100.0, 20.0], 600.0, np.arange(0, 90, 7.5), pol="s")
    rp, tp = thinfilm.rt(n, [100.0, 20.0], 600.0, np.arange(0, 90, 7.5), pol="p")
    ru, tu = thinfilm.rt(n, [100.0, 20.0], 600.0, np.arange(0, 90, 7.5))
    np.testing.assert_allclose(ru, 0.5 * (rs + rp), atol=1e-15)
    a = 1 - ru - tu
    assert np.all(a > 0) and np.all(a < 1)


def test_thick_metal_is_exact_not_nan():
    r, t = thinfilm.rt([1.0, 0.2 + 3.5j, 1.5], [10_000.0], 550.0, 0.0)
    r_bare, _ = thinfilm.rt([1.0, 0.2 + 3.5j], [], 550.0, 0.0)
    assert t == 0.0
    np.testing.assert_allclose(r, r_bare, atol=1e-13)


def test_shapes_broadcast():
    r, t = thinfilm.film_rt(np.zeros((2, 1, 3)), np.zeros((5, 1)), 550.0)
    assert r.shape == t.shape == (2, 5, 3)
    assert thinfilm.film_xyz(np.zeros((4, 1)), np.zeros(3)).shape == (4, 3, 3)
    assert thinfilm.xyz_to_srgb(np.ones((2, 2, 3))).shape == (2, 2, 3)
    r, _ = thinfilm.film_rt(100.0, 0.0, 550.0)
    assert r.shape == ()


def test_film_colour_of_no_film_is_black_and_white_is_white():
    assert np.all(thinfilm.film_xyz(0.0, 0.0) == 0.0)
    np.testing.assert_allclose(thinfilm.xyz_to_srgb([0.9505, 1.0, 1.089]), 1.0, atol=2e-3)
    y = thinfilm.film_xyz(np.arange(0, 1000, 50), 0.0)[..., 1]
    assert np.all(y <= 0.16) and y.max() > 0.05


@pytest.mark.parametrize(
    "call, needle",
    [
        (lambda: thinfilm.film_rt(-5.0, 0.0, 550.0), "-5"),
        (lambda: thinfilm.film_rt(100.0, 95.0, 550.0), "95"),
        (lambda: thinfilm.film_rt(100.0, 0.0, 50.0), "50"),
        (lambda: thinfilm.film_rt(100.0, 0.0, 550.0, n_film=1e155), "1e155"),
        (lambda: thinfilm.film_rt(np.zeros(2), np.zeros(3), 550.0), "broadcast"),
        (lambda: thinfilm.rt([1.0, 1.5], [10.0], 550.0, 0.0), "len(d_nm) + 2"),
        (lambda: thinfilm.rt([1.0, 0.2 - 3j], [], 550.0, 0.0), "0.2"),
        (lambda: thinfilm.rt([1.0 + 1j, 1.5], [], 550.0, 0.0), "n[0]"),
        (lambda: thinfilm.rt([1.0, 1.5], [], 550.0, 0.0, pol="x"), "'x'"),
        (lambda: thinfilm.film_xyz(100.0, 0.0, illuminant="d75"), "d75"),
        (lambda: thinfilm.film_xyz(100.0, 0.0, observer="1976"), "1976"),
        (lambda: thinfilm.xyz_to_srgb([1.0, 2.0]), "last axis"),
        (lambda: thinfilm.film_rt(float("nan"), 0.0, 550.0), "NaN"),
        (lambda: thinfilm.film_rt(-5.0, 0.0, 550.0, fast=True), "-5"),
        (lambda: thinfilm.film_rt([100.0, 1e39], 0.0, 550.0, fast=True), "1e39"),
        (lambda: thinfilm.film_rt([100.0, 2e3], 0.0, [550.0, 50.0], fast=True), "50"),
    ],
)
def test_bad_input_raises_value_error_naming_the_value(call, needle):
    with pytest.raises(ValueError) as info:
        call()
    assert needle in str(info.value), str(info.value)


def test_gil_is_released_during_long_calls():
    # A Python thread counts while a large call runs; with the GIL held it could not.
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)

    worker = threading.Thread(target=count)
    d = np.linspace(0, 2000, 400)[:, None, None]
    a = np.linspace(0, 75, 11)[None, :, None]
    l = np.arange(360.0, 831.0)[None, None, :]
    worker.start()
    before = len(ticks)
    thinfilm.film_rt(d, a, l)
    during = len(ticks) - before
    stop.set()
    worker.join()
    assert during > 0

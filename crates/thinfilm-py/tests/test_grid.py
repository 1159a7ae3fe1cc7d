"""film_rt_grid and film_rt's grid path against Byrnes' tmm.coh_tmm and the point-by-point
exact path, in every axis order, with evanescent films and grazing incidence."""

import numpy as np
import pytest
import tmm

import thinfilm

D = np.array([0.0, 5.0, 133.0, 1000.0, 4999.0])
A = np.array([0.0, 30.0, 60.0, 80.0, 89.9, 90.0])
L = np.array([360.0, 550.0, 830.0, 1550.0])


def coh_tmm_rt(pol, n_out, n_film, d, angle, wl):
    if angle == 90.0:
        return (0.0, 1.0) if n_out == n_film else (1.0, 0.0)
    out = tmm.coh_tmm(pol, [n_out, n_film, n_out], [np.inf, d, np.inf], np.radians(angle), wl)
    return out["R"], out["T"]


@pytest.mark.parametrize("n_out, n_film", [(1.0, 1.33), (1.33, 1.0), (1.5, 3.4)])
@pytest.mark.parametrize("pol", ["s", "p"])
def test_grid_matches_tmm_coh_tmm(n_out, n_film, pol):
    # (1.33, 1.0): an air gap in water, evanescent beyond 48.8 deg (the general path).
    r, t = thinfilm.film_rt_grid(D, A, L, n_film=n_film, n_outside=n_out, pol=pol)
    assert r.shape == t.shape == (D.size, A.size, L.size)
    for i, d in enumerate(D):
        for j, a in enumerate(A):
            for k, wl in enumerate(L):
                r_ref, t_ref = coh_tmm_rt(pol, n_out, n_film, d, a, wl)
                # Near grazing the fringes are sharp: the phase's rounding is amplified.
                tol = 1e-13 if a < 89 else 1e-10
                assert abs(r[i, j, k] - r_ref) <= tol, (d, a, wl, r[i, j, k], r_ref)
                assert abs(t[i, j, k] - t_ref) <= tol, (d, a, wl, t[i, j, k], t_ref)


def test_film_rt_takes_the_grid_in_any_axis_order_and_equals_the_point_path():
    rng = np.random.default_rng(3)
    d = rng.uniform(0, 3000, 7)
    a = rng.uniform(0, 89, 5)
    wl = rng.uniform(360, 900, 6)
    for order in [(0, 1, 2), (1, 0, 2), (2, 1, 0), (1, 2, 0)]:
        args = []
        for axis, values in zip(order, (d, a, wl)):
            shape = [1, 1, 1]
            shape[axis] = values.size
            args.append(values.reshape(shape))
        r, t = thinfilm.film_rt(*args, n_film=1.4)
        full = [np.ascontiguousarray(x) for x in np.broadcast_arrays(*args)]
        # Full arrays are no outer product: the point-by-point Airy path.
        r_ref, t_ref = thinfilm.film_rt(*full, n_film=1.4)
        assert r.shape == r_ref.shape
        np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-13)
        np.testing.assert_allclose(t, t_ref, rtol=0, atol=1e-13)


def test_unpolarised_grid_is_the_mean_and_conserves_energy():
    rs, ts = thinfilm.film_rt_grid(D, A, L, pol="s")
    rp, tp = thinfilm.film_rt_grid(D, A, L, pol="p")
    ru, tu = thinfilm.film_rt_grid(D, A, L)
    np.testing.assert_allclose(ru, 0.5 * (rs + rp), rtol=0, atol=1e-15)
    np.testing.assert_allclose(ru + tu, 1.0, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    "call, needle",
    [
        (lambda: thinfilm.film_rt_grid([-5.0], [0.0], [550.0]), "-5"),
        (lambda: thinfilm.film_rt_grid([5.0], [91.0], [550.0]), "91"),
        (lambda: thinfilm.film_rt_grid([5.0], [0.0], [50.0]), "50"),
        (lambda: thinfilm.film_rt_grid([5.0], [0.0], [550.0], pol="x"), "'x'"),
        (lambda: thinfilm.film_rt_grid(np.zeros((2, 2)), [0.0], [550.0]), "1-d"),
        (lambda: thinfilm.film_rt(np.array([5.0, np.nan])[:, None], [0.0, 1.0], 550.0), "NaN"),
    ],
)
def test_bad_grid_input_raises_value_error_naming_it(call, needle):
    with pytest.raises(ValueError) as info:
        call()
    assert needle in str(info.value), str(info.value)


@pytest.mark.parametrize("n_out, n_film", [(1.0, 1.33), (1.33, 1.0), (1.5, 3.4)])
@pytest.mark.parametrize("pol", ["s", "p", "u"])
def test_fast_grid_is_within_its_documented_bound_of_tmm(n_out, n_film, pol):
    # The f32 kernel: within 2.4e-7 of exact for films up to 5 um (the docstring's figure;
    # 5e-7 here). Cells near grazing (89.9 deg) and beyond the critical angle take the
    # exact path.
    r, t = thinfilm.film_rt_grid(D, A, L, n_film=n_film, n_outside=n_out, pol=pol, fast=True)
    r_exact, t_exact = thinfilm.film_rt_grid(D, A, L, n_film=n_film, n_outside=n_out, pol=pol)
    assert r.dtype == np.float64 and r.shape == (D.size, A.size, L.size)
    for i, d in enumerate(D):
        for j, a in enumerate(A):
            for k, wl in enumerate(L):
                rs, ts = coh_tmm_rt("s", n_out, n_film, d, a, wl)
                rp, tp = coh_tmm_rt("p", n_out, n_film, d, a, wl)
                r_ref, t_ref = {"s": (rs, ts), "p": (rp, tp), "u": (0.5 * (rs + rp), 0.5 * (ts + tp))}[pol]
                assert abs(r[i, j, k] - r_ref) <= 5e-7, (d, a, wl, r[i, j, k], r_ref)
                assert abs(t[i, j, k] - t_ref) <= 5e-7, (d, a, wl, t[i, j, k], t_ref)
    # f32 arithmetic somewhere, not the exact path under another name.
    assert np.abs(r - r_exact).max() > 1e-10


def test_film_rt_fast_takes_the_fast_grid_in_any_axis_order():
    d, a, wl = np.linspace(0, 3000, 7), np.linspace(0, 80, 5), np.linspace(360, 900, 6)
    r_grid, t_grid = thinfilm.film_rt_grid(d, a, wl, n_film=1.4, fast=True)
    r, t = thinfilm.film_rt(d[None, :, None], a[:, None, None], wl, n_film=1.4, fast=True)
    assert np.array_equal(r, r_grid.transpose(1, 0, 2))
    assert np.array_equal(t, t_grid.transpose(1, 0, 2))
    r, t = thinfilm.film_rt(d[None, :, None], a, wl[:, None, None], n_film=1.4, fast=True)
    assert np.array_equal(r, r_grid.transpose(2, 0, 1))


def test_large_outputs_reuse_pooled_buffers_without_showing_old_values():
    # 2 x 200 x 11 x 471 f64: above the pool's 1 MiB, so the buffers are recycled.
    d, a, wl = np.arange(0, 2000.0, 10.0), np.arange(0, 75.1, 7.5), np.arange(360, 831.0)
    first = thinfilm.film_rt_grid(d, a, wl)
    expected = [x.copy() for x in first]
    for x in first:
        x.fill(np.nan)  # what a reused buffer holds before the next call overwrites it
    del first, x
    held, bytes_held = thinfilm._native.pool_held()
    assert held >= 2 and bytes_held <= 64 << 20
    for fast in (True, False):
        again = thinfilm.film_rt_grid(d, a, wl, fast=fast)
        assert not np.isnan(again[0]).any() and not np.isnan(again[1]).any()
        if not fast:
            assert np.array_equal(again[0], expected[0]) and np.array_equal(again[1], expected[1])
        # Every task's runs land where they belong: random points against the point path.
        rng = np.random.default_rng(5)
        i, j, k = (rng.integers(0, n, 300) for n in (d.size, a.size, wl.size))
        r_point, t_point = thinfilm.film_rt(d[i], a[j], wl[k])  # exact, point by point
        tol = 5e-7 if fast else 1e-13
        np.testing.assert_allclose(again[0][i, j, k], r_point, rtol=0, atol=tol)
        np.testing.assert_allclose(again[1][i, j, k], t_point, rtol=0, atol=tol)
        # The angle-major order that film_rt writes directly, too.
        r_am, _ = thinfilm.film_rt(d[None, :, None], a[:, None, None], wl, fast=fast)
        np.testing.assert_array_equal(r_am[j, i, k], again[0][i, j, k])
        del r_am
        # A result stays valid (and unshared) while it lives.
        other = thinfilm.film_rt_grid(d, a, wl, n_film=1.5)
        assert not np.shares_memory(again[0], other[0]) and not np.shares_memory(again[1], other[1])
        del again, other

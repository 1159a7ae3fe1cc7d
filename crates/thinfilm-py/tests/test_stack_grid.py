"""rt's grid path (wavelength x angle as an outer product: Rouard's recursion once per
angle) against Byrnes' tmm.coh_tmm on random stacks, and against rt's own point path in
either axis order, with absorbing and evanescent layers."""

import numpy as np
import pytest
import tmm

import thinfilm

WL = np.array([360.0, 451.5, 550.0, 633.0, 830.0, 1550.0])
ANGLE = np.array([0.0, 20.0, 45.0, 60.0, 75.0, 85.0])


def random_stack(rng, layers, absorbing):
    n = [float(rng.uniform(1.0, 1.8))]
    for _ in range(layers):
        k = float(rng.uniform(0, 3)) if absorbing and rng.uniform() < 0.5 else 0.0
        n.append(complex(rng.uniform(1.0, 3.5), k))
    n.append(complex(rng.uniform(1.0, 3.5), float(rng.uniform(0, 0.5)) if absorbing else 0.0))
    d = [float(x) for x in rng.uniform(0, 2000, layers)]
    return n, d


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("pol", ["s", "p"])
def test_grid_matches_tmm_coh_tmm_on_random_stacks(seed, pol):
    rng = np.random.default_rng(seed)
    n, d = random_stack(rng, layers=int(rng.integers(1, 7)), absorbing=seed % 2 == 1)
    r, t = thinfilm.rt(n, d, WL[None, :], ANGLE[:, None], pol=pol)
    assert r.shape == t.shape == (ANGLE.size, WL.size)
    for i, angle in enumerate(ANGLE):
        for j, wl in enumerate(WL):
            out = tmm.coh_tmm(pol, n, [np.inf, *d, np.inf], np.radians(angle), wl)
            assert abs(r[i, j] - out["R"]) <= 1e-13, (n, d, angle, wl, r[i, j], out["R"])
            assert abs(t[i, j] - out["T"]) <= 1e-13, (n, d, angle, wl, t[i, j], out["T"])


def test_grid_path_equals_the_point_path_in_either_order_and_with_grazing_light():
    rng = np.random.default_rng(7)
    n, d = random_stack(rng, layers=5, absorbing=True)
    wl = rng.uniform(360, 900, 9)
    angle = np.append(rng.uniform(0, 89, 4), 90.0)
    for pol in ["s", "p", "u"]:
        for wl_arg, angle_arg in [(wl[None, :], angle[:, None]), (wl[:, None], angle[None, :])]:
            r, t = thinfilm.rt(n, d, wl_arg, angle_arg, pol=pol)
            full = [np.ascontiguousarray(x) for x in np.broadcast_arrays(wl_arg, angle_arg)]
            # Full arrays are no outer product: the transfer matrix point by point.
            r_ref, t_ref = thinfilm.rt(n, d, *full, pol=pol)
            assert r.shape == r_ref.shape
            np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-13)
            np.testing.assert_allclose(t, t_ref, rtol=0, atol=1e-13)


def test_frustrated_total_reflection_through_the_grid():
    # A glass prism, an air gap, glass: beyond 41.8 deg the gap is evanescent and T falls
    # with its thickness as the closed form of one evanescent layer says.
    angle = np.array([30.0, 50.0, 70.0])
    r, t = thinfilm.rt([1.5, 1.0, 1.5], [200.0], WL[None, :], angle[:, None], pol="s")
    np.testing.assert_allclose(r + t, 1.0, rtol=0, atol=1e-14)
    for i, a in enumerate(angle):
        for j, wl in enumerate(WL):
            out = tmm.coh_tmm("s", [1.5, 1.0, 1.5], [np.inf, 200.0, np.inf], np.radians(a), wl)
            assert abs(t[i, j] - out["T"]) <= 1e-13


def test_grid_errors_name_the_bad_value():
    with pytest.raises(ValueError, match="-5"):
        thinfilm.rt([1.0, 1.5, 1.0], [100.0], np.array([550.0, -5.0])[None, :], np.array([0.0])[:, None])
    with pytest.raises(ValueError, match="95"):
        thinfilm.rt([1.0, 1.5, 1.0], [100.0], np.array([550.0])[None, :], np.array([0.0, 95.0])[:, None])


def test_outer_products_of_any_rank_take_the_grid_and_points_do_not():
    rng = np.random.default_rng(11)
    n, d = random_stack(rng, layers=3, absorbing=False)
    wl = rng.uniform(380, 800, 5)
    angle = rng.uniform(0, 80, 3)
    for wl_arg, angle_arg in [
        (wl[:, None, None], angle[None, :, None]),  # rank 3, trailing axis of 1
        (wl[None, :], angle[:, None, None]),  # ranks differ
        (550.0, angle),  # a scalar wavelength
        (wl, 30.0),  # a scalar angle
        (wl, angle[:, None]),
    ]:
        r, t = thinfilm.rt(n, d, wl_arg, angle_arg)
        full = [np.ascontiguousarray(x) for x in np.broadcast_arrays(wl_arg, angle_arg)]
        assert r.shape == full[0].shape
        r_ref, t_ref = thinfilm.rt(n, d, *full)  # full arrays: no outer product
        np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-13)
        np.testing.assert_allclose(t, t_ref, rtol=0, atol=1e-13)
    # Points on one shared axis, an empty axis and mismatched shapes stay on the point path.
    r, _ = thinfilm.rt(n, d, wl, wl * 0.0 + 10.0)
    assert r.shape == (5,)
    r, _ = thinfilm.rt(n, d, np.zeros((0, 1)) + 500.0, angle)
    assert r.shape == (0, 3)
    with pytest.raises(ValueError, match="broadcast"):
        thinfilm.rt(n, d, wl, angle)

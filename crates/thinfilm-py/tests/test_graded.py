"""graded_rt: a constant profile is the homogeneous layer of rt, a CSV-like table equals
the linear ramp it tabulates, the error bound holds against tmm.coh_tmm on 4096 slices."""

import numpy as np
import pytest
import tmm

import thinfilm

WL = np.array([400.0, 550.0, 800.0])
ANGLE = np.array([[0.0], [45.0]])


def test_constant_profile_is_the_homogeneous_layer():
    n = [1.0, 1.38, 2.0 + 0.01j, 1.52]
    r, t = thinfilm.rt(n, [90.0, 300.0], WL, ANGLE)
    rg, tg, err = thinfilm.graded_rt(n, [90.0, 300.0], 1, ("linear", 2.0 + 0.01j, 2.0 + 0.01j), WL, ANGLE)
    np.testing.assert_allclose(rg, r, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tg, t, rtol=0, atol=1e-12)
    assert np.all(err <= 1e-9)


def test_table_equals_linear_ramp_and_the_bound_holds_against_tmm():
    n = [1.0, 1.0, 1.52]
    ramp = ("linear", 1.0, 1.52)
    table = [(0.0, 1.0, 0.0), (250.0, 1.26, 0.0), (500.0, 1.52, 0.0)]
    r1, t1, e1 = thinfilm.graded_rt(n, [500.0], 0, ramp, WL, ANGLE, tolerance=1e-7)
    r2, t2, _ = thinfilm.graded_rt(n, [0.0], 0, table, WL, ANGLE, tolerance=1e-7)
    np.testing.assert_allclose(r1, r2, rtol=0, atol=1e-15)
    slices = 4096
    n_slices = list(1.0 + 0.52 * (np.arange(slices) + 0.5) / slices)
    for i, a in enumerate(ANGLE[:, 0]):
        for j, wl in enumerate(WL):
            ref = 0.5 * sum(
                tmm.coh_tmm(pol, [1.0] + n_slices + [1.52], [np.inf] + [500.0 / slices] * slices + [np.inf],
                            np.radians(a), wl)["R"]
                for pol in "sp"
            )
            # 4096 slices are themselves within ~1e-8 of the continuum (second order).
            assert abs(r1[i, j] - ref) <= 2 * 1e-7 + 1e-8, (a, wl, r1[i, j], ref)
    # A graded anti-reflection layer: far below the bare glass's 4.3 % head-on.
    assert r1[0].max() < 0.005


@pytest.mark.parametrize(
    "call, needle",
    [
        (lambda: thinfilm.graded_rt([1.0, 1.5, 1.52], [100.0], 0, ("cubic", 1, 2), 550.0, 0.0), "'cubic'"),
        (lambda: thinfilm.graded_rt([1.0, 1.5, 1.52], [100.0], 2, ("linear", 1, 2), 550.0, 0.0), "layer = 2"),
        (lambda: thinfilm.graded_rt([1.0, 1.5, 1.52], [100.0], 0, [(0, 1, 0), (0, 2, 0)], 550.0, 0.0), "line 3"),
        (lambda: thinfilm.graded_rt([1.0, 1.5, 1.52], [100.0], 0, ("exponential", 1, 2j), 550.0, 0.0), "real"),
        (lambda: thinfilm.graded_rt([1.0, 1.5, 1.52], [100.0], 0, ("linear", 1, 2), 550.0, 0.0, tolerance=0), "tolerance 0"),
    ],
)
def test_bad_graded_input_raises_value_error_naming_it(call, needle):
    with pytest.raises(ValueError) as info:
        call()
    assert needle in str(info.value), str(info.value)

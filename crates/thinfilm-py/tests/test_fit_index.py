"""fit_thickness_and_index on spectra of an oxide-like Cauchy film on silicon made by the
exact model (tmm.coh_tmm, an independent implementation) with noise and an offset."""

import numpy as np
import pytest
import tmm

import thinfilm

WL = np.arange(400.0, 801.0, 2.0)
SILICON = 3.88 + 0.02j


def spectrum(d, a, b, rng, noise=1e-3, offset=0.004):
    out = []
    for wl in WL:
        film = a + b / wl**2
        out.append(tmm.coh_tmm("s", [1.0, film, SILICON], [np.inf, d, np.inf], 0.0, wl)["R"])
    return np.array(out) + offset + noise * rng.standard_normal(WL.size)


@pytest.mark.parametrize("d", [480.0, 1500.0, 3200.0])
def test_recovers_thickness_and_cauchy_index_within_the_intervals(d):
    rng = np.random.default_rng(int(d))
    r = spectrum(d, 1.46, 3500.0, rng)
    fit = thinfilm.fit_thickness_and_index(WL, r, thickness_range_nm=(0.0, 5000.0))
    # One spectrum per case: the truth must lie within the 95 % interval widened 1.5 times
    # (about 2.9 sigma, missed 0.4 % of the time if sigma is honest); the 95 % coverage
    # itself is checked over 60 seeded trials in crates/thinfilm/tests/optics_fit_cauchy.rs.
    for key, truth in [("thickness_nm", d), ("cauchy_a", 1.46), ("cauchy_b_nm2", 3500.0)]:
        low, high = fit[key + "_interval"]
        value = fit[key]
        assert value - 1.5 * (value - low) <= truth <= value + 1.5 * (high - value), (key, truth, fit)
    assert abs(fit["offset"] - 0.004) < 1e-3
    assert 5e-4 < fit["rms_residual"] < 2e-3


def test_bad_ranges_raise_value_error_naming_them():
    r = spectrum(500.0, 1.46, 3500.0, np.random.default_rng(0))
    with pytest.raises(ValueError, match=r"Cauchy a range \[1.7, 1.3\]"):
        thinfilm.fit_thickness_and_index(WL, r, a_range=(1.7, 1.3))
    with pytest.raises(ValueError, match="a_range"):
        thinfilm.fit_thickness_and_index(WL, r, a_range=(1.3,))
    with pytest.raises(ValueError, match="layer"):
        thinfilm.fit_thickness_and_index(WL, r, layer=3)

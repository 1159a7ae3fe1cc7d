"""fit_thickness on spectra made with tmm.coh_tmm (an independent model) with seeded
noise, an offset and a wavelength-calibration shift the test states."""

import numpy as np
import pytest
import tmm

import thinfilm


def spectrum(n, d_nm, wl, angle_deg):
    """Unpolarised R from tmm.coh_tmm."""
    d_list = [np.inf] + list(d_nm) + [np.inf]
    th = np.radians(angle_deg)
    return np.array([
        0.5 * sum(tmm.coh_tmm(pol, n, d_list, th, w)["R"] for pol in "sp") for w in wl
    ])


def test_noisy_spectra_put_the_truth_in_the_interval():
    # 20 seeded films (soap, 50 nm – 3 µm), noise 1e-3, offset ±0.005, shift ±0.2 nm.
    rng = np.random.default_rng(26)
    wl = np.arange(400.0, 801.0, 2.0)
    inside = 0
    for _ in range(20):
        truth = 50.0 * 60 ** rng.uniform()
        shift = rng.uniform(-0.2, 0.2)
        r = spectrum([1.0, 1.33, 1.0], [truth], wl + shift, 0.0)
        r = r + rng.uniform(-0.005, 0.005) + 1e-3 * rng.standard_normal(wl.size)
        fit = thinfilm.fit_thickness(wl, r, wavelength_uncertainty_nm=0.2)
        low, high = fit["interval_nm"]
        inside += low <= truth <= high
        assert abs(fit["thickness_nm"] - truth) < 0.02 * truth + 2.0, (truth, fit)
    assert inside >= 18, inside


def test_a_layer_on_a_substrate_under_a_known_coating():
    # Unknown silica under a known 20 nm of 2.0, on silicon, at 30 degrees, no noise.
    n = [1.0, 2.0, 1.46, 3.88 + 0.02j]
    wl = np.arange(450.0, 851.0, 5.0)
    r = spectrum(n, [20.0, 733.0], wl, 30.0)
    fit = thinfilm.fit_thickness(wl, r, n=n, d_nm=[20.0, 0.0], layer=1, angle_deg=30.0)
    assert abs(fit["thickness_nm"] - 733.0) < 1e-3, fit
    assert fit["rms_residual"] < 1e-6


@pytest.mark.parametrize(
    "call, needle",
    [
        (lambda: thinfilm.fit_thickness([400.0, 500.0, 600.0], [0.1, 0.2]), "reflectance has 2"),
        (lambda: thinfilm.fit_thickness([400.0, 500.0, np.nan], [0.1, 0.2, 0.3]), "NaN"),
        (lambda: thinfilm.fit_thickness([400.0, 500.0, 600.0], [0.1, 0.2, 0.3], layer=3), "layer = 3"),
        (lambda: thinfilm.fit_thickness([400.0, 500.0, 600.0], [0.1, 0.2, 0.3], thickness_range_nm=(9, 1)), "[9, 1]"),
        (lambda: thinfilm.fit_thickness([400.0, 500.0, 600.0], [0.1, 0.2, 0.3], wavelength_uncertainty_nm=-2), "-2"),
    ],
)
def test_bad_fit_input_raises_value_error_naming_it(call, needle):
    with pytest.raises(ValueError) as info:
        call()
    assert needle in str(info.value), str(info.value)

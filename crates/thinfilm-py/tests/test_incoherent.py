"""Incoherent layers (rt(..., coherent=[...])) against Byrnes' tmm.inc_tmm and closed forms.

`tmm` (PyPI) is installed in the test environment by .ci/run; it is imported outright so
that a missing install fails rather than skips.
"""

import numpy as np
import pytest
import tmm

import thinfilm


def inc_tmm_rt(pol, n, d_nm, coherent, wl, angle_deg):
    """``(R, T)`` from tmm.inc_tmm, one point at a time."""
    n_list = list(n)
    d_list = [np.inf] + list(d_nm) + [np.inf]
    c_list = ["i"] + ["c" if c else "i" for c in coherent] + ["i"]
    out = tmm.inc_tmm(pol, n_list, d_list, c_list, np.radians(angle_deg), wl)
    return out["R"], out["T"]


def random_stack(rng, incoherent_count, kappa_incoherent):
    """A random stack of up to 5 coherent layers (a thin metal among them sometimes) with
    `incoherent_count` incoherent ones at random places."""
    layers = []
    for _ in range(rng.integers(1, 6)):
        if rng.random() < 0.2:
            layers.append((complex(rng.uniform(0.1, 1.5), rng.uniform(0.5, 4.0)), rng.uniform(0, 20), True))
        else:
            layers.append((complex(rng.uniform(1.2, 2.6), rng.uniform(0, 0.05)), rng.uniform(0, 400), True))
    for _ in range(incoherent_count):
        n = complex(rng.uniform(1.2, 3.5), rng.uniform(0, kappa_incoherent))
        layers.insert(rng.integers(0, len(layers) + 1), (n, rng.uniform(1e4, 2e6), False))
    n = [1.0] + [layer[0] for layer in layers] + [complex(rng.uniform(1.0, 2.0), rng.uniform(0, 0.1))]
    return n, [layer[1] for layer in layers], [layer[2] for layer in layers]


@pytest.mark.parametrize("incoherent_count", [1, 2])
@pytest.mark.parametrize("kappa_incoherent", [0.0, 1e-4, 0.3])
def test_random_stacks_match_tmm_inc_tmm(incoherent_count, kappa_incoherent):
    # Worst measured |dR|, |dT| over the six cases: 2.1e-15; 1e-13 leaves rounding room.
    # κ = 0.3 in a thick incoherent layer checks the conventions where it absorbs strongly.
    rng = np.random.default_rng(100 * incoherent_count + int(kappa_incoherent * 1e4))
    worst = 0.0
    for _ in range(100):
        n, d, coherent = random_stack(rng, incoherent_count, kappa_incoherent)
        wl = rng.uniform(360, 1000)
        angle = rng.uniform(0, 80)
        for pol in "sp":
            r, t = thinfilm.rt(n, d, wl, angle, pol=pol, coherent=coherent)
            r_ref, t_ref = inc_tmm_rt(pol, n, d, coherent, wl, angle)
            worst = max(worst, abs(r - r_ref), abs(t - t_ref))
            assert abs(r - r_ref) <= 1e-13 and abs(t - t_ref) <= 1e-13, (n, d, coherent, wl, angle, pol, r, r_ref, t, t_ref)
    print(f"worst |diff| {worst:.1e}")


def test_bare_slab_is_the_closed_form():
    # R = R1 + T1² R1 / (1 − R1²) for a lossless slab, R1 its interface's reflectance.
    angle = np.array([0.0, 20.0, 45.0, 70.0, 85.0])
    for pol in "sp":
        r1, t1 = thinfilm.rt([1.0, 1.52], [], 550.0, angle, pol=pol)
        r, t = thinfilm.rt([1.0, 1.52, 1.0], [1e6], 550.0, angle, pol=pol, coherent=[False])
        np.testing.assert_allclose(r, r1 + t1**2 * r1 / (1 - r1**2), rtol=0, atol=1e-15)
        np.testing.assert_allclose(t, t1**2 / (1 - r1**2), rtol=0, atol=1e-15)


def test_film_on_a_slide_loses_the_slides_fringes():
    # 300 nm soap on a 1 mm slide: the coherent answer oscillates with the slide's
    # thickness, the incoherent one does not, and it is the coherent one's mean.
    wl = np.linspace(500, 501, 201)
    n = [1.0, 1.33, 1.52, 1.0]
    r_inc, _ = thinfilm.rt(n, [300, 1e6], wl, 0.0, coherent=[True, False])
    r_coh, _ = thinfilm.rt(n, [300, 1e6], wl, 0.0)
    assert np.ptp(r_coh) > 0.05 and np.ptp(r_inc) < 1e-3
    np.testing.assert_allclose(r_inc.mean(), r_coh.mean(), atol=2e-3)


@pytest.mark.parametrize(
    "call, needle",
    [
        (lambda: thinfilm.rt([1.0, 1.5, 1.0], [1e6], 550.0, 0.0, coherent=[False, True]), "coherent has 2"),
        (lambda: thinfilm.rt([1.0, 1.5, 1.0], [1e6], 550.0, 0.0, coherent=["i"]), "coherent[0] = 'i'"),
        (lambda: thinfilm.rt([1.0, 1.5, 1.0], [-1.0], 550.0, 0.0, coherent=[False]), "-1"),
    ],
)
def test_bad_coherent_flags_raise_value_error_naming_them(call, needle):
    with pytest.raises(ValueError) as info:
        call()
    assert needle in str(info.value), str(info.value)

"""thickness_from_rgb on synthetic photos made with the package's own colour functions
(film_xyz, xyz_to_srgb): a film thickening from 100 to 600 nm along x, photographed at a
known exposure; the formats, calibrations, masks, anchors, geometry and every error."""

import threading

import numpy as np
import pytest

import thinfilm

WIDTH, HEIGHT, EXPOSURE = 128, 8, 5.0
TRUTH = np.tile(np.linspace(100.0, 600.0, WIDTH), (HEIGHT, 1))


def encoded(truth=TRUTH, exposure=EXPOSURE):
    """The sRGB-encoded colours in [0, 1] a camera at `exposure` records (D65, head-on)."""
    return thinfilm.xyz_to_srgb(thinfilm.film_xyz(truth, 0.0) * exposure)


def srgb8(truth=TRUTH, exposure=EXPOSURE):
    return np.round(encoded(truth, exposure) * 255).astype(np.uint8)


def linear(truth=TRUTH):
    v = encoded(truth)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def assert_recovered(out, truth=TRUTH, tol_nm=5.0):
    assert out["status"].shape == truth.shape and out["status"].dtype == np.uint8
    assert (out["status"] == thinfilm.FITTED).all()
    for key in ("thickness_nm", "uncertainty_nm", "residual_de"):
        assert out[key].shape == truth.shape and out[key].dtype == np.float32, key
    np.testing.assert_allclose(out["thickness_nm"], truth, rtol=0, atol=tol_nm)


def test_given_exposure_recovers_the_ramp_within_5_nm():
    image = srgb8()
    assert image.max() < 255
    out = thinfilm.thickness_from_rgb(image, exposure=EXPOSURE)
    assert_recovered(out)
    assert out["rerender"].shape == (HEIGHT, WIDTH, 3) and out["rerender"].dtype == np.float32
    # sRGB is steep near black: a ΔE of 0.8 there moves an encoded channel by up to 0.03.
    np.testing.assert_allclose(out["rerender"], image / 255.0, atol=0.03)
    assert (out["residual_de"] < 2).all() and (out["uncertainty_nm"] > 0).all()
    s = out["summary"]
    assert s["calibration"] == "given"
    assert s["exposure"] == EXPOSURE and s["gains"] == (1.0, 1.0, 1.0)
    counts = (s["fitted"], s["saturated"], s["excluded"], s["unexplained"])
    assert counts == (WIDTH * HEIGHT, 0, 0, 0)
    assert abs(s["thickness_min_nm"] - 100) < 5 and abs(s["thickness_max_nm"] - 600) < 5
    assert s["regions"] >= 1 and s["regions_anchored"] == 0
    expected = {"exposure", "gains", "calibration", "fitted", "saturated", "excluded",
                "unexplained", "residual_mean_de", "residual_p95_de", "residual_max_de",
                "noise_encoded", "thickness_min_nm", "thickness_median_nm", "thickness_max_nm",
                "uncertainty_median_nm", "regions", "regions_anchored", "regions_shifted",
                "ambiguous", "regions_unplaced", "regions_refolded", "regions_lost"}
    assert set(s) == expected


@pytest.mark.parametrize("image", [
    np.round(encoded() * 65535).astype(np.uint16),
    linear().astype(np.float32),
    linear(),
], ids=["uint16", "float32", "float64"])
def test_every_format_recovers_the_ramp(image):
    assert_recovered(thinfilm.thickness_from_rgb(image, exposure=EXPOSURE))


def test_estimated_camera_recovers_the_ramp():
    out = thinfilm.thickness_from_rgb(srgb8())
    assert_recovered(out)
    assert out["summary"]["calibration"] == "estimated"
    assert abs(out["summary"]["exposure"] / EXPOSURE - 1) < 0.05


def test_white_region_fixes_the_camera_and_is_itself_unexplained():
    # A perfect mirror of D65 light is sRGB (1, 1, 1) times the exposure: four such columns
    # left of the film, 16-bit so that the dim film (exposure 0.9) keeps its precision.
    exposure = 0.9
    white = np.full((HEIGHT, 4, 3), 1.055 * exposure ** (1 / 2.4) - 0.055)
    photo = np.concatenate([white, encoded(TRUTH, exposure)], axis=1)
    out = thinfilm.thickness_from_rgb(np.round(photo * 65535).astype(np.uint16),
                                      white=(0, 0, 4, HEIGHT))
    s = out["summary"]
    assert s["calibration"] == "white region" and abs(s["exposure"] / exposure - 1) < 1e-3
    assert (out["status"][:, :4] == thinfilm.UNEXPLAINED).all()
    np.testing.assert_allclose(out["thickness_nm"][:, 4:], TRUTH, rtol=0, atol=5)


def test_reference_region_and_anchor():
    x = 64
    out = thinfilm.thickness_from_rgb(srgb8(), reference=((x, 0, 1, HEIGHT), TRUTH[0, x]),
                                      anchors=[(x, 4, TRUTH[4, x])])
    assert_recovered(out)
    assert out["summary"]["calibration"] == "reference region"
    assert out["summary"]["regions_anchored"] == 1


def test_mask_excludes_and_nan_marks_the_missing():
    mask = np.ones((HEIGHT, WIDTH), dtype=bool)
    mask[:, :10] = False
    out = thinfilm.thickness_from_rgb(srgb8(), exposure=EXPOSURE, mask=mask)
    assert (out["status"][:, :10] == thinfilm.EXCLUDED).all()
    for key in ("thickness_nm", "uncertainty_nm", "residual_de"):
        assert np.isnan(out[key][:, :10]).all() and not np.isnan(out[key][:, 10:]).any()
    np.testing.assert_allclose(out["thickness_nm"][:, 10:], TRUTH[:, 10:], atol=5)
    assert out["summary"]["excluded"] == 10 * HEIGHT
    # The photo's own colour where nothing is fitted.
    np.testing.assert_allclose(out["rerender"][:, :10], srgb8()[:, :10] / 255.0, atol=1e-6)


def test_saturated_pixels_are_marked_and_a_saturated_photo_refused():
    image = srgb8()
    image[2, 5] = (255, 10, 10)
    out = thinfilm.thickness_from_rgb(image, exposure=EXPOSURE)
    assert out["status"][2, 5] == thinfilm.SATURATED and np.isnan(out["thickness_nm"][2, 5])
    assert out["summary"]["saturated"] == 1
    with pytest.raises(ValueError, match="saturated"):
        thinfilm.thickness_from_rgb(srgb8(exposure=40.0), exposure=40.0)


def test_geometry_sphere_and_cos_map():
    out = thinfilm.thickness_from_rgb(srgb8(), exposure=EXPOSURE, sphere=(64.0, 4.0, 3.0))
    outside = out["status"] == thinfilm.EXCLUDED
    assert outside[0, 0] and outside[:, 70:].all() and not outside[4, 64]
    flat = thinfilm.thickness_from_rgb(srgb8(), exposure=EXPOSURE,
                                       cos_map=np.ones((HEIGHT, WIDTH)))
    assert_recovered(flat)


@pytest.mark.parametrize("kwargs, image, message", [
    ({}, np.zeros((HEIGHT, WIDTH, 3), dtype=np.int64), "dtype int64"),
    ({}, np.zeros((HEIGHT, WIDTH), dtype=np.uint8), r"shape \(8, 128\)"),
    ({}, np.zeros((HEIGHT, WIDTH, 4), dtype=np.uint8), r"shape \(8, 128, 4\)"),
    ({"white": (0, 0, 2, 2), "exposure": 5.0}, None, "white and exposure"),
    ({"reference": ((0, 0, 2, 2), 300.0), "exposure": 5.0}, None, "reference and exposure"),
    ({"gains": (1.0, 1.0, 1.0)}, None, "gains"),
    ({"exposure": 5.0, "gains": (1.0, 2.0)}, None, "gains"),
    ({"exposure": -1.0}, None, "exposure -1"),
    ({"anchors": [(200, 3, 300.0)]}, None, "anchor 200,3=300 is outside the 128x8 photo"),
    ({"anchors": [(-1, 3, 300.0)]}, None, r"anchors\[0\] x = -1"),
    ({"anchors": [(1, 3)]}, None, r"anchors\[0\] = \(1, 3\)"),
    ({"anchors": [(1, 3, 9000.0)]}, None, "anchor thickness_nm 9000"),
    ({"white": (120, 0, 20, 2)}, None, "white region 120,0,20,2 is outside"),
    ({"mask": np.ones((HEIGHT, WIDTH - 1), dtype=bool)}, None, r"mask has shape \(8, 127\)"),
    ({"mask": np.ones((HEIGHT, WIDTH))}, None, "mask has dtype float64"),
    ({"mask": np.zeros((HEIGHT, WIDTH), dtype=bool)}, None, "no pixel is left"),
    ({"cos_map": np.ones((HEIGHT, WIDTH)), "sphere": (1, 1, 1)}, None, "cos_map and sphere"),
    ({"cos_map": np.full((HEIGHT, WIDTH), 2.0)}, None, "cos θ at"),
    ({"sphere": (64, 4, 0.5)}, None, "sphere radius_px 0.5"),
    ({"angle_deg": 89.0}, None, "angle_deg 89"),
    ({"illuminant": "d99"}, None, 'illuminant = "d99"'),
    ({"n_film": 0.9}, None, "film index 0.9"),
    ({"thickness_max_nm": 10.0}, None, "thickness_max_nm 10"),
    ({"smoothness_nm": 0.0}, None, "smoothness_nm 0"),
    ({"max_residual_de": -1.0}, None, "max_residual_de -1"),
])
def test_bad_input_raises_value_error_naming_it(kwargs, image, message):
    with pytest.raises(ValueError, match=message):
        thinfilm.thickness_from_rgb(srgb8() if image is None else image, **kwargs)


def test_linear_photo_with_a_bad_value_is_named():
    image = linear()
    image[3, 7, 1] = -0.5
    with pytest.raises(ValueError, match=r"pixel \(7, 3\) has the value -0.5 in channel 1"):
        thinfilm.thickness_from_rgb(image, exposure=EXPOSURE)


def test_gil_is_released_during_recovery():
    row = srgb8(np.linspace(100.0, 900.0, 512)[None, :], 3.0)
    image = np.tile(row, (256, 1, 1))
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)

    worker = threading.Thread(target=count)
    worker.start()
    before = len(ticks)
    thinfilm.thickness_from_rgb(image, exposure=3.0)
    during = len(ticks) - before
    stop.set()
    worker.join()
    assert during > 0


def test_a_sampled_flat_spectrum_gives_the_map_of_the_equal_energy_illuminant():
    image = srgb8()
    named = thinfilm.thickness_from_rgb(image, exposure=EXPOSURE, illuminant="e")
    sampled = thinfilm.thickness_from_rgb(
        image, exposure=EXPOSURE, illuminant=(np.array([360.0, 830.0]), np.array([2.0, 2.0])))
    assert (named["status"] == thinfilm.FITTED).all()
    np.testing.assert_allclose(sampled["thickness_nm"], named["thickness_nm"], rtol=0, atol=1e-3)


def test_water_and_the_1964_observer_are_models_of_their_own():
    image = srgb8()
    const = thinfilm.thickness_from_rgb(image, exposure=EXPOSURE)
    water = thinfilm.thickness_from_rgb(image, exposure=EXPOSURE, n_film="water")
    assert (water["status"] == thinfilm.FITTED).all()
    # Water's index is about 1.333 against the photo's 1.33: the optical thickness n·h is
    # what the colours fix, so the map shrinks by about that ratio (dispersion moves the
    # thinnest, bluest fringes most), never by an order.
    ratio = water["thickness_nm"] / const["thickness_nm"]
    assert 0.98 < np.median(ratio) < 1.0 and np.abs(ratio - 1.0).max() < 0.04
    # The photo was made for the 1931 observer: the 10° one reads it a little differently.
    wide = thinfilm.thickness_from_rgb(image, exposure=EXPOSURE, observer="1964")
    assert (wide["status"] == thinfilm.FITTED).mean() > 0.9
    diff = np.abs(wide["thickness_nm"] - const["thickness_nm"])
    assert 0.0 < np.nanmax(diff) < 30.0


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"observer": "1900"}, 'observer = "1900"'),
        ({"n_film": "glass"}, 'n_film = "glass"'),
        ({"illuminant": ([500.0], [1.0])}, "illuminant spectrum"),
        ({"illuminant": 42}, "illuminant = 42"),
    ],
)
def test_bad_light_index_and_observer_name_the_value(kwargs, needle):
    with pytest.raises(ValueError, match=None) as err:
        thinfilm.thickness_from_rgb(srgb8(), exposure=EXPOSURE, **kwargs)
    assert needle in str(err.value), str(err.value)

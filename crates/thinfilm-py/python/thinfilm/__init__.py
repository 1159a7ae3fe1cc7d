"""Exact thin-film and multilayer optics and CIE colour, computed in Rust.

Every function takes numpy arrays (or scalars) that broadcast together, returns arrays of
the broadcast shape, releases the GIL while it computes, and raises ValueError naming any
bad value. Angles are in degrees, lengths in nm (vacuum wavelengths).
"""

import numpy as np

from . import _native

__all__ = ["rt", "graded_rt", "film_rt", "film_rt_grid", "fit_thickness", "fit_thickness_and_index",
           "film_xyz", "xyz_to_srgb", "thickness_from_rgb"]


def _flat(*arrays):
    """Broadcast the arrays together; return the shape and contiguous float64 copies."""
    try:
        parts = np.broadcast_arrays(*[np.asarray(a, dtype=np.float64) for a in arrays])
    except ValueError as err:
        raise ValueError(f"arguments do not broadcast together: {err}") from None
    shape = parts[0].shape if parts else ()
    return shape, [np.ascontiguousarray(p).ravel() for p in parts]


def rt(n, d_nm, wavelength_nm, angle_deg, pol="u", coherent=None):
    """Reflectance and transmittance ``(R, T)`` of a multilayer stack.

    ``n`` lists every medium's index from the incidence medium to the substrate (complex
    allowed, ``n + ik`` with ``k >= 0``; the first must be real), ``d_nm`` the inner layers'
    thicknesses: the order of ``tmm.coh_tmm`` without its infinite ends. ``pol`` is "s", "p"
    or "u" (unpolarised mean). ``wavelength_nm`` and ``angle_deg`` broadcast together.

    ``coherent`` marks each inner layer: ``True`` (the default for all) adds its multiple
    reflections in amplitude, ``False`` in intensity, for a layer thicker than the light's
    coherence length such as a 1 mm glass slide (``tmm.inc_tmm`` with ``c_list`` "c"/"i";
    the semi-infinite ends are always incoherent). For example a 300 nm film on a slide:
    ``rt([1, 1.33, 1.52, 1], [300, 1e6], wl, 0, coherent=[True, False])``.

    When wavelength and angle form an outer product (``wl[None, :]`` and ``angle[:, None]``,
    in either order), every interface is computed once per angle and each point then costs
    one phase per layer (Rouard's recursion, vectorised; within 1e-13 of the transfer
    matrix, which any other point, stack or pole still takes).
    """
    n = [complex(x) for x in np.atleast_1d(n)]
    d_nm = [float(x) for x in np.atleast_1d(d_nm)] if np.size(d_nm) else []
    if coherent is None:
        flags = [True] * len(d_nm)
    else:
        flags = []
        for k, flag in enumerate(np.atleast_1d(coherent).tolist() if np.size(coherent) else []):
            if not isinstance(flag, (bool, int)) or flag not in (0, 1):
                raise ValueError(f"coherent[{k}] = {flag!r} is not True or False")
            flags.append(bool(flag))
    try:
        wl_array = np.asarray(wavelength_nm, dtype=np.float64)
        angle_array = np.asarray(angle_deg, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"wavelength_nm or angle_deg is not numeric: {err}") from None
    grid = _native.rt_outer(n, d_nm, wl_array, angle_array, pol, flags)
    if grid is not None:
        return grid
    shape, (wl, angle) = _flat(wavelength_nm, angle_deg)
    r, t = _native.rt(n, d_nm, wl, angle, pol, flags)
    return r.reshape(shape), t.reshape(shape)


def _axes(*arrays):
    """For arrays that form an outer product (each has at most one axis longer than 1, and
    no two share one), each one's 1-d values and the position of its axis (-1 if none);
    otherwise None."""
    parts = [np.asarray(a, dtype=np.float64) for a in arrays]
    ndim = max(p.ndim for p in parts)
    values, positions = [], []
    for p in parts:
        long = [k for k, size in enumerate(p.shape) if size > 1]
        if len(long) > 1:
            return None
        values.append(np.ascontiguousarray(p).ravel())
        positions.append(ndim - p.ndim + long[0] if long else -1)
    taken = [k for k in positions if k >= 0]
    if len(set(taken)) != len(taken):
        return None
    return values, positions


def graded_rt(n, d_nm, layer, profile, wavelength_nm, angle_deg, pol="u", tolerance=1e-9):
    """``(R, T, error_bound)`` of a stack (as :func:`rt`) whose inner layer ``layer``
    (0-based) has an index graded with depth.

    ``profile`` is ``("linear", n_front, n_back)`` or ``("exponential", n_front, n_back)``
    over ``d_nm[layer]`` (linear: complex allowed, n and k alike; exponential: real), or an
    array of rows ``(z_nm, n, k)`` from the layer's front face (z = 0) to its back (the last
    z is its thickness). Each point slices the layer at midpoints, doubling the slices
    until the Richardson estimate of the remaining error, returned as ``error_bound``, is
    within ``tolerance``. ``wavelength_nm`` and ``angle_deg`` broadcast together.
    """
    n = [complex(x) for x in np.atleast_1d(n)]
    d_nm = [float(x) for x in np.atleast_1d(d_nm)] if np.size(d_nm) else []
    if isinstance(layer, bool) or not isinstance(layer, (int, np.integer)) or layer < 0:
        raise ValueError(f"layer = {layer!r} is not an index >= 0 into d_nm")
    front = back = 1.0
    table = []
    if isinstance(profile, tuple) and len(profile) == 3 and isinstance(profile[0], str):
        kind, front, back = profile[0], complex(profile[1]), complex(profile[2])
    else:
        rows = np.asarray(profile, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != 3:
            raise ValueError(f"profile of shape {rows.shape} is not rows of (z_nm, n, k)")
        kind, table = "table", [tuple(map(float, row)) for row in rows]
    shape, (wl, angle) = _flat(wavelength_nm, angle_deg)
    r, t, e = _native.graded_rt(n, d_nm, int(layer), kind, complex(front), complex(back), table,
                                wl, angle, pol, float(tolerance))
    return r.reshape(shape), t.reshape(shape), e.reshape(shape)


def film_rt_grid(thickness_nm, angle_deg, wavelength_nm, n_film=1.33, n_outside=1.0, pol="u",
                 fast=False):
    """``(R, T)`` of the film ``n_outside | n_film | n_outside`` on the grid of three 1-d axes,
    shape ``(len(thickness_nm), len(angle_deg), len(wavelength_nm))``.

    Exact in f64 (the closed-form Airy sum of all orders, within 1e-14 of the transfer
    matrix): the Fresnel terms are computed once per (angle, wavelength), then each
    thickness costs a sine per point, in parallel. ``pol`` is "s", "p" or "u" (the mean).
    ``film_rt`` takes this path by itself when its arguments form such a grid.

    ``fast=True`` evaluates the same closed form in f32 (8 SIMD lanes), still returning
    float64: within 2.4e-7 of the exact values in R and T for films up to 5 um and 1.8e-6
    up to 0.1 mm (measured, every angle, low- and high-index films), up to about twice as
    fast (less where writing the float64 output bounds the call).
    Cells an f32 phase cannot resolve (near grazing incidence, or the film's critical
    angle) are computed exactly.
    """
    axes = [np.ascontiguousarray(np.atleast_1d(np.asarray(a, dtype=np.float64))) for a in
            (thickness_nm, angle_deg, wavelength_nm)]
    for name, a in zip(("thickness_nm", "angle_deg", "wavelength_nm"), axes):
        if a.ndim != 1:
            raise ValueError(f"{name} has shape {a.shape}: film_rt_grid takes 1-d axes")
    d, angle, wl = axes
    r, t = _native.film_rt_grid(d, angle, wl, float(n_film), float(n_outside), str(pol), False,
                                bool(fast))
    shape = (d.size, angle.size, wl.size)
    return r.reshape(shape), t.reshape(shape)


def film_rt(thickness_nm, angle_deg, wavelength_nm, n_film=1.33, n_outside=1.0, fast=False):
    """``(R, T)`` of a free-standing film ``n_outside | n_film | n_outside`` (unpolarised).

    All three arrays broadcast together: the exact Airy sum of all orders in f64, in
    parallel (about 1e-15, for comparisons with tmm). ``fast=True`` runs thinfilm's f32
    batch kernel instead (SIMD, in parallel; the kernel is within 2e-7 for inputs f32 holds
    exactly). Rounding the inputs to f32 moves the phase by up to 6e-8 of itself, which for
    films up to 5 um stays within 5e-5 in R and T (worst near grazing incidence and for
    high-index films, where the fringes are sharp); R + T = 1 holds to 4e-7. Points f32
    cannot hold always take the exact path.

    When the three arrays form an outer product (as ``d[:, None, None]``,
    ``angle[None, :, None]``, ``wl[None, None, :]`` in any order), both run on
    :func:`film_rt_grid`, about 50 times faster: exact, or with ``fast=True`` its f32
    kernel, within 2.4e-7 of exact for films up to 5 um (the inputs are not rounded to
    f32 there).
    """
    axes = _axes(thickness_nm, angle_deg, wavelength_nm)
    if axes is not None:
        try:
            shape = np.broadcast_shapes(*(np.shape(a) for a in (thickness_nm, angle_deg, wavelength_nm)))
        except ValueError as err:
            raise ValueError(f"arguments do not broadcast together: {err}") from None
    if axes is not None and len(shape) >= 1:
        (d, angle, wl), positions = axes
        order = [int(k) for k in np.argsort(positions, kind="stable")]
        # The native call writes thickness- or angle-major directly; other orders transpose.
        angle_major = order == [1, 0, 2]
        r, t = _native.film_rt_grid(d, angle, wl, float(n_film), float(n_outside), "u", angle_major,
                                    bool(fast))
        if angle_major or order == [0, 1, 2]:
            return r.reshape(shape), t.reshape(shape)
        r = np.transpose(r.reshape(d.size, angle.size, wl.size), order).reshape(shape)
        t = np.transpose(t.reshape(d.size, angle.size, wl.size), order).reshape(shape)
        return r, t
    shape, (d, angle, wl) = _flat(thickness_nm, angle_deg, wavelength_nm)
    native = _native.film_rt_fast if fast else _native.film_rt
    r, t = native(d, angle, wl, float(n_film), float(n_outside))
    return r.reshape(shape), t.reshape(shape)


def fit_thickness(
    wavelength_nm,
    reflectance,
    n=(1.0, 1.33, 1.0),
    d_nm=None,
    layer=0,
    angle_deg=0.0,
    thickness_range_nm=(0.0, 5000.0),
    wavelength_uncertainty_nm=0.0,
):
    """Fit the thickness of one layer to a measured unpolarised reflectance spectrum.

    The model is the stack ``n`` (media from the incidence side, as in :func:`rt`) with
    inner thicknesses ``d_nm`` (default all 0), of which layer ``layer`` (0-based) is
    unknown, plus a constant offset. The fringe order is found by a global scan over
    ``thickness_range_nm``; the result is a dict with ``thickness_nm``, the 95 %
    ``interval_nm`` (statistical, from the residuals, plus the shift that
    ``wavelength_uncertainty_nm`` of calibration error causes), ``sigma_nm``,
    ``systematic_nm``, ``offset``, ``rms_residual``, and the runner-up minimum
    ``runner_up_nm`` / ``runner_up_rms`` (an ambiguous fringe order shows as a runner-up
    with nearly the same residual). A free soap film: the defaults. Silica on silicon:
    ``fit_thickness(wl, r, n=[1.0, 1.46, 3.88 + 0.02j])``.
    """
    n, d_nm, wl, r = _fit_inputs(wavelength_nm, reflectance, n, d_nm, layer)
    lo, hi = (float(x) for x in thickness_range_nm)
    out = _native.fit_thickness(wl, r, n, d_nm, int(layer), float(angle_deg), lo, hi,
                                float(wavelength_uncertainty_nm))
    keys = ["thickness_nm", "low", "high", "sigma_nm", "systematic_nm", "offset",
            "rms_residual", "runner_up_nm", "runner_up_rms"]
    fit = dict(zip(keys, out))
    fit["interval_nm"] = (fit.pop("low"), fit.pop("high"))
    return fit


def fit_thickness_and_index(
    wavelength_nm,
    reflectance,
    n=(1.0, 1.46, 3.88 + 0.02j),
    d_nm=None,
    layer=0,
    angle_deg=0.0,
    thickness_range_nm=(0.0, 5000.0),
    a_range=(1.3, 1.7),
    b_range_nm2=(0.0, 10000.0),
    wavelength_uncertainty_nm=0.0,
):
    """Fit one layer's thickness together with its Cauchy index ``n(λ) = a + b/λ²``.

    As :func:`fit_thickness` (the stack ``n``, ``d_nm``, the unknown ``layer``, whose own
    entry in ``n`` is replaced by the fitted index), with ``a`` searched in ``a_range``
    and ``b`` (nm²) in ``b_range_nm2``: a global thickness search at three values of
    ``a``, then Levenberg-Marquardt over thickness, ``a`` and ``b``. Returns a dict with
    ``thickness_nm``, ``cauchy_a``, ``cauchy_b_nm2``, each with its 95 % ``..._interval``
    (statistical plus the shift ``wavelength_uncertainty_nm`` of calibration causes) and
    ``..._sigma``, and ``offset``, ``rms_residual``. A film thinner than about one fringe
    measures only its optical thickness: the intervals then widen to say so.
    Silica on silicon: ``fit_thickness_and_index(wl, r)``.
    """
    n, d_nm, wl, r = _fit_inputs(wavelength_nm, reflectance, n, d_nm, layer)
    pairs = []
    for name, pair in [("thickness_range_nm", thickness_range_nm), ("a_range", a_range),
                       ("b_range_nm2", b_range_nm2)]:
        values = np.atleast_1d(np.asarray(pair, dtype=np.float64))
        if values.shape != (2,):
            raise ValueError(f"{name} = {pair!r} is not a (low, high) pair")
        pairs.append((float(values[0]), float(values[1])))
    out = _native.fit_thickness_cauchy(wl, r, n, d_nm, int(layer), float(angle_deg), *pairs,
                                       float(wavelength_uncertainty_nm))
    fit = {}
    for k, name in enumerate(["thickness_nm", "cauchy_a", "cauchy_b_nm2"]):
        value, low, high, sigma, systematic = out[5 * k:5 * k + 5]
        fit[name] = value
        fit[name + "_interval"] = (low, high)
        fit[name + "_sigma"] = sigma
        fit[name + "_systematic"] = systematic
    fit["offset"], fit["rms_residual"] = out[15], out[16]
    return fit


def _fit_inputs(wavelength_nm, reflectance, n, d_nm, layer):
    """A fit's stack (``d_nm`` all 0 when None) and contiguous spectrum, ``layer`` checked."""
    n = [complex(x) for x in np.atleast_1d(n)]
    if d_nm is None:
        d_nm = [0.0] * max(len(n) - 2, 0)
    d_nm = [float(x) for x in np.atleast_1d(d_nm)] if np.size(d_nm) else []
    wl = np.ascontiguousarray(np.asarray(wavelength_nm, dtype=np.float64).ravel())
    r = np.ascontiguousarray(np.asarray(reflectance, dtype=np.float64).ravel())
    if isinstance(layer, bool) or not isinstance(layer, (int, np.integer)) or layer < 0:
        raise ValueError(f"layer = {layer!r} is not an index >= 0 into d_nm")
    return n, d_nm, wl, r


def film_xyz(thickness_nm, angle_deg, n_film=1.33, illuminant="d65", observer="1931"):
    """CIE XYZ of the light a soap film in air reflects, shape ``(..., 3)``.

    The illuminant's perfect reflector has Y = 1. ``illuminant`` is one of d65, d50, a, e,
    f2, f11, sodium; ``observer`` is "1931" (2 degrees) or "1964" (10 degrees).
    """
    shape, (d, angle) = _flat(thickness_nm, angle_deg)
    xyz = _native.film_xyz(d, angle, float(n_film), str(illuminant), str(observer))
    return xyz.reshape(shape + (3,))


def xyz_to_srgb(xyz):
    """Encoded sRGB in [0, 1] (clamped; D65 white at Y = 1) of XYZ of shape ``(..., 3)``."""
    xyz = np.asarray(xyz, dtype=np.float64)
    if xyz.shape[-1:] != (3,):
        raise ValueError(f"xyz has shape {xyz.shape}: its last axis must have length 3")
    rgb = _native.xyz_to_srgb(np.ascontiguousarray(xyz).ravel())
    return rgb.reshape(xyz.shape)


# Pixel status codes of thickness_from_rgb.
FITTED, SATURATED, EXCLUDED, UNEXPLAINED, AMBIGUOUS = 0, 1, 2, 3, 4


def _index(name, value):
    """``value`` as a pixel coordinate or size (an int in [0, 2**32)), else ValueError."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) \
            or not 0 <= value < 2**32:
        raise ValueError(f"{name} = {value!r} is not a pixel index (an int >= 0)")
    return int(value)


def _rect(name, rect):
    """A region ``(x, y, w, h)`` in pixels as four ints, else ValueError naming it."""
    try:
        x, y, w, h = rect
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {rect!r} is not a region (x, y, w, h)") from None
    return tuple(_index(f"{name} {k}", v) for k, v in zip("xywh", (x, y, w, h)))


def _per_pixel(name, array, shape, dtype):
    """A per-pixel ``(H, W)`` array as a flat contiguous ``dtype`` copy, else ValueError."""
    array = np.asarray(array)
    if array.shape != shape:
        raise ValueError(f"{name} has shape {array.shape}: the image needs {shape} (H, W)")
    if dtype == np.bool_ and array.dtype != np.bool_:
        raise ValueError(f"{name} has dtype {array.dtype}: it must be a bool array")
    return np.ascontiguousarray(array, dtype=dtype).ravel()


def _pixels(image):
    """The image's ``(H, W)`` and its flat pixels in the dtype the native call takes."""
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"image has shape {image.shape}: it must be (H, W, 3) RGB")
    if image.dtype in (np.uint8, np.uint16):
        flat = np.ascontiguousarray(image).ravel()
    elif image.dtype in (np.float32, np.float64):
        flat = np.ascontiguousarray(image, dtype=np.float32).ravel()
    else:
        raise ValueError(f"image has dtype {image.dtype}: it must be uint8 or uint16 "
                         "(sRGB-encoded) or float32/float64 (linear)")
    return image.shape[:2], flat


def _calibration(white, reference, exposure, gains):
    """The native call's ``(white, reference, camera)``: at most one of them set."""
    given = [name for name, v in (("white", white), ("reference", reference),
                                  ("exposure", exposure)) if v is not None]
    if len(given) > 1:
        raise ValueError(f"{' and '.join(given)} are given together: "
                         "give at most one calibration")
    if gains is not None and exposure is None:
        raise ValueError(f"gains = {gains!r} needs an exposure")
    if white is not None:
        white = _rect("white", white)
    if reference is not None:
        try:
            rect, nm = reference
        except (TypeError, ValueError):
            raise ValueError(f"reference = {reference!r} is not ((x, y, w, h), nm)") from None
        reference = (_rect("reference region", rect), float(nm))
    camera = None
    if exposure is not None:
        g = np.asarray((1.0, 1.0, 1.0) if gains is None else gains, dtype=np.float64)
        if g.shape != (3,):
            raise ValueError(f"gains = {gains!r} is not three numbers (red, green, blue)")
        camera = (float(exposure), [float(v) for v in g])
    return white, reference, camera


def _anchors(anchors):
    """Anchors as ``(x, y, nm)`` tuples, else ValueError naming the bad one."""
    out = []
    for k, a in enumerate(anchors):
        try:
            x, y, nm = a
        except (TypeError, ValueError):
            raise ValueError(f"anchors[{k}] = {a!r} is not (x, y, nm)") from None
        out.append((_index(f"anchors[{k}] x", x), _index(f"anchors[{k}] y", y), float(nm)))
    return out


def _light(illuminant):
    """A built-in illuminant's name, or a sampled spectrum as two float lists."""
    if isinstance(illuminant, str):
        return illuminant
    try:
        wavelength_nm, value = illuminant
    except (TypeError, ValueError):
        raise ValueError(f"illuminant = {illuminant!r} is neither a name nor "
                         "(wavelength_nm, value)") from None
    w = np.asarray(wavelength_nm, dtype=np.float64).ravel()
    v = np.asarray(value, dtype=np.float64).ravel()
    return (w.tolist(), v.tolist())


def _film_index(n_film):
    """A constant index as a float, or a named dispersive model."""
    if isinstance(n_film, str):
        return n_film
    return float(n_film)


def thickness_from_rgb(
    image,
    *,
    illuminant="d65",
    n_film=1.33,
    n_outside=1.0,
    thickness_max_nm=1500.0,
    observer="1931",
    angle_deg=0.0,
    cos_map=None,
    sphere=None,
    white=None,
    reference=None,
    exposure=None,
    gains=None,
    anchors=(),
    mask=None,
    max_residual_de=8.0,
    smoothness_nm=30.0,
):
    """The thickness map of a soap film from an RGB photo of it in reflection.

    ``image`` is ``(H, W, 3)``: uint8 or uint16 sRGB-encoded (a channel at the format's
    maximum marks its pixel saturated), or float32/float64 linear. The film
    ``n_outside | n_film | n_outside`` (``n_film`` a number or ``"water"``, the IAPWS
    dispersion) is lit by ``illuminant`` (d65, d50, a, e, f2, f11, sodium, or a spectrum
    ``(wavelength_nm, value)`` of two 1-D arrays), seen by the CIE ``observer`` ("1931" or
    "1964"), and is up to ``thickness_max_nm`` thick.

    Viewing: one ``angle_deg`` of incidence for every pixel, or ``cos_map`` (``(H, W)``
    cos theta per pixel), or ``sphere=(cx, cy, radius_px)`` (a bubble seen from far away;
    pixels outside its disc are excluded). Calibration, at most one: ``white=(x, y, w, h)``
    a region showing the light in a perfect mirror, ``reference=((x, y, w, h), nm)`` a
    region of known thickness, or ``exposure`` (and optional white-balance ``gains``,
    three numbers) given; by default both are estimated from the photo. ``anchors`` are
    ``(x, y, nm)`` pixels of known thickness, fixing their region's fringe order; ``mask``
    (``(H, W)`` bool) leaves out the pixels where it is False. A fitted pixel whose
    re-rendered colour is further than ``max_residual_de`` (ΔE2000) from the photo is
    unexplained; ``smoothness_nm`` is the thickness step between neighbours the continuity
    prior expects. Fringe orders are resolved over the whole image (the Rust crate
    film-inverse).

    Returns a dict: ``thickness_nm``, ``uncertainty_nm`` (one sigma) and ``residual_de``
    (ΔE2000), each ``(H, W)`` float32 and NaN where a pixel is not fitted; ``status``
    (``(H, W)`` uint8: 0 fitted, 1 saturated, 2 excluded, 3 unexplained, also named
    ``thinfilm.FITTED``, ``SATURATED``, ``EXCLUDED``, ``UNEXPLAINED``, ``AMBIGUOUS``: a patch too small or too pale to place its fringe order); ``rerender``
    (``(H, W, 3)`` float32, the colours the map predicts, sRGB-encoded in [0, 1], the
    photo's own where not fitted); and ``summary``, a dict: the camera's ``exposure`` and
    ``gains``, how it was found (``calibration``: given, white region, reference region
    or estimated), pixel counts (``fitted``, ``saturated``, ``excluded``,
    ``unexplained``), the residual's mean, 95th percentile and maximum, ``noise_encoded``,
    the fitted thickness's minimum, median and maximum, the median uncertainty (these are
    NaN when nothing is fitted), and the regions grown (``regions``, ``regions_anchored``,
    ``regions_shifted``). The GIL is released while Rust computes (in parallel). Bad input,
    a saturated photo or a calibration region that cannot calibrate raise ValueError.
    """
    shape, pixels = _pixels(image)
    if cos_map is not None and sphere is not None:
        raise ValueError("cos_map and sphere are both given: give at most one viewing geometry")
    if (cos_map is not None or sphere is not None) and float(angle_deg) != 0.0:
        raise ValueError(f"angle_deg = {angle_deg!r} with a cos_map or sphere: give one geometry")
    if cos_map is not None:
        cos_map = _per_pixel("cos_map", cos_map, shape, np.float32)
    if sphere is not None:
        try:
            cx, cy, radius = (float(v) for v in sphere)
        except (TypeError, ValueError):
            raise ValueError(f"sphere = {sphere!r} is not (cx, cy, radius_px)") from None
        sphere = (cx, cy, radius)
    if mask is not None:
        mask = _per_pixel("mask", mask, shape, np.bool_)
    white, reference, camera = _calibration(white, reference, exposure, gains)
    height, width = (_index("image height", shape[0]), _index("image width", shape[1]))
    film = (_light(illuminant), _film_index(n_film), float(n_outside),
            float(thickness_max_nm), str(observer))
    h, sigma, de, status, rerender, summary = _native.thickness_from_rgb(
        pixels, width, height, film, float(angle_deg), cos_map, sphere, white, reference,
        camera, _anchors(anchors), mask, float(max_residual_de), float(smoothness_nm))
    status = status.reshape(shape)
    missing = status != FITTED
    maps = {"thickness_nm": h, "uncertainty_nm": sigma, "residual_de": de}
    out = {}
    for name, values in maps.items():
        values = values.reshape(shape)
        values[missing] = np.nan
        out[name] = values
    out["status"] = status
    out["rerender"] = rerender.reshape(shape + (3,))
    if summary["fitted"] == 0:
        for key in ("residual_mean_de", "residual_p95_de", "residual_max_de",
                    "thickness_min_nm", "thickness_median_nm", "thickness_max_nm",
                    "uncertainty_median_nm"):
            summary[key] = float("nan")
    out["summary"] = summary
    return out

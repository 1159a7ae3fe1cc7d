"""Speed of thinfilm.film_rt against colour-science's thin_film_tmm on one grid, one process.

Grid: d 0-2000 nm by 10, angles 0-75 deg by 7.5, wavelength 360-830 nm by 1 (soap 1.33 in
air), unpolarised R: 1.04 M points. Needs `pip install colour-science tmm numpy` and this
package installed; colour-science and tmm are used for this measurement only. Prints the
best of --repeat runs of each, the largest |R difference| against colour-science, and the
largest |R difference| against Byrnes' tmm.coh_tmm on --tmm-points random grid points.

Timed calls: `film_rt` on the broadcast axes (it takes the grid path, film_rt_grid, by
itself), `film_rt_grid` on the three axes, `film_rt(fast=True)` on the axes (the f32 grid
kernel), and the point-by-point exact path (`film_rt` on the full broadcast arrays, which
are no outer product) for reference. Each is timed back to back, best of --repeat; the
first call of the process (fresh output pages, nothing pooled yet) is printed too.
"""

import argparse
import os
import time

import numpy as np
import tmm

import thinfilm
from colour.phenomena import thin_film_tmm


def best_of(repeat, call, first=None):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = call()
        times.append(time.perf_counter() - start)
    if first is not None:
        first.append(times[0])
    return min(times), out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--tmm-points", type=int, default=2000)
    args = parser.parse_args()
    repeat = args.repeat
    d = np.arange(0, 2000.0 + 1e-9, 10.0)
    angle = np.arange(0, 75.0 + 1e-9, 7.5)
    wl = np.arange(360, 831.0)
    grid = (d[None, :, None], angle[:, None, None], wl[None, None, :])  # (A, T, W)
    first = []
    t_ours, (r_ours, _) = best_of(repeat, lambda: thinfilm.film_rt(*grid), first)
    t_grid, (r_grid, _) = best_of(repeat, lambda: thinfilm.film_rt_grid(d, angle, wl))
    t_fast, (r_fast, _) = best_of(repeat, lambda: thinfilm.film_rt(*grid, fast=True))
    full = [np.ascontiguousarray(a) for a in np.broadcast_arrays(*grid)]
    t_points, (r_points, _) = best_of(max(1, repeat // 2), lambda: thinfilm.film_rt(*full))
    t_theirs, (r_theirs, _) = best_of(
        max(1, repeat // 2), lambda: thin_film_tmm([1.0, 1.33, 1.0], d, wl, angle)
    )
    # colour-science returns (W, A, T, 2) with [..., 0] = s and [..., 1] = p.
    r_theirs = 0.5 * (r_theirs[..., 0] + r_theirs[..., 1])  # (W, A, T)
    r_theirs = np.transpose(r_theirs, (1, 2, 0))  # (A, T, W) as ours
    assert np.array_equal(r_grid.transpose(1, 0, 2), r_ours)
    rng = np.random.default_rng(0)
    worst_tmm = 0.0
    for _ in range(args.tmm_points):
        a, k, w = rng.integers(angle.size), rng.integers(d.size), rng.integers(wl.size)
        ref = [
            tmm.coh_tmm(pol, [1.0, 1.33, 1.0], [np.inf, d[k], np.inf], np.radians(angle[a]), wl[w])["R"]
            for pol in "sp"
        ]
        worst_tmm = max(worst_tmm, abs(r_ours[a, k, w] - 0.5 * (ref[0] + ref[1])))
    points = d.size * angle.size * wl.size
    print(f"points {points}, cpus {os.cpu_count()}, load {os.getloadavg()}")
    print(f"thinfilm.film_rt (grid path)   {t_ours:.4f} s (first call of the process {first[0]:.4f} s)")
    print(f"thinfilm.film_rt_grid          {t_grid:.4f} s")
    print(f"thinfilm.film_rt fast=True     {t_fast:.4f} s")
    print(f"thinfilm.film_rt point by point {t_points:.4f} s")
    print(f"colour thin_film_tmm           {t_theirs:.4f} s")
    print(f"ratio film_rt {t_theirs / t_ours:.1f}x, film_rt_grid {t_theirs / t_grid:.1f}x, "
          f"fast {t_theirs / t_fast:.1f}x, point by point {t_theirs / t_points:.1f}x")
    print(f"max |dR| vs colour {np.abs(r_ours - r_theirs).max():.2e}, "
          f"point by point vs grid {np.abs(r_points - r_ours).max():.2e}, "
          f"vs tmm.coh_tmm on {args.tmm_points} points {worst_tmm:.2e}")
    print(f"fast=True: max |dR| vs exact {np.abs(r_fast - r_ours).max():.2e}, "
          f"vs colour {np.abs(r_fast - r_theirs).max():.2e}")


if __name__ == "__main__":
    main()

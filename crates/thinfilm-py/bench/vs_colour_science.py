"""Speed of thinfilm.film_rt (exact and fast=True) against colour-science's thin_film_tmm on one grid, one process.

Grid: d 0-2000 nm by 10, angles 0-75 deg by 7.5, wavelength 360-830 nm by 1 (soap 1.33 in
air), unpolarised R. Needs `pip install colour-science numpy` and this package installed;
colour-science is used for this measurement only. Prints the best of --repeat runs of each
and the largest |R difference|.
"""

import argparse
import os
import time

import numpy as np

import thinfilm
from colour.phenomena import thin_film_tmm


def best_of(repeat, call):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = call()
        times.append(time.perf_counter() - start)
    return min(times), out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=3)
    repeat = parser.parse_args().repeat
    d = np.arange(0, 2000.0 + 1e-9, 10.0)
    angle = np.arange(0, 75.0 + 1e-9, 7.5)
    wl = np.arange(360, 831.0)
    t_ours, (r_ours, _) = best_of(
        repeat, lambda: thinfilm.film_rt(d[None, :, None], angle[:, None, None], wl[None, None, :])
    )
    grid = (d[None, :, None], angle[:, None, None], wl[None, None, :])
    t_fast, (r_fast, _) = best_of(repeat, lambda: thinfilm.film_rt(*grid, fast=True))
    t_theirs, (r_theirs, _) = best_of(
        repeat, lambda: thin_film_tmm([1.0, 1.33, 1.0], d, wl, angle)
    )
    # colour-science returns (W, A, T, 2) with [..., 0] = s and [..., 1] = p.
    r_theirs = 0.5 * (r_theirs[..., 0] + r_theirs[..., 1])  # (W, A, T)
    r_theirs = np.transpose(r_theirs, (1, 2, 0))  # (A, T, W) as ours
    points = d.size * angle.size * wl.size
    print(f"points {points}, cpus {os.cpu_count()}, load {os.getloadavg()}")
    print(f"thinfilm.film_rt       {t_ours:.3f} s")
    print(f"thinfilm.film_rt fast  {t_fast:.3f} s")
    print(f"colour thin_film_tmm   {t_theirs:.3f} s")
    print(f"ratio {t_theirs / t_ours:.1f}x, max |dR| {np.abs(r_ours - r_theirs).max():.2e}")
    print(f"fast ratio {t_theirs / t_fast:.1f}x, max |dR| {np.abs(r_fast - r_theirs).max():.2e}")


if __name__ == "__main__":
    main()

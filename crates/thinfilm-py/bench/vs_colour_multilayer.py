"""Speed of thinfilm.rt against colour-science's multilayer_tmm on a 5-layer stack over
wavelength 360-830 nm by 1 and angles 0-75 deg by 7.5 (5 181 points), one process,
unpolarised R. Needs `pip install colour-science numpy` and this package.

Two ways, both printed: back to back (each call --rounds times in a row, best kept, as
vs_colour_science.py measures), and alternating (the two calls take turns for --rounds
rounds, so a change of load hits both, but each of ours then starts cold: on the
development VM a 0.15 ms call runs 2-3 times slower right after another program's work or
a 20 ms sleep, while a 15 ms one barely notices). Also the largest |R difference|.
"""

import argparse
import os
import time

import numpy as np

import thinfilm
from colour.phenomena import multilayer_tmm

WL = np.arange(360, 831.0)
ANGLE = np.arange(0, 75.0 + 1e-9, 7.5)
N = [1.0, 1.38, 2.1, 1.46, 2.1, 1.38, 1.52]
D = [100.0, 60.0, 90.0, 60.0, 100.0]


def timed(call):
    start = time.perf_counter()
    out = call()
    return time.perf_counter() - start, out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--rounds", type=int, default=41)
    args = parser.parse_args()
    call_ours = lambda: thinfilm.rt(N, D, WL[None, :], ANGLE[:, None])  # noqa: E731
    call_theirs = lambda: multilayer_tmm(N, D, WL, ANGLE)  # noqa: E731
    best_ours = min(timed(call_ours)[0] for _ in range(args.rounds))
    best_theirs = min(timed(call_theirs)[0] for _ in range(args.rounds))
    ours, theirs = [], []
    for _ in range(args.rounds):
        t, (r_ours, _) = timed(lambda: thinfilm.rt(N, D, WL[None, :], ANGLE[:, None]))
        ours.append(t)
        t, res = timed(lambda: multilayer_tmm(N, D, WL, ANGLE))
        theirs.append(t)
    r_theirs = np.asarray(res[0])
    r_theirs = np.squeeze(0.5 * (r_theirs[..., 0] + r_theirs[..., 1])).T  # (A, W) as ours
    ours, theirs = np.array(ours), np.array(theirs)
    print(f"points {WL.size * ANGLE.size}, cpus {os.cpu_count()}, load {os.getloadavg()}")
    print(f"back to back: thinfilm.rt best {1e3 * best_ours:.3f} ms, colour multilayer_tmm "
          f"best {1e3 * best_theirs:.3f} ms, ratio {best_theirs / best_ours:.1f}x")
    print("alternating:")
    print(f"thinfilm.rt           best {1e3 * ours.min():.3f} ms, median {1e3 * np.median(ours):.3f} ms")
    print(f"colour multilayer_tmm best {1e3 * theirs.min():.3f} ms, median {1e3 * np.median(theirs):.3f} ms")
    print(f"ratio of bests {theirs.min() / ours.min():.1f}x, median of the rounds' ratios "
          f"{np.median(theirs / ours):.1f}x, max |dR| {np.abs(r_theirs - r_ours).max():.1e}")


if __name__ == "__main__":
    main()

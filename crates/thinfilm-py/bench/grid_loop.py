"""Times N calls of thinfilm.film_rt on colour-science's grid axes (d 0-2000 nm by 10,
angles 0-75 deg by 7.5, wavelength 360-830 nm by 1: 1.04 M points), each call's result
kept until the next one returns, as a user's loop would: prints min, median and 90th
percentile. `python grid_loop.py N [fast]`; for profiles, `perf record -g python
grid_loop.py 300`. Needs only numpy and this package.
"""

import sys, time, numpy as np, thinfilm
d = np.arange(0, 2000.0 + 1e-9, 10.0); angle = np.arange(0, 75.0 + 1e-9, 7.5); wl = np.arange(360, 831.0)
g = (d[None, :, None], angle[:, None, None], wl[None, None, :])
n = int(sys.argv[1]) if len(sys.argv) > 1 else 200
fast = len(sys.argv) > 2 and sys.argv[2] == "fast"
ts = []
for _ in range(n):
    s = time.perf_counter(); r, t = thinfilm.film_rt(*g, fast=fast); ts.append(time.perf_counter() - s)
ts = np.array(ts) * 1e3
print(f"min {ts.min():.2f} ms, median {np.median(ts):.2f} ms, p90 {np.percentile(ts,90):.2f}")

"""Worst excess of R + T over 1 for an absorbing incoherent layer (Byrnes' forward-flux
convention, exact only to O(kappa^2)): the table in docs/physics.md, "Incoherent layers".

Random stacks air | 1.5 (incoherent, 0.1 mm) | n + i kappa (incoherent, 0-1 um) | 1-2, n in
1-3.5, angles 0-89 deg, s and p, 2000 stacks per kappa (seed 1); then a 10 nm metal.
"""

import numpy as np

import thinfilm


def main():
    rng = np.random.default_rng(1)
    angles = np.linspace(0, 89, 30)
    for kappa in [1e-4, 1e-3, 1e-2, 1e-1]:
        worst = 0.0
        for _ in range(2000):
            n = [1.0, 1.5, complex(rng.uniform(1, 3.5), kappa), rng.uniform(1, 2)]
            d = [1e5, rng.uniform(0, 1e3)]
            for pol in "sp":
                r, t = thinfilm.rt(n, d, 550.0, angles, pol=pol, coherent=[False, False])
                worst = max(worst, (r + t).max() - 1)
        print(f"kappa {kappa:g}: worst R + T - 1 = {worst:.2g}")
    r, t = thinfilm.rt([1.0, 0.7 + 3.5j, 1.5], [10.0], 550.0, 0.0, coherent=[False])
    print(f"10 nm of 0.7+3.5i, incoherent, head-on: R + T - 1 = {float(r + t - 1):.2f}")


if __name__ == "__main__":
    main()

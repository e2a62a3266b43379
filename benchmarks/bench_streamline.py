"""Streamline throughput and the wall time of the full fractal-hurst reproduction (a script)."""

import time

import numpy as np

from spine_mj.reproduce import fractal_hurst
from spine_mj.surfaces import fractal_fbm, single_gaussian
from spine_mj.theory.streamline import StreamlineParams, streamlines


def steps_per_second(surface, starts, params, repeat=5, backend="auto"):
    """Steps actually taken (sum of n_steps) over the wall time of one call, best of
    ``repeat`` calls (the machine is shared). The kernel runs on one core; ``backend``
    "numpy" times the plain numpy reference instead."""
    streamlines(surface, starts[:2], params, store_paths=False, backend=backend)  # compile / load cache
    best = 0.0
    for _ in range(repeat):
        t = time.perf_counter()
        r = streamlines(surface, starts, params, store_paths=False, backend=backend)
        best = max(best, r.n_steps.sum() / (time.perf_counter() - t))
    return best


def main():
    y = np.linspace(-4.9, 4.9, 2000)
    rate = steps_per_second(
        single_gaussian(sign=1), np.c_[np.full(2000, -4.9), y], StreamlineParams(mu=1.23, dl=0.015)
    )
    print(f"analytic single Gaussian, 2000 starts: {rate:.3g} steps/s (target 2e7)")
    grid = fractal_fbm(nx=256, size=20.0, hurst=0.8, rms_slope=0.5, rng=1)
    rate = steps_per_second(grid, np.c_[np.full(2000, -9.9), 2 * y], StreamlineParams(mu=1.0, dl=0.02))
    print(f"gridded fractal 256^2, 2000 starts: {rate:.3g} steps/s (target 5e6)")
    t = time.perf_counter()
    fractal_hurst(workers=2)
    print(
        f"fractal-hurst full run (7 H x 300 surfaces, 2 workers): {time.perf_counter() - t:.1f} s "
        "(target 60 s)"
    )


if __name__ == "__main__":
    main()

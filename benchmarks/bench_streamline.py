"""Streamline throughput and the wall time of the full fractal-hurst reproduction (a script)."""

import time

import numpy as np
from bench_common import fmt, target_cell

from spine_mj.reproduce import fractal_hurst
from spine_mj.surfaces import fractal_fbm, single_gaussian
from spine_mj.theory.streamline import streamlines
from spine_mj.theory.streamline_types import StreamlineParams


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


def bench_streamline(quick: bool) -> dict:
    n = 500 if quick else 2000
    n_np = 100 if quick else 300
    y = np.linspace(-4.9, 4.9, n)
    cases = {
        "analytic single Gaussian": (
            single_gaussian(sign=1),
            np.c_[np.full(n, -4.9), y],
            StreamlineParams(mu=1.23, dl=0.015),
        ),
        "gridded fractal 256^2": (
            fractal_fbm(nx=256, size=20.0, hurst=0.8, rms_slope=0.5, rng=1),
            np.c_[np.full(n, -9.9), 2 * y],
            StreamlineParams(mu=1.0, dl=0.02),
        ),
    }
    out = {}
    for name, (surface, starts, params) in cases.items():
        kernel = steps_per_second(surface, starts, params, repeat=3 if quick else 5)
        sub = starts[:: max(1, n // n_np)]
        numpy_rate = steps_per_second(surface, sub, params, repeat=2, backend="numpy")
        out[name] = {
            "starts": len(starts),
            "kernel_steps_s": kernel,
            "numpy_starts": len(sub),
            "numpy_steps_s": numpy_rate,
            "kernel_over_numpy": kernel / numpy_rate,
        }
    out["facets"] = facet_rates(quick)
    if not quick:
        t0 = time.perf_counter()
        fractal_hurst(workers=2)
        out["fractal_hurst_full_s"] = time.perf_counter() - t0
    return out


#: The facet walk's target: the quick plan's compare analyses trace every start on the
#: engine's facets at R / 8 steps, ~4e5 steps (the numpy reference's ~94 CPU-s there at its
#: ~4e3 steps per CPU-s on the P600 facets); at 4e4 steps per CPU-s they cost 10 CPU-s of
#: the demo. Steps here are accepted ones: a rejected, halved step costs an evaluation too.
FACET_TARGET_STEPS_PER_CPU_S = 4e4


def facet_rates(quick: bool) -> dict:
    """Steps per CPU second of the facet streamline (the compare analysis's reference: the
    engine's ball on the P600 sandpaper's facets, steps of R / 8) compiled
    (:mod:`spine_mj.theory._facet_streamline_kernel`) and numpy, on the same starts, and
    whether the two gave the same paths (within 1e-9)."""
    from spine_mj import presets
    from spine_mj.sim import Rig, TipParams

    contact = Rig(presets.make_surface("sandpaper-P600"), tip=TipParams(mu_s=0.5)).contact_surface()
    xmin, xmax, ymin, ymax = contact.bounds
    n = 4 if quick else 12
    starts = np.c_[np.full(n, xmin + 0.25 * (xmax - xmin)), np.linspace(ymin, ymax, n + 2)[1:-1]]
    params = StreamlineParams(mu=0.5, dl=contact.radius / 8, kappa_cap=20.0)

    def cpu(backend):
        t = time.process_time()
        r = streamlines(contact, starts, params, backend=backend)
        return r, time.process_time() - t

    cpu("numba")  # compile or load the cache
    fast, fast_s = min((cpu("numba") for _ in range(3)), key=lambda r: r[1])
    slow, slow_s = cpu("numpy")
    same = np.array_equal(fast.outcome, slow.outcome) and fast.x.shape == slow.x.shape
    same = same and bool(np.allclose(fast.x, slow.x, rtol=0, atol=1e-9 * contact.radius))
    steps = int(fast.n_steps.sum())
    return {
        "starts": n,
        "steps": steps,
        "kernel_steps_per_cpu_s": steps / max(fast_s, 1e-9),
        "numpy_steps_per_cpu_s": steps / max(slow_s, 1e-9),
        "same_paths": same,
    }


def markdown(sl: dict | None) -> list[str]:
    """The streamline rows of the Performance table."""
    lines = []
    if sl:
        ld = f"{sl['load_before']}-{sl['load_after']}"
        for name in ("analytic single Gaussian", "gridded fractal 256^2"):
            r = sl[name]
            target = 2e7 if name.startswith("analytic") else 5e6
            lines.append(
                f"| streamline kernel, {name}, {r['starts']} starts, one core | "
                f"{fmt(r['kernel_steps_s'])} steps/s | "
                f"{target_cell(r['kernel_steps_s'], '>=', target)} | {ld} |"
            )
            lines.append(
                f"| plain numpy streamline (`backend='numpy'`), {name}, {r['numpy_starts']} starts | "
                f"{fmt(r['numpy_steps_s'])} steps/s (kernel / numpy = "
                f"{r['kernel_over_numpy']:.0f}x) | | {ld} |"
            )
        if "facets" in sl:
            f = sl["facets"]
            same = "the same paths" if f["same_paths"] else "**paths differ**"
            rate = f["kernel_steps_per_cpu_s"]
            lines.append(
                f"| facet streamline (compare's reference: ball on the P600 facets, steps R / 8), "
                f"{f['starts']} starts, compiled | {fmt(rate)} steps / CPU-s (numpy "
                f"{fmt(f['numpy_steps_per_cpu_s'])}: {rate / f['numpy_steps_per_cpu_s']:.0f}x; {same}) | "
                f"{target_cell(rate, '>=', FACET_TARGET_STEPS_PER_CPU_S)} | {ld} |"
            )
        if "fractal_hurst_full_s" in sl:
            lines.append(
                f"| full Fig. 9 Monte Carlo (7 H x 300 surfaces, 2 workers) | "
                f"{sl['fractal_hurst_full_s']:.1f} s | "
                f"{target_cell(sl['fractal_hurst_full_s'], '<=', 60, ' s')} | {ld} |"
            )
    return lines


if __name__ == "__main__":
    main()

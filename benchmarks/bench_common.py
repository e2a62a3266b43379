"""What every benchmark section shares: the load average, the median's interval, a section's
timing, and the target cell of a Performance row (a missed target marked :data:`MISSED`)."""

from __future__ import annotations

import math
import os
import time


def load() -> float:
    return round(os.getloadavg()[0], 2)


def median_interval(values, confidence: float = 0.95) -> tuple[float, float] | None:
    """A distribution-free confidence interval of the median: the order statistics
    ``x_(k)`` and ``x_(n+1-k)`` with the largest ``k`` for which a Binomial(n, 1/2) count
    falls below ``k`` with probability at most ``(1 - confidence) / 2``. It tells how far a
    median of so many noisy pairs can be trusted. None when ``n`` is too small (under 6)."""
    x, n = sorted(values), len(values)
    tail, k, below = (1 - confidence) / 2, 0, 0.0
    while k < n // 2 and below + math.comb(n, k) / 2**n <= tail:
        below += math.comb(n, k) / 2**n
        k += 1
    return (x[k - 1], x[n - k]) if k else None


def section(fn, *args):
    """Run one benchmark section; its dict gains the load average before and after it."""
    before, t0 = load(), time.perf_counter()
    out = fn(*args)
    out.update(load_before=before, load_after=load(), wall_s=round(time.perf_counter() - t0, 1))
    print(f"  {fn.__name__}: {out['wall_s']} s, load {before} -> {out['load_after']}", flush=True)
    return out


#: How the target cell of a row whose measurement misses its target ends.
MISSED = "**missed**"


def target_cell(value: float, op: str, bound: float, unit: str = "") -> str:
    """The target cell ``>= 0.85``, marked :data:`MISSED` where ``value`` misses it."""
    met = value >= bound if op == ">=" else value <= bound
    return f"{op} {bound:g}".replace("e+0", "e") + unit + ("" if met else f" {MISSED}")


def fmt(v, digits=3) -> str:
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    return str(v)


def ci_text(ro: dict) -> str:
    """``; 95 % CI of the median a-b`` where the results have it (older ones do not)."""
    ci = ro.get("ratio_median_ci95")
    return f"; 95 % CI of the median {ci[0]:.3f}-{ci[1]:.3f}" if ci else ""


def rig_detection(rig):
    """The detection settings a run of ``rig`` uses (resolved against its scales)."""
    from spine_mj.sim import Detection

    return Detection().resolve(rig.scales)

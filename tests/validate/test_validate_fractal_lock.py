"""The fractal self-lock study's rates and intervals on constructed counts (no engine runs)."""

import math

import numpy as np
import pandas as pd
import pytest

from spine_mj.reproduce import fig9_rms_height, fig9_seeds
from spine_mj.validate import PLANS
from spine_mj.validate.fractal_lock import CONFIDENCE, hurst_rows, lock_rate, surfaces_table


def wilson(k: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """The Wilson score interval written out (95 %)."""
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


@pytest.mark.parametrize("k, n", [(0, 6), (2, 5), (6, 6), (13, 30)])
def test_lock_rate_is_the_fraction_with_its_wilson_interval(k, n):
    assert CONFIDENCE == 0.95
    r = lock_rate([True] * k + [False] * (n - k))
    lo, hi = wilson(k, n)
    assert (r["n"], r["n_ok"], r["locked"], r["failed_runs"]) == (n, n, k, 0)
    assert r["rate"] == pytest.approx(k / n)
    assert r["ci_low"] == pytest.approx(lo, abs=1e-9) and r["ci_high"] == pytest.approx(hi, abs=1e-9)
    assert r["ci_low"] <= r["rate"] <= r["ci_high"]


def test_failed_runs_are_counted_and_left_out_of_the_rate():
    # a failed run that "locked" must not count: 1 of 2 ok runs locked, 2 failed
    r = lock_rate([True, True, False, True], ok=[True, False, True, False])
    assert (r["n"], r["n_ok"], r["locked"], r["failed_runs"]) == (4, 2, 1, 2)
    assert r["rate"] == 0.5
    assert (r["ci_low"], r["ci_high"]) == pytest.approx(wilson(1, 2))


def test_no_ok_run_gives_no_rate():
    r = lock_rate([True, False], ok=[False, False])
    assert r["n_ok"] == 0 and r["failed_runs"] == 2
    assert all(math.isnan(r[k]) for k in ("rate", "ci_low", "ci_high"))


def test_lock_rate_rejects_mismatched_lengths():
    with pytest.raises(ValueError, match="one shape"):
        lock_rate([True, False], ok=[True])


def test_hurst_rows_group_by_h_and_series():
    runs = pd.DataFrame.from_records(
        [
            *({"hurst": 0.95, "series": "streamline", "locked": i < 3, "ok": True} for i in range(4)),
            *({"hurst": 0.65, "series": "streamline", "locked": i < 1, "ok": True} for i in range(4)),
            *({"hurst": 0.65, "series": "mujoco_corner", "locked": True, "ok": i != 0} for i in range(4)),
        ]
    )
    rows = hurst_rows(runs)
    assert [r["hurst"] for r in rows] == [0.65, 0.95]
    low, high = rows
    assert low["rate_streamline"] == 0.25 and high["rate_streamline"] == 0.75
    assert (low["locked_mujoco_corner"], low["n_ok_mujoco_corner"], low["failed_runs_mujoco_corner"]) == (
        3,
        3,
        1,
    )
    assert low["rate_mujoco_corner"] == 1.0 and low["ci_high_mujoco_corner"] == pytest.approx(1.0)
    assert "rate_mujoco_corner" not in high and "rate_facets" not in low


def test_surfaces_are_fig9s_with_h_set_and_distinct_seeds():
    plan = PLANS["full"]
    table = surfaces_table(plan.fractal.hursts, plan.fractal.surfaces)
    assert len(plan.fractal.hursts) >= 5 and plan.fractal.surfaces >= 30
    assert all(0.6 <= h <= 0.95 for h in plan.fractal.hursts)
    seeds = [s for entry in table for s in entry["seeds"]]
    assert len(seeds) == len(set(seeds)) == len(plan.fractal.hursts) * plan.fractal.surfaces
    entry = table[0]
    assert entry["set"]["hurst"] == plan.fractal.hursts[0] and entry["set"]["rms_slope"] is None
    # H = 0.65 is the first H of the preset's Fig. 9 list: the same seeds and height scale
    assert entry["seeds"] == list(fig9_seeds(0, plan.fractal.surfaces))
    rms = fig9_rms_height(0.65, 256, 20.0, "pixel", 0.0014)
    assert entry["set"]["rms_height"] == pytest.approx(rms, rel=1e-5)
    heights = [e["set"]["rms_height"] for e in table]
    assert np.all(np.diff(heights) > 0)  # the Fig. 9 synthesis: roughness grows with H


def test_a_refined_rate_is_paired_on_the_surfaces_both_ran_cleanly():
    from spine_mj.validate.fractal_lock import _add_convergence

    # six surfaces at one H: 3 of 6 lock at the default step
    base = pd.DataFrame(
        {
            "hurst": 0.8,
            "surface": [f"s{i}" for i in range(6)],
            "series": "mujoco_corner",
            "locked": [True, True, True, False, False, False],
            "ok": True,
        }
    )
    rows = hurst_rows(base)
    # the halved step reruns the first four: s0 fails, s3 locks now; s4, s5 not rerun
    refined = pd.DataFrame(
        {
            "hurst": 0.8,
            "surface": ["s0", "s1", "s2", "s3"],
            "series": "mujoco_corner",
            "locked": [False, True, True, True],
            "ok": [False, True, True, True],
        }
    )
    _add_convergence(rows, base, {("dt_halved", "corner"): refined}, ("dt_halved",))
    conv = rows[0]["convergence_mujoco_corner"]
    entry = conv["dt_halved"]
    # paired on s1, s2, s3: 2 of 3 locked before, 3 of 3 after
    assert entry["runs"] == 3
    assert entry["base"] == pytest.approx(2 / 3) and entry["refined_value"] == 1.0
    assert entry["change"] == pytest.approx(1 / 3)
    lo, hi = rows[0]["ci_low_mujoco_corner"], rows[0]["ci_high_mujoco_corner"]
    assert entry["converged"] is (lo <= 0.5 + 1 / 3 <= hi)
    assert "convergence_mujoco_dynamic" not in rows[0]  # the series did not run

"""Intervals on headline numbers and the target rule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import norm

from spine_mj.validate.intervals import TARGET_SLACK, bootstrap, meets_target, runs_to_meet, wilson
from spine_mj.validate.platform import platform_info


def _wilson_by_hand(k, n, confidence=0.95):
    z = norm.ppf(0.5 + confidence / 2)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


@pytest.mark.parametrize(("k", "n"), [(26, 30), (24, 30), (30, 30), (0, 9), (5, 9), (100, 104)])
def test_wilson_is_the_score_interval(k, n):
    assert wilson(k, n) == pytest.approx(_wilson_by_hand(k, n), abs=1e-9)
    lo, hi = wilson(k, n)
    assert lo <= k / n <= hi


def test_wilson_narrows_as_one_over_root_n():
    w30 = np.diff(wilson(27, 30))[0]
    w120 = np.diff(wilson(108, 120))[0]
    assert w120 == pytest.approx(w30 / 2, rel=0.15)


def test_wilson_refuses_counts_outside_the_sample_and_is_nan_without_runs():
    with pytest.raises(ValueError, match="successes must lie"):
        wilson(5, 4)
    assert all(math.isnan(v) for v in wilson(0, 0))


def test_bootstrap_of_the_median_covers_it_and_is_reproducible():
    rng = np.random.default_rng(1)
    v = rng.lognormal(-4, 1, 60)
    lo, hi = bootstrap(v)
    assert lo <= np.median(v) <= hi
    assert (lo, hi) == bootstrap(v)  # a function of the values alone
    assert bootstrap([0.2, 0.2, 0.2]) == (0.2, 0.2)
    assert all(math.isnan(b) for b in bootstrap([0.1, np.nan]))


def test_a_target_needs_the_point_and_the_interval():
    t = 0.95
    assert meets_target(0.96, (0.91, 0.99), t, higher_is_better=True)
    assert not meets_target(0.96, (t - TARGET_SLACK - 0.01, 0.99), t, higher_is_better=True)
    assert not meets_target(0.94, (0.93, 0.99), t, higher_is_better=True)
    # a small sample cannot pass: 10 of 10 has a Wilson low of 0.72
    assert not meets_target(1.0, wilson(10, 10), t, higher_is_better=True)
    assert meets_target(1.0, wilson(100, 100), t, higher_is_better=True)
    assert meets_target(0.05, (0.03, 0.104), 0.1, higher_is_better=False)
    assert not meets_target(0.05, (0.03, 0.2), 0.1, higher_is_better=False)
    assert not meets_target(float("nan"), (0.9, 1.0), t, higher_is_better=True)


def test_platform_names_the_cpu_and_the_versions():
    info = platform_info()
    assert info["cpu"] and info["python"].count(".") == 2
    assert info["numpy"] == np.__version__
    assert isinstance(info["vector_instruction_sets"], list)
    assert info["mujoco"]


def test_the_fewest_runs_that_can_meet_a_rate_target():
    n = runs_to_meet(0.95)
    assert meets_target(1.0, wilson(n, n), 0.95, higher_is_better=True)
    assert not meets_target(1.0, wilson(n - 1, n - 1), 0.95, higher_is_better=True)
    assert n == 35  # z^2 (1 - 0.9) / 0.1 rounded up: 30 all-agreeing runs are not enough


def test_platform_records_the_variables_that_switch_code_paths(monkeypatch):
    monkeypatch.setenv("NPY_DISABLE_CPU_FEATURES", "X86_V4")
    monkeypatch.delenv("GLIBC_TUNABLES", raising=False)
    assert platform_info()["dispatch_overrides"] == {"NPY_DISABLE_CPU_FEATURES": "X86_V4"}


def test_the_reports_platform_line_names_switched_code_paths():
    from spine_mj.validate.report.verdicts import platform_line

    info = {**platform_info(), "dispatch_overrides": {"NUMBA_CPU_NAME": "x86-64-v2"}}
    assert "NUMBA_CPU_NAME=x86-64-v2" in platform_line(info)[0]
    assert "switched" not in platform_line({**info, "dispatch_overrides": {}})[0]


def test_the_bootstrap_interval_does_not_depend_on_the_order_of_the_runs():
    v = np.random.default_rng(3).lognormal(size=41)
    assert bootstrap(v) == bootstrap(v[::-1]) == bootstrap(np.random.default_rng(4).permutation(v))

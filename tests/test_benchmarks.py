"""The benchmark report's statistics (``benchmarks/run_all.py``)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from run_all import median_interval


def test_median_interval_is_the_binomial_order_statistics_and_covers_the_median():
    assert median_interval(list(range(1, 22))) == (6, 16)  # n = 21: P(Bin <= 5) = 0.013, <= 6: 0.039
    assert median_interval(list(range(1, 12))) == (2, 10)  # n = 11
    assert median_interval([3.0, 1.0, 2.0, 5.0, 4.0]) is None  # n = 5: even min-max covers only 94 %
    rng = np.random.default_rng(0)
    hits = 0
    for _ in range(2000):
        lo, hi = median_interval(list(rng.standard_cauchy(21)))  # heavy tails: distribution-free
        hits += lo <= 0.0 <= hi
    assert 0.95 <= hits / 2000 <= 0.99  # exact coverage 0.973

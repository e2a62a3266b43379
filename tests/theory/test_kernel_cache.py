"""The compiled streamline kernel gives the same numbers whether it was compiled in the
process or loaded from numba's on-disk cache (a fastmath reassociation once made the scan
di-1's corner depend on which: K_path 102.6 cold, 290.1 warm)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_TRACE = """
import hashlib, numpy as np
from spine_mj.surfaces import fractal_fbm
from spine_mj.theory.streamline import streamlines
from spine_mj.theory.streamline_types import StreamlineParams
g = fractal_fbm(nx=96, size=10.0, hurst=0.8, rms_slope=0.8, rng=3)
y = np.linspace(-4.5, 4.5, 40)
r = streamlines(g, np.c_[np.full(40, -4.8), y], StreamlineParams(mu=1.0, dl=0.02), backend="numba")
print(hashlib.sha1(np.concatenate([r.x, r.y, r.end_x]).tobytes()).hexdigest())
"""


@pytest.mark.slow
def test_a_kernel_loaded_from_the_cache_traces_the_same_paths_as_one_just_compiled(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")}

    def trace() -> str:
        out = subprocess.run(
            [sys.executable, "-c", _TRACE], env=env, capture_output=True, text=True, check=True
        )
        return out.stdout.strip()

    cold = trace()
    assert any((tmp_path / "numba-cache").rglob("*.nbc"))  # the first process wrote the cache
    assert trace() == cold

"""The machine a validation ran on, for ``validation.json``.

Vectorized code paths round differently on different CPUs (an AVX-512 machine flipped two
fractal runs against the committed AVX2 numbers), so every set of headline numbers names
the CPU, its vector instruction sets, the versions that made them, and any variable that
switched the run-time choice of code paths.
"""

from __future__ import annotations

import os
import platform as _platform
import sys
from pathlib import Path

__all__ = ["platform_info"]

#: CPU flags that name the vector instruction sets MuJoCo's compiled code can take.
VECTOR_FLAGS = ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512dq", "avx512vl", "neon", "asimd")


#: Environment variables that change which vector code paths numpy, the C library's maths,
#: OpenBLAS and numba take at run time (recorded when set: the numbers then stand for another CPU's paths).
DISPATCH_VARIABLES = (
    "NPY_DISABLE_CPU_FEATURES",
    "NPY_ENABLE_CPU_FEATURES",
    "GLIBC_TUNABLES",
    "NUMBA_CPU_NAME",
    "OPENBLAS_CORETYPE",
)


def _cpuinfo() -> tuple[str, list[str]]:
    """CPU model name and its vector flags from ``/proc/cpuinfo`` (Linux); else the
    ``platform`` module's processor string and no flags."""
    path = Path("/proc/cpuinfo")
    model, flags = _platform.processor() or _platform.machine(), []
    try:
        text = path.read_text(errors="replace")
    except OSError:
        return model, flags
    for line in text.splitlines():
        key, _, value = line.partition(":")
        key = key.strip().lower()
        if key in ("model name", "hardware", "cpu model") and value.strip():
            model = value.strip()
        elif key in ("flags", "features") and not flags:
            have = set(value.split())
            flags = [f for f in VECTOR_FLAGS if f in have]
    return model, flags


def platform_info() -> dict:
    """CPU, vector instruction sets, OS and versions of Python, numpy and MuJoCo.

    ``vector_instruction_sets`` are those the CPU offers; numpy and the C library pick
    their code paths at run time from them, unless ``dispatch_overrides`` (the environment
    variables of :data:`DISPATCH_VARIABLES` that were set) switched some off.
    """
    import numpy as np

    model, flags = _cpuinfo()
    try:
        import mujoco

        mj_version = mujoco.__version__
    except ImportError:  # pragma: no cover - mujoco is a dependency
        mj_version = None
    return {
        "cpu": model,
        "machine": _platform.machine(),
        "vector_instruction_sets": flags,
        "cpu_count": os.cpu_count(),
        "os": f"{_platform.system()} {_platform.release()}",
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "mujoco": mj_version,
        # set to emulate another CPU's code paths (analysis/reproduction_check.py)
        "dispatch_overrides": {k: os.environ[k] for k in DISPATCH_VARIABLES if os.environ.get(k)},
    }

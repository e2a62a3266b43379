"""What the reproductions share: a preset's settings, the five starts of Figs. 3-4, and
the number formats of their JSON."""

from __future__ import annotations

import math
from collections.abc import Callable

from spine_mj.presets import load_preset, resolve_mu
from spine_mj.theory.streamline_types import Outcome

Progress = Callable[[int, int], None] | None
FIVE_Y0 = (-0.5, -1.0, -2.0, -3.0, -4.0)


def _settings(preset: str, mu: float | None) -> tuple[float, dict, object]:
    """mu_s (``mu``, else the preset's calibrated one: :func:`~spine_mj.presets.resolve_mu`),
    the preset's ``[reproduce]`` table and the preset itself."""
    p = load_preset(preset)
    return resolve_mu(p, mu), dict(p.extras.get("reproduce", {})), p


def _outcome_name(code: int) -> str:
    return Outcome(int(code)).name.lower()


def _finite_or_str(v: float):
    return float(v) if math.isfinite(v) else ("inf" if v > 0 else "nan")


def _nan_none(v):
    v = float(v)
    return v if math.isfinite(v) else None

"""Do a validation's headline numbers reproduce? Another run's numbers against the committed
intervals.

MuJoCo, numpy and the C library take different vectorized code paths on different CPUs, and
those round differently in the last bits; near a watershed that flips a run. The issue's
test of a verdict that holds on any machine: the numbers another machine gives lie inside
the 95 % intervals the committed run reports, and each family's verdict (target met or not)
is the same. :func:`headline_numbers` lists the numbers that carry an interval in a
``validation.json``; :func:`check_reproduction` puts a new run's beside them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from spine_mj.errors import SpineInputError

__all__ = ["Headline", "ReproductionRow", "check_reproduction", "headline_numbers"]


@dataclass(frozen=True)
class Headline:
    """One headline number of a ``validation.json`` with its 95 % interval.

    ``interval`` is ``(low, high)``; ``verdict`` the family's target verdict where the
    number decides one (None otherwise)."""

    key: str
    value: float | None
    interval: tuple[float, float] | None
    verdict: bool | None = None


@dataclass(frozen=True)
class ReproductionRow:
    """A headline number of the committed run beside the new run's."""

    key: str
    committed: float | None
    interval: tuple[float, float] | None
    new: float | None
    inside: bool
    verdict_kept: bool

    @property
    def ok(self) -> bool:
        return self.inside and self.verdict_kept


def _num(v) -> float | None:
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)


def _pair(lo, hi) -> tuple[float, float] | None:
    lo, hi = _num(lo), _num(hi)
    return None if lo is None or hi is None else (lo, hi)


def headline_numbers(validation: dict) -> dict[str, Headline]:
    """The numbers of ``validation`` (a loaded ``validation.json``) that carry an interval.

    Per family of the quasistatic-limit corner (``limit_families``): the well-conditioned
    agreement (``agreement_ci``, Wilson), the agreement over all runs
    (``outcome_agreement_ci``) and the median Frechet distance (``median_frechet_ci``,
    bootstrap); the family's ``meets_target`` is the verdict. I_e* of each drive
    (``ie_star``, bootstrap over starts). The fractal self-lock rates per H and series
    (Wilson). Keys read ``limit.fractal.agreement_well_conditioned`` and so on.
    """
    if not isinstance(validation, dict) or "limit_families" not in validation:
        raise SpineInputError("validation must be a loaded validation.json (with limit_families)")
    out: dict[str, Headline] = {}
    for fam, s in validation["limit_families"].items():
        verdict = bool(s["meets_target"]) if "meets_target" in s else None
        for name, ci in (
            ("agreement_well_conditioned", "agreement_ci"),
            ("outcome_agreement", "outcome_agreement_ci"),
            ("median_frechet", "median_frechet_ci"),
        ):
            if name in s and ci in s:
                key = f"limit.{fam}.{name}"
                out[key] = Headline(key, _num(s[name]), _pair(*s[ci]), verdict)
    for drive, est in (validation.get("ie_star") or {}).items():
        if isinstance(est, dict) and "ci_low" in est:
            key = f"ie_star.{drive}"
            out[key] = Headline(key, _num(est.get("value")), _pair(est["ci_low"], est["ci_high"]))
    for row in (validation.get("fractal_lock_rate") or {}).get("rows", []):
        for series in ("streamline", "mujoco_corner", "mujoco_dynamic"):
            if f"rate_{series}" in row:
                key = f"fractal_lock.H{row['hurst']}.{series}"
                interval = _pair(row[f"ci_low_{series}"], row[f"ci_high_{series}"])
                out[key] = Headline(key, _num(row[f"rate_{series}"]), interval)
    return out


def check_reproduction(new: dict, committed: dict) -> list[ReproductionRow]:
    """Each headline number of ``committed`` beside ``new``'s: inside the committed 95 %
    interval (two runs without a value, such as I_e* below the grid on both, agree), and
    the family verdict kept. A number the new run lacks is not inside."""
    ours, theirs = headline_numbers(committed), headline_numbers(new)
    rows = []
    for key, c in ours.items():
        n = theirs.get(key)
        value = n.value if n else None
        if c.value is None and value is None:
            inside = True
        elif value is None or c.interval is None:
            inside = False
        else:
            lo, hi = c.interval
            inside = lo - 1e-12 <= value <= hi + 1e-12
        kept = c.verdict is None or (n is not None and n.verdict == c.verdict)
        rows.append(ReproductionRow(key, c.value, c.interval, value, inside, kept))
    return rows

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


def _number(where: str, v, *, missing: bool = False) -> float | None:
    """``v`` as a finite number; None (or NaN) only where ``missing`` values are allowed."""
    if missing and _num(v) is None:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise SpineInputError(f"{where} must be a finite number, got {v!r}")
    return float(v)


def _table(where: str, v) -> dict:
    if not isinstance(v, dict):
        raise SpineInputError(f"{where} must be a JSON object, got {type(v).__name__} {v!r:.60}")
    return v


def _interval(where: str, v, *, missing: bool = False) -> tuple[float, float] | None:
    if not (isinstance(v, (list, tuple)) and len(v) == 2):
        raise SpineInputError(f"{where} must be a pair [low, high], got {v!r:.60}")
    lo, hi = (_number(f"{where}[{i}]", x, missing=missing) for i, x in enumerate(v))
    return None if lo is None or hi is None else (lo, hi)


def headline_numbers(validation: dict) -> dict[str, Headline]:
    """The numbers of ``validation`` (a loaded ``validation.json``) that carry an interval.

    Per family of the quasistatic-limit corner (``limit_families``): the well-conditioned
    agreement (``agreement_ci``, Wilson), the agreement over all runs
    (``outcome_agreement_ci``) and the median Frechet distance (``median_frechet_ci``,
    bootstrap); the family's ``meets_target`` is the verdict. I_e* of each drive
    (``ie_star``, bootstrap over starts; None or NaN where it lies outside the grid). The
    fractal self-lock rates per H and series (Wilson). Keys read
    ``limit.fractal.agreement_well_conditioned`` and so on.

    Raises
    ------
    SpineInputError
        Naming the field, for what is not a validation: no or empty ``limit_families``, a
        field of the wrong type (a number where a table or a pair belongs), a family's
        number or interval NaN or infinite.
    """
    if not isinstance(validation, dict) or "limit_families" not in validation:
        raise SpineInputError("validation must be a loaded validation.json (with limit_families)")
    families = _table("limit_families", validation["limit_families"])
    if not families:
        raise SpineInputError("limit_families must hold at least one family, got none")
    out: dict[str, Headline] = {}
    for fam, s in families.items():
        s = _table(f"limit_families.{fam}", s)
        verdict = s.get("meets_target")
        if verdict is not None and not isinstance(verdict, bool):
            raise SpineInputError(f"limit_families.{fam}.meets_target must be true or false, got {verdict!r}")
        for name, ci in (
            ("agreement_well_conditioned", "agreement_ci"),
            ("outcome_agreement", "outcome_agreement_ci"),
            ("median_frechet", "median_frechet_ci"),
        ):
            if name in s and ci in s:
                key = f"limit.{fam}.{name}"
                where = f"limit_families.{fam}."
                out[key] = Headline(
                    key, _number(where + name, s[name]), _interval(where + ci, s[ci]), verdict
                )
    for drive, est in _table("ie_star", validation.get("ie_star") or {}).items():
        est = _table(f"ie_star.{drive}", est)
        if "ci_low" in est:
            key, where = f"ie_star.{drive}", f"ie_star.{drive}."
            value = _number(where + "value", est.get("value"), missing=True)
            interval = _interval(where + "ci_low/ci_high", [est["ci_low"], est.get("ci_high")], missing=True)
            out[key] = Headline(key, value, interval)
    lock = _table("fractal_lock_rate", validation.get("fractal_lock_rate") or {})
    rows = lock.get("rows", [])
    if not isinstance(rows, list):
        raise SpineInputError(f"fractal_lock_rate.rows must be a list, got {rows!r:.60}")
    for i, row in enumerate(rows):
        row = _table(f"fractal_lock_rate.rows[{i}]", row)
        for series in ("streamline", "mujoco_corner", "mujoco_dynamic"):
            if f"rate_{series}" in row:
                key = f"fractal_lock.H{row.get('hurst')}.{series}"
                where = f"fractal_lock_rate.rows[{i}]."
                value = _number(where + f"rate_{series}", row[f"rate_{series}"])
                pair = [row.get(f"ci_low_{series}"), row.get(f"ci_high_{series}")]
                out[key] = Headline(key, value, _interval(where + f"ci_low/high_{series}", pair))
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

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

from dataclasses import dataclass

from spine_mj.errors import SpineInputError
from spine_mj.validate import studies
from spine_mj.validate.report.common import Headline, read_table

__all__ = ["ReproductionRow", "check_reproduction", "headline_numbers"]


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


def headline_numbers(validation: dict) -> dict[str, Headline]:
    """The numbers of ``validation`` (a loaded ``validation.json``) that carry an interval:
    each study's own (:meth:`~spine_mj.validate.studies.Study.headline_numbers`), in the
    order of the registry.

    Today the boundary study's I_e* per drive (``ie_star.spring``), the quasistatic limit's
    agreement and median Frechet distance per family with its verdict
    (``limit.fractal.agreement_well_conditioned``) and the fractal self-lock rates
    (``fractal_lock.H0.65.streamline``); each report module's ``headline_numbers`` says what
    its numbers and intervals are. ``limit_families`` is what marks a ``validation.json``:
    every plan runs that study.

    Raises
    ------
    SpineInputError
        Naming the field, for what is not a validation: no or empty ``limit_families``, a
        field of the wrong type (a number where a table or a pair belongs), a family's
        number or interval NaN or infinite.
    """
    if not isinstance(validation, dict) or "limit_families" not in validation:
        raise SpineInputError("validation must be a loaded validation.json (with limit_families)")
    if not read_table("limit_families", validation["limit_families"]):
        raise SpineInputError("limit_families must hold at least one family, got none")
    return {key: h for study in studies.STUDIES for key, h in study.headline_numbers(validation).items()}


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

"""Input checks of a sweep's cases before anything runs or is written.

A value that only a surface can judge (a time step too long for its contact, a step
``dl`` lost in the rounding of its coordinates, a run longer than the step limit at a tiny
inertia number) used to be found when its case ran and recorded as a failed run, the
sweep exiting 0. :func:`check_cases` asks every analysis to check (``check_case``, with
the same functions its run uses) a set of cases that holds every value of every
parameter on every surface source at least once, and refuses the config on the first
problem, naming the case.
"""

from __future__ import annotations

from collections.abc import Sequence

from spine_mj.errors import SpineInputError
from spine_mj.sweep.cases import Case
from spine_mj.sweep.registry import ANALYSES

__all__ = ["check_cases", "covering_cases"]


def covering_cases(cases: Sequence[Case]) -> list[Case]:
    """The cases, in order, that first bring a surface source or a parameter value to it:
    at most one per value of each parameter per surface source (seeds of one preset count
    as one source)."""
    picked, seen = [], set()
    for case in cases:
        source = (case.surface.kind, case.surface.source, case.surface.overrides)
        keys = {(source, None, None)} | {(source, k, repr(v)) for k, v in case.params.items()}
        if not keys <= seen:
            picked.append(case)
            seen |= keys
    return picked


def check_cases(cases: Sequence[Case], swept: Sequence[str] = ()) -> None:
    """Refuse, as one SpineInputError line naming the case, the first input error any
    analysis would meet in the :func:`covering_cases` of ``cases``.

    ``swept`` names the parameters with more than one value (shown in the message).
    """
    for case in covering_cases(cases):
        where = ", ".join([case.surface.label] + [f"{k} = {case.params[k]!r}" for k in swept])
        try:
            surface = case.surface.make()
            starts = case.starts.resolve(surface.bounds, case.seed)
            for name in case.analyses:
                check = ANALYSES[name].check_case
                if check is not None:
                    check(case, surface, starts)
        except SpineInputError as exc:
            raise SpineInputError(f"sweep case ({where}): {exc}") from None

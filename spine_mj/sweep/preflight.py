"""Input checks of a sweep's cases before anything runs or is written.

A value that only a surface can judge (a time step too long for its contact, a step
``dl`` lost in the rounding of its coordinates, a run longer than the step limit at a tiny
inertia number) used to be found when its case ran and recorded as a failed run, the
sweep exiting 0. :func:`check_cases` asks every analysis to check (``check_case``, with
the same functions its run uses) every combination of the grid on every surface, and
refuses the config on the first problem, naming the case: a problem that only a
combination makes (a spring drive swinging too far at the largest I_e and the stiffest
K, the longest run at the smallest I_e and the smallest step factor) is found as surely
as one a single value makes.

It stays fast on large grids: each analysis checks each distinct combination of the
parameters it reads (its own and those of the analyses it needs) once per surface and
start set, and the checks are closed forms on the rig's scales and step rule
(:class:`~spine_mj.sim.build.RigPlan`), no rig being built (the surface is measured once
per tip sizing). Within a check, what reads fewer keys is done once per distinct
combination of those (a case's rig inputs, hfield limits, sizing and starts,
:func:`~spine_mj.sweep.analyses.engine.case_plan`; MuJoCo's settings once per rounded rule
step, :func:`~spine_mj.sim.step_rule.mujoco_settings`), so an I_e x K grid's cases cost
their drive's checks alone (~130 us a case, 2026-11: 166 CPU-s listing and checking
999,999, ``make bench``'s ``prepare``). The checks that need no sizing (an analysis's ``precheck_case``: the
planned hfield's limits) run on the whole grid first: sizing an 8000-a-side hfield takes
half a minute, and a grid over both engines spent it on MuJoCo's before refusing Bullet's.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

from spine_mj.errors import SpineInputError
from spine_mj.sweep.cases import PROGRESS_EVERY_S, Case, values_key
from spine_mj.sweep.registry import ANALYSES

__all__ = ["check_cases", "checked_keys"]


def checked_keys(analysis: str) -> tuple[str, ...]:
    """The parameters ``analysis``'s check reads: its ``check_reads``, else its own and
    those of the analyses it needs (a check may build on theirs, as compare's on the
    mujoco rig)."""
    if ANALYSES[analysis].check_reads is not None:
        return tuple(sorted(ANALYSES[analysis].check_reads))
    names, todo = [], [analysis]
    while todo:
        a = ANALYSES[todo.pop()]
        names += [s.name for s in a.parameters]
        todo += list(a.requires)
    return tuple(sorted(set(names)))


def check_cases(
    cases: Sequence[Case], swept: Sequence[str] = (), progress: Callable[[int, int], None] | None = None
) -> None:
    """Refuse, as one SpineInputError line naming the case, the first input error any
    analysis would meet in any case of ``cases``.

    ``swept`` names the parameters with more than one value (shown in the message).
    ``progress``, if given, is called as ``progress(checked, total)`` every ten seconds
    while the check runs.
    """
    _prechecks(cases, swept)
    keys = {name: checked_keys(name) for name in ANALYSES}
    seen: set = set()
    resolved: dict = {}  # the start points of each source, resolved once
    last = time.monotonic()
    for i, case in enumerate(cases):
        if progress is not None and time.monotonic() - last > PROGRESS_EVERY_S:
            progress(i, len(cases))
            last = time.monotonic()
        # random starts are drawn from the case's seed: each case has its own (the specs by
        # identity, as values_key names values: the cases hold them)
        source = (id(case.surface), id(case.starts), case.seed if case.starts.random is not None else None)
        todo = []
        for name in case.analyses:
            if ANALYSES[name].check_case is None:
                continue
            key = (name, source, values_key(case.params, keys[name]))
            if key not in seen:
                seen.add(key)
                todo.append(name)
        if source not in seen:
            seen.add(source)
            todo = todo or [None]  # the surface and starts are made even without a check
        if todo:
            _check(case, todo, swept, resolved, source)
    if progress is not None:
        progress(len(cases), len(cases))


def _prechecks(cases: Sequence[Case], swept: Sequence[str]) -> None:
    """Every analysis's ``precheck_case`` once per distinct combination of its
    ``precheck_reads`` on each surface, over the whole grid."""
    seen: set = set()
    for case in cases:
        for name in case.analyses:
            analysis = ANALYSES[name]
            if analysis.precheck_case is None:
                continue
            key = (name, id(case.surface), values_key(case.params, analysis.precheck_reads))
            if key not in seen:
                seen.add(key)
                try:
                    analysis.precheck_case(case, case.surface.make())
                except SpineInputError as exc:
                    raise SpineInputError(f"sweep case ({_where(case, swept)}): {exc}") from None


def _where(case: Case, swept: Sequence[str]) -> str:
    """The case as a refusal names it: its surface and its swept parameters."""
    return ", ".join([case.surface.label] + [f"{k} = {case.params[k]!r}" for k in swept])


def _check(case: Case, analyses, swept: Sequence[str], resolved: dict, source) -> None:
    try:
        surface = case.surface.make()
        if source not in resolved:
            resolved[source] = case.starts.resolve(surface.bounds, case.seed)
        starts = resolved[source]
        for name in analyses:
            if name is not None:
                ANALYSES[name].check_case(case, surface, starts)
    except SpineInputError as exc:
        raise SpineInputError(f"sweep case ({_where(case, swept)}): {exc}") from None

"""``report.md``: the studies' sections, in the order of the registry, under one header.

:func:`write_report` hands every study's result to its report module
(:data:`spine_mj.validate.studies.STUDIES`), which draws its figures under
``out/figures`` and returns its section, and where it has any its lines of the headline
(:meth:`~spine_mj.validate.studies.Study.headline`); the header, the engine settings and the
timings come from the summary that ``validation.json`` holds, so that both say the same numbers.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path

from spine_mj.atomic import atomic_output
from spine_mj.plotting import sig
from spine_mj.templates import render
from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET
from spine_mj.validate import studies
from spine_mj.validate.plans import STATIC_TARGET
from spine_mj.validate.report.common import ReportContext

__all__ = ["PLAN_NOTES", "write_report"]

#: What each plan is, for the report's first lines.
PLAN_NOTES = {
    "smoke": "the seconds-long test plan: two planes, one family with two starts, two I_e values; "
    "its numbers only show that the pipeline runs",
    "quick": "the quick plan (`spine-mj validate --quick`, `make demo`): few starts, six I_e values, "
    "coarse hfields; its agreement numbers are noisier and usually lower than the full plan's",
    "full": "the full plan (`spine-mj validate`), the one the README's headline numbers come from",
}


def write_report(out: Path, summary: dict, results: Iterable) -> Path:
    """Write the figures under ``out/figures`` and ``out/report.md``; returns the report path.

    Parameters
    ----------
    out : Path
        The validation's output folder.
    summary : dict
        The content of ``validation.json`` (``plan``, ``engine_settings``, ``timings_s``).
    results : iterable
        Study results, one per study at most (e.g. a :class:`StaticMapResult`); a study
        without a result has no section. The report links only figures that were
        written (a study with nothing to draw has no figure).

    Raises
    ------
    TypeError
        A result that no study of the registry returns.
    """
    out = Path(out)
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    given = {}
    for res in results:
        study = next((s for s in studies.STUDIES if isinstance(res, s.result)), None)
        if study is None:
            raise TypeError(f"no study of spine_mj.validate.studies returns a {type(res).__name__}")
        given[study.name] = res
    ctx = ReportContext(out=out, figures=figs, results=given)
    ran = [(s, given[s.name]) for s in studies.STUDIES if s.name in given]
    headline = [line for s, res in ran for line in s.headline(res)]
    sections = [text for s, res in ran if (text := s.report.section(res, ctx)) is not None]
    plan = summary["plan"]
    text = render(
        "validation_report.md.j2",
        plan=plan,
        plan_note=PLAN_NOTES.get(plan, f"the plan {plan!r}"),
        headline=headline,
        targets={"outcome": OUTCOME_TARGET, "frechet": FRECHET_TARGET, "static": STATIC_TARGET},
        sections=sections,
        engine_settings=json.dumps(summary["engine_settings"], indent=2, default=str),
        timings=", ".join(f"{k} {sig(v)}" for k, v in summary["timings_s"].items()),
    )
    path = out / "report.md"
    with atomic_output(path) as tmp:
        tmp.write_text(text)
    return path

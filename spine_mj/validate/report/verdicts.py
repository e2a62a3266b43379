"""The quasistatic limit's verdicts (part of :mod:`spine_mj.validate.report.quasistatic_limit`):
every headline number with its 95 % interval, the target rule, and the platform that made
them."""

from __future__ import annotations

import math

from spine_mj.theory.targets import OUTCOME_TARGET
from spine_mj.validate.convergence import quoted
from spine_mj.validate.ensembles import ENSEMBLE_RADIUS_LC
from spine_mj.validate.intervals import TARGET_RULE, runs_to_meet
from spine_mj.validate.report.common import corner_text

__all__ = ["platform_line", "verdicts_section"]


def _num(v, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return f"{v:.{digits}g}"


def _ci(pair, digits: int = 3) -> str:
    if not pair or any(v is None or not math.isfinite(v) for v in pair):
        return "-"
    return f"[{_num(pair[0], digits)}, {_num(pair[1], digits)}]"


def verdicts_section(families: dict, convergence: dict | None = None) -> list[str]:
    """Markdown lines: per family the agreement on well-conditioned starts with its Wilson
    interval, the ill-conditioned share on each side (:mod:`spine_mj.validate.ensembles`),
    the agreement over all starts and the median Frechet distance with their intervals, and
    the verdict under the target rule; ``families`` is ``validation.json``'s
    ``limit_families``. A headline that a refinement moved outside its interval
    (``convergence``, family -> :func:`~spine_mj.validate.convergence.family_convergence`)
    is marked unconverged."""
    convergence = convergence or {}
    head = [
        "family",
        "corner I_e, K",
        "agreement, well-conditioned [95 % CI]",
        "well-conditioned / starts (a member stopped)",
        "ill-conditioned: MuJoCo / reference",
        "agreement, all starts [95 % CI]",
        "median Frechet / L_c [95 % CI]",
        "target met",
    ]
    table = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    members = set()
    for name, f in families.items():
        ill = f.get("ill_conditioned_share") or {}
        members.add(f.get("members", 1))
        at = f.get("corner") or {}
        row = [
            name,
            corner_text(at),
            quoted(
                f"{_num(f.get('agreement_well_conditioned'))} {_ci(f.get('agreement_ci'))}",
                convergence.get(name),
                "agreement_well_conditioned",
            ),
            f"{f.get('well_conditioned_runs', '-')} / {f.get('starts', f['runs'])} "
            f"({f.get('stopped_starts', 0)})",
            f"{_num(ill.get('mujoco'))} / {_num(ill.get('reference'))}",
            quoted(
                f"{_num(f['outcome_agreement'])} {_ci(f.get('outcome_agreement_ci'))}",
                convergence.get(name),
                "outcome_agreement",
            ),
            quoted(
                f"{_num(f['median_frechet'])} {_ci(f.get('median_frechet_ci'))}",
                convergence.get(name),
                "median_frechet",
            ),
            "no verdict (unconverged)"
            if (convergence.get(name) or {}).get("converged") is False
            else ("yes" if f.get("meets_target") else "no"),
        ]
        table.append("| " + " | ".join(row) + " |")
    m = max(members, default=1)
    how = (
        f"Each start ran as an ensemble of {m} (the start and {m - 1} around it at "
        f"{ENSEMBLE_RADIUS_LC:g} L_c) on both sides; a start is ill-conditioned on a side when its "
        "members there end in different outcomes (held or free, and which trap), and the "
        "agreement that the target judges is over the starts well-conditioned on both sides."
        if m > 1
        else "Each start ran once (no ensembles: no start is found ill-conditioned)."
    )
    least = runs_to_meet(OUTCOME_TARGET)
    return [
        "### Verdicts with their intervals",
        "",
        f"{how} Each headline number with its 95 % interval (Wilson for agreements, percentile "
        f"bootstrap over runs for medians); a target is {TARGET_RULE}. An agreement of "
        f"{OUTCOME_TARGET:g} needs at least {least} well-conditioned starts to be met, all agreeing: "
        "a family with fewer cannot meet it whatever it measures.",
        "",
        *table,
        "",
    ]


def platform_line(platform: dict | None) -> list[str]:
    """One line naming the machine and versions that made the numbers (empty without)."""
    if not platform:
        return []
    isa = ", ".join(platform.get("vector_instruction_sets") or []) or "unknown"
    overrides = platform.get("dispatch_overrides") or {}
    switched = (
        " Code paths switched by " + ", ".join(f"{k}={v}" for k, v in overrides.items()) + "."
        if overrides
        else ""
    )
    return [
        f"Made on {platform.get('cpu')} ({platform.get('machine')}; vector instruction sets: {isa}; "
        f"{platform.get('cpu_count')} cores), {platform.get('os')}, Python {platform.get('python')}, "
        f"numpy {platform.get('numpy')}, MuJoCo {platform.get('mujoco')}.{switched} Other CPUs take "
        "other vector code paths in numpy, the C library's maths, OpenBLAS and numba, which round "
        "differently: runs near a watershed may flip there; the intervals say how far the "
        "numbers may move (analysis/reproduction_check.py compares a run with them).",
        "",
    ]

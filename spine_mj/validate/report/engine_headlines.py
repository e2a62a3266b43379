"""The report of the engines' headlines (:mod:`spine_mj.validate.engine_headlines`): the
section "Engines side by side: the headlines", each family's corner agreement with the
streamline in MuJoCo and Bullet with intervals, which engine the streamline supports where
they part, the soft-contact misses rerun in both, and the cost.
"""

from __future__ import annotations

import math

from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET
from spine_mj.validate.report.common import corner_text, table

__all__ = ["section"]


def _num(v, spec: str = ".3f") -> str:
    return "n/a" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, spec)


def _ci(lo, hi, spec: str = ".3f") -> str:
    return f"[{_num(lo, spec)}, {_num(hi, spec)}]"


def _agreeing(s: dict) -> int:
    """Agreeing starts among the well-conditioned ones of a family's summary."""
    n = s["well_conditioned_runs"]
    return round(s["agreement_well_conditioned"] * n) if n else 0


def _bounds(d: dict) -> tuple[float, float]:
    return d["ci_low"], d["ci_high"]


def section(res) -> str:
    """The report section "Engines side by side: the headlines" of ``res``, an
    :class:`~spine_mj.validate.engine_headlines.EngineHeadlinesResult` ("" without one)."""
    if res is None:
        return ""
    size = "all" if res.starts_per_surface is None else f"{res.starts_per_surface}"
    parts = [
        "## Engines side by side: the headlines",
        f"The corner of the quasistatic-limit study (plan `{res.plan}`, {_corners(res)}, "
        f"{size} y starts per surface, every start an ensemble of its own and its neighbours "
        "1e-3 L_c away) run in both engines on the same surfaces and starts, one sweep per family "
        "with `engine = [mujoco, bullet]`. The theory is the streamline on the rig's facets "
        f"(the closed form of the quasistatic limit): target agreement >= {OUTCOME_TARGET:g} on the "
        f"starts well-conditioned on both sides, median Frechet <= {FRECHET_TARGET:g} L_c. Agreement "
        "with its 95 % Wilson interval (agreeing / well-conditioned starts), median Frechet with "
        "its bootstrap interval; the difference Bullet - MuJoCo with Newcombe's interval.",
        _agreement_table(res),
        *_pairs(res),
        *_rechecks(res),
        *_cost(res),
    ]
    return "\n\n".join(parts) + "\n"


def _corners(res) -> str:
    """Where the corner ran: each surface's own (I_e, K), or the one I_e of an older result."""
    if not res.corners:
        return f"I_e = {res.lowest_ie:g}"
    return "each surface at its own (I_e, K): " + "; ".join(
        f"{fam} {corner_text(c)}" for fam, c in res.corners.items()
    )


def _agreement_table(res) -> str:
    """Per family and engine: agreement, counts, ill-conditioned shares, Frechet, stops, misses."""
    rows = []
    for fam, f in res.families.items():
        for e in res.engines:
            s = f[e]
            n = s["well_conditioned_runs"]
            ill = s["ill_conditioned_share"]
            rows.append(
                {
                    "family": fam,
                    "theory": f"streamline, >= {OUTCOME_TARGET:g}",
                    "engine": e,
                    "agree": f"{_num(s['agreement_well_conditioned'])} {_ci(*s['agreement_ci'])}",
                    "counts": f"{_agreeing(s)} / {n} ({s['starts']})",
                    "ill": f"{_num(ill['mujoco'], '.0%')} / {_num(ill['reference'], '.0%')}",
                    "frechet": f"{_num(s['median_frechet'], '.4f')} {_ci(*s['median_frechet_ci'], '.4f')}",
                    "stops": ", ".join(f"{r} {v}" for r, v in s["failed_runs"].items()) or "-",
                    "misses": "; ".join(f"{r} {v['runs']}" for r, v in s["misses"].items()) or "-",
                    "target": "met" if s["meets_target"] else "not met",
                }
            )
    names = [
        "family",
        "theory",
        "engine",
        "agreement [95 %]",
        "agreeing / well-conditioned (of starts)",
        "ill-conditioned (engine / reference)",
        "median Frechet [95 %] L_c",
        "engine stops",
        "misses",
        "target",
    ]
    return table(rows, list(rows[0]) if rows else [], names)


def _pairs(res) -> list[str]:
    """Where the engines disagree, which one the streamline supports."""
    e0, e1 = res.engines[0], res.engines[-1]
    rows = [
        {
            "family": fam,
            "diff": f"{f['difference']['diff']:+.3f} {_ci(*_bounds(f['difference']))}",
        }
        | f["pairs"]
        for fam, f in res.families.items()
        if "pairs" in f
    ]
    if not rows:
        return []
    cols = ["family", "diff", "starts", "both_agree", "only_first", "only_second", "neither", "engines_alike"]
    names = ["family", f"{e1} - {e0} [95 %]", "starts", "both agree", f"only {e0}", f"only {e1}", "neither"]
    return [
        f"Where the engines disagree, per start well-conditioned in both: the difference {e1} - "
        f"{e0} in agreement, and the starts only one engine ends as the streamline does (the "
        "closed form supports that engine).",
        table(rows, cols, [*names, "engines end alike"]),
    ]


def _rechecks(res) -> list[str]:
    """The soft-contact misses, both engines."""
    if not res.rechecks:
        return []
    rows = [
        {
            "start": r["start"],
            "engine": r["engine"],
            "agrees": "yes" if r["agree"] else "no",
            "outcome": f"{r['end_reason']} / {r['reference_outcome']}",
            "miss": r["miss_reason"] or "-",
            "ill": r["ill_conditioned"] or "-",
        }
        for r in res.rechecks
    ]
    names = [
        "start",
        "engine",
        "agrees",
        "outcome (engine end / reference)",
        "miss reason",
        "ill-conditioned",
    ]
    return [
        f"The starts the `{res.recheck_plan}` plan's report attributes to MuJoCo's soft contact "
        "(`engine_held`: MuJoCo held where the rigid-facet reference, restarted at its end, moves "
        f"on), rerun with the `{res.recheck_plan}` plan's settings and ensembles in both engines.",
        table(rows, list(rows[0]), names),
    ]


def _cost(res) -> list[str]:
    """CPU seconds per family and engine: the engine's runs, the streamlines compared."""
    rows = [
        {
            "family": fam,
            "engine": e,
            "runs": c["runs"],
            "engine_s": f"{c['engine']:.1f}",
            "per_run": _num(c["engine"] / c["runs"] if c["runs"] else math.nan, ".2f"),
            "reference_s": f"{c['reference']:.1f}",
        }
        for fam, per in res.cpu_s.items()
        for e, c in per.items()
    ]
    names = ["family", "engine", "runs", "engine CPU s", "per run", "reference CPU s"]
    return [
        f"Cost on this machine (CPU seconds; wall {res.wall_s:g} s in all): each engine's runs, and "
        "the streamlines compared with them, as each engine's cases recorded them (a worker "
        "that runs both engines' cases of a surface traces them once: the sweep's memo).",
        table(rows, list(rows[0]) if rows else [], names),
    ]

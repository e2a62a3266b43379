"""The report of the boundary study (:mod:`spine_mj.validate.boundary`): agreement against
I_e per drive protocol, the I_e* headline, and MuJoCo's paths over the streamline.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from spine_mj.plotting import (
    THRESHOLD_COLOR,
    new_figure,
    path_overlay_figure,
    protocol_color,
    save_figure,
    sig,
    styled,
)
from spine_mj.presets import list_presets, make_surface
from spine_mj.sweep.store import load_runs
from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET
from spine_mj.validate.boundary import BoundaryCurve, BoundaryResult
from spine_mj.validate.convergence import refinement_note
from spine_mj.validate.paths import stored_paths
from spine_mj.validate.report.common import (
    Headline,
    ReportContext,
    assemble,
    cell,
    image,
    read_interval,
    read_number,
    read_table,
    refinement_rows,
    table,
)


def star_to_draw(star: dict) -> dict | None:
    """The bracketed I_e* to draw: the headline one, else the departure criterion's."""
    if star.get("kind") == "bracketed":
        return star
    dep = star.get("by_criterion", {}).get("departure")
    return dep if dep and dep.get("kind") == "bracketed" else None


@styled
def _boundary_figure(bnd: BoundaryResult, path: Path) -> Path | None:
    if not bnd.curves:
        return None
    fig = new_figure(figsize=(12, 4.6), constrained_layout=True)
    a1, a2 = fig.subplots(1, 2)
    for proto, c in bnd.curves.items():
        color = protocol_color(proto)
        lab = proto if proto != "ramp" else "ramp (equivalent I_e)"
        a1.semilogx(c.ie, c.agreement, "o-", color=color, label=lab)
        used = bnd.ie_star[proto].get("ie_used", c.ie)
        off = [i for i, v in enumerate(c.ie) if not np.isclose(used, v).any()]
        if off:  # points that take no part in I_e* (a capped ramp covering < half the path)
            a1.plot(
                np.asarray(c.ie)[off],
                np.asarray(c.agreement)[off],
                "o",
                ms=10,
                mfc="white",
                mec=color,
                zorder=0,
                label=f"{proto}: not used for I_e* (path coverage < 50 %)",
            )
        a2.loglog(
            c.ie, np.maximum(np.asarray(c.frechet, float), 1e-5), "o-", color=color, label=f"{proto}: mean"
        )
        a2.loglog(
            c.ie,
            np.maximum(np.asarray(c.median_frechet, float), 1e-5),
            "s--",
            color=color,
            label=f"{proto}: median",
        )
        s = star_to_draw(bnd.ie_star[proto])
        if s is not None:
            for ax in (a1, a2):
                ax.axvspan(
                    s["low"],
                    s["high"],
                    alpha=0.12,
                    color=color,
                    label=f"{proto}: I_e* bracket [{sig(s['low'])}, {sig(s['high'])}]" if ax is a1 else None,
                )
                ax.axvline(
                    s["value"],
                    ls=":",
                    color=color,
                    label=f"{proto}: I_e* = {sig(s['value'])}" if ax is a1 else None,
                )
    a1.axhline(
        OUTCOME_TARGET,
        color=THRESHOLD_COLOR,
        lw=1,
        ls="--",
        label=f"target: agreement >= {sig(OUTCOME_TARGET)}",
    )
    a2.axhline(
        FRECHET_TARGET,
        color=THRESHOLD_COLOR,
        lw=1,
        ls="--",
        label=f"target: deviation <= {sig(FRECHET_TARGET)} L_c",
    )
    a1.set(xlabel="inertia number I_e [1]", ylabel="runs that agree [fraction]", ylim=(-0.05, 1.05))
    a2.set(xlabel="inertia number I_e [1]", ylabel="Frechet deviation [L_c] (ramp: prefix)")
    a1.legend(fontsize=7)
    a2.legend(fontsize=7)
    fig.suptitle("Agreement with the quasistatic streamline against I_e (colour = drive protocol)")
    return save_figure(fig, path)


def _overlay_figure(out: Path, path: Path) -> Path | None:
    """MuJoCo paths over the streamline at the lowest and highest I_e of the boundary
    study's spring sweeps (``out/sweeps/boundary/spring-*``); None when there are none."""
    panels = []
    for store in sorted((out / "sweeps" / "boundary").glob("spring-*")):
        if not (store / "manifest.json").is_file():
            continue
        df = load_runs(store)
        mj = df[(df.analysis == "engine") & (df.status == "ok")]
        comp = df[(df.analysis == "compare") & (df.status == "ok")].set_index(["case_id", "start"])
        if mj.empty:
            continue
        preset = str(mj["surface"].iloc[0]).split("#")[0]
        surface = make_surface(preset) if preset in list_presets() else None
        for ie in sorted({mj["ie"].min(), mj["ie"].max()}):
            case_id = mj.loc[mj["ie"] == ie, "case_id"].iloc[0]
            starts = sorted(mj.loc[mj["case_id"] == case_id, "start"].astype(int))[:3]
            qs = stored_paths(store, case_id, "quasistatic")
            mp = stored_paths(store, case_id, "engine")
            pairs = [(qs[s], mp.get(s, np.zeros((0, 2)))) for s in starts if s in qs]
            n_agree = sum(bool(comp["agree"].get((case_id, s), False)) for s in starts)
            title = f"{preset}, spring, I_e = {sig(ie)}: {n_agree}/{len(starts)} agree"
            panels.append({"title": title, "paths": pairs, "surface": surface})
    if not panels:
        return None
    return save_figure(path_overlay_figure(panels), path)


def _estimates(ie_star: dict) -> Iterator[tuple[str, dict | None, str]]:
    """Per protocol of ``ie_star`` (the study's ``ie_star``, its key of ``validation.json``)
    ``(protocol, estimate, note)`` for its I_e* by the main criterion, then by departure where
    it has one; ``note`` is the main estimate's refinement note, or for a protocol not
    measured (estimate None) why."""
    for proto, s in ie_star.items():
        if s.get("valid") is False:
            yield proto, None, s.get("note", "")
            continue
        for star in (s, s.get("by_criterion", {}).get("departure")):
            if star:
                yield proto, star, refinement_note(s.get("convergence")) if star is s else ""


def _estimate_text(star: dict, num: Callable[[float], str]) -> str:
    """An I_e* estimate in words, its numbers written by ``num``: bracketed, above or below
    the grid."""
    if star["kind"] == "bracketed":
        value, low, high = (num(star[k]) for k in ("value", "low", "high"))
        return f"I_e* = {value} in [{low}, {high}]"
    if star["kind"] == "above":
        return f"I_e* > {num(star['low'])} (agreement holds on the whole grid)"
    return f"I_e* < {num(star['high'])} (no agreement at the lowest I_e)"


def summary_lines(validation: dict) -> list[str]:
    """Per protocol its I_e* by the main criterion and by departure where it has one, each
    criterion on its line and the estimate indented under it (or why there is none)."""
    lines = []
    for proto, star, note in _estimates(validation.get("ie_star", {})):
        if star is None:
            lines.append(f"I_e* ({proto}) {note}")
        else:
            lines += [
                f"I_e* ({proto}) criterion: {star['criterion']}",
                f"  {_estimate_text(star, '{:.3g}'.format)}{note}",
            ]
    return lines


def headline_numbers(validation: dict) -> dict[str, Headline]:
    """Per drive its I_e* with the bootstrap interval over starts (``ie_star``; None or NaN
    where it lies outside the grid), keyed ``ie_star.DRIVE``."""
    out: dict[str, Headline] = {}
    for drive, est in read_table("ie_star", validation.get("ie_star") or {}).items():
        est = read_table(f"ie_star.{drive}", est)
        if "ci_low" in est:
            key, where = f"ie_star.{drive}", f"ie_star.{drive}."
            value = read_number(where + "value", est.get("value"), missing=True)
            pair = [est["ci_low"], est.get("ci_high")]
            out[key] = Headline(key, value, read_interval(where + "ci_low/ci_high", pair, missing=True))
    return out


def results_lines(validation: dict) -> list[str]:
    """The I_e* table of the site's results page: per drive its I_e* by the main criterion,
    the grid's bracket and the bootstrap interval over starts (``ie_star``); none without it."""
    ie = validation.get("ie_star") or {}
    if not ie:
        return []
    lines = [
        "## Where the quasistatic picture breaks: I_e*",
        "",
        "| drive | criterion | I_e* | bracket | bootstrap interval |",
        "|---|---|---|---|---|",
    ]
    for drive, s in ie.items():
        if isinstance(s, dict):
            value, low, high, ci_low, ci_high = (
                cell(s.get(k)) for k in ("value", "low", "high", "ci_low", "ci_high")
            )
            lines.append(
                f"| {drive} | {s.get('criterion', '')} | {value} | [{low}, {high}] | [{ci_low}, {ci_high}] |"
            )
    return [*lines, ""]


def headline(boundary: BoundaryResult) -> list[str]:
    """One line per protocol and criterion: its I_e* (or why there is none)."""
    lines = []
    for proto, star, note in _estimates(boundary.ie_star):
        if star is None:
            lines.append(f"{proto}: I_e* not measured ({note})")
        else:
            lines.append(f"{proto} ({star.get('criterion', '')}): {_estimate_text(star, sig)}{note}")
    return lines


def _lines(boundary: BoundaryResult) -> list[str]:
    star_rows = [
        {"protocol": p, "criterion_id": k, **v}
        for p, s in boundary.ie_star.items()
        for k, v in s["by_criterion"].items()
    ]
    lines = [
        "## Agreement against I_e (boundary study)",
        "",
        f"Families: {', '.join(boundary.families)}. Spring: a run agrees when its "
        "outcome agrees (`agreement.outcome_agreement`); its deviation is the Frechet "
        "distance from the streamline. Ramp with reset: its I_e is the equivalent one, "
        "m v_eq^2 / (F_p L_c) with v_eq = L_c rate / F_p; its duration comes from a "
        "pilot run's per-cycle slip so that it would cover the path to the domain edge, "
        "capped at a step budget. A ramp run agrees when it has no engine trouble, does "
        "not self-lock where the streamline does not, and deviates <= 0.1 L_c from the "
        "streamline cut at its own arc length (prefix Frechet). I_e* interpolated in "
        "log I_e inside the bracket [last pass, first fail] for four criteria "
        "(headline: median; `departure` measures where agreement falls below its own "
        "low-I_e level); ramp I_e values whose runs cover under half the path take no "
        "part; ci = 16-84 % bootstrap over starts.",
        "",
        table(star_rows, ["protocol", "criterion", "kind", "value", "low", "high", "ci_low", "ci_high"]),
        "",
    ]
    lines += [
        f"**I_e* ({p}) {s['note']}**" for p, s in boundary.ie_star.items() if s.get("valid") is False
    ] + [""]
    lines += _convergence_lines(boundary)
    for proto, c in boundary.curves.items():
        lines += _curve_table(c, proto, boundary.skip_rate[proto])
    return lines


def _convergence_lines(boundary: BoundaryResult) -> list[str]:
    """The headline I_e*'s solution verification (empty where the plan refined nothing):
    per protocol and refinement the I_e* of the refined window against the headline's and
    the verdict, and the observed order where three step levels ran."""
    rows, orders = [], []
    for proto, s in boundary.ie_star.items():
        conv = s.get("convergence")
        if not conv:
            continue
        window = ", ".join(sig(v) for v in conv.get("ie_refined", []))
        ci = "[" + ", ".join(sig(v) for v in conv["ci95"]) + "]"
        rows += refinement_rows(conv, protocol=proto, window=window, ci95=ci)
        if "dt_order" in conv:
            o = conv["dt_order"]
            orders.append(f"{proto}: {cell(o['order'])} (Richardson: I_e* = {cell(o['richardson'])})")
    if not rows:
        return []
    lines = [
        "### Solution verification of I_e*",
        "",
        "Every start rerun under each refinement at the I_e values around the headline's "
        "bracket (the step halved or quartered, the contact's time constant kept "
        "so that only the step changes; an analytic surface's hfield at twice the samples a "
        "side, the tip kept); the refined I_e* is read from the curve with those values "
        "replaced (the others keep their runs). Converged: the refined I_e* inside the "
        "headline's 95 % bootstrap interval over starts; change = log10(refined / headline).",
        "",
        table(
            rows,
            ["protocol", "refinement", "window", "runs", "base", "refined", "ci95", "change", "verdict"],
            [
                "protocol",
                "refinement",
                "I_e rerun",
                "runs",
                "I_e*",
                "I_e* refined",
                "95 % interval",
                "change (log10)",
                "verdict",
            ],
        ),
        "",
    ]
    if orders:
        lines += ["Observed order of I_e* in the step (dt, dt / 2, dt / 4): " + "; ".join(orders) + ".", ""]
    return lines


def _curve_table(c: BoundaryCurve, proto: str, skip_rate: list[float]) -> list[str]:
    rows = [
        {
            "ie": ie,
            "agreement": a,
            "mean_frechet": f,
            "median_frechet": fm,
            "lateral": la,
            "engine_trouble": e,
            "trap_skip": s,
        }
        for ie, a, f, fm, la, e, s in zip(
            c.ie, c.agreement, c.frechet, c.median_frechet, c.lateral, c.engine_trouble, skip_rate
        )
    ]
    n = c.runs_per_ie
    for r in rows:
        r["agree_n"] = f"{round(r['agreement'] * n)}/{n}"
        r["ok_n"] = f"{round((1 - r['engine_trouble']) * n)}/{n}"
    cols = [
        "ie",
        "agreement",
        "agree_n",
        "mean_frechet",
        "median_frechet",
        "lateral",
        "ok_n",
        "engine_trouble",
        "trap_skip",
    ]
    if proto == "ramp":
        for r, cv, ach in zip(rows, c.coverage, c.ie_achieved):
            r.update({"coverage": cv, "ie_achieved": ach})
        cols += ["coverage", "ie_achieved"]
    lines = [
        f"**{proto}** ({c.runs_per_ie} runs per I_e; deviation: {c.frechet_kind})",
        "",
        table(rows, cols),
        "",
    ]
    if proto == "ramp":
        plans = [
            {"surface": p, "ie": float(ie), **rp} for p, d in c.ramp_plans.items() for ie, rp in d.items()
        ]
        lines += [
            f"Ramp durations (pilot from the family's first start; cap "
            f"{c.ramp_max_steps} steps; coverage = x advance / distance to the "
            "domain edge; ie_achieved from the mean x speed):",
            "",
            table(
                plans,
                [
                    "surface",
                    "ie",
                    "rate_n_s",
                    "slip_per_cycle_lc",
                    "cycle_s",
                    "target_lc",
                    "required_steps",
                    "duration_s",
                    "capped",
                    "coverage_expected",
                ],
            ),
            "",
        ]
    return lines


def section(boundary: BoundaryResult, ctx: ReportContext) -> str:
    curves = ctx.draw(_boundary_figure, boundary, "boundary.png")
    overlays = ctx.link(_overlay_figure(ctx.out, ctx.figures / "boundary_paths.png"))
    return assemble(
        "\n".join(_lines(boundary)),
        image(
            "Agreement and deviation against I_e; dashed lines: targets; shaded: the I_e* bracket "
            "and dotted: I_e* of the first bracketed criterion listed above",
            curves,
        ),
        image(
            "MuJoCo paths over the streamline at the lowest and highest I_e",
            overlays,
            before="MuJoCo paths (dashed) over the streamline (solid) at the lowest and the highest "
            "I_e of the\nspring sweeps, a few starts each:\n\n",
        ),
    )

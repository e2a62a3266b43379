"""The map's convergence to the theory in the report (:mod:`spine_mj.validate.theory_orders`):
the log-log gap figure with fitted and predicted orders, the predicted limits against the
measured ones, and what remains where a family misses the targets at its stiffest, slowest
point. Part of the (I_e, K) map's section (:mod:`spine_mj.validate.report.stiffness_map`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from spine_mj.plotting import SERIES_COLORS, new_figure, save_figure, sig, styled
from spine_mj.theory.targets import FRECHET_TARGET
from spine_mj.validate.report.common import cell, table
from spine_mj.validate.stiffness_map import StiffnessMapResult
from spine_mj.validate.theory_orders import FRECHET_FLOOR_LC, PREDICTION_FACTOR

__all__ = ["causes_lines", "orders_figure", "orders_lines", "prediction_lines"]

_AXES = {"ie": "I_e (at the stiffest K)", "inverse_k": "1 / K (at the lowest I_e, K >= K*)"}
_GAPS = {"agreement_gap": "1 - outcome agreement", "median_frechet": "median Frechet / L_c"}


@styled
def orders_figure(km: StiffnessMapResult, path: Path) -> Path | None:
    """Per family (rows) the gap against I_e and against 1/K (columns), log-log: every
    point, the fitted line over the points fitted, and a line of the predicted order
    through the fitted points' first one."""
    fams = list(dict.fromkeys(r["family"] for r in km.orders))
    if not fams:
        return None
    fig = new_figure(figsize=(9.5, 3.2 * len(fams)), constrained_layout=True)
    axes = np.atleast_2d(fig.subplots(len(fams), 2, squeeze=False))
    drawn = False
    for i, fam in enumerate(fams):
        for j, axis in enumerate(_AXES):
            ax = axes[i, j]
            for c, gap in enumerate(_GAPS):
                row = next(
                    (r for r in km.orders if r["family"] == fam and r["axis"] == axis and r["gap"] == gap),
                    None,
                )
                if row is None:
                    continue
                x, g = np.asarray(row["all_x"], float), np.asarray(row["all_gap"], float)
                ok = (x > 0) & (g > 0) & np.isfinite(g)
                if not ok.any():
                    continue
                drawn = True
                color = SERIES_COLORS[c]
                ax.plot(x[ok], g[ok], "o", color=color, mfc="white", label=_GAPS[gap])
                if row["n"] >= 2 and math.isfinite(row["order"]):
                    fx, fg = np.asarray(row["x_fitted"]), np.asarray(row["gap_fitted"])
                    ax.plot(fx, fg, "o", color=color)
                    xs = np.geomspace(fx.min(), fx.max(), 20)
                    b = np.mean(np.log(fg) - row["order"] * np.log(fx))
                    ax.plot(xs, np.exp(b) * xs ** row["order"], "-", color=color, lw=1.2)
                    p = row["predicted"]
                    ax.plot(xs, fg[0] * (xs / fx[0]) ** p, ":", color=color, lw=1.2)
            ax.axhline(FRECHET_FLOOR_LC, color="0.6", lw=0.8, ls="--")
            ax.set(xscale="log", yscale="log", xlabel=_AXES[axis], title=f"{fam.replace('_', ' ')}")
            if j == 0:
                ax.set_ylabel("gap to the streamline")
            if ax.get_legend_handles_labels()[0]:
                ax.legend(loc="best", fontsize=7)
    if not drawn:
        return None
    fig.suptitle(
        "Gap against I_e and 1/K: filled points fitted (solid line), dotted: the predicted order; "
        "dashed grey: the Frechet resolution",
        fontsize=9,
    )
    return save_figure(fig, path)


def _order_cell(r: dict) -> str:
    if not math.isfinite(r["order"]):
        return f"- ({r['n']} points resolved)"
    ci = f" [{sig(r['ci_low'])}, {sig(r['ci_high'])}]" if math.isfinite(r["ci_low"]) else ""
    return f"{sig(r['order'])}{ci} ({r['n']} points)"


def orders_lines(km: StiffnessMapResult) -> list[str]:
    """The fitted orders against the predicted ones (empty without a map)."""
    if not km.orders:
        return []
    rows = [
        {
            "family": r["family"],
            "axis": _AXES[r["axis"]],
            "at": r["at"],
            "gap": _GAPS[r["gap"]],
            "order": _order_cell(r),
            "predicted": r["predicted"],
            "consistent": {True: "yes", False: "no", None: "-"}[r["consistent"]],
        }
        for r in km.orders
    ]
    return [
        "### Convergence to the theory: the gap against I_e and 1/K",
        "",
        "The gap between MuJoCo and the rigid streamline (1 - outcome agreement, and the median "
        "Frechet distance) against I_e at each family's stiffest K, and against 1/K at the lowest "
        "I_e every K ran at, over K >= K* (below K* the compliant path folds: no power law). "
        "The order is the least-squares slope on log-log axes with its 95 % t interval, over the "
        "points the metric resolves (a median Frechet above twice its resolution of "
        f"{FRECHET_FLOOR_LC:g} L_c, the paths resampled at L_c / 50; an agreement gap above zero). "
        "Predicted (docs/physics.md §10): first order in I_e (the lag behind a turn, "
        "I_e L_c / (2 mu)) and first order in 1/K (the compliant offset, kappa l_s / K).",
        "",
        table(
            rows,
            ["family", "axis", "at", "gap", "order", "predicted", "consistent"],
            [
                "family",
                "against",
                "at K or I_e",
                "gap",
                "fitted order [95 %]",
                "predicted",
                "interval holds it",
            ],
        ),
        "",
    ]


def _bracket(lo: float, hi: float) -> str:
    if math.isinf(hi):
        return f"> {sig(lo)}"
    if not math.isfinite(lo):
        return f"<= {sig(hi)}" if math.isfinite(hi) else "-"
    return f"{sig(lo)}-{sig(hi)}"


def _factor(verdict: str, factor: float) -> str:
    """A verdict with how far outside its bracket the prediction lies."""
    return f"{verdict} (x {sig(factor)})" if verdict == "outside" and math.isfinite(factor) else verdict


def prediction_lines(km: StiffnessMapResult) -> list[str]:
    """The predicted K boundary and I_e* against the measured brackets, with the factor-2
    verdicts, how far outside a prediction lies and how wide each bracket is."""
    if not km.prediction_check:
        return []
    rows = [
        {
            **r,
            "k_measured": _bracket(r["k_low"], r["k_high"]),
            "ie_measured": _bracket(r["ie_low"], r["ie_high"]),
            "k_verdict_x": _factor(r["k_verdict"], r.get("k_factor", math.nan)),
            "k_verdict_fold_x": _factor(r["k_verdict_fold"], r.get("k_factor_fold", math.nan)),
            "ie_verdict_x": _factor(r["ie_verdict"], r.get("ie_factor", math.nan)),
        }
        for r in km.prediction_check
    ]
    return [
        f"The predicted limits against the measured ones, judged within a factor of {PREDICTION_FACTOR:g}: "
        "*within* where the whole measured bracket lies within the factor of the prediction, "
        "*consistent* where they overlap but the bracket is wider than the factor allows to "
        f"decide (a bracket wider than {PREDICTION_FACTOR**2:g} times cannot be decided: a finer "
        "ladder would), *outside* where they do not overlap, with the factor by which the "
        "prediction misses the nearer end. The K boundary predicted is `K_path`: the stiffness "
        "where the compliant-drive paths from the family's own starts, each carriage stopping "
        "where the map's runs stop theirs (1.1 times the distance to the +x edge plus the "
        "spring's stretch at (1 + mu) F_p), meet the criterion against the rigid ones "
        "(docs/physics.md §8). A soft spring's run ends with the tip short of a hold it must "
        "stretch the spring further for (a lock decided at kappa_cap F_p, a tip lagging by "
        "`H l_s / K`): that, not the folds, sets the boundary where `K_path` exceeds the "
        "endless carriage's. The fold K* (the first fold anywhere on the paths, "
        "`l_s max(-dH/dx)`) is set beside it: a fold whose jump is shorter than the tolerance "
        "or runs along the path passes the criterion. The measured boundary is read where the "
        "spring's swing is small and the stiffest K passes (at an I_e where the stiffest "
        "spring fails too, the tip's inertia fails every K).",
        "",
        table(
            rows,
            [
                "family",
                "k_path_predicted",
                "k_path_endless",
                "k_path_set_by",
                "k_star_predicted",
                "k_measured",
                "k_verdict_x",
                "k_verdict_fold_x",
                "ie_star_predicted",
                "ie_limit",
                "ie_at_k",
                "ie_measured",
                "ie_verdict_x",
            ],
            [
                "family",
                "K_path predicted (runs' travel)",
                "K_path (endless carriage)",
                "K_path set by",
                "fold K*",
                "K boundary measured",
                "K_path",
                "fold K*",
                "I_e* predicted",
                "set by",
                "at K",
                "I_e* measured",
                "I_e*",
            ],
        ),
        "",
    ]


def _stiffest_slowest(cells: dict, comp: dict) -> dict[str, Any] | None:
    """The numbers at the stiffest K and its lowest I_e (and the next I_e up), rigid and
    compliant references."""
    if not cells:
        return None
    k = max(cells, key=float)
    c = cells[k]
    order = np.argsort(c["ie"])
    i0 = int(order[0])
    i1 = int(order[1]) if len(order) > 1 else None
    cc = comp.get(k)
    return {
        "K": float(k),
        "ie": c["ie"][i0],
        "passes": c["passes"][i0],
        "agreement": c["agreement"][i0],
        "frechet": c["median_frechet"][i0],
        "ie_next": c["ie"][i1] if i1 is not None else math.nan,
        "agreement_next": c["agreement"][i1] if i1 is not None else math.nan,
        "frechet_next": c["median_frechet"][i1] if i1 is not None else math.nan,
        "agreement_compliant": cc["agreement"][i0] if cc else math.nan,
        "frechet_compliant": cc["median_frechet"][i0] if cc else math.nan,
    }


def causes_lines(km: StiffnessMapResult, limit: Any = None) -> list[str]:
    """Where a family misses the criterion at its stiffest, slowest point, each cause the
    studies measure beside it: inertia (the trend from the next I_e up), the spring (the
    compliant reference), the facets (the corner's geometry Frechet), the soft contact (the
    contact's time constant varied on the single peak), chaos (the corner's ill-conditioned
    share). ``limit`` is the quasistatic-limit study's result (None: its columns are ``-``)."""
    rows = []
    lim_fams = getattr(limit, "families", {}) or {}
    variations = getattr(limit, "variations", {}) or {}
    soft = next((v for k, v in variations.items() if "soft contact" in k), None)
    for fam, cells in km.agreement.items():
        p = _stiffest_slowest(cells, km.agreement_compliant.get(fam, {}))
        if p is None or p["passes"]:
            continue
        lf = lim_fams.get(fam, {})
        ill = lf.get("ill_conditioned_share") or {}
        soft_cell = (
            f"{cell(soft['outcome_agreement'])} / {cell(soft['median_frechet'])} ({soft['surface']})"
            if soft and fam == "single_peak_valley"
            else "not measured on this family"
        )
        rows.append(
            {
                "family": fam,
                "point": f"K {sig(p['K'])}, I_e {sig(p['ie'])}",
                "here": f"{cell(p['agreement'])} / {cell(p['frechet'])}",
                "inertia": f"{cell(p['agreement_next'])} / {cell(p['frechet_next'])} "
                f"at I_e {sig(p['ie_next'])}",
                "spring": f"{cell(p['agreement_compliant'])} / {cell(p['frechet_compliant'])}",
                "facets": f"{cell(lf.get('mean_geometry_frechet'))} (target {sig(FRECHET_TARGET)})",
                "soft": soft_cell,
                "chaos": f"{cell(ill.get('mujoco'))} / {cell(ill.get('reference'))}" if ill else "-",
            }
        )
    if not rows:
        return ["Every family meets the criterion at its stiffest, slowest point of the map.", ""]
    return [
        "### What remains at the stiffest, slowest point",
        "",
        "Families that still miss the criterion at their stiffest K and lowest I_e, with each "
        "cause measured beside it (outcome agreement / median Frechet in L_c): *inertia*, the same "
        "at the next I_e up (if the gap still shrinks from there, a slower drive helps); *spring*, "
        "against the compliant-drive streamline (if that agrees where the rigid one does not, the "
        "spring remains); *facets*, the corner's mean Frechet between the smooth and the facet "
        "streamlines; *soft contact*, the corner with the contact's time constant at 10 dt on the "
        "single peak (the plan's one solref variation); *chaos*, the corner's ill-conditioned "
        "share of starts, MuJoCo / reference.",
        "",
        table(
            rows,
            ["family", "point", "here", "inertia", "spring", "facets", "soft", "chaos"],
            [
                "family",
                "point",
                "rigid reference",
                "inertia: next I_e up",
                "spring: compliant reference",
                "facets: geometry Frechet",
                "soft contact",
                "chaos: ill-conditioned",
            ],
        ),
        "",
    ]

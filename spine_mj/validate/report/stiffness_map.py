"""The report of the (I_e, K) map (:mod:`spine_mj.validate.stiffness_map`): agreement as a heat
map per family with I_e*(K) over it, the elastic energy released at breakaway, and the
slip-size and force-drop CCDFs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spine_mj.plotting import (
    SEQUENTIAL_CMAP,
    THRESHOLD_COLOR,
    new_figure,
    save_figure,
    sig,
    styled,
)
from spine_mj.validate.report.common import ReportContext, assemble, cell, image, table
from spine_mj.validate.report.theory_orders import causes_lines, orders_figure, orders_lines, prediction_lines
from spine_mj.validate.slip_tails import MIN_EVENTS
from spine_mj.validate.stick_slip import complementary_cdf
from spine_mj.validate.stiffness_map import CRITERION, SLIP_FAMILIES, SLIPS_PER_LC, StiffnessMapResult
from spine_mj.validate.theory_orders import common_lowest_ie, k_boundary

#: At most this many (I_e, K) series in the CCDF figure.
MAX_CCDF_SERIES = 5


def _log_edges(values) -> np.ndarray:
    """Cell edges of a log-spaced grid: geometric midpoints, the ends half a step out."""
    v = np.log10(np.asarray(values, dtype=float))
    step = np.diff(v) if v.size > 1 else np.array([1.0])
    mid = (v[:-1] + v[1:]) / 2
    return 10 ** np.r_[v[0] - step[0] / 2, mid, v[-1] + step[-1] / 2]


def _star_point(star: dict) -> tuple[float, float, float] | None:
    """(I_e*, lower error, upper error) to draw, or None: a bracketed I_e* with its bootstrap
    interval; an unbracketed one at the grid edge it points at, without errors."""
    kind = star.get("kind")
    if kind == "bracketed" and np.isfinite(star.get("value", np.nan)):
        v = star["value"]
        lo = star.get("ci_low", np.nan)
        hi = star.get("ci_high", np.nan)
        return v, max(v - lo, 0.0) if np.isfinite(lo) else 0.0, max(hi - v, 0.0) if np.isfinite(hi) else 0.0
    if kind == "above":
        return star["low"], 0.0, 0.0
    if kind == "below":
        return star["high"], 0.0, 0.0
    return None


@styled
def map_figure(km: StiffnessMapResult, path: Path) -> Path | None:
    """Outcome agreement over (I_e, K) per family (``cividis``, 0..1), crosses on the cells
    where the criterion fails (outcome or median Frechet) and I_e*(K) over it; None when
    the map has fewer than two I_e values."""
    if not km.agreement or len(km.ie) < 2:
        return None
    fams = [f for f in km.families if f in km.agreement]
    fig = new_figure(figsize=(4.2 * len(fams) + 1.2, 3.8), constrained_layout=True)
    axes = np.atleast_1d(fig.subplots(1, len(fams), sharey=True))
    ie_e = _log_edges(km.ie)
    mesh = None
    for ax, fam in zip(axes, fams):
        ks = km.family_k(fam)
        # relative to the family's predicted K* where the plan set the axis so
        scale = km.predicted.get(fam, {}).get("k_star", np.nan) if km.k_factors else 1.0
        k_e = _log_edges(np.asarray(ks) / scale)
        grid = np.full((len(ks), len(km.ie)), np.nan)
        xs, ys, lo, hi, open_x, open_y, fail_x, fail_y = [], [], [], [], [], [], [], []
        for i, k_abs in enumerate(ks):
            k = k_abs / scale
            cell = km.agreement[fam].get(f"{k_abs:g}")
            if cell is None:
                continue
            for ie, a, ok in zip(cell["ie"], cell["agreement"], cell["passes"]):
                j = int(np.argmin(np.abs(np.log10(km.ie) - np.log10(ie))))
                grid[i, j] = a
                if not ok:
                    fail_x.append(ie)
                    fail_y.append(k)
            p = _star_point(cell["ie_star"])
            if p is not None and cell["ie_star"]["kind"] == "bracketed":
                xs.append(p[0])
                ys.append(k)
                lo.append(p[1])
                hi.append(p[2])
            elif p is not None:
                open_x.append(p[0])
                open_y.append(k)
        mesh = ax.pcolormesh(ie_e, k_e, grid, cmap=SEQUENTIAL_CMAP, vmin=0, vmax=1, shading="flat")
        if fail_x:
            ax.plot(fail_x, fail_y, ls="none", marker="x", color="#D55E00", label="criterion fails")
        if xs:
            ax.errorbar(
                xs,
                ys,
                xerr=[lo, hi],
                color=THRESHOLD_COLOR,
                marker="o",
                ms=5,
                lw=1.5,
                capsize=3,
                label="I_e*(K) (68 % bootstrap)",
            )
        if open_x:
            ax.plot(
                open_x,
                open_y,
                ls="none",
                marker="o",
                mfc="white",
                mec=THRESHOLD_COLOR,
                label="I_e* outside the grid (edge shown)",
            )
        pred = km.predicted.get(fam)
        _draw_prediction(ax, pred if not km.k_factors or not pred else {**pred, "k_star": 1.0})
        ax.set(xscale="log", yscale="log", xlabel="I_e", title=fam.replace("_", " "))
        ax.grid(False)
    axes[0].set_ylabel("K / K* (predicted)" if km.k_factors else "K = k l_s / F_p")
    fig.colorbar(mesh, ax=list(axes), label="outcome agreement [1]")
    handles = {}
    for ax in axes:  # one legend for the panels, below them: the cells stay visible
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    if handles:
        fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncols=len(handles))
    fig.suptitle(f"Spring drive: agreement with the streamline (starts per preset: {km.starts_per_preset})")
    return save_figure(fig, path)


def _draw_prediction(ax, pred: dict | None) -> None:
    """The geometry's prediction (docs/physics.md §8): dashed K* and I_e* lines, quasistatic
    to their lower right (K > K*, I_e < I_e*), inside the axes' current limits."""
    if not pred:
        return
    lo, hi = ax.get_xlim()
    klo, khi = ax.get_ylim()
    k, ie = pred.get("k_star", np.nan), pred.get("ie_star", np.nan)
    if np.isfinite(k) and klo < k < khi:
        ax.axhline(k, color=THRESHOLD_COLOR, ls="--", lw=1.2, label="predicted K*")
    if np.isfinite(ie) and lo < ie < hi:
        ax.axvline(ie, color=THRESHOLD_COLOR, ls=":", lw=1.5, label="predicted I_e*")
    off = [f"K* = {sig(k)}" for v, a, b in [(k, klo, khi)] if np.isfinite(v) and not a < v < b]
    off += [f"I_e* = {sig(ie)}" for v, a, b in [(ie, lo, hi)] if np.isfinite(v) and not a < v < b]
    if off:  # a prediction beyond the grid: named in the panel
        ax.text(
            0.02,
            0.02,
            "predicted, off the grid: " + ", ".join(off),
            transform=ax.transAxes,
            fontsize=7,
            bbox={"facecolor": "white", "alpha": 0.85, "lw": 0},
        )
    ax.set(xlim=(lo, hi), ylim=(klo, khi))


def measured_k_star(cells: dict, lc_over_ls: float = np.nan) -> str:
    """The measured K boundary of a family's map (``K`` -> agreement cell), each K read at
    its lowest I_e where the spring's swing is small
    (:func:`~spine_mj.validate.theory_orders.k_boundary`): ``low-high`` between the
    largest K that fails and the next, which passes, ``< K`` when the smallest passes,
    ``not read`` when every cell swings too much or the stiffest K fails too (the tip's
    inertia, not the spring)."""
    low, high = k_boundary(cells, lc_over_ls)
    if not (np.isfinite(low) or np.isfinite(high)):
        return "not read"
    if not np.isfinite(low):
        return f"< {sig(high)}"
    return f"{sig(low)}-{sig(high)}"


def _prediction_rows(km: StiffnessMapResult) -> list[dict]:
    """Per family: predicted K* and I_e* (and which mechanism), the measured K boundary at
    the lowest I_e and I_e* at the largest K (rigid and compliant references)."""
    rows = []
    check = {r["family"]: r for r in km.prediction_check}
    for fam, pred in km.predicted.items():
        rigid = km.agreement.get(fam, {})
        comp = km.agreement_compliant.get(fam, {})
        k_top = max(rigid, key=float) if rigid else None
        ratio = pred.get("lc_over_ls", np.nan)
        at_k = check.get(fam, {})
        rows.append(
            {
                "family": fam,
                "k_star": pred["k_star"],
                "k_path": pred.get("k_path", np.nan),
                "k_measured": measured_k_star(rigid, ratio) if rigid else "-",
                "k_measured_compliant": measured_k_star(comp, ratio) if comp else "-",
                "ie_star": at_k.get("ie_star_predicted", pred["ie_star"]),
                "limit": at_k.get("ie_limit", pred["limit"]),
                "ie_measured": _bracket(rigid[k_top]["ie_star"]) if k_top else "-",
                "ie_measured_compliant": _bracket(comp[k_top]["ie_star"]) if k_top and k_top in comp else "-",
                "at_k": float(k_top) if k_top else np.nan,
            }
        )
    return rows


def _ccdf_series(km: StiffnessMapResult) -> list[tuple[float, float]]:
    """Up to :data:`MAX_CCDF_SERIES` (I_e, K) keys with slip events: the extreme corners of
    the map and its middle first."""
    keys = sorted(k for k, v in km.slip_samples.items() if v["jump_lc"].size)
    if len(keys) <= MAX_CCDF_SERIES:
        return keys
    idx = np.unique(np.linspace(0, len(keys) - 1, MAX_CCDF_SERIES).round().astype(int))
    return [keys[i] for i in idx]


@styled
def ccdf_figure(km: StiffnessMapResult, path: Path) -> Path | None:
    """CCDFs of slip size (L_c) and force drop (F_p) on log axes, a few (I_e, K) as series
    with their event counts; None without slip events."""
    keys = _ccdf_series(km)
    if not keys:
        return None
    fig = new_figure(figsize=(10, 4), constrained_layout=True)
    ax_j, ax_f = fig.subplots(1, 2)
    for ie, k in keys:
        d = km.slip_samples[(ie, k)]
        label = f"I_e = {sig(ie)}, K = {sig(k)} ({d['jump_lc'].size} events)"
        for ax, name in ((ax_j, "jump_lc"), (ax_f, "force_drop_fp")):
            x, p = complementary_cdf(d[name][d[name] > 0])
            if x.size:
                ax.step(x, p, where="post", label=label)
    ax_j.set(xscale="log", yscale="log", xlabel="slip size / L_c", ylabel="P(size >= x) [1]")
    ax_f.set(xscale="log", yscale="log", xlabel="force drop / F_p", ylabel="P(drop >= x) [1]")
    ax_j.legend(fontsize=7)
    fig.suptitle(f"Slip events of the spring drive on the {' and '.join(SLIP_FAMILIES)} surfaces")
    return save_figure(fig, path)


def _bracket(star: dict) -> str:
    """The I_e* bracket as text: ``low-high``, or ``< high`` / ``> low`` off the grid."""
    kind = star.get("kind")
    if kind == "below":
        return f"< {cell(star.get('high'))}"
    if kind == "above":
        return f"> {cell(star.get('low'))}"
    return f"{cell(star.get('low'))}-{cell(star.get('high'))}"


def _ratio(row: dict) -> str:
    v = row.get("release_over_work")
    return sig(v) if v is not None and np.isfinite(v) else "- (no quasistatic work)"


def _transition_lines(km: StiffnessMapResult) -> list[str]:
    """Where stick-slip gives way to steady sliding along K at each I_e ([] without)."""
    if not km.transitions:
        return []
    return [
        f"Where stick-slip (at least {SLIPS_PER_LC:g} slip events per L_c) gives way to steady "
        "sliding along K, per I_e. The predicted K* of these families comes from their geometry "
        "(the quasistatic-boundary prediction, not part of this study); on a corrugation, where "
        "K* is exact, the stick-slip study's K scan sets the measured transition beside it.",
        "",
        table(
            km.transitions,
            ["ie", "k_low", "k_high", "k_transition"],
            ["I_e", "last K with stick-slip", "first K below the rate", "transition K"],
        ),
        "",
    ]


def _tail_lines(km: StiffnessMapResult) -> list[str]:
    """The maximum-likelihood tail fits of slip size and force drop ([] without)."""
    if not km.tails:
        return []
    rows = [
        {
            **t,
            "alpha_ci": f"{cell(t['alpha'])} ({cell(t['ci_low'])}-{cell(t['ci_high'])})"
            if t["fitted"]
            else "-",
            "vs_exp": f"{cell(t['loglik_ratio_vs_exponential'])} (p {cell(t['p_vs_exponential'])})"
            if t["fitted"]
            else "-",
        }
        for t in km.tails
    ]
    return [
        f"Tails fitted by maximum likelihood (`powerlaw`; density p(S) ~ S^-alpha above xmin, 95 % "
        f"interval; series of fewer than {MIN_EVENTS} events are counted, not fitted). The "
        "likelihood ratio against an exponential tail is positive where the power law fits better. "
        "The ABBM model (a random-walk force landscape) gives alpha = 3/2; short-range correlated "
        "slopes have no universal exponent.",
        "",
        table(
            rows,
            ["ie", "K", "quantity", "n", "alpha_ci", "xmin", "n_tail", "vs_exp"],
            ["I_e", "K", "quantity", "events", "alpha (95 %)", "xmin", "in tail", "log-lik. ratio vs exp."],
        ),
        "",
    ]


def map_sections(km: StiffnessMapResult) -> dict[str, str]:
    """Report text of the map: ``map`` (I_e*(K) table), ``energy`` and ``slip`` (tables
    with one sentence each); empty strings without a map (an empty grid)."""
    if not km.agreement:
        return {"map": "", "energy": "", "slip": ""}
    return {
        "map": "\n".join(_map_lines(km)),
        "energy": "\n".join(_energy_lines(km)),
        "slip": "\n".join(_slip_lines(km)),
    }


def _k_axis(km: StiffnessMapResult) -> str:
    """The map's K axis in words: a ladder relative to each family's predicted K*, or the
    absolute values."""
    if km.k_factors:
        per = "; ".join(f"{f}: {', '.join(sig(v) for v in km.family_k(f))}" for f in km.families)
        return (
            f"K = k l_s / F_p at {', '.join(sig(v) for v in km.k_factors)} x each family's predicted "
            f"K_path (the boundary its criterion sees), with its fold K* and 10 K* ({per})"
        )
    return f"K = k l_s / F_p = {', '.join(sig(v) for v in km.stiffness_numbers)}"


def _map_lines(km: StiffnessMapResult) -> list[str]:
    """The I_e*(K) table per family and K, with what its columns mean."""
    star_rows = []
    for fam, by_k in km.agreement.items():
        for k, grid_cell in by_k.items():
            s = grid_cell["ie_star"]
            k_star = km.predicted.get(fam, {}).get("k_star", np.nan)
            star_rows.append(
                {
                    "family": fam,
                    "K": float(k),
                    "k_rel": float(k) / k_star if np.isfinite(k_star) and k_star > 0 else np.nan,
                    "ie_star": s.get("value"),
                    "bracket": _bracket(s),
                    "ci": f"{cell(s.get('ci_low'))}-{cell(s.get('ci_high'))}",
                    "kind": s.get("kind"),
                    "runs": f"{min(grid_cell['n_ok'])}-{max(grid_cell['n_ok'])} ok / {max(grid_cell['n'])}",
                }
            )
    head = [
        "## The quasistatic boundary over (I_e, K)",
        "",
        f"Spring drive over I_e = {', '.join(sig(v) for v in km.ie)} and {_k_axis(km)}, "
        f"{km.starts_per_preset} starts per preset "
        "(few: the lowest I_e and the many K are the expensive corner, so every cell's agreement "
        "moves in steps of one run). A cell agrees when the boundary study's criterion holds "
        f"({CRITERION.replace('_', ' ')}: outcome agreement >= 95 % and median Frechet <= 0.1 L_c); "
        "I_e*(K) is where it first fails along I_e, with its bracket and the 16-84 % bootstrap "
        "interval over starts; `above`: it holds up to the largest I_e, `below`: it fails already "
        "at the smallest.",
        "",
        table(
            star_rows,
            ["family", "K", "k_rel", "ie_star", "bracket", "ci", "kind", "runs"],
            [
                "family",
                "K",
                "K / K*",
                "I_e*",
                "bracket",
                "bootstrap 16-84 %",
                "kind",
                "runs (ok / all, per I_e)",
            ],
        ),
        "",
        "The heat map shows the fraction of runs whose outcome agrees in each cell (crosses: the "
        "criterion fails there, by outcome or by median Frechet); the markers, I_e* against K "
        "(hollow where it lies outside the grid).",
        "",
    ]
    return head + _prediction_text(km)


def _energy_lines(km: StiffnessMapResult) -> list[str]:
    """The spring energy released at breakaways against the quasistatic work, per K."""
    return (
        [
            "### Why a soft spring breaks quasistatics",
            "",
            f"At the lowest I_e ({sig(km.energy[0]['ie'])}) of the map, pooled over the families: the "
            "spring energy released at breakaways (sum of (F_onset^2 - F_stop^2) / 2k over the slip "
            "events) per L_c the MuJoCo tip advanced, against the quasistatic work F_p integral kappa dx "
            "per L_c along the streamline (both in F_p L_c per L_c, i.e. F_p). Runs that ended in "
            "engine trouble are left out of the energies (ok / runs): at small K these are often the "
            "runs a release threw into a hop, so the soft-spring rows understate the release.",
            "",
            table(
                km.energy,
                [
                    "K",
                    "release_per_lc",
                    "qs_work_per_lc",
                    "release_over_work",
                    "slip_events_per_lc",
                    "agreement",
                    "n_ok",
                    "n",
                ],
                [
                    "K",
                    "released / L_c [F_p]",
                    "W_qs / L_c [F_p]",
                    "released / W_qs",
                    "slip events / L_c",
                    "outcome agreement",
                    "ok",
                    "runs",
                ],
            ),
            "",
            f"The released share of the quasistatic work goes from {_ratio(km.energy[0])} at K = "
            f"{sig(km.energy[0]['K'])} to {_ratio(km.energy[-1])} at K = {sig(km.energy[-1]['K'])}: where "
            "it is large, each breakaway throws the tip however slowly the carriage moves. A stiff "
            "spring stores little per event, but its many short events (slip events / L_c) add up.",
            "",
        ]
        if km.energy
        else []
    )


def _slip_lines(km: StiffnessMapResult) -> list[str]:
    """Slip events and trap skipping over the map."""
    return (
        [
            "### Stick-slip across the map",
            "",
            f"Slip events on the {' and '.join(SLIP_FAMILIES)} runs (stretches where the tip outruns "
            "the carriage while the spring unloads and reaches 5 times its speed: steady sliding is "
            "no slip; docs/physics.md §6), per L_c advanced and as the fraction of recorded time "
            "spent slipping; "
            "trap skipping over every family's runs without engine trouble: of the runs whose "
            "streamline self-locks (traps), those where MuJoCo slides on (skipped).",
            "",
            table(
                km.slip,
                [
                    "ie",
                    "K",
                    "slip_events_per_lc",
                    "slip_time_fraction",
                    "traps",
                    "skipped",
                    "trap_skip_rate",
                    "n_ok",
                    "n",
                ],
                [
                    "I_e",
                    "K",
                    "slip events / L_c",
                    "time slipping",
                    "traps",
                    "skipped",
                    "skip rate",
                    "ok",
                    "runs",
                ],
            ),
            "",
            *_transition_lines(km),
            *_tail_lines(km),
        ]
        if km.slip
        else []
    )


def _prediction_text(km: StiffnessMapResult) -> list[str]:
    """The predicted boundary against the measured one, and the compliant reference's
    agreement (lines of the map section; empty without predictions)."""
    if not km.predicted:
        return []
    comp_rows = []
    for fam, by_k in km.agreement_compliant.items():
        low = common_lowest_ie(by_k)
        for k, c in by_k.items():
            rigid = km.agreement.get(fam, {}).get(k)
            i = c["ie"].index(low)
            comp_rows.append(
                {
                    "family": fam,
                    "K": float(k),
                    "ie": low,
                    "rigid": f"{cell(rigid['agreement'][i])} / {cell(rigid['median_frechet'][i])}"
                    if rigid
                    else "-",
                    "compliant": f"{cell(c['agreement'][i])} / {cell(c['median_frechet'][i])}",
                    "star": _bracket(c["ie_star"]),
                }
            )
    return [
        "### The predicted boundary",
        "",
        "Predicted from each family's geometry alone (docs/physics.md §8, `spine-mj surface info`), on "
        "the surfaces the map runs traced under the rig's tip: K* = l_s max(-dH/dx) along the "
        "streamlines (below it the compliant-drive streamline folds: stick-slip at vanishing speed), "
        "K_path the stiffness where the compliant-drive paths from the family's starts meet the "
        "map's criterion against the rigid ones (what the criterion sees of the folds), "
        "and I_e* the lowest of lift-off over crests, skipping the shallowest trap, the lag "
        "behind turns (I_e < 2 mu 0.1) and, at the stiffest K, the spring-block swing "
        "sqrt(I_e K L_c / l_s) reaching F_p. Measured: the K "
        "boundary is where the criterion first holds as K grows, each K read at its lowest I_e "
        "whose swing is at most F_p; I_e* is the map's "
        "at its stiffest K; both against the rigid streamline and against the compliant-drive "
        "streamline of each run's spring. Dashed and dotted lines on the map.",
        "",
        table(
            _prediction_rows(km),
            [
                "family",
                "k_star",
                "k_path",
                "k_measured",
                "k_measured_compliant",
                "ie_star",
                "limit",
                "at_k",
                "ie_measured",
                "ie_measured_compliant",
            ],
            [
                "family",
                "K* predicted",
                "K_path predicted",
                "K boundary (rigid ref.)",
                "(compliant ref.)",
                "I_e* predicted",
                "set by",
                "at K",
                "I_e* measured (rigid ref.)",
                "(compliant ref.)",
            ],
        ),
        "",
        "What the compliant reference changes at the lowest I_e (outcome agreement / median Frechet "
        "in L_c against each reference; what stiffness does is in the compliant one, what is left "
        "over is inertia):",
        "",
        table(
            comp_rows,
            ["family", "K", "ie", "rigid", "compliant", "star"],
            ["family", "K", "I_e", "rigid reference", "compliant reference", "I_e* (compliant)"],
        ),
        "",
    ]


def section(km: StiffnessMapResult, ctx: ReportContext) -> str | None:
    """The map's sections (I_e*(K), energy, slip), or None without a map."""
    if not km.agreement:
        return None
    text = map_sections(km)
    heat = ctx.draw(map_figure, km, "ie_k_map.png")
    ccdf = ctx.draw(ccdf_figure, km, "slip_ccdf.png")
    orders = ctx.draw(orders_figure, km, "gap_orders.png")
    return assemble(
        text["map"],
        "\n".join(prediction_lines(km) + causes_lines(km, ctx.results.get("limit"))),
        image("Outcome agreement over (I_e, K) per family with I_e*(K)", heat),
        "\n".join(orders_lines(km)),
        image("The gap to the streamline against I_e and 1/K, log-log, with the orders", orders),
        text["energy"],
        text["slip"],
        image("Complementary CDFs of slip size and force drop", ccdf),
    )

"""HTML report of a sweep store (template ``spine_mj/templates/sweep_report.html.j2``).

It leads with the agreement of MuJoCo against the quasistatic streamline over the inertia
number I_e (and the spring stiffness when the sweep varies it) and a few MuJoCo paths over
the streamline at the lowest and highest I_e; then, per analysis, mean metrics (with units
and ``ok / runs`` beside them) by the swept parameters that analysis reads, and plots of
the metrics that vary against those parameters. Figures are embedded PNGs, so the report
is one self-contained file.
"""

from __future__ import annotations

import base64
import io
import os
from pathlib import Path

import numpy as np
import pandas as pd
from pandas.api.types import is_bool_dtype, is_numeric_dtype

from spine_mj.atomic import atomic_output
from spine_mj.plotting import (
    THRESHOLD_COLOR,
    house_style,
    new_figure,
    path_overlay_figure,
    sig,
    styled,
)
from spine_mj.sweep.registry import ANALYSES, RESERVED
from spine_mj.sweep.store import load_runs, load_trajectories, read_manifest, store_status
from spine_mj.templates import render
from spine_mj.theory.targets import FRECHET_TARGET, OUTCOME_TARGET

__all__ = ["METRIC_UNITS", "write_report"]

#: Unit of each metric of the built-in analyses ("surface units": the surface's own
#: length unit; L_c: its characteristic length; F_p: the preload; fraction: of the runs).
METRIC_UNITS = {
    "self_locked": "fraction",
    "agree": "fraction",
    "agree_lock": "fraction",
    "agree_end": "fraction",
    "same_trap": "fraction",
    "max_kappa": "1",
    "kappa_ratio": "1",
    "kappa_mj": "1",
    "path_length": "surface units",
    "frechet": "L_c",
    "lateral_deviation": "L_c",
    "end_distance": "L_c",
    "inertia_number": "1",
    "speed_m_s": "m/s",
    "end_time_s": "s",
    "max_drive_over_fp": "F_p",
    "n_move_onsets": "count",
    "slip_events": "count",
    "slip_onset_fp_mean": "F_p",
    "slip_onset_fp_max": "F_p",
    "stuck_fraction": "fraction",
    "sliding_fraction": "fraction",
    "slipping_fraction": "fraction",
    "max_speed_over_drive": "V",
    "max_penetration_m": "m",
    "timestep_s": "s",
    "char_length": "surface units",
    "tip_radius_m": "m",
    "dl_used": "surface units",
}
#: Unit of each sweepable parameter shown as a column or an axis.
PARAM_UNITS = {"ie": "1", "mu": "1", "stiffness": "N/m", "speed": "m/s", "mass": "kg", "timestep": "s"}
#: Columns that are bookkeeping or positions, not results to average or plot.
_HIDDEN = {"end_x", "end_y", "end_z", "n_steps"}
_ID_COLUMNS = set(RESERVED)
#: Metrics plotted first (the rest follow in table order), at most this many per analysis.
_PRIORITY = (
    "agree",
    "frechet",
    "lateral_deviation",
    "self_locked",
    "max_kappa",
    "max_drive_over_fp",
    "slip_events",
    "kappa_ratio",
    "path_length",
)
_MAX_PANELS = 6
#: Metrics that restate a drive parameter (the achieved I_e and speed): tables, not plots.
_ECHOES = {"inertia_number", "speed_m_s"}
_OVERLAY_STARTS = 3


def write_report(out_dir: str | os.PathLike, output: str | os.PathLike) -> Path:
    """Write the HTML report of the sweep store in ``out_dir`` to ``output``.

    Parameters
    ----------
    out_dir : str or os.PathLike
        The result store.
    output : str or os.PathLike
        The ``.html`` file to write: runs by status, metric tables, plots of the metrics
        against the swept parameters.

    Returns
    -------
    Path
        ``output``.
    """
    out_dir, output = Path(out_dir), Path(output)
    st = store_status(out_dir)
    manifest = read_manifest(out_dir)
    df = load_runs(out_dir)
    swept = [p for p in manifest.get("swept", []) if p in df.columns]
    context = {
        "st": st,
        "runs_done": sum(st.status_counts.values()),
        "corrupt": [str(c) for c in getattr(st, "corrupt_cases", ())],
        "swept": swept,
        "status_table": _status_table(df),
        "not_ok": _not_ok(df),
        "agreement": _agreement_section(df),
        "overlays": _overlay_section(out_dir, df),
        "analyses": [_analysis_section(a, sub, swept) for a, sub in _by_analysis(df)],
    }
    doc = render("sweep_report.html.j2", **context)
    with atomic_output(output) as tmp:
        tmp.write_text(doc)
    return output


def _by_analysis(df: pd.DataFrame):
    return [] if df.empty else df.groupby("analysis", sort=False)


def _status_table(df: pd.DataFrame) -> dict | None:
    if df.empty:
        return None
    counts = df.groupby(["analysis", "status"], sort=False).size().unstack(fill_value=0)
    return {
        "statuses": list(counts.columns),
        "rows": [{"analysis": a, "counts": [int(v) for v in row]} for a, row in counts.iterrows()],
    }


def _not_ok(df: pd.DataFrame) -> list[dict]:
    if df.empty:
        return []
    bad = df[df.status != "ok"]
    return bad[["analysis", "surface", "start", "status", "reason"]].head(50).to_dict("records")


def _depends_on(analysis: str) -> set[str]:
    """Parameters an analysis reads, its own and those of the analyses it needs."""
    spec = ANALYSES.get(analysis)
    if spec is None:
        return set()
    names = {p.name for p in spec.parameters}
    for req in spec.requires:
        names |= _depends_on(req)
    return names


def _unit(name: str) -> str:
    return METRIC_UNITS.get(name) or PARAM_UNITS.get(name) or ""


def _metric_columns(ok: pd.DataFrame, params: set[str]) -> tuple[list[str], list[tuple[str, str]]]:
    """Metrics that vary between ok runs, and (name, value) of those that are constant."""
    varying, constant = [], []
    for c in ok.columns:
        if c in _ID_COLUMNS or c in params or c in _HIDDEN or not is_numeric_dtype(ok[c]):
            continue
        vals = ok[c].dropna()
        if vals.empty:
            continue
        if vals.nunique() > 1:
            varying.append(c)
        else:
            constant.append((c, sig(vals.iloc[0])))
    return varying, constant


def _analysis_section(analysis: str, sub: pd.DataFrame, swept: list[str]) -> dict:
    """Mean metrics per surface and relevant swept values (each row once: a quasistatic
    row does not depend on the drive, so it is not repeated per I_e), and one figure."""
    depends = _depends_on(analysis)
    keys = ["surface", *[p for p in swept if p in depends]]
    dropped = [p for p in swept if p not in depends]
    sub = sub.drop_duplicates(
        subset=[*keys, "start", "surface_seed"] if "surface_seed" in sub else [*keys, "start"]
    )
    sub = _bools_as_float(sub)
    ok = sub[sub.status == "ok"]
    metrics, constant = _metric_columns(ok, depends | set(swept))
    section = {
        "name": analysis,
        "doc": ANALYSES[analysis].doc if analysis in ANALYSES else "",
        "group_by": [(k, _unit(k)) for k in keys],
        "metrics": [(m, _unit(m)) for m in metrics],
        "constant": [(n, v, _unit(n)) for n, v in constant],
        "dropped": dropped,
        "rows": [],
        "figure": None,
    }
    if not metrics:
        return section
    for key, grp in sub.groupby(keys, sort=True, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        g_ok = grp[grp.status == "ok"]
        cells = [_mean_cell(g_ok[m], len(g_ok)) for m in metrics]
        section["rows"].append(
            {
                "key": [sig(k) if not isinstance(k, str) else k for k in key],
                "n_ok": len(g_ok),
                "n": len(grp),
                "cells": cells,
            }
        )
    x = next(
        (p for p in keys[1:] if is_numeric_dtype(ok[p]) and not is_bool_dtype(ok[p]) and ok[p].nunique() > 1),
        None,
    )
    if x is not None:
        shown = [m for m in metrics if m not in _ECHOES]
        ranked = sorted(shown, key=lambda m: _PRIORITY.index(m) if m in _PRIORITY else len(_PRIORITY))
        series = [p for p in keys[1:] if p != x and ok[p].nunique() > 1]
        section["figure"] = _png(_metrics_figure(ok, analysis, x, ranked[:_MAX_PANELS], series))
        section["x"] = x
    return section


def _bools_as_float(df: pd.DataFrame) -> pd.DataFrame:
    """Object columns that hold only True / False / None as floats (their mean: a fraction)."""
    df = df.copy()
    for c in df.columns:
        if df[c].dtype == object:
            vals = set(df[c].dropna())
            if vals and vals <= {True, False}:
                df[c] = df[c].astype(float)
    return df


def _mean_cell(values: pd.Series, n_ok: int) -> dict:
    """Mean of the finite values; ``n`` is how many there were when fewer than ``n_ok``."""
    v = values.astype(float).replace([np.inf, -np.inf], np.nan).dropna()
    return {"mean": sig(v.mean()) if len(v) else "-", "n": len(v) if len(v) < n_ok else None}


@styled
def _metrics_figure(ok: pd.DataFrame, analysis: str, x: str, metrics: list[str], series: list[str]):
    """One panel per metric against the swept parameter ``x``: one line per surface and
    value of the other swept parameters ``series`` (mean over starts, band min-max)."""
    ncols = min(3, len(metrics))
    nrows = -(-len(metrics) // ncols)
    fig = new_figure(figsize=(4.2 * ncols, 3.3 * nrows + 0.4), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    logx = bool((ok[x] > 0).all() and ok[x].max() / ok[x].min() > 50)
    for ax, metric in zip(axes, metrics):
        for key, grp in ok.groupby(["surface", *series]):
            key = key if isinstance(key, tuple) else (key,)
            label = ", ".join([str(key[0]), *(f"{p} {sig(v)}" for p, v in zip(series, key[1:]))])
            y = grp[metric].astype(float).replace([np.inf, -np.inf], np.nan)
            stats = y.groupby(grp[x]).agg(["mean", "min", "max"])
            (line,) = ax.plot(stats.index, stats["mean"], "o-", label=str(label))
            ax.fill_between(stats.index, stats["min"], stats["max"], alpha=0.2, color=line.get_color())
        if logx:
            ax.set_xscale("log")
        ax.set_xlabel(_label(x))
        ax.set_ylabel(_label(metric))
    for ax in axes[len(metrics) :]:
        ax.set_visible(False)
    axes[0].legend(title="band: min-max over starts")
    fig.suptitle(f"{analysis}: metrics against {x} (mean over starts, ok runs)")
    return fig


def _label(name: str) -> str:
    unit = _unit(name)
    return f"{name} [{unit}]" if unit else name


# --------------------------------------------------------------------------- agreement


def _agreement_section(df: pd.DataFrame) -> dict | None:
    """Agreement of MuJoCo with the streamline against I_e (and stiffness), from the
    ``compare`` rows; None when the sweep has none or no I_e column."""
    if df.empty or "compare" not in set(df["analysis"]) or "ie" not in df.columns:
        return None
    comp = df[df.analysis == "compare"].copy()
    if comp["ie"].isna().all():
        return None
    by_k = "stiffness" in comp.columns and comp["stiffness"].nunique() > 1
    keys = ["surface", *(["stiffness"] if by_k else []), "ie"]
    rows = []
    for key, grp in comp.groupby(keys, sort=True):
        ok = grp[grp.status == "ok"]
        agree = ok["agree"].fillna(False).astype(bool)
        rows.append(
            {
                "key": dict(zip(keys, key)),
                "n_ok": len(ok),
                "n": len(grp),
                "n_agree": int(agree.sum()),
                "agreement": sig(agree.mean()) if len(ok) else "-",
                "frechet": _mean_cell(ok["frechet"], len(ok)),
                "lateral": _mean_cell(ok["lateral_deviation"], len(ok)),
            }
        )

    fig = _agreement_figure(comp[comp.status == "ok"], by_k, OUTCOME_TARGET, FRECHET_TARGET)
    return {
        "by_stiffness": by_k,
        "rows": rows,
        "figure": _png(fig),
        "outcome_target": OUTCOME_TARGET,
        "frechet_target": FRECHET_TARGET,
    }


@styled
def _agreement_figure(ok: pd.DataFrame, by_k: bool, outcome_target: float, frechet_target: float):
    """Agreement fraction (left) and mean Frechet deviation (right) against I_e, one line
    per surface (and stiffness), the targets as labelled lines."""
    fig = new_figure(figsize=(11, 4.2), layout="constrained")
    a1, a2 = fig.subplots(1, 2)
    groups = ["surface", "stiffness"] if by_k else ["surface"]
    for key, grp in ok.groupby(groups):
        key = key if isinstance(key, tuple) else (key,)
        label = str(key[0]) + (f", k = {sig(key[1])} N/m" if by_k else "")
        stats = grp.groupby("ie").agg(
            agree=("agree", lambda s: s.fillna(False).astype(bool).mean()), frechet=("frechet", "mean")
        )
        (line,) = a1.semilogx(stats.index, stats["agree"], "o-", label=label)
        a2.loglog(stats.index, np.maximum(stats["frechet"], 1e-5), "o-", color=line.get_color(), label=label)
    a1.axhline(
        outcome_target,
        color=THRESHOLD_COLOR,
        ls="--",
        lw=1,
        label=f"target: agreement >= {sig(outcome_target)}",
    )
    a2.axhline(
        frechet_target,
        color=THRESHOLD_COLOR,
        ls="--",
        lw=1,
        label=f"target: deviation <= {sig(frechet_target)} L_c",
    )
    a1.set(xlabel="inertia number I_e [1]", ylabel="runs that agree [fraction]", ylim=(-0.05, 1.05))
    a2.set(xlabel="inertia number I_e [1]", ylabel="mean Frechet deviation [L_c]")
    a1.legend()
    a2.legend()
    fig.suptitle("MuJoCo (spring drive) against the quasistatic streamline")
    return fig


def _overlay_section(out_dir: Path, df: pd.DataFrame) -> dict | None:
    """A few MuJoCo paths over the streamline at the lowest and highest I_e (first surface)."""
    if df.empty or not {"quasistatic", "engine"} <= set(df["analysis"]) or "ie" not in df.columns:
        return None
    mj = df[(df.analysis == "engine") & df["ie"].notna()]
    if mj.empty:
        return None
    surface = mj["surface"].iloc[0]
    mj = mj[mj.surface == surface]
    comp = df[(df.analysis == "compare") & (df.status == "ok")]
    agree = comp.set_index(["case_id", "start"])["agree"] if "agree" in comp else None
    panels = []
    for ie in sorted({mj["ie"].min(), mj["ie"].max()}):
        case_id = mj.loc[mj["ie"] == ie, "case_id"].iloc[0]
        try:
            qs = load_trajectories(out_dir, case_id, analysis="quasistatic", columns=["x", "y"])
            mp = load_trajectories(out_dir, case_id, analysis="engine", columns=["x", "y"])
        except Exception:  # a case without stored paths (record off, or a corrupt file)
            continue
        starts = sorted(set(qs["start"]))[:_OVERLAY_STARTS]
        paths = [(_xy(qs, s), _xy(mp, s)) for s in starts]
        n_agree = "" if agree is None else sum(bool(agree.get((case_id, s), False)) for s in starts)
        title = f"{surface}, I_e = {sig(ie)}" + (
            f": {n_agree}/{len(starts)} agree" if agree is not None else ""
        )
        panels.append({"title": title, "paths": paths})
    if not panels:
        return None
    return {"figure": _png(path_overlay_figure(panels)), "surface": surface}


def _xy(traj: pd.DataFrame, start: int) -> np.ndarray:
    part = traj[traj["start"] == start].sort_values("step")
    return part[["x", "y"]].to_numpy(float)


def _png(fig) -> str:
    """``fig`` as a base64 PNG for an ``<img src="data:...">``."""
    buf = io.BytesIO()
    with house_style():
        fig.savefig(buf, format="png", dpi=100)
    return base64.b64encode(buf.getvalue()).decode()

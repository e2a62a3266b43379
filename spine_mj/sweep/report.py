"""HTML report of a sweep store: status counts, metric tables, metrics against swept
parameters (matplotlib PNGs embedded as base64)."""

from __future__ import annotations

import base64
import html
import io
import os
from pathlib import Path

import numpy as np
from pandas.api.types import is_bool_dtype, is_numeric_dtype

from spine_mj.errors import atomic_output
from spine_mj.plotting import new_figure
from spine_mj.sweep.store import load_runs, read_manifest, store_status

_MAX_PLOTS_PER_ANALYSIS = 12
_SKIP = {"start", "case_index", "seed", "surface_seed", "start_x", "start_y", "time_s", "cpu_s"}


def write_report(out_dir: str | os.PathLike, output: str | os.PathLike) -> Path:
    """Write an HTML report of the store: status counts, metric tables and plots of the
    metrics against the swept parameters (embedded PNGs). Returns the output path."""
    out_dir, output = Path(out_dir), Path(output)
    st = store_status(out_dir)
    manifest = read_manifest(out_dir)
    df = load_runs(out_dir)
    swept = [p for p in manifest.get("swept", []) if p in df.columns]
    params = set(manifest["config"]["grid"])
    parts = [
        f"<h1>Sweep {html.escape(st.name)}</h1>",
        f"<p>config hash <code>{st.config_hash[:12]}</code>, created {html.escape(st.created)}, "
        f"git {html.escape(str(st.git_commit))}; cases {st.finished_cases}/{st.total_cases}, "
        f"runs {sum(st.status_counts.values())}/{st.total_runs}"
        f"{'' if st.complete else ' (unfinished)'}.</p>",
        "<h2>Runs by status</h2>",
    ]
    if df.empty:
        parts.append("<p>No finished runs.</p>")
    else:
        counts = df.groupby(["analysis", "status"]).size().unstack(fill_value=0)
        parts.append(counts.to_html())
        bad = df[df.status != "ok"]
        if len(bad):
            parts.append("<h3>Not ok (first 50)</h3>")
            parts.append(
                bad[["analysis", "surface", "start", "status", "reason"]].head(50).to_html(index=False)
            )
    for analysis, sub in [] if df.empty else df.groupby("analysis", sort=False):
        parts.extend(_analysis_section(analysis, sub, swept, params))
    doc = (
        "<!DOCTYPE html><html><head><meta charset='utf-8'><title>"
        f"{html.escape(st.name)}</title><style>body{{font-family:sans-serif;max-width:1100px;"
        "margin:auto}} table{{border-collapse:collapse;font-size:12px}} td,th{{border:1px "
        "solid #ccc;padding:2px 6px}} img{{max-width:100%}}</style></head><body>"
        + "\n".join(parts)
        + "</body></html>\n"
    )
    with atomic_output(output) as tmp:
        tmp.write_text(doc)
    return output


def _analysis_section(analysis: str, sub, swept: list[str], params: set[str]) -> list[str]:
    """HTML parts of one analysis: mean metrics per surface and swept values, and plots."""
    ok = sub[sub.status == "ok"].dropna(axis=1, how="all")
    metrics = _numeric_metrics(ok, params)
    parts = [f"<h2>{html.escape(analysis)}</h2>"]
    if ok.empty or not metrics:
        parts.append("<p>No metrics (no run ended ok).</p>")
        return parts
    table = ok.groupby(["surface", *swept])[metrics].mean(numeric_only=False)
    parts.append("<p>Mean over starts (ok runs).</p>")
    parts.append(table.to_html(float_format=lambda v: f"{v:.4g}"))
    n_plots = 0
    for param in swept:
        values = ok[param]
        if not is_numeric_dtype(values) or is_bool_dtype(values):
            continue
        for metric in metrics:
            if n_plots >= _MAX_PLOTS_PER_ANALYSIS:
                break
            parts.append(
                f'<img alt="{html.escape(metric)} vs {html.escape(param)}" '
                f'src="data:image/png;base64,{_plot(ok, analysis, param, metric)}">'
            )
            n_plots += 1
    return parts


def _plot(ok, analysis: str, param: str, metric: str) -> str:
    """``metric`` against ``param`` per surface (mean over starts, band min-max), as PNG."""
    fig = new_figure(figsize=(6, 4), layout="constrained")
    ax = fig.add_subplot()
    for label, grp in ok.groupby("surface"):
        y = grp[metric].astype(float).replace([np.inf, -np.inf], np.nan)
        stats = y.groupby(grp[param]).agg(["mean", "min", "max"])
        ax.plot(stats.index, stats["mean"], "o-", label=str(label))
        ax.fill_between(stats.index, stats["min"], stats["max"], alpha=0.2)
    values = ok[param]
    positive = values[values > 0]
    if len(positive) == len(values) and values.max() / values.min() > 50:
        ax.set_xscale("log")
    ax.set_xlabel(param)
    ax.set_ylabel(metric)
    ax.set_title(f"{analysis}: {metric} (mean over starts, band min-max)")
    ax.legend(fontsize="small")
    return _png(fig)


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    return base64.b64encode(buf.getvalue()).decode()


def _numeric_metrics(df, params) -> list[str]:
    cols = []
    for c in df.columns:
        if c in _SKIP or c in params or c in ("run_id", "case_id", "analysis", "surface", "status", "reason"):
            continue
        if is_numeric_dtype(df[c]) and df[c].notna().any():
            cols.append(c)
    return cols

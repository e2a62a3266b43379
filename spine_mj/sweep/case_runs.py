"""Running one case: every analysis of the case in order, one row of the run table per start.

A *run* is one start of one case under one analysis. :func:`run_case` never raises for a
failing analysis or surface: the failure is the status and reason of its rows (see
:data:`~spine_mj.sweep.registry.STATUSES`), so a sweep goes on. Rows and paths come back
as pyarrow tables, the form in which the store writes them.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np
import pyarrow as pa

from spine_mj.sweep.cases import Case
from spine_mj.sweep.registry import ANALYSES, RESERVED, AnalysisResult, param_specs


def run_case(case: Case) -> tuple[Any, Any]:
    """Run every analysis of ``case``; never raises for a failing analysis.

    Parameters
    ----------
    case : Case
        One surface instance at one grid point, with its starts.

    Returns
    -------
    rows : pyarrow.Table
        One row per (analysis, start) with the columns of the run table.
    trajectories : pyarrow.Table or None
        Long table (``analysis``, ``start``, ``step``, ...) of the stored paths.
    """
    n = case.starts.count
    starts = np.full((n, 2), np.nan)
    surface = None
    surface_error = None
    try:
        surface = case.surface.make()
        starts = case.starts.resolve(surface.bounds, case.seed)
    except Exception as exc:  # any failure to build the surface is recorded
        surface_error = _reason(exc)
    rows, trajs = [], []
    results: dict[str, AnalysisResult] = {}
    for name in case.analyses:
        analysis = ANALYSES[name]
        status = np.full(n, "ok", dtype=object)
        reason = np.full(n, "", dtype=object)
        metrics: dict[str, np.ndarray] = {}
        t0, c0 = time.perf_counter(), time.process_time()
        if surface_error is not None:
            status[:], reason[:] = "bad_surface", surface_error
        elif any(r not in results for r in analysis.requires):
            status[:] = "dependency_failed"
            reason[:] = "no result from " + ", ".join(r for r in analysis.requires if r not in results)
        else:
            try:
                res = analysis.func(case, surface, starts, {r: results[r] for r in analysis.requires})
                metrics = _check_metrics(res.metrics, n, name)
                if res.status is not None:
                    status[:] = res.status
                if res.reason is not None:
                    reason[:] = res.reason
                results[name] = res
                if res.trajectories and case.store_trajectories:
                    trajs.append(_traj_table(res.trajectories, name))
            except Exception as exc:  # recorded; the sweep goes on
                status[:], reason[:] = "failed", _reason(exc)
                metrics = {}
        elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
        rows.append(_rows(case, name, starts, status, reason, metrics, elapsed, cpu))
    table = pa.concat_tables(rows, promote_options="permissive")
    traj = pa.concat_tables(trajs, promote_options="permissive") if trajs else None
    return table, traj


def failed_rows(case: Case, reason: str):
    """The rows of ``case`` when it gave no result at all (its worker process died): every
    run ``failed`` with ``reason``, start points unknown (NaN)."""
    n = case.starts.count
    starts = np.full((n, 2), np.nan)
    status = np.full(n, "failed", dtype=object)
    why = np.full(n, reason, dtype=object)
    tables = [_rows(case, name, starts, status, why, {}, 0.0, 0.0) for name in case.analyses]
    return pa.concat_tables(tables, promote_options="permissive")


def _rows(case: Case, analysis: str, starts, status, reason, metrics, elapsed: float, cpu: float):
    """The rows of one analysis of ``case``: the reserved columns, parameters, metrics."""
    n = case.starts.count
    cols = {
        "run_id": [f"{case.case_id}-{analysis}-{i}" for i in range(n)],
        "case_id": [case.case_id] * n,
        "case_index": np.full(n, case.index, np.int64),
        "analysis": [analysis] * n,
        "start": np.arange(n, dtype=np.int64),
        "start_x": starts[:, 0],
        "start_y": starts[:, 1],
        "surface": [case.surface.label] * n,
        "surface_seed": pa.array([case.surface.seed] * n, pa.int64()),
        "seed": np.full(n, case.seed, np.int64),
    }
    specs = param_specs(case.analyses)
    for k, v in case.params.items():
        cols[k] = pa.array([v] * n, _arrow_type(v, specs[k].kind if k in specs else None))
    cols["status"] = list(status)
    cols["reason"] = list(reason)
    cols["time_s"] = np.full(n, elapsed / max(n, 1))
    cols["cpu_s"] = np.full(n, cpu / max(n, 1))
    for k, v in metrics.items():
        cols[k] = v
    return pa.table(cols)


#: The column type of a parameter's kind (what a None of that parameter is stored as).
_KIND_TYPES = {"float": pa.float64(), "int": pa.int64(), "str": pa.string(), "bool": pa.bool_()}


def _arrow_type(value, kind: str | None = None):
    if value is None and kind in _KIND_TYPES:
        return _KIND_TYPES[kind]
    if isinstance(value, bool):
        return pa.bool_()
    if isinstance(value, int):
        return pa.int64()
    if isinstance(value, float) or value is None:
        return pa.float64()
    return pa.string()


def _reason(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}"[:500]


def _check_metrics(metrics: Mapping, n: int, analysis: str) -> dict[str, np.ndarray]:
    out = {}
    for k, v in metrics.items():
        if k in RESERVED:
            raise RuntimeError(f"analysis {analysis} returned metric {k!r}, a reserved column")
        arr = np.asarray(v)
        if arr.ndim == 0:
            arr = np.full(n, arr[()])
        if arr.shape != (n,):
            raise RuntimeError(f"analysis {analysis}: metric {k!r} must have shape ({n},), got {arr.shape}")
        out[k] = arr
    return out


def _traj_table(traj: Mapping[str, np.ndarray], analysis: str):
    cols = {k: np.asarray(v) for k, v in traj.items()}
    n = len(next(iter(cols.values())))
    return pa.table({"analysis": pa.repeat(pa.scalar(analysis, pa.string()), n), **cols})

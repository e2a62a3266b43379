"""The result store of a sweep: a folder that a killed sweep resumes from.

The store in the output folder::

    manifest.json              config, its hash, seeds, versions, git commit
    runs.parquet               one row per run (parameters, metrics, status, reason, timing)
    runs/<case_id>.parquet     the rows of one case, written atomically when the case ends
    trajectories/<case_id>.parquet   long table of the case's paths (analysis, start, step, ...)

A case counts as finished when its ``runs/`` file exists, so a sweep killed at any moment
resumes without losing or repeating a run; ``runs.parquet`` is rebuilt from those files at
the end of every sweep (:func:`consolidate`). Only the process holding the store's lock
writes to it; workers send each finished case back as encoded Parquet bytes. The readers
(:func:`store_status`, :func:`load_runs`, :func:`load_trajectories`) work while a sweep runs.
"""

from __future__ import annotations

import contextlib
import fcntl
import importlib.metadata
import json
import os
import re
import subprocess
import sys
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from spine_mj.atomic import atomic_output
from spine_mj.errors import SpineInputError
from spine_mj.jsonio import write_json
from spine_mj.sweep.cases import Case
from spine_mj.sweep.config import SweepConfig
from spine_mj.sweep.digests import input_digests
from spine_mj.sweep.registry import ANALYSES

MANIFEST = "manifest.json"
RUNS_TABLE = "runs.parquet"
RUNS_DIR = "runs"
TRAJ_DIR = "trajectories"
LOCK = ".sweep.lock"
#: What a store writes in its folder (folders end in "/": their case files and temporaries),
#: recorded in the manifest; --overwrite removes these and nothing else.
WRITTEN = (MANIFEST, RUNS_TABLE, f"{RUNS_DIR}/", f"{TRAJ_DIR}/")


def versions() -> dict:
    """Versions of Python and of the packages a sweep's numbers depend on."""
    out = {"python": sys.version.split()[0]}
    for pkg in ("spine_mj", "mujoco", "numpy", "pyarrow", "dask", "distributed"):
        try:
            out[pkg] = importlib.metadata.version(pkg)
        except importlib.metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def git_commit() -> dict:
    """``{"commit", "dirty"}`` of the checkout spine_mj runs from (None outside git)."""
    repo = Path(__file__).resolve().parents[2]
    try:
        commit = subprocess.run(
            ["git", "-C", str(repo), "rev-parse", "HEAD"],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
        dirty = (
            subprocess.run(
                ["git", "-C", str(repo), "status", "--porcelain", "--untracked-files=no"],
                capture_output=True,
                text=True,
                timeout=10,
                check=True,
            ).stdout.strip()
            != ""
        )
    except (OSError, subprocess.SubprocessError):
        return {"commit": None, "dirty": None}
    return {"commit": commit, "dirty": dirty}


def read_manifest(out_dir: Path) -> dict | None:
    """The manifest of the store in ``out_dir``, or None where there is none."""
    path = out_dir / MANIFEST
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SpineInputError(f"{path} is not a sweep manifest: {exc}") from None


def prepare_store(
    config: SweepConfig, cases: list[Case], out_dir: Path, *, overwrite: bool, session: dict
) -> dict:
    """Make ``out_dir`` the store of ``config`` (a new manifest, or the one of an earlier
    session of the same config and inputs, with ``session`` appended) and return its
    manifest. A store of another config or of changed inputs (surface files, presets) is
    replaced only with ``overwrite``, and then only the files the store wrote are removed;
    a folder holding anything else is refused."""
    manifest = read_manifest(out_dir)
    inputs = input_digests(config)
    if manifest is None and any(p.name != LOCK for p in out_dir.iterdir()):
        raise SpineInputError(
            f"--out {out_dir} exists, is not empty and holds no sweep manifest: use another "
            f"folder (--overwrite replaces only a sweep store)"
        )
    if manifest is not None:
        why = _mismatch(manifest, config, inputs, out_dir)
        if why and not overwrite:
            raise SpineInputError(f"{why}: use another folder or --overwrite to replace it")
        if why:
            _clear_store(out_dir)
            manifest = None
    if manifest is None:
        manifest = _new_manifest(config, cases, inputs, session)
    manifest.setdefault("inputs", inputs)
    manifest["sessions"].append(session)
    (out_dir / RUNS_DIR).mkdir(parents=True, exist_ok=True)
    (out_dir / TRAJ_DIR).mkdir(parents=True, exist_ok=True)
    write_json(out_dir / MANIFEST, manifest)
    return manifest


def _mismatch(manifest: dict, config: SweepConfig, inputs: dict, out_dir: Path) -> str:
    """Why the store in ``out_dir`` cannot be resumed with ``config`` ("" if it can)."""
    if manifest.get("config_hash") != config.hash:
        return (
            f"--out {out_dir} holds a sweep of another config ({manifest.get('name')!r}, "
            f"hash {str(manifest.get('config_hash'))[:12]}); this config has hash {config.hash[:12]}"
        )
    old = manifest.get("inputs")
    if old is None or old == inputs:  # a store from before inputs were recorded: taken as is
        return ""
    changed = sorted(k for k in set(old) | set(inputs) if old.get(k) != inputs.get(k))
    return (
        f"--out {out_dir} holds a sweep of this config computed on other inputs: "
        f"{', '.join(changed)} changed since (resuming would mix old and new results)"
    )


def _new_manifest(config: SweepConfig, cases: list[Case], inputs: dict, session: dict) -> dict:
    return {
        "format": "spine_mj-sweep/1",
        "name": config.name,
        "config_hash": config.hash,
        "config": config.as_dict(),
        "config_source": config.source,
        "inputs": inputs,
        "written": list(WRITTEN),
        "seeds": {
            "master": config.seed,
            "surfaces": {s.label: s.seed for s in config.surfaces},
        },
        "n_cases": len(cases),
        "n_runs": sum(c.starts.count for c in cases) * len(config.analyses),
        "swept": list(config.swept),
        "versions": versions(),
        "git": git_commit(),
        "created": session["started"],
        "sessions": [],
    }


_CASE_FILE = re.compile(r"^[0-9a-f]{16}\.parquet$")


def _clear_store(out_dir: Path) -> None:
    """Remove what the store wrote (its manifest, run table, case files and their
    temporaries); any other file in the folder stays."""
    for sub in (w.rstrip("/") for w in WRITTEN if w.endswith("/")):
        folder = out_dir / sub
        if not folder.is_dir():
            continue
        for p in folder.iterdir():
            if p.is_file() and (_CASE_FILE.match(p.name) or p.name.startswith(".")):
                p.unlink()
        with contextlib.suppress(OSError):
            folder.rmdir()  # only if nothing else is in it
    for name in (w for w in WRITTEN if not w.endswith("/")):
        (out_dir / name).unlink(missing_ok=True)


def _case_files(out_dir: Path) -> list[Path]:
    """Finished cases' files (a kill can leave hidden temporary files; they do not count)."""
    return sorted(p for p in (out_dir / RUNS_DIR).glob("*.parquet") if not p.name.startswith("."))


def finished_cases(out_dir: Path) -> set[str]:
    """Ids of the cases whose rows are in the store."""
    return {p.stem for p in _case_files(out_dir)}


def _read(path: Path, **kwargs):
    """A Parquet file of the store as a table, or None where it is unreadable (a disk
    that filled up, a copy cut short...)."""
    try:
        return pq.read_table(path, **kwargs)
    except (pa.ArrowException, OSError):
        return None


def corrupt_cases(out_dir: Path) -> list[str]:
    """Ids of the finished cases whose rows file cannot be read (its footer is checked)."""
    bad = []
    for f in _case_files(out_dir):
        try:
            pq.read_metadata(f)
        except (pa.ArrowException, OSError):
            bad.append(f.stem)
    return bad


def remove_temporaries(out_dir: Path) -> None:
    """Delete the temporary files a killed sweep may have left."""
    for sub in (RUNS_DIR, TRAJ_DIR):
        for p in (out_dir / sub).glob(".*"):
            p.unlink(missing_ok=True)


def encode_case(case_id: str, rows, traj) -> tuple:
    """A finished case as Parquet bytes: ``(case_id, statuses, rows file, trajectory file)``.

    Workers encode (the CPU-heavy part of writing) and send these few compressed bytes back;
    the process that owns the store only writes them (:func:`store_encoded`), so workers
    need no shared file system.
    """

    def encode(table, **kwargs) -> bytes:
        sink = pa.BufferOutputStream()
        pq.write_table(table, sink, **kwargs)
        return sink.getvalue().to_pybytes()

    traj_bytes = None if traj is None else encode(traj, row_group_size=65_536, use_dictionary=["analysis"])
    return case_id, rows["status"].to_pylist(), encode(rows), traj_bytes


def store_encoded(out_dir: Path, encoded: tuple) -> None:
    """Write a case encoded by :func:`encode_case`: its paths, then its rows (which mark it
    finished)."""
    case_id, _, rows_bytes, traj_bytes = encoded
    if traj_bytes is not None:
        with atomic_output(out_dir / TRAJ_DIR / f"{case_id}.parquet") as tmp:
            tmp.write_bytes(traj_bytes)
    with atomic_output(out_dir / RUNS_DIR / f"{case_id}.parquet") as tmp:  # written last: done
        tmp.write_bytes(rows_bytes)


def reopen_cases(out_dir: Path, case_ids) -> None:
    """Mark the cases ``case_ids`` unfinished (their rows leave the store)."""
    for cid in case_ids:
        (out_dir / RUNS_DIR / f"{cid}.parquet").unlink(missing_ok=True)


def consolidate(out_dir: str | os.PathLike):
    """Rebuild ``runs.parquet`` from the per-case files.

    Parameters
    ----------
    out_dir : str or os.PathLike
        The result store.

    Returns
    -------
    pyarrow.Table
        The run table, one row per run.
    """
    out_dir = Path(out_dir)
    tables = [t for t in (_read(f) for f in _case_files(out_dir)) if t is not None]
    if not tables:
        table = pa.table({c: pa.array([], pa.string()) for c in ("run_id", "status")})
    else:
        table = pa.concat_tables(tables, promote_options="permissive")
        rank = {name: i for i, name in enumerate(ANALYSES)}
        analysis_rank = np.array([rank.get(a, len(rank)) for a in table["analysis"].to_pylist()])
        order = np.lexsort((np.asarray(table["start"]), analysis_rank, np.asarray(table["case_index"])))
        table = table.take(pa.array(order))
    with atomic_output(out_dir / RUNS_TABLE) as tmp:
        pq.write_table(table, tmp)
    return table


_HELD: set[str] = set()
_HELD_GUARD = threading.Lock()


@contextlib.contextmanager
def store_lock(out_dir: Path):
    """Exclusive lock on the store for one sweep at a time.

    A POSIX record lock (``lockf``): it belongs to this process alone, so worker processes
    forked while it is held do not hold it, and the OS releases it the moment this process
    ends, however it ends; a resume after a kill starts at once. Record locks do not
    exclude within one process, so the stores locked here are also kept in a set.
    """
    key = str(out_dir.resolve())
    busy = SpineInputError(f"--out {out_dir}: another sweep is writing to it")
    with _HELD_GUARD:
        if key in _HELD:
            raise busy
        _HELD.add(key)
    created = not (out_dir / LOCK).exists()
    try:
        with open(out_dir / LOCK, "a") as fh:
            try:
                fcntl.lockf(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                raise busy from None
            try:
                yield
            finally:
                if created and not (out_dir / MANIFEST).exists():  # refused: leave the folder as it was
                    (out_dir / LOCK).unlink(missing_ok=True)
                fcntl.lockf(fh, fcntl.LOCK_UN)
    finally:
        with _HELD_GUARD:
            _HELD.discard(key)


@dataclass(frozen=True)
class StoreStatus:
    """State of a result store (see :func:`store_status`).

    Attributes
    ----------
    name, config_hash : str
    total_cases, finished_cases : int
    total_runs : int
    status_counts : dict of str to int
        Over the finished runs.
    sessions : int
        How many times the sweep was started on this store.
    created : str
    git_commit : str or None
    corrupt_cases : tuple of str
        Ids of the cases whose rows file cannot be read (not counted as finished; a resume
        runs them again).
    """

    name: str
    config_hash: str
    total_cases: int
    finished_cases: int
    total_runs: int
    status_counts: dict[str, int]
    sessions: int
    created: str
    git_commit: str | None
    corrupt_cases: tuple[str, ...] = ()

    @property
    def complete(self) -> bool:
        return self.finished_cases == self.total_cases


def store_status(out_dir: str | os.PathLike) -> StoreStatus:
    """Read the state of the store in ``out_dir`` (works while a sweep is running).

    Parameters
    ----------
    out_dir : str or os.PathLike
        The result store.

    Returns
    -------
    StoreStatus
        Cases and runs done, by status, and any truncated case files.
    """
    out_dir = Path(out_dir)
    manifest = read_manifest(out_dir)
    if manifest is None:
        raise SpineInputError(f"{out_dir} holds no sweep ({MANIFEST} not found)")
    counts: dict[str, int] = {}
    corrupt, n_good = [], 0
    for f in _case_files(out_dir):
        table = _read(f, columns=["status"])
        if table is None:
            corrupt.append(f.stem)
            continue
        n_good += 1
        for s in table["status"].to_pylist():
            counts[s] = counts.get(s, 0) + 1
    try:
        return StoreStatus(
            name=str(manifest["name"]),
            config_hash=str(manifest["config_hash"]),
            total_cases=int(manifest["n_cases"]),
            finished_cases=n_good,
            total_runs=int(manifest["n_runs"]),
            status_counts=counts,
            sessions=len(manifest.get("sessions", [])),
            created=str(manifest.get("created", "")),
            git_commit=(manifest.get("git") or {}).get("commit"),
            corrupt_cases=tuple(corrupt),
        )
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise SpineInputError(f"{out_dir / MANIFEST} is not a sweep manifest: {exc!r}") from None


def load_runs(out_dir: str | os.PathLike, *, columns: list[str] | None = None):
    """The run table of a store as a pandas DataFrame (rebuilt if the sweep is unfinished).

    Parameters
    ----------
    out_dir : str or os.PathLike
        The result store.
    columns : list of str, optional
        Only these columns.

    Returns
    -------
    pandas.DataFrame
        One row per run: the case's parameters, the analysis's metrics, ``status`` and
        ``reason``, timing.
    """
    out_dir = Path(out_dir)
    if read_manifest(out_dir) is None:
        raise SpineInputError(f"{out_dir} holds no sweep ({MANIFEST} not found)")
    path = out_dir / RUNS_TABLE
    ids = _read(path, columns=["case_id"]) if path.is_file() else None
    files = {f.stem for f in _case_files(out_dir)}
    table = None
    if ids is not None and set(ids["case_id"].to_pylist()) == files:
        table = _read(path)
    if table is None:
        table = consolidate(out_dir)
    if columns is not None:
        table = table.select(columns)
    return table.to_pandas()


def load_trajectories(
    out_dir: str | os.PathLike,
    case_id: str,
    *,
    analysis: str | None = None,
    start: int | None = None,
    columns: list[str] | None = None,
):
    """Paths of one case as a pandas DataFrame, reading only the rows and columns asked for.

    Parameters
    ----------
    out_dir : path
        The result store.
    case_id : str
        The case's id (``case_id`` in the run table).
    analysis : str, optional
        Only this analysis's paths.
    start : int, optional
        Only this start's path.
    columns : list of str, optional
        Columns to read (``analysis``, ``start``, ``step`` always come along).
    """
    path = Path(out_dir) / TRAJ_DIR / f"{case_id}.parquet"
    if not path.is_file():
        raise SpineInputError(f"no trajectories for case {case_id!r} in {out_dir}")
    filters = []
    if analysis is not None:
        filters.append(("analysis", "=", analysis))
    if start is not None:
        filters.append(("start", "=", int(start)))
    if columns is not None:
        columns = list(dict.fromkeys(["analysis", "start", "step", *columns]))
    try:
        table = pq.read_table(path, columns=columns, filters=filters or None)
    except (pa.ArrowException, OSError) as exc:
        raise SpineInputError(
            f"trajectories of case {case_id!r} in {out_dir} cannot be read: {exc}"
        ) from None
    return table.to_pandas()

"""Headless batch sweeps: a TOML config, cases, a resumable result store, local or Dask workers.

A sweep config names surfaces (presets or files, with seeds), start points, a parameter
grid and the analyses to run on every case::

    [sweep]
    name = "quasistatic-mu"
    seed = 0                          # master seed; each case derives its own
    analyses = ["quasistatic"]        # any of: quasistatic, mujoco, compare

    [[surfaces]]
    preset = "paper-random-convex"
    seeds = [1, 2, 3]                 # or seed = 1, or n_seeds = 3 (derived from the master seed)
    set = { n_peaks = 40 }            # generator overrides

    [[surfaces]]
    file = "scan.npz"                 # relative to the config file

    [starts]
    frame = "relative"                # or "absolute" (the surface's length unit)
    x = [0.05]                        # starts: product of x and y, or points = [[x, y], ...],
    y = { linspace = [0.1, 0.9], num = 9 }   # or random = N (uniform, from the case seed)

    [grid]
    mu = [0.3, 0.5, 0.8]              # a value, a list, or { linspace | logspace = [a, b], num = n }
    tip_radius = 0.0

A *case* is one surface instance and one point of the grid, with all its starts; its id is
a hash of those parameters, and its seed is derived from the master seed and that id, so a
case gives the same numbers whatever the order or the machine it runs on. A *run* is one
start of one case under one analysis: a row of the result table.

The store in the output folder::

    manifest.json              config, its hash, seeds, versions, git commit
    runs.parquet               one row per run (parameters, metrics, status, reason, timing)
    runs/<case_id>.parquet     the rows of one case, written atomically when the case ends
    trajectories/<case_id>.parquet   long table of the case's paths (analysis, start, step, ...)

A case counts as finished when its ``runs/`` file exists, so a sweep killed at any moment
resumes without losing or repeating a run; ``runs.parquet`` is rebuilt from those files at
the end of every sweep.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import functools
import hashlib
import importlib.metadata
import inspect
import itertools
import json
import math
import os
import subprocess
import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from spine_mj.errors import SpineInputError, atomic_output
from spine_mj.jsonio import to_jsonable, write_json

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = [
    "ANALYSES",
    "STATUSES",
    "Analysis",
    "AnalysisResult",
    "Case",
    "ParamSpec",
    "Progress",
    "StartsSpec",
    "StoreStatus",
    "SurfaceSpec",
    "SweepConfig",
    "SweepSummary",
    "expand_cases",
    "load_config",
    "load_runs",
    "load_trajectories",
    "parse_config",
    "register_analysis",
    "run_case",
    "run_sweep",
    "store_status",
    "write_report",
]

#: Row statuses. ``ok``; ``failed`` (an exception in the analysis); ``bad_surface`` (the
#: surface could not be made or loaded); ``diverged`` and ``engine_warning`` (MuJoCo);
#: ``dependency_failed`` (an analysis this one needs did not give a result for the start).
STATUSES = ("ok", "failed", "bad_surface", "diverged", "engine_warning", "dependency_failed")

MANIFEST = "manifest.json"
RUNS_TABLE = "runs.parquet"
RUNS_DIR = "runs"
TRAJ_DIR = "trajectories"
LOCK = ".sweep.lock"
_RESERVED = (
    "run_id",
    "case_id",
    "case_index",
    "analysis",
    "start",
    "start_x",
    "start_y",
    "surface",
    "surface_seed",
    "seed",
    "status",
    "reason",
    "time_s",
    "cpu_s",
)


# --------------------------------------------------------------------------- parameters


@dataclass(frozen=True)
class ParamSpec:
    """A sweepable parameter that an analysis reads from ``case.params``.

    Attributes
    ----------
    name : str
    kind : {"float", "int", "str", "bool"}
    doc : str
        One line: meaning and unit.
    default : Any
        Used when the config does not set it; ``REQUIRED`` makes the key mandatory.
    minimum : float, optional
        Lower bound (inclusive unless ``exclusive``).
    exclusive : bool
    choices : tuple of str, optional
        Allowed values of a ``str`` parameter.
    drive : bool
        May also be given in the ``[drive]`` table.
    """

    name: str
    kind: str
    doc: str
    default: Any = None
    minimum: float | None = None
    exclusive: bool = False
    choices: tuple[str, ...] | None = None
    drive: bool = False

    def expected(self) -> str:
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        what = {"float": "a finite number", "int": "an integer", "str": "a string", "bool": "true or false"}[
            self.kind
        ]
        if self.minimum is not None:
            what += f" {'>' if self.exclusive else '>='} {self.minimum:g}"
        return what

    def check(self, value, key: str):
        """``value`` converted to the parameter's type, or SpineInputError naming ``key``."""
        ok = False
        if self.kind == "float":
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            value = float(value) if ok else value
        elif self.kind == "int":
            ok = isinstance(value, int) and not isinstance(value, bool)
        elif self.kind == "str":
            ok = isinstance(value, str) and (not self.choices or value in self.choices)
        elif self.kind == "bool":
            ok = isinstance(value, bool)
        if ok and self.minimum is not None:
            ok = value > self.minimum if self.exclusive else value >= self.minimum
        if not ok:
            raise SpineInputError(
                f"config key {key}: must be {self.expected()} (or a list of them), got {value!r}"
            )
        return value


REQUIRED = object()


# --------------------------------------------------------------------------- analyses


@dataclass(frozen=True, eq=False)
class AnalysisResult:
    """What one analysis gives for one case.

    Attributes
    ----------
    metrics : dict of str to ndarray, each shape (n_starts,)
        Scalars per start (floats, ints or bools); stored as columns of the run table.
    trajectories : dict of str to ndarray, each shape (n_points,), optional
        Long table of paths; must contain ``start`` (int) and ``step`` (int).
    status, reason : ndarray of str, shape (n_starts,), optional
        Per-start status (see :data:`STATUSES`) and reason; None means all ``ok``.
    data : Any
        In-memory result for the analyses that depend on this one (not stored).
    """

    metrics: dict[str, np.ndarray]
    trajectories: dict[str, np.ndarray] | None = None
    status: np.ndarray | None = None
    reason: np.ndarray | None = None
    data: Any = None


@dataclass(frozen=True)
class Analysis:
    """A named analysis: ``func(case, surface, starts, upstream) -> AnalysisResult``.

    ``starts`` is ``(n_starts, 2)`` in the surface's length unit; ``upstream`` maps the
    names in ``requires`` to their results for the same case. ``check_config``, if given,
    is called with every validated config that chooses this analysis and raises
    SpineInputError for a combination of values its parameters cannot check one by one.
    """

    name: str
    func: Callable[..., AnalysisResult]
    parameters: tuple[ParamSpec, ...]
    requires: tuple[str, ...] = ()
    doc: str = ""
    check_config: Callable[[Any], None] | None = None


#: Registry of analyses by name; :func:`register_analysis` adds to it.
ANALYSES: dict[str, Analysis] = {}


def register_analysis(analysis: Analysis) -> Analysis:
    """Add ``analysis`` to :data:`ANALYSES` (replacing one of the same name)."""
    for spec in analysis.parameters:
        if spec.name in _RESERVED:
            raise SpineInputError(f"parameter name {spec.name!r} is reserved for the run table")
    ANALYSES[analysis.name] = analysis
    return analysis


def _param_specs(analyses: tuple[str, ...]) -> dict[str, ParamSpec]:
    specs: dict[str, ParamSpec] = {}
    for name in analyses:
        for spec in ANALYSES[name].parameters:
            specs.setdefault(spec.name, spec)
    return specs


# --------------------------------------------------------------------------- config


@dataclass(frozen=True)
class SurfaceSpec:
    """One surface instance: a preset (with seed and overrides) or a saved file.

    Attributes
    ----------
    kind : {"preset", "file"}
    source : str
        Preset name, or the absolute path of a .npz / instrument file.
    seed : int or None
        Generator seed (None: the preset's own).
    overrides : tuple of (str, value) pairs
        Generator parameters replacing the preset's.
    label : str
        Short name used in tables (``preset`` or file stem, ``#seed`` appended).
    """

    kind: str
    source: str
    seed: int | None = None
    overrides: tuple[tuple[str, Any], ...] = ()
    label: str = ""

    def as_dict(self) -> dict:
        return {
            "kind": self.kind,
            "source": self.source,
            "seed": self.seed,
            "overrides": {k: to_jsonable(v) for k, v in self.overrides},
        }

    def make(self):
        """Build the surface (cached per process)."""
        return _make_surface(self)


@dataclass(frozen=True)
class StartsSpec:
    """Start points of every case.

    Attributes
    ----------
    frame : {"relative", "absolute"}
        Relative coordinates are fractions of the surface's bounds (0 = xmin, 1 = xmax).
    points : tuple of (x, y), optional
        Explicit points; else the product of ``x`` and ``y``; else ``random`` uniform points
        drawn from the case seed.
    """

    frame: str = "relative"
    points: tuple[tuple[float, float], ...] | None = None
    x: tuple[float, ...] | None = None
    y: tuple[float, ...] | None = None
    random: int | None = None

    @property
    def count(self) -> int:
        if self.points is not None:
            return len(self.points)
        if self.random is not None:
            return self.random
        return len(self.x) * len(self.y)

    def as_dict(self) -> dict:
        return {k: to_jsonable(v) for k, v in dataclasses.asdict(self).items() if v is not None}

    def resolve(self, bounds, seed: int) -> np.ndarray:
        """Start points ``(n_starts, 2)`` in the surface's length unit."""
        if self.points is not None:
            pts = np.array(self.points, dtype=float)
        elif self.random is not None:
            pts = np.random.default_rng(seed).random((self.random, 2))
            if self.frame == "absolute":
                raise SpineInputError("random starts are drawn in the relative frame")
        else:
            gx, gy = np.meshgrid(self.x, self.y, indexing="ij")
            pts = np.column_stack([gx.ravel(), gy.ravel()])
        if self.frame == "relative" or self.random is not None:
            xmin, xmax, ymin, ymax = bounds
            pts = np.column_stack([xmin + pts[:, 0] * (xmax - xmin), ymin + pts[:, 1] * (ymax - ymin)])
        return pts


@dataclass(frozen=True)
class SweepConfig:
    """A validated sweep config (see the module docstring for the TOML form).

    Attributes
    ----------
    name : str
    seed : int
        Master seed.
    analyses : tuple of str
        In run order (dependencies first).
    surfaces : tuple of SurfaceSpec
    starts : StartsSpec
    grid : tuple of (str, tuple of values)
        Every parameter of the chosen analyses with its value list (defaults filled in).
    store_trajectories : bool
    starts_by_surface : tuple of (int, StartsSpec)
        Per-surface starts replacing ``starts`` (index into ``surfaces`` before seeds).
    source : str
        Path of the TOML file ("" when parsed from a dict).
    """

    name: str
    seed: int
    analyses: tuple[str, ...]
    surfaces: tuple[SurfaceSpec, ...]
    starts: StartsSpec
    grid: tuple[tuple[str, tuple], ...]
    store_trajectories: bool = True
    surface_starts: tuple[StartsSpec | None, ...] = ()
    source: str = ""

    @property
    def swept(self) -> tuple[str, ...]:
        """Names of the parameters with more than one value."""
        return tuple(k for k, v in self.grid if len(v) > 1)

    def as_dict(self) -> dict:
        """The normalized config (what the hash covers)."""
        return {
            "name": self.name,
            "seed": self.seed,
            "analyses": list(self.analyses),
            "surfaces": [s.as_dict() for s in self.surfaces],
            "starts": self.starts.as_dict(),
            "surface_starts": [None if s is None else s.as_dict() for s in self.surface_starts],
            "grid": {k: [to_jsonable(v) for v in vals] for k, vals in self.grid},
            "store_trajectories": self.store_trajectories,
        }

    @property
    def hash(self) -> str:
        """sha256 of the normalized config (comments and key order do not matter)."""
        return _digest(self.as_dict())


def load_config(path: str | os.PathLike) -> SweepConfig:
    """Read and validate a sweep config TOML file.

    Raises
    ------
    SpineInputError
        Unreadable TOML, unknown keys or analyses, bad values: the message names the key,
        the allowed values and what arrived.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise SpineInputError(f"config file not found: {path}") from None
    except (IsADirectoryError, UnicodeDecodeError) as exc:
        raise SpineInputError(f"config {path} cannot be read: {exc}") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpineInputError(f"config {path} is not valid TOML: {exc}") from None
    return dataclasses.replace(parse_config(doc, base_dir=path.resolve().parent), source=str(path))


def parse_config(doc: Mapping, *, base_dir: str | os.PathLike = ".") -> SweepConfig:
    """Validate a config given as a dict (the parsed TOML); relative file paths are taken
    from ``base_dir``. See :func:`load_config`."""
    from spine_mj import presets

    doc = dict(doc)
    _allowed_keys(doc, "", ("sweep", "surfaces", "starts", "grid", "drive"))
    sweep = _table(doc, "sweep")
    _allowed_keys(sweep, "sweep", ("name", "seed", "analyses", "store_trajectories"))
    name = sweep.get("name", "sweep")
    if not isinstance(name, str) or not name:
        raise SpineInputError(f"config key sweep.name: must be a non-empty string, got {name!r}")
    seed = sweep.get("seed", 0)
    _check_seed(seed, "sweep.seed")
    store = sweep.get("store_trajectories", True)
    if not isinstance(store, bool):
        raise SpineInputError(f"config key sweep.store_trajectories: must be true or false, got {store!r}")
    analyses = sweep.get("analyses", ["quasistatic"])
    if isinstance(analyses, str):
        analyses = [analyses]
    if not isinstance(analyses, list) or not analyses:
        raise SpineInputError(
            f"config key sweep.analyses: must be a non-empty list of {_names(ANALYSES)}, got {analyses!r}"
        )
    for a in analyses:
        if a not in ANALYSES:
            raise SpineInputError(
                f"config key sweep.analyses: allowed values are {_names(ANALYSES)}, got {a!r}"
            )
    if len(set(analyses)) != len(analyses):
        raise SpineInputError(f"config key sweep.analyses: each analysis once, got {analyses!r}")
    for a in analyses:
        missing = [r for r in ANALYSES[a].requires if r not in analyses]
        if missing:
            raise SpineInputError(
                f"config key sweep.analyses: {a!r} needs {missing} as well, got {analyses!r}"
            )
    order = tuple(a for a in ANALYSES if a in analyses)

    raw_surfaces = doc.get("surfaces")
    if not isinstance(raw_surfaces, list) or not raw_surfaces:
        raise SpineInputError(
            "config key surfaces: must be a non-empty array of tables "
            "([[surfaces]] with preset = ... or file = ...), got "
            f"{raw_surfaces!r}"
        )
    base_dir = Path(base_dir)
    surfaces_, per_surface = [], []
    for i, entry in enumerate(raw_surfaces):
        key = f"surfaces[{i}]"
        if not isinstance(entry, dict):
            raise SpineInputError(f"config key {key}: must be a table, got {entry!r}")
        _allowed_keys(entry, key, ("preset", "file", "seed", "seeds", "n_seeds", "set", "starts"))
        if ("preset" in entry) == ("file" in entry):
            raise SpineInputError(
                f"config key {key}: give exactly one of preset or file, got {sorted(entry)}"
            )
        n_seed_keys = sum(k in entry for k in ("seed", "seeds", "n_seeds"))
        if n_seed_keys > 1:
            raise SpineInputError(f"config key {key}: give at most one of seed, seeds, n_seeds")
        overrides = entry.get("set", {})
        if not isinstance(overrides, dict):
            raise SpineInputError(
                f"config key {key}.set: must be a table of generator parameters, got {overrides!r}"
            )
        if "preset" in entry:
            preset_name = entry["preset"]
            if not isinstance(preset_name, str) or preset_name not in presets.list_presets():
                raise SpineInputError(
                    f"config key {key}.preset: allowed values are "
                    f"{', '.join(presets.list_presets())}, got {preset_name!r}"
                )
            preset = presets.load_preset(preset_name)
            try:
                presets._check_params(preset.generator, overrides, f"config key {key}.set")
            except SpineInputError as exc:
                raise SpineInputError(str(exc)) from None
            kind, source = "preset", preset_name
            takes_seed = "rng" in inspect.signature(presets.GENERATORS[preset.generator]).parameters
        else:
            if overrides:
                raise SpineInputError(
                    f"config key {key}.set: only presets take generator overrides, got {sorted(overrides)}"
                )
            file = entry["file"]
            if not isinstance(file, str):
                raise SpineInputError(f"config key {key}.file: must be a path, got {file!r}")
            path = (base_dir / file).resolve()
            if not path.is_file():
                raise SpineInputError(f"config key {key}.file: no such file {str(path)!r}")
            kind, source, takes_seed = "file", str(path), False
        if n_seed_keys and not takes_seed:
            raise SpineInputError(
                f"config key {key}: {source!r} takes no seed, got "
                f"{[k for k in ('seed', 'seeds', 'n_seeds') if k in entry]}"
            )
        seeds: list[int | None]
        if "seed" in entry:
            _check_seed(entry["seed"], f"{key}.seed")
            seeds = [entry["seed"]]
        elif "seeds" in entry:
            seeds = entry["seeds"]
            if not isinstance(seeds, list) or not seeds:
                raise SpineInputError(
                    f"config key {key}.seeds: must be a non-empty list of "
                    f"non-negative integers, got {seeds!r}"
                )
            for s in seeds:
                _check_seed(s, f"{key}.seeds")
            if len(set(seeds)) != len(seeds):
                raise SpineInputError(f"config key {key}.seeds: repeated seed in {seeds!r}")
        elif "n_seeds" in entry:
            n = entry["n_seeds"]
            if not isinstance(n, int) or isinstance(n, bool) or n < 1:
                raise SpineInputError(f"config key {key}.n_seeds: must be an integer >= 1, got {n!r}")
            seeds = [int(s) for s in np.random.SeedSequence([seed, i]).generate_state(n) >> 1]
        else:
            seeds = [None]
        starts_i = _parse_starts(entry["starts"], f"{key}.starts") if "starts" in entry else None
        frozen = tuple(sorted((k, _freeze(v)) for k, v in overrides.items()))
        stem = source if kind == "preset" else Path(source).stem
        for s in seeds:
            surfaces_.append(
                SurfaceSpec(
                    kind=kind,
                    source=source,
                    seed=s,
                    overrides=frozen,
                    label=stem if s is None else f"{stem}#{s}",
                )
            )
            per_surface.append(starts_i)

    if "starts" not in doc and any(s is None for s in per_surface):
        raise SpineInputError(
            "config key starts: required (a [starts] table, or starts in every [[surfaces]] entry)"
        )
    starts = (
        _parse_starts(doc["starts"], "starts")
        if "starts" in doc
        else StartsSpec(frame="relative", points=((0.0, 0.0),))
    )

    specs = _param_specs(order)
    grid_doc = _table(doc, "grid")
    drive_doc = _table(doc, "drive")
    for key in grid_doc:
        if key not in specs:
            raise SpineInputError(
                f"config key grid.{key}: unknown parameter for analyses "
                f"{list(order)}; allowed: {', '.join(sorted(specs))}"
            )
    drive_keys = sorted(k for k, s in specs.items() if s.drive)
    for key in drive_doc:
        if key not in specs or not specs[key].drive:
            raise SpineInputError(
                f"config key drive.{key}: unknown drive parameter for "
                f"analyses {list(order)}; allowed: "
                f"{', '.join(drive_keys) or 'none'}"
            )
        if key in grid_doc:
            raise SpineInputError(f"config key drive.{key}: also given as grid.{key}; give it once")
    values = {**grid_doc, **drive_doc}
    grid = []
    for pname, spec in specs.items():
        key = ("drive." if pname in drive_doc else "grid.") + pname
        if pname in values:
            vals = _expand_values(values[pname], key)
            vals = tuple(spec.check(v, key) for v in vals)
            if len(set(vals)) != len(vals):
                raise SpineInputError(f"config key {key}: repeated value in {list(vals)!r}")
        elif spec.default is REQUIRED:
            raise SpineInputError(
                f"config key grid.{pname}: required by analyses "
                f"{list(order)} ({spec.doc}); must be {spec.expected()}"
            )
        else:
            vals = (spec.default,)
        grid.append((pname, vals))
    config = SweepConfig(
        name=name,
        seed=seed,
        analyses=order,
        surfaces=tuple(surfaces_),
        starts=starts,
        grid=tuple(grid),
        store_trajectories=store,
        surface_starts=tuple(per_surface),
    )
    for a in order:
        if ANALYSES[a].check_config is not None:
            ANALYSES[a].check_config(config)
    return config


def _parse_starts(doc, key: str) -> StartsSpec:
    if not isinstance(doc, dict):
        raise SpineInputError(f"config key {key}: must be a table, got {doc!r}")
    _allowed_keys(doc, key, ("frame", "points", "x", "y", "random"))
    frame = doc.get("frame", "relative")
    if frame not in ("relative", "absolute"):
        raise SpineInputError(
            f"config key {key}.frame: allowed values are 'relative', 'absolute', got {frame!r}"
        )
    modes = [m for m in ("points", "x", "random") if m in doc]
    if "y" in doc and "x" not in doc:
        modes.append("y")
    if len(modes) != 1:
        raise SpineInputError(
            f"config key {key}: give exactly one of points, x and y, or random, got {sorted(doc)}"
        )
    lo_hi = "in [0, 1]" if frame == "relative" else "finite"

    def coord(v, k):
        if (
            isinstance(v, bool)
            or not isinstance(v, (int, float))
            or not math.isfinite(v)
            or (frame == "relative" and not 0 <= v <= 1)
        ):
            raise SpineInputError(f"config key {k}: coordinates must be numbers {lo_hi}, got {v!r}")
        return float(v)

    if "points" in doc:
        pts = doc["points"]
        if not isinstance(pts, list) or not pts or not all(isinstance(p, list) and len(p) == 2 for p in pts):
            raise SpineInputError(
                f"config key {key}.points: must be a non-empty list of [x, y] pairs, got {pts!r}"
            )
        return StartsSpec(
            frame=frame,
            points=tuple((coord(p[0], f"{key}.points"), coord(p[1], f"{key}.points")) for p in pts),
        )
    if "random" in doc:
        n = doc["random"]
        if not isinstance(n, int) or isinstance(n, bool) or n < 1:
            raise SpineInputError(f"config key {key}.random: must be an integer >= 1, got {n!r}")
        if frame != "relative":
            raise SpineInputError(
                f"config key {key}.frame: random starts need frame = 'relative', got {frame!r}"
            )
        return StartsSpec(frame=frame, random=n)
    if "y" not in doc:
        raise SpineInputError(f"config key {key}.y: required with {key}.x")
    xs = tuple(coord(v, f"{key}.x") for v in _expand_values(doc["x"], f"{key}.x"))
    ys = tuple(coord(v, f"{key}.y") for v in _expand_values(doc["y"], f"{key}.y"))
    return StartsSpec(frame=frame, x=xs, y=ys)


def _expand_values(value, key: str) -> list:
    """A scalar, a list, or ``{linspace|logspace = [a, b], num = n}`` as a list."""
    if isinstance(value, list):
        if not value:
            raise SpineInputError(f"config key {key}: empty list")
        return value
    if isinstance(value, dict):
        kinds = [k for k in ("linspace", "logspace") if k in value]
        extra = sorted(set(value) - {"linspace", "logspace", "num"})
        if len(kinds) != 1 or extra or "num" not in value:
            raise SpineInputError(
                f"config key {key}: a table must be {{linspace = [a, b], "
                f"num = n}} or {{logspace = [a, b], num = n}}, got {value!r}"
            )
        ends, num = value[kinds[0]], value["num"]
        if (
            not isinstance(ends, list)
            or len(ends) != 2
            or not all(
                isinstance(e, (int, float)) and not isinstance(e, bool) and math.isfinite(e) for e in ends
            )
        ):
            raise SpineInputError(
                f"config key {key}.{kinds[0]}: must be [a, b] (finite end values), got {ends!r}"
            )
        if not isinstance(num, int) or isinstance(num, bool) or num < 1:
            raise SpineInputError(f"config key {key}.num: must be an integer >= 1, got {num!r}")
        if kinds[0] == "logspace":
            if min(ends) <= 0:
                raise SpineInputError(
                    f"config key {key}.logspace: end values must be > 0 "
                    f"(they are values, not exponents), got {ends!r}"
                )
            return [float(v) for v in np.geomspace(ends[0], ends[1], num)]
        return [float(v) for v in np.linspace(ends[0], ends[1], num)]
    return [value]


def _allowed_keys(doc: Mapping, where: str, allowed: tuple[str, ...]) -> None:
    for key in doc:
        if key not in allowed:
            name = f"{where}.{key}" if where else key
            raise SpineInputError(
                f"config key {name}: unknown; allowed keys"
                f"{' in ' + where if where else ''}: {', '.join(allowed)}"
            )


def _table(doc: Mapping, key: str) -> dict:
    value = doc.get(key, {})
    if not isinstance(value, dict):
        raise SpineInputError(f"config key {key}: must be a table, got {value!r}")
    return value


def _check_seed(value, key: str) -> None:
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise SpineInputError(f"config key {key}: must be a non-negative integer, got {value!r}")


def _names(mapping) -> str:
    return ", ".join(repr(k) for k in sorted(mapping))


def _freeze(value):
    if isinstance(value, list):
        return tuple(_freeze(v) for v in value)
    if isinstance(value, dict):
        return tuple(sorted((k, _freeze(v)) for k, v in value.items()))
    return value


def _digest(obj) -> str:
    text = json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()


# --------------------------------------------------------------------------- cases


@dataclass(frozen=True)
class Case:
    """One surface instance at one point of the grid, with all its starts.

    Attributes
    ----------
    case_id : str
        16 hex digits of the sha256 of ``surface``, ``starts`` and ``params``.
    index : int
        Position in the expansion (for ordering tables).
    surface : SurfaceSpec
    starts : StartsSpec
    params : dict
        Every parameter of the sweep's analyses (one value each).
    seed : int
        Derived from the master seed and ``case_id``: the only randomness of the case.
    analyses : tuple of str
    store_trajectories : bool
    """

    case_id: str
    index: int
    surface: SurfaceSpec
    starts: StartsSpec
    params: dict = field(hash=False)
    seed: int = 0
    analyses: tuple[str, ...] = ()
    store_trajectories: bool = True


def expand_cases(config: SweepConfig) -> list[Case]:
    """The cases of ``config``: surfaces x grid (product of all parameter lists), in order.

    Raises
    ------
    SpineInputError
        When two cases have the same parameters.
    """
    names = [k for k, _ in config.grid]
    combos = list(itertools.product(*(v for _, v in config.grid)))
    cases, seen = [], set()
    for si, surf in enumerate(config.surfaces):
        starts = (
            config.surface_starts[si]
            if (si < len(config.surface_starts) and config.surface_starts[si] is not None)
            else config.starts
        )
        for combo in combos:
            params = dict(zip(names, combo))
            case_id = _digest(
                {
                    "surface": surf.as_dict(),
                    "starts": starts.as_dict(),
                    "params": {k: to_jsonable(v) for k, v in params.items()},
                }
            )[:16]
            if case_id in seen:
                raise SpineInputError(
                    f"config produces the same case twice (surface {surf.label}, parameters {params})"
                )
            seen.add(case_id)
            case_seed = int(
                np.random.SeedSequence([config.seed, int(case_id, 16)]).generate_state(1, np.uint64)[0]
                >> np.uint64(1)
            )
            cases.append(
                Case(
                    case_id=case_id,
                    index=len(cases),
                    surface=surf,
                    starts=starts,
                    params=params,
                    seed=case_seed,
                    analyses=config.analyses,
                    store_trajectories=config.store_trajectories,
                )
            )
    return cases


@functools.lru_cache(maxsize=8)
def _make_surface(spec: SurfaceSpec):
    from spine_mj import presets, surface_io

    if spec.kind == "file":
        path = Path(spec.source)
        if path.suffix == ".npz":
            return surface_io.load_surface(path)
        return surface_io.import_topography(path)
    overrides = {k: _thaw(v) for k, v in spec.overrides}
    if spec.seed is not None:
        overrides["seed"] = spec.seed
    return presets.make_surface(spec.source, **overrides)


def _thaw(value):
    if isinstance(value, tuple):
        if value and all(isinstance(v, tuple) and len(v) == 2 and isinstance(v[0], str) for v in value):
            return {k: _thaw(v) for k, v in value}
        return [_thaw(v) for v in value]
    return value


# --------------------------------------------------------------------------- one case


def run_case(case: Case) -> tuple[Any, Any]:
    """Run every analysis of ``case``; never raises for a failing analysis.

    Returns
    -------
    rows : pyarrow.Table
        One row per (analysis, start) with the columns of the run table.
    trajectories : pyarrow.Table or None
        Long table (``analysis``, ``start``, ``step``, ...) of the stored paths.
    """
    import pyarrow as pa

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
        cols = {
            "run_id": [f"{case.case_id}-{name}-{i}" for i in range(n)],
            "case_id": [case.case_id] * n,
            "case_index": np.full(n, case.index, np.int64),
            "analysis": [name] * n,
            "start": np.arange(n, dtype=np.int64),
            "start_x": starts[:, 0],
            "start_y": starts[:, 1],
            "surface": [case.surface.label] * n,
            "surface_seed": pa.array([case.surface.seed] * n, pa.int64()),
            "seed": np.full(n, case.seed, np.int64),
        }
        for k, v in case.params.items():
            cols[k] = pa.array([v] * n, _arrow_type(v))
        cols["status"] = list(status)
        cols["reason"] = list(reason)
        cols["time_s"] = np.full(n, elapsed / max(n, 1))
        cols["cpu_s"] = np.full(n, cpu / max(n, 1))
        for k, v in metrics.items():
            cols[k] = v
        rows.append(pa.table(cols))
    table = pa.concat_tables(rows, promote_options="permissive")
    traj = pa.concat_tables(trajs, promote_options="permissive") if trajs else None
    return table, traj


def _arrow_type(value):
    import pyarrow as pa

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
        if k in _RESERVED:
            raise RuntimeError(f"analysis {analysis} returned metric {k!r}, a reserved column")
        arr = np.asarray(v)
        if arr.ndim == 0:
            arr = np.full(n, arr[()])
        if arr.shape != (n,):
            raise RuntimeError(f"analysis {analysis}: metric {k!r} must have shape ({n},), got {arr.shape}")
        out[k] = arr
    return out


def _traj_table(traj: Mapping[str, np.ndarray], analysis: str):
    import pyarrow as pa

    cols = {k: np.asarray(v) for k, v in traj.items()}
    n = len(next(iter(cols.values())))
    return pa.table({"analysis": pa.repeat(pa.scalar(analysis, pa.string()), n), **cols})


# --------------------------------------------------------------------------- the store


@dataclass(frozen=True)
class Progress:
    """Progress of a running sweep, passed to the ``progress`` callback after each case.

    Attributes
    ----------
    total_cases, finished_cases, skipped_cases : int
        ``finished_cases`` counts cases finished in this session and ``skipped_cases`` those
        found done in the store.
    ok_runs, failed_runs : int
        Runs finished in this session with status ``ok`` / any other status.
    elapsed_s : float
    case_id : str or None
        The case that just finished.
    """

    total_cases: int
    finished_cases: int
    skipped_cases: int
    ok_runs: int
    failed_runs: int
    elapsed_s: float
    case_id: str | None = None


@dataclass(frozen=True)
class SweepSummary:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    out_dir : Path
    total_cases, run_cases, skipped_cases : int
    total_runs, ok_runs, failed_runs, skipped_runs : int
        Runs done now with status ok / other, and runs found finished in the store.
    elapsed_s : float
    workers : int or None
        Local worker processes (None for a Dask scheduler).
    status_counts : dict of str to int
        Whole store (including earlier sessions).
    """

    out_dir: Path
    total_cases: int
    run_cases: int
    skipped_cases: int
    total_runs: int
    ok_runs: int
    failed_runs: int
    skipped_runs: int
    elapsed_s: float
    workers: int | None
    status_counts: dict[str, int]


def _versions() -> dict:
    out = {"python": sys.version.split()[0]}
    for pkg in ("spine_mj", "mujoco", "numpy", "pyarrow", "dask", "distributed"):
        try:
            out[pkg] = importlib.metadata.version(pkg)
        except importlib.metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def _git_commit() -> dict:
    repo = Path(__file__).resolve().parent.parent
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


def _read_manifest(out_dir: Path) -> dict | None:
    path = out_dir / MANIFEST
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SpineInputError(f"{path} is not a sweep manifest: {exc}") from None


def _prepare_store(
    config: SweepConfig, cases: list[Case], out_dir: Path, *, overwrite: bool, session: dict
) -> dict:
    manifest = _read_manifest(out_dir)
    if manifest is not None and manifest.get("config_hash") != config.hash:
        if not overwrite:
            raise SpineInputError(
                f"--out {out_dir} holds a sweep of another config ({manifest.get('name')!r}, "
                f"hash {str(manifest.get('config_hash'))[:12]}); this config has hash "
                f"{config.hash[:12]}: use another folder or --overwrite to replace it"
            )
        _clear_store(out_dir)
        manifest = None
    elif manifest is None and any(p.name != LOCK for p in out_dir.iterdir()):
        if not overwrite:
            raise SpineInputError(
                f"--out {out_dir} exists, is not empty and holds no sweep "
                f"manifest: use another folder or --overwrite"
            )
        _clear_store(out_dir)
    if manifest is None:
        manifest = {
            "format": "spine_mj-sweep/1",
            "name": config.name,
            "config_hash": config.hash,
            "config": config.as_dict(),
            "config_source": config.source,
            "seeds": {
                "master": config.seed,
                "surfaces": {s.label: s.seed for s in config.surfaces},
            },
            "n_cases": len(cases),
            "n_runs": sum(c.starts.count for c in cases) * len(config.analyses),
            "swept": list(config.swept),
            "versions": _versions(),
            "git": _git_commit(),
            "created": session["started"],
            "sessions": [],
        }
    manifest["sessions"].append(session)
    (out_dir / RUNS_DIR).mkdir(parents=True, exist_ok=True)
    (out_dir / TRAJ_DIR).mkdir(parents=True, exist_ok=True)
    write_json(out_dir / MANIFEST, manifest)
    return manifest


def _clear_store(out_dir: Path) -> None:
    import shutil

    for name in (RUNS_DIR, TRAJ_DIR):
        if (out_dir / name).is_dir():
            shutil.rmtree(out_dir / name)
    for name in (MANIFEST, RUNS_TABLE, "report.html"):
        if (out_dir / name).is_file():
            (out_dir / name).unlink()
    for p in out_dir.iterdir():
        if p.is_file() and p.name.startswith(".") and p.name != LOCK:
            p.unlink()


def _case_files(out_dir: Path) -> list[Path]:
    """Finished cases' files (a kill can leave hidden temporary files; they do not count)."""
    return sorted(p for p in (out_dir / RUNS_DIR).glob("*.parquet") if not p.name.startswith("."))


def _finished(out_dir: Path) -> set[str]:
    return {p.stem for p in _case_files(out_dir)}


def _remove_temporaries(out_dir: Path) -> None:
    for sub in (RUNS_DIR, TRAJ_DIR):
        for p in (out_dir / sub).glob(".*"):
            p.unlink(missing_ok=True)


def _store_case(out_dir: Path, case_id: str, rows, traj) -> None:
    _store_encoded(out_dir, _encode_case(case_id, rows, traj))


def _encode_case(case_id: str, rows, traj) -> tuple:
    """A finished case as Parquet bytes: ``(case_id, statuses, rows file, trajectory file)``.

    Workers encode (the CPU-heavy part of writing) and send these few compressed bytes back;
    the process that owns the store only writes them (:func:`_store_encoded`), so workers
    need no shared file system.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    def encode(table, **kwargs) -> bytes:
        sink = pa.BufferOutputStream()
        pq.write_table(table, sink, **kwargs)
        return sink.getvalue().to_pybytes()

    traj_bytes = None if traj is None else encode(traj, row_group_size=65_536, use_dictionary=["analysis"])
    return case_id, rows["status"].to_pylist(), encode(rows), traj_bytes


def _store_encoded(out_dir: Path, encoded: tuple) -> None:
    case_id, _, rows_bytes, traj_bytes = encoded
    if traj_bytes is not None:
        with atomic_output(out_dir / TRAJ_DIR / f"{case_id}.parquet") as tmp:
            tmp.write_bytes(traj_bytes)
    with atomic_output(out_dir / RUNS_DIR / f"{case_id}.parquet") as tmp:  # written last: done
        tmp.write_bytes(rows_bytes)


def consolidate(out_dir: str | os.PathLike):
    """Rebuild ``runs.parquet`` from the per-case files; returns the table (pyarrow)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    out_dir = Path(out_dir)
    tables = [pq.read_table(f) for f in _case_files(out_dir)]
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


def run_sweep(
    config: SweepConfig | str | os.PathLike,
    out_dir: str | os.PathLike,
    *,
    workers: int | None = None,
    scheduler=None,
    overwrite: bool = False,
    retry_failed: bool = False,
    progress: Callable[[Progress], None] | None = None,
) -> SweepSummary:
    """Run (or resume) a sweep into ``out_dir``.

    Parameters
    ----------
    config : SweepConfig or path
        A validated config, or the path of its TOML file.
    out_dir : path
        The result store (created if missing). If it holds a sweep of the same config, the
        finished cases are skipped; of another config, SpineInputError unless ``overwrite``.
    workers : int, optional
        Local worker processes; default all cores (``os.cpu_count()``). 1 runs in this
        process. Ignored when ``scheduler`` is given.
    scheduler : str or distributed.Client, optional
        Address of a Dask distributed scheduler (``tcp://host:8786``) or a connected client:
        cases run on its workers, which need spine_mj installed. Results come back to this
        process, which writes the store, so workers need no shared file system (surface
        files named in the config must be readable by them, though).
    overwrite : bool
        Replace a store holding another config.
    retry_failed : bool
        Run again the finished cases that have a run with a status other than ``ok``.
    progress : callable, optional
        Called with a :class:`Progress` once after the skipped cases are counted and after
        every finished case.

    Returns
    -------
    SweepSummary
    """
    if not isinstance(config, SweepConfig):
        config = load_config(config)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SpineInputError(f"workers must be an integer >= 1, got {workers!r}")
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise SpineInputError(f"--out {out_dir} exists and is not a folder")
    cases = expand_cases(config)
    n_workers = None if scheduler is not None else (workers or os.cpu_count() or 1)
    session = {
        "started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "workers": n_workers,
        "scheduler": None if scheduler is None else str(getattr(scheduler, "scheduler", scheduler)),
        "versions": _versions(),
        "git": _git_commit(),
    }
    out_dir.mkdir(parents=True, exist_ok=True)
    with _store_lock(out_dir):
        return _run_locked(
            config,
            cases,
            out_dir,
            session,
            n_workers=n_workers,
            scheduler=scheduler,
            overwrite=overwrite,
            retry_failed=retry_failed,
            progress=progress,
        )


@contextlib.contextmanager
def _store_lock(out_dir: Path):
    """Exclusive lock on the store for one sweep at a time (released by the OS on a kill)."""
    import fcntl

    with open(out_dir / LOCK, "w") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise SpineInputError(f"--out {out_dir}: another sweep is writing to it") from None
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def _run_locked(
    config, cases, out_dir, session, *, n_workers, scheduler, overwrite, retry_failed, progress
) -> SweepSummary:
    _prepare_store(config, cases, out_dir, overwrite=overwrite, session=session)
    _remove_temporaries(out_dir)
    done = _finished(out_dir)
    if retry_failed and done:
        import pyarrow.compute as pc

        table = consolidate(out_dir)
        bad = set(table.filter(pc.not_equal(table["status"], "ok"))["case_id"].to_pylist())
        for cid in bad:
            (out_dir / RUNS_DIR / f"{cid}.parquet").unlink()
        done -= bad
    todo = [c for c in cases if c.case_id not in done]
    skipped = len(cases) - len(todo)
    skipped_runs = sum(c.starts.count for c in cases if c.case_id in done) * len(config.analyses)
    t0 = time.perf_counter()
    counts = {"finished": 0, "ok": 0, "failed": 0}

    def report(case_id):
        if progress is not None:
            progress(
                Progress(
                    total_cases=len(cases),
                    finished_cases=counts["finished"],
                    skipped_cases=skipped,
                    ok_runs=counts["ok"],
                    failed_runs=counts["failed"],
                    elapsed_s=time.perf_counter() - t0,
                    case_id=case_id,
                )
            )

    def handle(encoded):
        _store_encoded(out_dir, encoded)
        case_id, statuses = encoded[:2]
        ok = sum(1 for s in statuses if s == "ok")
        counts["finished"] += 1
        counts["ok"] += ok
        counts["failed"] += len(statuses) - ok
        report(case_id)

    report(None)
    if todo:
        if scheduler is not None:
            _run_dask(_longest_first(todo), scheduler, handle)
        elif n_workers == 1:
            _run_here(todo, handle)
        else:
            _run_processes(_longest_first(todo), n_workers, handle)
    table = consolidate(out_dir)
    status_counts = {}
    if table.num_rows:
        vals, cnt = np.unique(np.asarray(table["status"].to_pylist(), dtype=str), return_counts=True)
        status_counts = {str(v): int(c) for v, c in zip(vals, cnt)}
    return SweepSummary(
        out_dir=out_dir,
        total_cases=len(cases),
        run_cases=counts["finished"],
        skipped_cases=skipped,
        total_runs=sum(c.starts.count for c in cases) * len(config.analyses),
        ok_runs=counts["ok"],
        failed_runs=counts["failed"],
        skipped_runs=skipped_runs,
        elapsed_s=time.perf_counter() - t0,
        workers=n_workers,
        status_counts=status_counts,
    )


def _run_case_remote(case: Case):
    return _encode_case(case.case_id, *run_case(case))


def _run_here(todo: list[Case], handle) -> None:
    """One worker: the cases run in this process, in order; each case's store files are
    encoded and written on a helper thread while the next case runs (pyarrow releases the
    GIL), and handled here in order as they complete."""
    import concurrent.futures as cf

    with cf.ThreadPoolExecutor(max_workers=1) as writer:
        pending = None
        for case in todo:
            rows, traj = run_case(case)
            if pending is not None:
                handle(pending.result())
            pending = writer.submit(_encode_case, case.case_id, rows, traj)
        if pending is not None:
            handle(pending.result())


def _case_cost(case: Case) -> float:
    """A rough relative cost of a case, to start the longest cases first (the order of the
    cases changes no result). MuJoCo spring runs last ~ 1 / speed ~ I_e^-1/2."""
    p = case.params
    cost = 1.0
    if "mujoco" in case.analyses and p.get("protocol", "spring") == "spring":
        if p.get("duration") is not None:
            cost = float(p["duration"])
        elif p.get("speed") is not None:
            cost = 1.0 / float(p["speed"])
        else:
            cost = (1e-3 if p.get("ie") is None else float(p["ie"])) ** -0.5
    return cost * case.starts.count


def _longest_first(todo: list[Case]) -> list[Case]:
    return sorted(todo, key=lambda c: -_case_cost(c))  # stable: ties keep the config order


def _run_processes(todo: list[Case], n_workers: int, handle) -> None:
    # one BLAS thread per worker process (idle BLAS threads spinning in every worker cost a
    # third of the throughput on 2 cores); the worker server reads these when it starts
    saved = {k: os.environ.get(k) for k in _ONE_THREAD}
    for k in _ONE_THREAD:
        os.environ.setdefault(k, "1")
    try:
        _run_pool(todo, n_workers, handle)
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


_ONE_THREAD = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _run_pool(todo: list[Case], n_workers: int, handle) -> None:
    import concurrent.futures as cf
    import multiprocessing
    import threading

    if threading.active_count() == 1 and "fork" in multiprocessing.get_all_start_methods():
        # a single-threaded process forks safely, and its workers inherit every module it
        # has imported: no second start-up (about 1 s of imports on one core per pool)
        _preload_worker_modules()
        ctx = multiprocessing.get_context("fork")
    else:
        # with other threads alive a fork could copy a held lock: workers fork instead from
        # a server that has imported these once
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(list(_WORKER_MODULES))
    started = ctx.SimpleQueue()
    with cf.ProcessPoolExecutor(
        max_workers=n_workers, mp_context=ctx, initializer=_worker_started, initargs=(started,)
    ) as pool:
        futures = [pool.submit(_run_case_remote, c) for c in todo]
        try:
            # until the first worker is up (a fresh forkserver imports mujoco, numba,
            # pyarrow... on one core first), this process runs the shortest pending cases
            # itself; a case is taken only if its future could be cancelled: never twice
            for case, fut in zip(reversed(todo), reversed(futures)):
                if not started.empty() or not fut.cancel():
                    break
                handle(_encode_case(case.case_id, *run_case(case)))
            for fut in cf.as_completed([f for f in futures if not f.cancelled()]):
                handle(fut.result())
        except BaseException:
            for f in futures:
                f.cancel()
            raise


#: What a worker imports before its first case (pandas: pyarrow imports it when it builds a
#: table; mujoco: spine_mj.sim imports it lazily).
_WORKER_MODULES = (
    "spine_mj.sweep",
    "spine_mj.streamline",
    "spine_mj.sim",
    "pyarrow.parquet",
    "pandas",
    "mujoco",
    "mujoco.rollout",
)


def _preload_worker_modules() -> None:
    import importlib

    for name in _WORKER_MODULES:
        importlib.import_module(name)


def _worker_started(queue) -> None:
    queue.put(os.getpid())


def _run_dask(todo: list[Case], scheduler, handle) -> None:
    from distributed import Client, as_completed

    own = not isinstance(scheduler, Client)
    client = Client(scheduler) if own else scheduler
    try:
        futures = client.map(
            _run_case_remote,
            todo,
            pure=False,
            key=[f"spine-mj-case-{c.case_id}-{os.getpid()}-{time.monotonic_ns()}" for c in todo],
        )
        for fut in as_completed(futures):
            result = fut.result()
            fut.release()
            handle(result)
    finally:
        if own:
            client.close()


# --------------------------------------------------------------------------- reading


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

    @property
    def complete(self) -> bool:
        return self.finished_cases == self.total_cases


def store_status(out_dir: str | os.PathLike) -> StoreStatus:
    """Read the state of the store in ``out_dir`` (works while a sweep is running)."""
    import pyarrow.parquet as pq

    out_dir = Path(out_dir)
    manifest = _read_manifest(out_dir)
    if manifest is None:
        raise SpineInputError(f"{out_dir} holds no sweep ({MANIFEST} not found)")
    counts: dict[str, int] = {}
    files = _case_files(out_dir)
    for f in files:
        for s in pq.read_table(f, columns=["status"])["status"].to_pylist():
            counts[s] = counts.get(s, 0) + 1
    return StoreStatus(
        name=manifest["name"],
        config_hash=manifest["config_hash"],
        total_cases=manifest["n_cases"],
        finished_cases=len(files),
        total_runs=manifest["n_runs"],
        status_counts=counts,
        sessions=len(manifest.get("sessions", [])),
        created=manifest.get("created", ""),
        git_commit=manifest.get("git", {}).get("commit"),
    )


def load_runs(out_dir: str | os.PathLike, *, columns: list[str] | None = None):
    """The run table of a store as a pandas DataFrame (rebuilt if the sweep is unfinished)."""
    import pyarrow.parquet as pq

    out_dir = Path(out_dir)
    if _read_manifest(out_dir) is None:
        raise SpineInputError(f"{out_dir} holds no sweep ({MANIFEST} not found)")
    path = out_dir / RUNS_TABLE
    n_files = len(_case_files(out_dir))
    stale = (
        not path.is_file()
        or len(set(pq.read_table(path, columns=["case_id"])["case_id"].to_pylist())) != n_files
    )
    table = consolidate(out_dir) if stale else pq.read_table(path)
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
    case_id : str
    analysis : str, optional
        Only this analysis's paths.
    start : int, optional
        Only this start's path.
    columns : list of str, optional
        Columns to read (``analysis``, ``start``, ``step`` always come along).
    """
    import pyarrow.parquet as pq

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
    table = pq.read_table(path, columns=columns, filters=filters or None)
    return table.to_pandas()


def write_report(out_dir: str | os.PathLike, output: str | os.PathLike) -> Path:
    """Write an HTML report of the store: status counts, metric tables and plots of the
    metrics against the swept parameters (embedded PNGs). Returns the output path."""
    from spine_mj._sweep_report import write_report as _write

    return _write(Path(out_dir), Path(output))


# --------------------------------------------------------------------------- analyses

from spine_mj import _sweep_analyses  # noqa: E402,F401  (registers the built-in analyses)

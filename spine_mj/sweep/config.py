"""The sweep config: its TOML schema, validation and normalized form.

A config names surfaces (presets or files, with seeds), start points, a parameter grid and
the analyses to run on every case (see :mod:`spine_mj.sweep` for the TOML form). The keys
of the tables are declared here once; the parameters of [grid] and [drive], their types,
bounds, defaults and the whole-config checks come from the analyses' declarations in
:mod:`spine_mj.sweep.registry`. Every error is a SpineInputError naming the key, what is
allowed and what arrived. The normalized config (:meth:`SweepConfig.as_dict`) is what the
config hash, and so the resume of a store, covers.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import inspect
import json
import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from spine_mj import presets, surface_io
from spine_mj.errors import SpineInputError
from spine_mj.jsonio import to_jsonable
from spine_mj.sweep.registry import ANALYSES, PRESET_MU, REQUIRED, param_specs

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

_TOP_KEYS = ("sweep", "surfaces", "starts", "grid", "drive")
_SWEEP_KEYS = ("name", "seed", "analyses", "store_trajectories")
_SURFACE_KEYS = ("preset", "file", "seed", "seeds", "n_seeds", "set", "starts")
_STARTS_KEYS = ("frame", "points", "x", "y", "random")

#: Most cases and runs one config may expand to (checked before anything is allocated).
MAX_CASES = 1_000_000
MAX_RUNS = 10_000_000
#: Rough bytes of the run table per run, for the size in the message.
_BYTES_PER_RUN = 300


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
        """Build the surface (cached per process; a file's cache entry lasts while its size
        and modification time do)."""
        stamp = None
        if self.kind == "file":
            with contextlib.suppress(OSError):
                st = os.stat(self.source)
                stamp = (st.st_mtime_ns, st.st_size)
        return _make_surface(self, stamp)


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
        return digest(self.as_dict())


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
    doc = dict(doc)
    _allowed_keys(doc, "", _TOP_KEYS)
    name, seed, store, order = _parse_sweep_table(_table(doc, "sweep"))
    surfaces, per_surface = _parse_surfaces(doc.get("surfaces"), Path(base_dir), seed)
    if "starts" not in doc and any(s is None for s in per_surface):
        raise SpineInputError(
            "config key starts: required (a [starts] table, or starts in every [[surfaces]] entry)"
        )
    starts = (
        _parse_starts(doc["starts"], "starts")
        if "starts" in doc
        else StartsSpec(frame="relative", points=((0.0, 0.0),))
    )
    config = SweepConfig(
        name=name,
        seed=seed,
        analyses=order,
        surfaces=surfaces,
        starts=starts,
        grid=_parse_grid(_table(doc, "grid"), _table(doc, "drive"), order, surfaces),
        store_trajectories=store,
        surface_starts=per_surface,
    )
    check_size(config)
    for a in order:
        if ANALYSES[a].check_config is not None:
            ANALYSES[a].check_config(config)
    return config


def check_size(config: SweepConfig) -> None:
    """Refuse a config of more than :data:`MAX_CASES` cases or :data:`MAX_RUNS` runs,
    with its size, before any case is made."""
    points = math.prod(len(v) for _, v in config.grid)
    n_cases = len(config.surfaces) * points
    n_runs = 0
    for i, _ in enumerate(config.surfaces):
        own = config.surface_starts[i] if i < len(config.surface_starts) else None
        n_runs += (own or config.starts).count * points * len(config.analyses)
    if n_cases > MAX_CASES or n_runs > MAX_RUNS:
        raise SpineInputError(
            f"config expands to {n_cases:,} cases ({len(config.surfaces)} surfaces x {points:,} "
            f"grid points) and {n_runs:,} runs, a run table of about "
            f"{_human_bytes(n_runs * _BYTES_PER_RUN)}; the limit is {MAX_CASES:,} cases and "
            f"{MAX_RUNS:,} runs per sweep: split it into several sweeps"
        )


def _human_bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000:
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"


def _parse_sweep_table(sweep: dict) -> tuple[str, int, bool, tuple[str, ...]]:
    """``name, seed, store_trajectories, analyses`` (in run order) of the [sweep] table."""
    _allowed_keys(sweep, "sweep", _SWEEP_KEYS)
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
    return name, seed, store, tuple(a for a in ANALYSES if a in analyses)


def _parse_surfaces(
    raw_surfaces, base_dir: Path, master_seed: int
) -> tuple[tuple[SurfaceSpec, ...], tuple[StartsSpec | None, ...]]:
    """The surface instances of the [[surfaces]] entries (one per seed) and the starts of
    the entry each comes from (None: the [starts] table)."""
    if not isinstance(raw_surfaces, list) or not raw_surfaces:
        raise SpineInputError(
            "config key surfaces: must be a non-empty array of tables "
            "([[surfaces]] with preset = ... or file = ...), got "
            f"{raw_surfaces!r}"
        )
    surfaces, per_surface = [], []
    for i, entry in enumerate(raw_surfaces):
        key = f"surfaces[{i}]"
        if not isinstance(entry, dict):
            raise SpineInputError(f"config key {key}: must be a table, got {entry!r}")
        _allowed_keys(entry, key, _SURFACE_KEYS)
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
        kind, source, takes_seed = _surface_source(entry, key, overrides, base_dir)
        if n_seed_keys and not takes_seed:
            raise SpineInputError(
                f"config key {key}: {source!r} takes no seed, got "
                f"{[k for k in ('seed', 'seeds', 'n_seeds') if k in entry]}"
            )
        seeds = _surface_seeds(entry, key, master_seed, i)
        starts_i = _parse_starts(entry["starts"], f"{key}.starts") if "starts" in entry else None
        frozen = tuple(sorted((k, _freeze(v)) for k, v in overrides.items()))
        stem = source if kind == "preset" else Path(source).stem
        for s in seeds:
            surfaces.append(
                SurfaceSpec(
                    kind=kind,
                    source=source,
                    seed=s,
                    overrides=frozen,
                    label=stem if s is None else f"{stem}#{s}",
                )
            )
            per_surface.append(starts_i)
    return tuple(surfaces), tuple(per_surface)


def _surface_source(entry: dict, key: str, overrides: dict, base_dir: Path) -> tuple[str, str, bool]:
    """``kind, source, takes_seed`` of a [[surfaces]] entry (its preset or file checked)."""
    if "preset" in entry:
        preset_name = entry["preset"]
        if not isinstance(preset_name, str) or preset_name not in presets.list_presets():
            raise SpineInputError(
                f"config key {key}.preset: allowed values are "
                f"{', '.join(presets.list_presets())}, got {preset_name!r}"
            )
        preset = presets.load_preset(preset_name)
        try:
            presets.check_generator_params(preset.generator, overrides, f"config key {key}.set")
        except SpineInputError as exc:
            raise SpineInputError(str(exc)) from None
        takes_seed = "rng" in inspect.signature(presets.GENERATORS[preset.generator]).parameters
        return "preset", preset_name, takes_seed
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
    return "file", str(path), False


def _surface_seeds(entry: dict, key: str, master_seed: int, index: int) -> list[int | None]:
    """The generator seeds of a [[surfaces]] entry (``n_seeds``: derived from the master
    seed and the entry's index; none given: ``[None]``, the preset's own)."""
    if "seed" in entry:
        _check_seed(entry["seed"], f"{key}.seed")
        return [entry["seed"]]
    if "seeds" in entry:
        seeds = entry["seeds"]
        if not isinstance(seeds, list) or not seeds:
            raise SpineInputError(
                f"config key {key}.seeds: must be a non-empty list of non-negative integers, got {seeds!r}"
            )
        for s in seeds:
            _check_seed(s, f"{key}.seeds")
        if len(set(seeds)) != len(seeds):
            raise SpineInputError(f"config key {key}.seeds: repeated seed in {seeds!r}")
        return seeds
    if "n_seeds" in entry:
        n = entry["n_seeds"]
        if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_CASES:
            raise SpineInputError(
                f"config key {key}.n_seeds: must be an integer from 1 to {MAX_CASES:,}, got {n!r}"
            )
        return [int(s) for s in np.random.SeedSequence([master_seed, index]).generate_state(n) >> 1]
    return [None]


def _parse_grid(
    grid_doc: dict, drive_doc: dict, order: tuple[str, ...], surfaces: tuple[SurfaceSpec, ...]
) -> tuple[tuple[str, tuple], ...]:
    """Every parameter of the analyses ``order`` with its values from [grid] or [drive]
    (checked by its ParamSpec) or its default (None for :data:`PRESET_MU`: each case's
    preset's, filled in by :func:`spine_mj.sweep.cases.expand_cases`)."""
    specs = param_specs(order)
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
        elif spec.default is PRESET_MU:
            _check_preset_mu(surfaces, pname, spec, order)
            vals = (None,)
        else:
            vals = (spec.default,)
        grid.append((pname, vals))
    return tuple(grid)


def _check_preset_mu(surfaces, pname: str, spec, order) -> None:
    """Every surface must come from a preset with a calibrated mu when the config sets none."""
    lacking = sorted({s.label for s in surfaces if s.kind != "preset" or presets.preset_mu(s.source) is None})
    if lacking:
        raise SpineInputError(
            f"config key grid.{pname}: required by analyses {list(order)} ({spec.doc}) since "
            f"{', '.join(lacking)} has no calibrated mu; must be {spec.expected()}"
        )


def _parse_starts(doc, key: str) -> StartsSpec:
    if not isinstance(doc, dict):
        raise SpineInputError(f"config key {key}: must be a table, got {doc!r}")
    _allowed_keys(doc, key, _STARTS_KEYS)
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
        if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_RUNS:
            raise SpineInputError(
                f"config key {key}.random: must be an integer from 1 to {MAX_RUNS:,}, got {n!r}"
            )
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
        if not isinstance(num, int) or isinstance(num, bool) or not 1 <= num <= MAX_CASES:
            raise SpineInputError(
                f"config key {key}.num: must be an integer from 1 to {MAX_CASES:,}, got {num!r}"
            )
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


def input_digests(config: SweepConfig) -> dict[str, str]:
    """sha256 of every input of ``config`` beyond its text: the contents of each surface
    file, and the resolved preset (generator, parameters, seed, [engagement] and other
    tables; the contents of a measured preset's file). Keyed ``file:<path>`` /
    ``preset:<name>``; a store resumes only while these are unchanged."""
    out = {}
    for spec in config.surfaces:
        key = f"{spec.kind}:{spec.source}"
        if key in out:
            continue
        if spec.kind == "file":
            out[key] = _file_digest(Path(spec.source))
            continue
        preset = presets.load_preset(spec.source)
        resolved = {
            "generator": preset.generator,
            "params": to_jsonable(preset.params),
            "seed": preset.seed,
            "extras": to_jsonable(preset.extras),
        }
        measured = preset.params.get("file") if preset.generator == "measured" else None
        if isinstance(measured, str) and Path(measured).is_file():
            resolved["file_sha256"] = _file_digest(Path(measured))
        out[key] = digest(resolved)
    return out


def _file_digest(path: Path) -> str:
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except OSError as exc:
        raise SpineInputError(f"surface file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    return h.hexdigest()


def digest(obj) -> str:
    """sha256 (hex) of ``obj`` as canonical JSON (sorted keys): config hashes and case ids."""
    text = json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()


@functools.lru_cache(maxsize=8)
def _make_surface(spec: SurfaceSpec, stamp=None):
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

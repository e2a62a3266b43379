"""The sweep config: its TOML schema, validation and normalized form.

A config names surfaces (presets or files, with seeds), start points, a parameter grid and
the analyses to run on every case (see :mod:`spine_mj.sweep` for the TOML form). Its shape
is declared once, as frozen pydantic models that refuse undeclared keys: the tables here,
and [grid], [drive] and [array] (the array analysis's layout), built by
:func:`_parameters_model` from the analyses' parameter declarations in
:mod:`spine_mj.sweep.registry` (types, bounds, defaults). The checks that span tables
(defaults, the size, the analyses' own config checks) follow in :func:`parse_config`.
Every error is one SpineInputError line naming the key, what is allowed and what arrived
(:func:`~spine_mj.sweep.tables.validate_table`; the tables' base and value types are
:mod:`spine_mj.sweep.tables`'). The normalized config (:meth:`SweepConfig.as_dict`) is what
the config hash (:mod:`spine_mj.sweep.digests`), and so the resume of a store, covers.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import inspect
import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    Field,
    StrictBool,
    StrictStr,
    create_model,
    field_validator,
    model_validator,
)

from spine_mj import examples, presets
from spine_mj.errors import SpineInputError
from spine_mj.jsonio import to_jsonable
from spine_mj.sweep.digests import digest
from spine_mj.sweep.registry import ANALYSES, PRESET_MU, REQUIRED, ParamSpec, param_specs
from spine_mj.sweep.tables import (
    MAX_CASES,
    MAX_RUNS,
    Finite,
    Seed,
    Table,
    count_type,
    validate_table,
    value_list,
)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

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


class StartsSpec(Table):
    """Start points of every case: the [starts] table, or a [[surfaces]] entry's ``starts``.

    Attributes
    ----------
    frame : {"relative", "absolute"}
        Relative coordinates are fractions of the surface's bounds (0 = xmin, 1 = xmax);
        absolute ones are in the surface's length unit.
    points : tuple of (x, y), optional
        Explicit points; else the product of ``x`` and ``y`` (each a value, a list or a
        linspace/logspace table); else ``random`` uniform points (relative frame) drawn
        from the case seed. Exactly one of these is given.
    """

    frame: Literal["relative", "absolute"] = "relative"
    points: tuple[tuple[Finite, Finite], ...] | None = None
    x: value_list(Finite, "a finite number") | None = None
    y: value_list(Finite, "a finite number") | None = None
    random: count_type(MAX_RUNS) | None = None

    @model_validator(mode="before")
    def _one_kind(cls, data):
        if isinstance(data, Mapping):
            given = sorted(k for k, v in data.items() if v is not None)
            if sum(k in given for k in ("points", "x", "random")) != 1 or ("x" in given) != ("y" in given):
                raise ValueError(f"give exactly one of points, x and y, or random, got {given}")
        return data

    @field_validator("points", "x", "y")
    def _in_frame(cls, value, info):
        if not value:
            raise ValueError("must be a non-empty list of [x, y] pairs, got []")
        for c in np.ravel(value).tolist():
            if info.data.get("frame") == "relative" and not 0 <= c <= 1:
                raise ValueError(f"coordinates must be numbers in [0, 1] in the relative frame, got {c!r}")
        return value

    @field_validator("random")
    def _relative(cls, n, info):
        if info.data.get("frame") != "relative":
            raise ValueError(f"random starts need frame = 'relative', got frame = {info.data.get('frame')!r}")
        return n

    @property
    def count(self) -> int:
        if self.points is not None:
            return len(self.points)
        if self.random is not None:
            return self.random
        return len(self.x) * len(self.y)

    def as_dict(self) -> dict:
        return to_jsonable(self.model_dump(exclude_none=True))

    def resolve(self, bounds, seed: int) -> np.ndarray:
        """Start points ``(n_starts, 2)`` in the surface's length unit."""
        if self.points is not None:
            pts = np.array(self.points, dtype=float)
        elif self.random is not None:
            pts = np.random.default_rng(seed).random((self.random, 2))
        else:
            gx, gy = np.meshgrid(self.x, self.y, indexing="ij")
            pts = np.column_stack([gx.ravel(), gy.ravel()])
        if self.frame == "relative":
            xmin, xmax, ymin, ymax = bounds
            pts = np.column_stack([xmin + pts[:, 0] * (xmax - xmin), ymin + pts[:, 1] * (ymax - ymin)])
        return pts


class _SurfaceEntry(Table):
    """A [[surfaces]] entry: a preset, with one of ``seed``, ``seeds`` or ``n_seeds`` (that
    many, derived from the master seed) if its generator takes one and generator overrides
    ``set``; or a ``file`` (.npz or instrument), relative to the config. ``starts`` replaces
    the [starts] table for it."""

    preset: StrictStr | None = None
    file: StrictStr | None = None
    seed: Seed | None = None
    seeds: list[Seed] | None = Field(None, min_length=1)
    n_seeds: count_type(MAX_CASES) | None = None
    overrides: dict[str, Any] = Field({}, alias="set")
    starts: StartsSpec | None = None

    @model_validator(mode="before")
    def _one_source_one_seed_key(cls, data):
        if isinstance(data, Mapping):
            if ("preset" in data) == ("file" in data):
                raise ValueError(f"give exactly one of preset or file, got {sorted(data)}")
            if sum(k in data for k in ("seed", "seeds", "n_seeds")) > 1:
                raise ValueError(f"give at most one of seed, seeds, n_seeds, got {sorted(data)}")
        return data

    @field_validator("preset")
    def _known_preset(cls, name):
        if name not in presets.list_presets():
            raise ValueError(f"allowed values are {', '.join(presets.list_presets())}, got {name!r}")
        return name

    @field_validator("file")
    def _existing_file(cls, file, info):
        try:
            file = examples.resolve(file)  # example:NAME, a shipped scan
        except SpineInputError as exc:
            raise ValueError(str(exc)) from None
        path = (Path((info.context or {}).get("base_dir", ".")) / file).resolve()
        if not path.is_file():
            raise ValueError(f"no such file {str(path)!r}")
        return str(path)

    @field_validator("seeds")
    def _distinct_seeds(cls, seeds):
        if len(set(seeds)) != len(seeds):
            raise ValueError(f"repeated seed in {seeds!r}")
        return seeds

    @field_validator("overrides")
    def _generator_params(cls, overrides, info):
        """Names the generator takes, and values it accepts: the preset is made once here
        (with its own seed), so a bad value ends the config, not every case at run time."""
        if info.data.get("preset") is not None:
            generator = presets.load_preset(info.data["preset"]).generator
            presets.check_generator_params(generator, overrides, f"preset {info.data['preset']!r}")
            if overrides:
                presets.make_surface(info.data["preset"], **overrides)
        elif overrides:
            raise ValueError(f"only presets take generator overrides, got {sorted(overrides)}")
        return overrides

    @model_validator(mode="after")
    def _seed_only_if_taken(self):
        given = [k for k in ("seed", "seeds", "n_seeds") if getattr(self, k) is not None]
        generator = self.preset and presets.GENERATORS[presets.load_preset(self.preset).generator]
        takes = generator and "rng" in inspect.signature(generator).parameters
        if given and not takes:
            raise ValueError(f"{self.preset or Path(self.file).name!r} takes no seed, got {given}")
        return self

    def instances(self, master_seed: int, index: int) -> list[SurfaceSpec]:
        """One SurfaceSpec per seed (``n_seeds`` from ``master_seed`` and the entry's
        ``index``; no seed key: ``None``, the preset's own)."""
        if self.n_seeds is not None:
            seeds = [
                int(s) for s in np.random.SeedSequence([master_seed, index]).generate_state(self.n_seeds) >> 1
            ]
        else:
            seeds = self.seeds or [self.seed]
        kind, source = ("preset", self.preset) if self.preset is not None else ("file", self.file)
        stem = source if kind == "preset" else Path(source).stem
        overrides = tuple(sorted((k, _freeze(v)) for k, v in self.overrides.items()))
        return [SurfaceSpec(kind, source, s, overrides, stem if s is None else f"{stem}#{s}") for s in seeds]


class _Sweep(Table):
    """The [sweep] table: ``seed`` is the master seed (each case derives its own);
    ``analyses``, a name or a list, run in the registry's order."""

    name: StrictStr = Field("sweep", min_length=1)
    seed: Seed = 0
    analyses: tuple[StrictStr, ...] = ("quasistatic",)
    store_trajectories: StrictBool = True

    @field_validator("analyses", mode="before")
    def _one_name_is_a_list(cls, analyses):
        return [analyses] if isinstance(analyses, str) else analyses

    @field_validator("analyses")
    def _known_each_once_with_needs(cls, analyses):
        names = ", ".join(repr(k) for k in sorted(ANALYSES))
        if not analyses:
            raise ValueError(f"must be a non-empty list of {names}, got []")
        for a in analyses:
            if a == "mujoco" and a not in ANALYSES:
                raise ValueError(
                    "the analysis 'mujoco' is now 'engine' (it runs the grid's engine, MuJoCo or "
                    "Bullet); write 'engine'"
                )
            if a not in ANALYSES:
                raise ValueError(f"allowed values are {names}, got {a!r}")
            missing = [r for r in ANALYSES[a].requires if r not in analyses]
            if missing:
                raise ValueError(f"{a!r} needs {missing} as well, got {list(analyses)!r}")
        if len(set(analyses)) != len(analyses):
            raise ValueError(f"each analysis once, got {list(analyses)!r}")
        return tuple(a for a in ANALYSES if a in analyses)


class _Document(Table):
    """A whole config; [grid] and [drive] are checked by :func:`_parameters_model` once the
    analyses are known."""

    sweep: _Sweep = _Sweep()
    surfaces: list[_SurfaceEntry] = Field(min_length=1)
    starts: StartsSpec | None = Field(None, validate_default=True)
    grid: dict[str, Any] = Field(default_factory=dict)
    drive: dict[str, Any] = Field(default_factory=dict)
    array: dict[str, Any] = Field(default_factory=dict)

    @field_validator("starts")
    def _for_every_surface(cls, starts, info):
        """[starts] may be left out when every [[surfaces]] entry has its own (a placeholder
        then stands in the normalized config)."""
        if starts is None and any(e.starts is None for e in info.data.get("surfaces", ())):
            raise ValueError("required (a [starts] table, or starts in every [[surfaces]] entry)")
        return starts or StartsSpec(points=((0.0, 0.0),))


@functools.lru_cache(maxsize=16)
def _parameters_model(analyses: tuple[str, ...], specs: tuple[ParamSpec, ...]) -> type[BaseModel]:
    """The [grid] and [drive] tables of a config that runs ``analyses``, whose parameters are
    ``specs``: a key per parameter, [drive] only those marked ``drive``; each optional here
    (:func:`_grid` fills in the defaults)."""

    def table(name: str, noun: str, keys) -> type[BaseModel]:
        fields = {s.name: (value_list(s.annotation, s.expected(), distinct=True), None) for s in keys}
        model = create_model(name, __base__=Table, **fields)
        model.noun = f"{noun} for analyses {list(analyses)}"
        return model

    specs = sorted(specs, key=lambda s: s.name)
    grid = table("grid", "parameter", specs)
    drive = table("drive", "drive parameter", [s for s in specs if s.drive])
    array = table("array", "array parameter", [s for s in specs if s.array])
    return create_model(
        "parameters", __base__=Table, grid=(grid, grid()), drive=(drive, drive()), array=(array, array())
    )


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
    surface_starts : tuple of (StartsSpec or None)
        Per surface, the starts of its [[surfaces]] entry, replacing ``starts`` (None: none).
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

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file (``example:NAME`` for a shipped one); relative file paths in it are
        taken from its folder.

    Returns
    -------
    SweepConfig

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
    """Validate a config given as a dict (the parsed TOML). See :func:`load_config`.

    Parameters
    ----------
    doc : Mapping
        The config's tables (``sweep``, ``surfaces``, ``starts``, ``drive``, ``grid``,
        ``array``) as a dict.
    base_dir : str or os.PathLike
        Folder relative file paths are taken from.

    Returns
    -------
    SweepConfig

    Raises
    ------
    SpineInputError
        Unknown keys or analyses, bad values: the message names the key's path.
    """
    document = validate_table(_Document, doc, context={"base_dir": Path(base_dir)})
    sweep = document.sweep
    specs = tuple(param_specs(sweep.analyses).values())
    params = validate_table(
        _parameters_model(sweep.analyses, specs),
        {"grid": document.grid, "drive": document.drive, "array": document.array},
    )
    entries = [(e, spec) for i, e in enumerate(document.surfaces) for spec in e.instances(sweep.seed, i)]
    surfaces = tuple(spec for _, spec in entries)
    config = SweepConfig(
        name=sweep.name,
        seed=sweep.seed,
        analyses=sweep.analyses,
        surfaces=surfaces,
        starts=document.starts,
        grid=_grid(params, sweep.analyses, surfaces),
        store_trajectories=sweep.store_trajectories,
        surface_starts=tuple(e.starts for e, _ in entries),
    )
    check_size(config)
    for a in sweep.analyses:
        if ANALYSES[a].check_config is not None:
            ANALYSES[a].check_config(config)
    return config


def surface_mu(surface: SurfaceSpec, key: str = "mu") -> float:
    """The mu_s a config that does not give ``key`` runs ``surface`` with: the one mu rule of
    every command (:func:`spine_mj.presets.resolve_mu`: its preset's calibrated mu, else
    refused, named as the config key)."""
    source = surface.source if surface.kind == "preset" else None
    return presets.resolve_mu(source, None, name=f"config key grid.{key}")


def _has_mu(surface: SurfaceSpec) -> bool:
    try:
        surface_mu(surface)
    except SpineInputError:
        return False
    return True


def _grid(params, analyses: tuple[str, ...], surfaces) -> tuple[tuple[str, tuple], ...]:
    """Every parameter of ``analyses`` with its values from [grid] or [drive], else its
    default (None for :data:`PRESET_MU`: each case's preset's, filled in by
    :func:`spine_mj.sweep.cases.expand_cases`)."""
    given = {k: getattr(params.grid, k) for k in params.grid.model_fields_set}
    for table in ("drive", "array"):
        for k in getattr(params, table).model_fields_set:
            if k in given:
                raise SpineInputError(f"config key {table}.{k}: also given as grid.{k}; give it once")
            given[k] = getattr(getattr(params, table), k)
    grid = []
    for pname, spec in param_specs(analyses).items():
        if pname not in given and (spec.default is REQUIRED or spec.default is PRESET_MU):
            lacking = spec.default is PRESET_MU and sorted({s.label for s in surfaces if not _has_mu(s)})
            if spec.default is REQUIRED or lacking:
                since = f" since {', '.join(lacking)} has no calibrated mu" if lacking else ""
                raise SpineInputError(
                    f"config key grid.{pname}: required by analyses {list(analyses)} ({spec.doc})"
                    f"{since}; must be {spec.expected()}"
                )
        grid.append((pname, given.get(pname, (None if spec.default is PRESET_MU else spec.default,))))
    return tuple(grid)


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


def _freeze(value):
    if isinstance(value, list):
        return tuple(_freeze(v) for v in value)
    if isinstance(value, dict):
        return tuple(sorted((k, _freeze(v)) for k, v in value.items()))
    return value


@functools.lru_cache(maxsize=8)
def _make_surface(spec: SurfaceSpec, stamp=None):
    overrides = {k: _thaw(v) for k, v in spec.overrides}
    if spec.seed is not None:
        overrides["seed"] = spec.seed
    return presets.open_surface(spec.source, **overrides)


def _thaw(value):
    if isinstance(value, tuple):
        if value and all(isinstance(v, tuple) and len(v) == 2 and isinstance(v[0], str) for v in value):
            return {k: _thaw(v) for k, v in value}
        return [_thaw(v) for v in value]
    return value

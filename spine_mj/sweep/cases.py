"""Cases: one surface instance at one point of the grid, with all its starts.

A case's id is a hash of its surface, starts and parameters, and its seed is derived from
the master seed and that id, so a case gives the same numbers whatever the order or the
machine it runs on. :func:`expand_cases` lists the cases of a config; :func:`longest_first`
orders them for the workers by a rough cost (the order changes no result).
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import json
import math
import operator
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.jsonio import to_jsonable
from spine_mj.memory import check_memory
from spine_mj.sweep.config import StartsSpec, SurfaceSpec, SweepConfig, digest, surface_mu
from spine_mj.sweep.registry import PRESET_MU, applied_params, param_specs

#: Seconds between two progress reports of a long preparation (listing or checking cases).
PROGRESS_EVERY_S = 10.0
#: Bytes a case takes while a sweep is prepared (listed, checked, its manifest written):
#: a fixed part and one per parameter: 961 B with the quasistatic analysis's 6
#: parameters, 1677 B with the engine's 30, 1790 B with quasistatic, engine and compare's
#: 36 (the growth of the peak resident set over 20,000 cases). A million take 1.7 GB.
CASE_BYTES, CASE_BYTES_PER_PARAM = 800, 30


def cases_bytes(n_cases: int, n_params: int) -> int:
    """Bytes ``n_cases`` cases of ``n_params`` parameters take while a sweep is prepared."""
    return n_cases * (CASE_BYTES + CASE_BYTES_PER_PARAM * n_params)


def case_count(config: SweepConfig) -> int:
    """How many cases ``config`` expands to (surfaces x grid points), none made."""
    return len(config.surfaces) * math.prod(len(v) for _, v in config.grid)


def check_cases_memory(config: SweepConfig) -> None:
    """Refuse (SpineInputError, :func:`~spine_mj.memory.check_memory`) a config whose
    cases would take more than the memory budget to prepare, before any is made."""
    total = case_count(config)
    check_memory(cases_bytes(total, len(config.grid)), where=f"preparing the sweep's {total:,} cases")


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
        Every parameter of the sweep's analyses (one value each; None for one the case's
        engine does not read).
    master_seed : int
        The sweep's seed.
    seed : int
        Derived from ``master_seed`` and ``case_id`` (:func:`case_seed`, when first read):
        the only randomness of the case.
    analyses : tuple of str
    store_trajectories : bool
    """

    case_id: str
    index: int
    surface: SurfaceSpec
    starts: StartsSpec
    params: dict = field(hash=False)
    master_seed: int = 0
    analyses: tuple[str, ...] = ()
    store_trajectories: bool = True

    @functools.cached_property
    def seed(self) -> int:
        return case_seed(self.master_seed, self.case_id)


def expand_cases(config: SweepConfig, progress: Callable[[int, int], None] | None = None) -> list[Case]:
    """The cases of ``config``: surfaces x grid (product of all parameter lists), in order.

    Parameters
    ----------
    config : SweepConfig
        A validated config.
    progress : callable, optional
        Called as ``progress(listed, total)`` every :data:`PROGRESS_EVERY_S` seconds while
        the cases are listed.

    Returns
    -------
    list of Case
        Each with its id (a hash of its parameters) and its seed (from the master seed and
        that id, computed when first read).

    Raises
    ------
    SpineInputError
        When two cases have the same parameters.

    Notes
    -----
    A million cases are listed in seconds: the canonical JSON the id hashes
    (:func:`~spine_mj.sweep.digests.digest` of the case's surface, starts and parameters)
    is joined from each parameter's text, written once per distinct value
    (:func:`_case_text`; the same bytes, so the same ids), and the seed (a SeedSequence,
    33 us) is drawn only when a case's starts or rows need it.
    """
    check_cases_memory(config)
    names = [k for k, _ in config.grid]
    total = case_count(config)
    specs = param_specs(config.analyses)
    engine_at = names.index("engine") if "engine" in names else None
    unread = {e: [names.index(k) for k in ks] for e, ks in _unread_options(config, specs).items()}
    order = sorted(range(len(names)), key=names.__getitem__)  # the canonical JSON's key order
    pick = operator.itemgetter(*order) if len(order) > 1 else (lambda texts: [texts[i] for i in order])
    fragment = _memo_fragments()
    none_texts = [fragment(k, None) for k in names]
    cases, seen = [], set()
    last = time.monotonic()
    for si, surf in enumerate(config.surfaces):
        starts = (
            config.surface_starts[si]
            if (si < len(config.surface_starts) and config.surface_starts[si] is not None)
            else config.starts
        )
        head, tail = _case_text_ends(surf, starts)
        values = [_surface_values(surf, k, v, specs) for k, v in config.grid]
        texts = [[fragment(k, x) for x in v] for k, v in zip(names, values, strict=True)]
        for combo, parts in zip(itertools.product(*values), itertools.product(*texts), strict=True):
            if progress is not None and time.monotonic() - last > PROGRESS_EVERY_S:
                progress(len(cases), total)
                last = time.monotonic()
            params = dict(zip(names, combo, strict=True))
            if engine_at is not None and unread[combo[engine_at]]:
                parts = list(parts)
                for i in unread[combo[engine_at]]:
                    params[names[i]], parts[i] = None, none_texts[i]
            text = head + ",".join(pick(parts)) + tail
            case_id = hashlib.sha256(text.encode()).hexdigest()[:16]
            if case_id in seen:
                raise SpineInputError(
                    f"config produces the same case twice (surface {surf.label}, parameters {params})"
                )
            seen.add(case_id)
            cases.append(
                Case(
                    case_id=case_id,
                    index=len(cases),
                    surface=surf,
                    starts=starts,
                    params=params,
                    master_seed=config.seed,
                    analyses=config.analyses,
                    store_trajectories=config.store_trajectories,
                )
            )
    return cases


def _surface_values(surf: SurfaceSpec, key: str, values: tuple, specs: dict) -> tuple:
    """``values`` of ``key`` on ``surf``: a None of a key whose default is the preset's mu
    (:data:`PRESET_MU`) replaced by the surface's (the one mu rule: :func:`surface_mu`)."""
    if specs[key].default is not PRESET_MU or None not in values:
        return values
    mu = surface_mu(surf, key)
    return tuple(mu if v is None else v for v in values)


def _unread_options(config: SweepConfig, specs: dict) -> dict[str, list[str]]:
    """The parameters that are None in a case of each engine of ``config``'s grid: the
    options that engine does not read (the one rule: :func:`applied_params`)."""
    grid = dict(config.grid)
    out = {}
    for engine in grid.get("engine", ()):
        applied = applied_params({**dict.fromkeys(grid, 0), "engine": engine}, specs)
        out[engine] = [k for k, v in applied.items() if v is None]
    return out


def _case_text_ends(surf: SurfaceSpec, starts: StartsSpec) -> tuple[str, str]:
    """The canonical JSON (:func:`~spine_mj.sweep.digests.digest`'s) of a case's
    ``{"params": ..., "starts": ..., "surface": ...}`` before and after its parameters
    (sorted keys: ``params`` comes first)."""
    rest = json.dumps(
        {"starts": starts.as_dict(), "surface": surf.as_dict()},
        sort_keys=True,
        separators=(",", ":"),
        allow_nan=True,
    )
    return '{"params":{', "}," + rest[1:]


def case_id_of(surf: SurfaceSpec, starts: StartsSpec, params: dict) -> str:
    """The id of the case of ``params`` on ``surf`` from ``starts``, by its definition: 16
    hex digits of :func:`~spine_mj.sweep.digests.digest` of them (what
    :func:`expand_cases` computes faster, joining each parameter's text)."""
    where = {"surface": surf.as_dict(), "starts": starts.as_dict()}
    return digest({**where, "params": {k: to_jsonable(v) for k, v in params.items()}})[:16]


def _memo_fragments() -> Callable[[str, object], str]:
    """``fragment(key, value)``: ``"key":value`` as the canonical JSON writes it, each
    distinct pair written once (a grid's million cases repeat a few values per key)."""
    memo: dict = {}

    def fragment(key, value):
        k = (key, type(value), repr(value))  # repr keeps -0.0 apart from 0.0
        if k not in memo:
            memo[k] = json.dumps(
                {key: to_jsonable(value)}, sort_keys=True, separators=(",", ":"), allow_nan=True
            )[1:-1]
        return memo[k]

    return fragment


def values_key(params: dict, keys: tuple[str, ...]) -> bytes:
    """16 bytes naming the values of ``keys`` in ``params`` by their identities, for the
    memos of a grid's checks: the cases :func:`expand_cases` lists share the value objects
    of the grid's lists (and None), so equal identities are equal values while the cases
    hold them (equal values of distinct objects are only checked twice). Not their reprs:
    2.3 kB a case for the engine's 38 parameters held 2.3 GB for a million cases, and
    writing them took a third of the check."""
    ids = struct.pack(f"{len(keys)}Q", *map(id, map(params.get, keys)))
    return hashlib.blake2b(ids, digest_size=16).digest()


def case_seed(master_seed: int, case_id: str) -> int:
    """The seed of a case: from a SeedSequence of the master seed and the case id (63 bits)."""
    return int(
        np.random.SeedSequence([master_seed, int(case_id, 16)]).generate_state(1, np.uint64)[0]
        >> np.uint64(1)
    )


def case_cost(case: Case) -> float:
    """A rough relative cost of a case, to start the longest cases first (the order of the
    cases changes no result). MuJoCo spring runs last ~ 1 / speed ~ I_e^-1/2."""
    p = case.params
    cost = 1.0
    if "engine" in case.analyses and p.get("protocol", "spring") == "spring":
        if p.get("duration") is not None:
            cost = float(p["duration"])
        elif p.get("speed") is not None:
            cost = 1.0 / float(p["speed"])
        else:
            cost = (1e-3 if p.get("ie") is None else float(p["ie"])) ** -0.5
    return cost * case.starts.count


def longest_first(todo: list[Case]) -> list[Case]:
    """``todo`` by decreasing :func:`case_cost`."""
    return sorted(todo, key=lambda c: -case_cost(c))  # stable: ties keep the config order

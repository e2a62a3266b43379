"""Cases: one surface instance at one point of the grid, with all its starts.

A case's id is a hash of its surface, starts and parameters, and its seed is derived from
the master seed and that id, so a case gives the same numbers whatever the order or the
machine it runs on. :func:`expand_cases` lists the cases of a config; :func:`longest_first`
orders them for the workers by a rough cost (the order changes no result).
"""

from __future__ import annotations

import itertools
import math
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


def expand_cases(config: SweepConfig, progress: Callable[[int, int], None] | None = None) -> list[Case]:
    """The cases of ``config``: surfaces x grid (product of all parameter lists), in order.

    Parameters
    ----------
    config : SweepConfig
        A validated config.
    progress : callable, optional
        Called as ``progress(listed, total)`` every :data:`PROGRESS_EVERY_S` seconds while
        the cases are listed (a million take minutes).

    Returns
    -------
    list of Case
        Each with its id (a hash of its parameters) and its seed (from the master seed and
        that id).

    Raises
    ------
    SpineInputError
        When two cases have the same parameters.
    """
    check_cases_memory(config)
    names = [k for k, _ in config.grid]
    combos = list(itertools.product(*(v for _, v in config.grid)))
    total = len(config.surfaces) * len(combos)
    specs = param_specs(config.analyses)
    from_preset = [k for k in names if specs[k].default is PRESET_MU]
    cases, seen = [], set()
    last, jsonable = time.monotonic(), _memo_jsonable()
    for si, surf in enumerate(config.surfaces):
        starts = (
            config.surface_starts[si]
            if (si < len(config.surface_starts) and config.surface_starts[si] is not None)
            else config.starts
        )
        where = {"surface": surf.as_dict(), "starts": starts.as_dict()}
        default_mu = None  # the surface's, by the one mu rule, read once where needed
        for combo in combos:
            if progress is not None and time.monotonic() - last > PROGRESS_EVERY_S:
                progress(len(cases), total)
                last = time.monotonic()
            params = applied_params(dict(zip(names, combo)), specs)
            for k in from_preset:
                if params[k] is None:
                    default_mu = surface_mu(surf, k) if default_mu is None else default_mu
                    params[k] = default_mu
            case_id = digest({**where, "params": {k: jsonable(v) for k, v in params.items()}})[:16]
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
                    seed=case_seed(config.seed, case_id),
                    analyses=config.analyses,
                    store_trajectories=config.store_trajectories,
                )
            )
    return cases


def _memo_jsonable() -> Callable:
    """:func:`~spine_mj.jsonio.to_jsonable` remembering the values it has seen: a grid's
    million cases repeat a few values per key (a third of the listing's time was spent
    converting them again)."""
    memo: dict = {}

    def jsonable(value):
        key = (type(value), repr(value))  # repr keeps -0.0 apart from 0.0
        if key not in memo:
            memo[key] = to_jsonable(value)
        return memo[key]

    return jsonable


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

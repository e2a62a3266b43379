"""Predicted drive limits of the validation's families (:mod:`spine_mj.theory.drive_limits`),
set beside the measured boundary of the (I_e, K) map.

Each family's prediction is made on the surfaces the map runs (its presets, first seed
and generator variant: :func:`spine_mj.validate.stiffness_map.subset_starts`), with the
family's mu_s and traced on the surface dilated by the rig's tip radius
(:func:`spine_mj.validate.paths.tip_radius`), i.e. what the MuJoCo tip's centre rides on.
The family's ``K*`` is the largest of its surfaces' and its ``I_e*`` the smallest.

``k_path`` is the boundary the map's criterion sees (:func:`~spine_mj.theory.path_stiffness.path_stiffness`):
the compliant-drive paths from the family's own starts (its x, its y range respread over as
many rows as it has: the criterion's 95 % of outcomes tolerates one miss in 20, none in 15,
so the count is the measurement's; measured on the fractal's map surface, K_path 29 from 8
or 10 starts, 20 from its 30) against the rigid ones, each carriage stopping where the map's runs stop
theirs (the sweep gives them no duration: :func:`~spine_mj.theory.path_stiffness.spring_run_travel`
to the surface's +x edge), the largest over its surfaces; ``k_path_endless`` the same with
an endless carriage (the folds' part alone). ``lc_over_ls`` is the largest ``L_c / l_s`` of
its surfaces (the spring-block swing's scale, :func:`spine_mj.sim.holding.spring_swing`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from spine_mj import presets
from spine_mj.sim.step_rule import DEFAULT_STIFFNESS_NUMBER
from spine_mj.sweep.executors import map_processes
from spine_mj.theory.drive_limits import Corner, DriveLimits, drive_limits, quasistatic_corner
from spine_mj.validate.paths import tip_radius
from spine_mj.validate.plans import FamilySpec, ValidationPlan
from spine_mj.validate.sweep_configs import surface_inputs

__all__ = [
    "CORNER_GRID_STARTS",
    "CORNER_PATH_STARTS",
    "corner_drives",
    "families_limits",
    "family_corner",
    "family_corners",
    "family_k_axis",
    "family_limits",
    "k_ladder",
    "path_starts",
    "stored_corners",
    "surface_corner",
]

#: Starts a side of the grid whose paths give a corner's ``I_e*`` (:func:`family_corner`).
CORNER_GRID_STARTS = 6
#: Starts a corner's ``K_path`` is read on, the family's y range respread over them: the
#: criterion's 95 % of outcomes tolerates one miss from 20 starts, none from fewer, and the
#: families' own measurements (30 starts and more) tolerate at least one.
CORNER_PATH_STARTS = 20


def path_starts(fam: FamilySpec, surface, n: int) -> np.ndarray:
    """``n`` starts of ``fam`` on ``surface``: its first x, its y range respread over ``n``
    values (a relative frame scaled to the surface's bounds); shape ``(n, 2)``."""
    t = fam.starts_table()
    ys = np.linspace(min(t["y"]), max(t["y"]), n)
    x = np.full(n, float(t["x"][0]))
    if t.get("frame") == "relative":
        xmin, xmax, ymin, ymax = surface.bounds
        x, ys = xmin + x * (xmax - xmin), ymin + ys * (ymax - ymin)
    return np.column_stack([x, ys])


def family_limits(plan: ValidationPlan, fam: FamilySpec, *, n_starts: int = 8) -> dict:
    """``{"k_star", "k_path", "k_path_endless", "ie_star", "limit", "lc_over_ls", "presets":
    {preset: DriveLimits.as_dict()}}`` of ``fam`` on its first seed and variant (see
    module), from ``n_starts x n_starts`` paths per surface and ``K_path`` from as many
    starts as the family has."""
    return families_limits(plan, [fam], n_starts=n_starts)[fam.name]


def families_limits(plan: ValidationPlan, fams, *, n_starts: int = 8, workers: int = 1) -> dict:
    """:func:`family_limits` of each family of ``fams``, by name, every surface's limits
    predicted on ``workers`` local processes at once (each surface's own numbers, as one by
    one)."""
    jobs = [(plan, fam, preset, n_starts) for fam in fams for preset in fam.presets]
    limits = iter(map_processes(_preset_limits, jobs, workers))
    out = {}
    for fam in fams:
        per = {preset: next(limits) for preset in fam.presets}
        worst = min(per.values(), key=lambda d: d["ie_star"])
        out[fam.name] = {
            "k_star": max(d["k_star"] for d in per.values()),
            "k_path": max(d["k_path"] for d in per.values()),
            "k_path_endless": max(d["k_path_endless"] for d in per.values()),
            "lc_over_ls": max(d["char_length"] / d["slope_length"] for d in per.values()),
            "ie_star": worst["ie_star"],
            "limit": worst["limit"],
            "presets": per,
        }
    return out


def _preset_limits(job) -> dict:
    """One preset's limits of :func:`family_limits` (``DriveLimits.as_dict()`` with its
    ``tip_radius``), ``job`` its ``(plan, family, preset, n_starts)``."""
    plan, fam, preset, n_starts = job
    seed = fam.seeds[0] if fam.seeds else None
    variant = dict(fam.variants[0]) if fam.variants else {}
    overrides = dict(variant, **({} if seed is None else {"seed": seed}))
    surface = presets.make_surface(preset, **overrides)
    mu = fam.mu if fam.mu is not None else presets.calibrated_mu(preset)
    tip = tip_radius(preset, None if seed is None else (seed,), plan.hfield_resolution)
    limits = drive_limits(
        surface,
        mu,
        tip_radius=tip,
        n_starts=n_starts,
        path_starts=path_starts(fam, surface, len(fam.starts_table()["y"])),
        carriage_edge=surface.bounds[1],
    )
    return dict(limits.as_dict(), tip_radius=tip)


def corner_drives(presets: dict) -> dict:
    """Each preset's drive at its corner, ``{preset: {"ie", "K"}}``, from
    :func:`family_corner`'s ``presets`` (what ``validation.json``'s ``corner`` records), with
    the family's ``timestep_factor`` where its step is not the rule's
    (:class:`~spine_mj.validate.plans.FamilySpec`)."""
    return {
        preset: {"ie": c["ie"], "K": c["K"], **_own_step(c.get("timestep_factor", 1.0))}
        for preset, c in presets.items()
    }


def _own_step(factor: float) -> dict:
    return {} if factor == 1.0 else {"timestep_factor": factor}


def family_corner(plan: ValidationPlan, fam: FamilySpec) -> dict:
    """The quasistatic corner each preset of ``fam`` is judged at
    (:func:`~spine_mj.theory.drive_limits.quasistatic_corner`) from its own predicted limits
    over its generator variants at the first seed (a generator's seeds are replicas of one
    roughness; its variants, a Hurst exponent, are not): the lowest ``I_e*``, the highest
    ``K_path`` (on :data:`CORNER_PATH_STARTS` starts over the family's y range, each
    carriage stopping where a run's does) and ``L_c / l_s``, traced with the rig's tip and
    the family's mu_s; paths from a :data:`CORNER_GRID_STARTS` square grid.

    Each preset has its own corner: one drive shared by surfaces of different scales holds
    none of them to its limits (the shipped scans: a spring stiff enough for di-1's folds,
    K 1.7e4, swings by 5 F_p on plu-1, whose ``L_c / l_s`` is 28 times di-1's).

    Returns
    -------
    dict
        ``presets``: per preset its corner
        (:meth:`~spine_mj.theory.drive_limits.Corner.as_dict`: ``ie``, ``K``, ``swing_fp``,
        ...); ``surfaces``: per surface label its ``ie_star``, ``limit``, ``k_star``,
        ``k_path``, ``k_path_left_out`` and ``lc_over_ls``.
    """
    return family_corners(plan, [fam])[fam.name]


def family_corners(plan: ValidationPlan, fams, *, workers: int = 1) -> dict:
    """:func:`family_corner` of each family of ``fams``, by name, every surface's limits
    predicted on ``workers`` local processes at once (each surface's own numbers, as one by
    one: the corners are the quasistatic-limit study's serial start, ~50 s on one core)."""
    jobs = [(plan, fam, preset, v) for fam in fams for preset in fam.presets for v in fam.variants or ((),)]
    limits = iter(map_processes(_surface_limits, jobs, workers))
    out = {}
    for fam in fams:
        per, corners = {}, {}
        for preset in fam.presets:
            own = []
            for variant in fam.variants or ((),):
                d = next(limits)
                per[preset + "".join(f" {k}={v}" for k, v in variant)] = _limit_row(d)
                own.append(d)
            corners[preset] = surface_corner(own).as_dict()
        out[fam.name] = {"presets": corners, "surfaces": per}
    return out


def stored_corners(plan: ValidationPlan, fams, runner) -> dict:
    """:func:`family_corners` of ``fams`` on the runner's workers, kept in its output folder
    (:meth:`~spine_mj.validate.study_runner.StudyRunner.stored`, keyed by the families, the
    plan's hfield resolution, the corner's start counts and the surfaces' inputs): a resumed
    validation reads them back instead of tracing them again (~30 CPU-s of the quick plan)."""
    inputs = {
        "families": list(fams),
        "hfield_resolution": plan.hfield_resolution,
        "starts": [CORNER_GRID_STARTS, CORNER_PATH_STARTS],
        "surfaces": [surface_inputs(p) for fam in fams for p in fam.presets],
    }
    compute = functools.partial(family_corners, plan, fams, workers=runner.n_workers)
    return runner.stored("limit-corners", inputs, compute)


def _surface_limits(job) -> DriveLimits:
    """The predicted limits of one surface of a corner (:func:`family_corner`), ``job`` its
    ``(plan, family, preset, generator variant)``."""
    plan, fam, preset, variant = job
    seed = fam.seeds[0] if fam.seeds else None
    mu = fam.mu if fam.mu is not None else presets.calibrated_mu(preset)
    tip = tip_radius(preset, None if seed is None else (seed,), plan.hfield_resolution)
    surface = presets.open_surface(preset, **dict(variant, **({} if seed is None else {"seed": seed})))
    return drive_limits(
        surface,
        mu,
        tip_radius=tip,
        n_starts=CORNER_GRID_STARTS,
        path_starts=path_starts(fam, surface, CORNER_PATH_STARTS),
        carriage_edge=surface.bounds[1],
    )


def surface_corner(limits) -> Corner:
    """The corner one surface is judged at, from its :class:`~spine_mj.theory.drive_limits.DriveLimits`
    (one or several: a generator's variants, then the lowest ``I_e*`` and highest
    ``K_path``, ``K*`` and ``L_c / l_s``), with ``K`` at least the default spring
    (:func:`~spine_mj.theory.drive_limits.quasistatic_corner`; the rule of the validation's
    families and of ``spine-mj hold``)."""
    rows = [_limit_row(d) for d in limits]
    worst = min(rows, key=lambda v: v["ie_star"])
    return quasistatic_corner(
        ie_star=worst["ie_star"],
        k_path=max(v["k_path"] for v in rows),
        k_star=max(v["k_star"] for v in rows),
        lc_over_ls=max(v["lc_over_ls"] for v in rows),
        ie_limit=worst["limit"],
        # measured: K = 3 and 10 hop on landing (penetration) on the fractal, 30 runs clean
        k_floor=DEFAULT_STIFFNESS_NUMBER,
    )


def _limit_row(d: DriveLimits) -> dict:
    """What a corner reads of one surface's limits, as ``validation.json`` keeps it."""
    return {
        "ie_star": d.ie_star,
        "limit": d.limit,
        "k_star": d.k_star,
        "k_path": d.k_path,
        "k_path_left_out": d.k_path_left_out,
        "lc_over_ls": d.char_length / d.slope_length,
    }


def family_k_axis(predicted: dict, factors) -> list[float]:
    """A family's K axis for the (I_e, K) map: ``factors`` x its ``k_path`` (the boundary the
    map's criterion sees, :func:`~spine_mj.theory.path_stiffness.path_stiffness`: the measured
    boundary is judged against it within a factor of 2), with its fold ``k_star`` and ten
    times it rounded up (the map reaches at least a decade past the first fold anywhere);
    the fold's ladder alone where ``k_path`` is not finite, empty without factors."""
    ladder = k_ladder(predicted.get("k_path", float("nan")), factors) or k_ladder(
        predicted["k_star"], factors
    )
    if not ladder:
        return []
    fold = k_ladder(predicted["k_star"], (1.0,)) + k_ladder(predicted["k_star"], (10.0,), round_up=True)
    return sorted(set(ladder) | set(fold))


def k_ladder(k_star: float, factors, *, round_up: bool = False) -> list[float]:
    """The K axis ``factors`` x ``k_star``, each to two significant digits, the nearest or
    (``round_up``) the next up (empty without factors or without a finite positive K*)."""
    if not factors or not (np.isfinite(k_star) and k_star > 0):
        return []
    if not round_up:
        return sorted({float(f"{f * k_star:.2g}") for f in factors})
    out = set()
    for f in factors:
        scale = 10.0 ** (math.floor(math.log10(f * k_star)) - 1)
        out.add(float(f"{math.ceil(f * k_star / scale - 1e-9) * scale:.2g}"))
    return sorted(out)

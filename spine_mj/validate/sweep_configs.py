"""The sweep configs the studies write: a family's document, engine-variation grid keys,
the calibrated mu of a preset.

Every study runs its MuJoCo cases as a sweep (:mod:`spine_mj.sweep`); the pieces of a
config that several studies share are built here, once.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from spine_mj import examples, presets, sim, sweep
from spine_mj.errors import SpineInputError
from spine_mj.sim.drives import spring_stiffness_n_m
from spine_mj.sim.rig_hfield import grid_keeps_samples
from spine_mj.sim.scales import engine_tip_radius_m
from spine_mj.sweep.digests import surface_digest
from spine_mj.sweep.preflight import check_cases
from spine_mj.validate.plans import MASS_KG, FamilySpec, ValidationPlan

__all__ = [
    "RELATIVE_ENGINE_KEYS",
    "engine_default",
    "engine_grid",
    "family_doc",
    "gridded",
    "refined_resolution",
    "refused_by_rig",
    "relative_engine_keys",
    "rig_engine",
    "surface_inputs",
    "surfaces_table",
]


def surfaces_table(presets_: Sequence[str], seeds, variants=((),)) -> list[dict]:
    """A sweep ``surfaces`` table: one entry per preset and generator parameter set
    (``variants``, see :class:`FamilySpec`), with ``seeds`` when given; a shipped scan
    (``example:NAME``) as a ``file`` entry."""
    out = []
    for p in presets_:
        for variant in variants:
            entry = {"file": p} if p.startswith(examples.PREFIX) else {"preset": p}
            if seeds is not None:
                entry["seeds"] = list(seeds)
            if variant:
                entry["set"] = dict(variant)
            out.append(entry)
    return out


def surface_inputs(preset: str) -> str:
    """The digest of what ``preset`` of a family reads (a shipped scan's file, else the
    resolved preset: :func:`~spine_mj.sweep.digests.surface_digest`), as a sweep's store keys
    its resume: for a stage computed from the family's surfaces outside any sweep."""
    if preset.startswith(examples.PREFIX):
        return surface_digest("file", str(examples.resolve(preset)))
    return surface_digest("preset", preset)


def family_doc(
    fam: FamilySpec,
    *,
    name: str,
    preset: str,
    drive: dict,
    grid: dict,
    analyses=("quasistatic", "engine", "compare"),
    miss_reasons: bool = False,
) -> dict:
    """The sweep config of one preset of ``fam`` with its starts, ``drive`` and ``grid``;
    ``compare`` tells why runs disagree only where ``miss_reasons`` (a trace per checkpoint
    of each miss: the studies away from the quasistatic corner, where most runs disagree by
    design, skip it)."""
    if "compare" in analyses:  # the studies cross the corner's edge on purpose (spring_swing_fp per row)
        grid = {**grid, "miss_reasons": miss_reasons, "dynamic_drive": True}
    return {
        "sweep": {"name": name, "seed": 11, "analyses": list(analyses)},
        "surfaces": surfaces_table([preset], fam.seeds, fam.variants),
        "starts": fam.starts_table(),
        "drive": drive,
        "grid": grid,
    }


def engine_default(key: str):
    """Default of the sweep's ``engine`` analysis parameter ``key``."""
    return {p.name: p.default for p in sweep.ANALYSES["engine"].parameters}[key]


def rig_engine(
    surface,
    *,
    tip: float | None,
    mu: float,
    ie: float,
    hfield_resolution: int | None,
    stiffness_number: float | None = None,
) -> sim.EngineSettings:
    """The engine settings the sweep's rig gets for ``surface``, a tip of radius ``tip``
    (surface units; None: the rig's default), mu, the drive at ``ie`` and the spring of
    stiffness number ``stiffness_number`` (None: the default spring): the same rule
    (:func:`spine_mj.sim.default_engine`), from the same speed and stiffness, without
    compiling a model."""
    scales = sim.Scales.for_surface(
        surface,
        tip=sim.TipParams(tip_radius_m=engine_tip_radius_m(surface, tip), mass_kg=MASS_KG, mu_s=mu),
        hfield_resolution=grid_keeps_samples(surface, hfield_resolution),
    )
    speed = sim.drive_speed_m_s(scales, ie=ie)
    spring = spring_stiffness_n_m(scales, stiffness_number=stiffness_number)
    return sim.default_engine(scales, speed_m_s=speed, stiffness_n_m=spring)


#: Engine overrides relative to the rig's own settings that the sweep does not take as
#: they are (:func:`relative_engine_keys`; its ``timestep_factor`` it does, case by case).
RELATIVE_ENGINE_KEYS = ("solref_timeconst_factor",)


def relative_engine_keys(overrides: dict, engine: Callable[[], sim.EngineSettings]) -> dict:
    """The grid keys of the relative engine overrides in ``overrides`` (removed from it):
    ``solref_timeconst_factor`` scales the contact's time constant of the rig
    (``engine()``), passed explicitly."""
    if not any(k in overrides for k in RELATIVE_ENGINE_KEYS):
        return {}
    return {"solref_timeconst": engine().solref[0] * float(overrides.pop("solref_timeconst_factor"))}


def refined_resolution(resolution: int, factor: int) -> int:
    """Samples a side ``factor`` times as dense, every old sample kept: ``(n - 1) f + 1``."""
    return (int(resolution) - 1) * int(factor) + 1


def engine_grid(
    plan: ValidationPlan,
    overrides: Sequence[tuple[str, Any]],
    preset: str,
    seeds,
    tip: float,
    *,
    mu: float,
    ie: float,
    stiffness_number: float | None = None,
) -> dict:
    """Grid keys of an engine variation. Three keys are relative to the rig's own settings
    (:func:`rig_engine`): ``timestep_factor``, which the sweep applies to each case's own
    step with the contact's time constant kept (only the step changes,
    :class:`~spine_mj.sim.EngineOverrides`), ``solref_timeconst_factor``
    (:func:`relative_engine_keys`), and ``hfield_factor``, the rig's hfield at that many
    times its samples a side, every one kept, with the tip kept (the sweep's
    ``hfield_refinement``: an analytic surface's plan resolution refined,
    :func:`refined_resolution`, a grid's own samples through its interpolant)."""
    out = {"hfield_resolution": plan.hfield_resolution}
    ov = dict(overrides)
    if "hfield_factor" in ov:
        out["hfield_refinement"] = int(ov.pop("hfield_factor"))
    out.update(
        relative_engine_keys(
            ov,
            lambda: rig_engine(
                presets.open_surface(preset, **({} if seeds is None else {"seed": seeds[0]})),
                tip=tip,
                mu=mu,
                ie=ie,
                hfield_resolution=plan.hfield_resolution,
                stiffness_number=stiffness_number,
            ),
        )
    )
    out.update(ov)
    return out


def gridded(preset: str, fam: FamilySpec) -> bool:
    """Whether ``preset`` (``fam``'s first seed and variant) is a grid, refined through its
    interpolant (:func:`spine_mj.surfaces.refine_grid`)."""
    seed = {} if fam.seeds is None else {"seed": fam.seeds[0]}
    return grid_keeps_samples(presets.open_surface(preset, **seed, **dict(fam.variants[0])), 1) is None


def refused_by_rig(docs: Sequence[dict]) -> str:
    """Why the sweep's preflight refuses the configs ``docs`` (a corner whose runs need more
    steps than a run may take), empty where it runs them."""
    try:
        for doc in docs:
            config = sweep.parse_config(doc)
            check_cases(sweep.expand_cases(config), config.swept, None)
    except SpineInputError as exc:
        return str(exc)
    return ""

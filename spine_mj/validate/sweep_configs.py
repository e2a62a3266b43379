"""The sweep configs the studies write: a family's document, engine-variation grid keys,
the calibrated mu of a preset.

Every study runs its MuJoCo cases as a sweep (:mod:`spine_mj.sweep`); the pieces of a
config that several studies share are built here, once.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from spine_mj import presets, sim, sweep
from spine_mj.validate.plans import MASS_KG, FamilySpec, ValidationPlan

__all__ = ["engine_default", "engine_grid", "family_doc", "surfaces_table"]


def surfaces_table(presets_: Sequence[str], seeds, variants=((),)) -> list[dict]:
    """A sweep ``surfaces`` table: one entry per preset and generator parameter set
    (``variants``, see :class:`FamilySpec`), with ``seeds`` when given."""
    out = []
    for p in presets_:
        for variant in variants:
            entry = {"preset": p}
            if seeds is not None:
                entry["seeds"] = list(seeds)
            if variant:
                entry["set"] = dict(variant)
            out.append(entry)
    return out


def family_doc(
    fam: FamilySpec,
    *,
    name: str,
    preset: str,
    drive: dict,
    grid: dict,
    analyses=("quasistatic", "mujoco", "compare"),
    miss_reasons: bool = False,
) -> dict:
    """The sweep config of one preset of ``fam`` with its starts, ``drive`` and ``grid``;
    ``compare`` tells why runs disagree only where ``miss_reasons`` (a trace per checkpoint
    of each miss: the studies away from the quasistatic corner, where most runs disagree by
    design, skip it)."""
    if "compare" in analyses:
        grid = {**grid, "miss_reasons": miss_reasons}
    return {
        "sweep": {"name": name, "seed": 11, "analyses": list(analyses)},
        "surfaces": surfaces_table([preset], fam.seeds, fam.variants),
        "starts": fam.starts_table(),
        "drive": drive,
        "grid": grid,
    }


def engine_default(key: str):
    """Default of the sweep's ``mujoco`` analysis parameter ``key``."""
    return {p.name: p.default for p in sweep.ANALYSES["mujoco"].parameters}[key]


def engine_grid(
    plan: ValidationPlan, overrides: Sequence[tuple[str, Any]], preset: str, seeds, tip: float
) -> dict:
    """Grid keys of an engine variation; ``*_factor`` keys scale the rig's default dt."""
    out = {"hfield_resolution": plan.hfield_resolution}
    ov = dict(overrides)
    if "timestep_factor" in ov or "solref_timeconst_factor" in ov:
        surface = presets.make_surface(preset, **({} if seeds is None else {"seed": seeds[0]}))
        unit_m = sim.DEFAULT_LENGTH_SCALE_M if surface.unit == "1" else 1.0
        scales = sim.Scales.for_surface(
            surface, tip=sim.TipParams(tip_radius_m=tip * unit_m, mass_kg=MASS_KG)
        )
        dt = sim.default_engine(scales).timestep_s
        dt_new = dt * float(ov.pop("timestep_factor", 1.0))
        out["timestep"] = dt_new
        out["solref_timeconst"] = 2 * dt_new * float(ov.pop("solref_timeconst_factor", 1.0))
    out.update(ov)
    return out

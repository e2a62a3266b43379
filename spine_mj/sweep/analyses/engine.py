"""The ``engine`` analysis: a run of an engine's rig from every start with the chosen drive,
in any registered engine (the grid's ``engine``: MuJoCo, Bullet, :data:`spine_mj.choices.ENGINES`).

Touches the API of :mod:`spine_mj.sim` here only. The rig and drive of a case come from
:func:`spine_mj.sim.build_rig` and :func:`spine_mj.sim.build_drive` (the builder
``spine-mj simulate`` uses too); the rig is cached per process, so cases that differ only
in the drive share it.
"""

from __future__ import annotations

import collections
import dataclasses
import functools

import numpy as np

from spine_mj import sim
from spine_mj.choices import DEFAULT_ENGINE, ENGINES, PROTOCOLS
from spine_mj.errors import SpineInputError
from spine_mj.sim.build import RigPlan, check_planned_hfield, plan_rig, plan_settings, rig_of_plan, rig_sizing
from spine_mj.sim.model import has_mujoco_model
from spine_mj.sim.open_loop import drive_steps
from spine_mj.sim.rig_inputs import RigInputs
from spine_mj.sim.scales import check_tip_radius, engine_tip_radius_m
from spine_mj.sim.step_rule import SOLREF_DAMPRATIO
from spine_mj.sweep.analyses.engine_metrics import run_metrics, run_trajectories
from spine_mj.sweep.cases import values_key
from spine_mj.sweep.registry import (
    CASE_THREADS,
    KAPPA_CAP_PARAM,
    MU_PARAM,
    TIP_RADIUS_PARAM,
    Analysis,
    AnalysisResult,
    ParamSpec,
    check_engine_options,
    register_analysis,
)

#: The tip's defaults (:class:`spine_mj.sim.TipParams`), the sweep's too.
_TIP = {f.name: f.default for f in dataclasses.fields(sim.TipParams)}
#: MuJoCo's solver settings that the step rule leaves at their defaults
#: (:class:`spine_mj.sim.EngineSettings`), the sweep's too.
_SOLVER = {f.name: f.default for f in dataclasses.fields(sim.EngineSettings)}

ENGINE_PARAMS = (
    MU_PARAM,
    ParamSpec(
        "engine",
        "str",
        "physics engine, a registered one (spine_mj.choices.ENGINES: "
        + "; ".join(f"{e.name}, {e.summary}" for e in ENGINES.values())
        + "); an engine option the engine does not read is refused",
        DEFAULT_ENGINE,
    ),
    TIP_RADIUS_PARAM,
    ParamSpec("protocol", "str", "drive protocol", "spring", choices=PROTOCOLS, drive=True),
    ParamSpec(
        "ie",
        "float",
        "inertia number I_e = m v^2 / (F_p L_c); sets the carriage speed "
        "(spring) or the force rate (ramp, static); default 1e-3 unless speed is given",
        None,
        0.0,
        exclusive=True,
        drive=True,
        maximum=sim.MAX_INERTIA_NUMBER,
    ),
    ParamSpec(
        "speed",
        "float",
        "carriage speed [m/s] (spring; instead of ie)",
        None,
        0.0,
        exclusive=True,
        drive=True,
    ),
    ParamSpec(
        "stiffness",
        "float",
        "spring stiffness [N/m] (instead of K; default K = 30)",
        None,
        0.0,
        exclusive=True,
        drive=True,
    ),
    ParamSpec(
        "K",
        "float",
        "drive stiffness number K = k l_s / F_p, l_s the slope correlation length "
        "(spring; instead of stiffness)",
        None,
        0.0,
        exclusive=True,
        drive=True,
    ),
    ParamSpec(
        "duration",
        "float",
        "drive duration [s] (default: from the drive)",
        None,
        0.0,
        exclusive=True,
        drive=True,
    ),
    ParamSpec("settle_time", "float", "settling time before the drive [s]", None, 0.0, drive=True),
    ParamSpec("start_force", "float", "static probe: force held at the start [N]", 0.0, 0.0, drive=True),
    ParamSpec(
        "slide_distance",
        "float",
        "ramp: distance slid after breakaway before the force "
        "resets [m] (default 0.01 L_c, the paper's step dl)",
        None,
        0.0,
        drive=True,
    ),
    # the tip's defaults are sim.TipParams' (one home: a changed default changes every command)
    ParamSpec("mass", "float", "effective moving mass m_eff [kg]", _TIP["mass_kg"], 0.0, exclusive=True),
    ParamSpec("preload", "float", "extra downward preload [N] (added to m g)", _TIP["preload_n"], 0.0),
    ParamSpec("gravity", "float", "gravitational acceleration [m/s^2]", _TIP["gravity_m_s2"], 0.0),
    ParamSpec(
        "length_scale",
        "float",
        "metres per surface unit (default 0.01 for dimensionless surfaces, 1 for metres)",
        None,
        0.0,
        exclusive=True,
    ),
    ParamSpec(
        "timestep",
        "float",
        "the engine's recorded time step [s] (default: from the scales)",
        None,
        0.0,
        exclusive=True,
        option="timestep_s",
    ),
    ParamSpec(
        "integrator",
        "str",
        "MuJoCo integrator",
        _SOLVER["integrator"].value,
        choices=tuple(i.value for i in sim.Integrator),
        option="integrator",
    ),
    ParamSpec(
        "cone",
        "str",
        "friction cone",
        _SOLVER["cone"].value,
        choices=tuple(c.value for c in sim.Cone),
        option="cone",
    ),
    ParamSpec(
        "impratio",
        "float",
        "frictional / normal impedance ratio",
        _SOLVER["impratio"],
        0.0,
        exclusive=True,
        option="impratio",
    ),
    ParamSpec(
        "noslip_iterations",
        "int",
        "noslip solver passes",
        _SOLVER["noslip_iterations"],
        0,
        option="noslip_iterations",
    ),
    ParamSpec(
        "tolerance",
        "float",
        f"MuJoCo solver tolerance (default {_SOLVER['tolerance']:g})",
        None,
        0.0,
        exclusive=True,
        option="tolerance",
    ),
    ParamSpec(
        "noslip_tolerance",
        "float",
        f"MuJoCo noslip solver tolerance (default {_SOLVER['noslip_tolerance']:g})",
        None,
        0.0,
        exclusive=True,
        option="noslip_tolerance",
    ),
    ParamSpec(
        "timestep_factor",
        "float",
        "the rule's time step times this, the contact's time constant kept (not with timestep)",
        None,
        0.0,
        exclusive=True,
        option="timestep_factor",
    ),
    ParamSpec(
        "solref_timeconst",
        "float",
        "contact time constant [s] (default 2 timestep)",
        None,
        0.0,
        exclusive=True,
        option="solref_timeconst_s",
    ),
    ParamSpec(
        "solref_dampratio",
        "float",
        "contact damping ratio",
        SOLREF_DAMPRATIO,
        0.0,
        exclusive=True,
        option="solref_dampratio",
    ),
    ParamSpec(
        "hfield_resolution",
        "int",
        "hfield samples per side for analytic surfaces (a gridded surface keeps its own)",
        None,
        4,
    ),
    ParamSpec(
        "hfield_refinement",
        "int",
        "the hfield at this many times its samples a side, every one kept, the tip's default "
        "radius kept (a grid refined through its interpolant; solution verification)",
        1,
        1,
    ),
    KAPPA_CAP_PARAM,
    ParamSpec("record_every", "int", "store every k-th recorded step of the trajectories", 1, 1),
)


#: The drive keys each protocol reads (the others, ie, speed and settle_time, every one).
PROTOCOL_KEYS = {
    "K": ("spring",),
    "stiffness": ("spring",),
    "duration": ("spring", "ramp"),
    "start_force": ("static",),
    "slide_distance": ("ramp",),
}


def check_speed(config) -> None:
    """One of ie/speed, K/stiffness and timestep/timestep_factor; a tip that is a ball (no
    point); no drive key that a chosen protocol would ignore."""
    grid = dict(config.grid)
    for a, b, what in (
        ("ie", "speed", "the inertia number or the speed"),
        ("K", "stiffness", "K or k"),
        ("timestep", "timestep_factor", "the step or the rule's step's factor"),
    ):
        if grid[a] != (None,) and grid[b] != (None,):
            raise SpineInputError(
                f"config keys grid.{a} and grid.{b}: give one of them ({what}), got "
                f"{a} = {list(grid[a])} and {b} = {list(grid[b])}"
            )
    for radius in grid["tip_radius"]:
        check_tip_radius(radius, "config key grid.tip_radius", point=False)
    for engine in grid["engine"]:
        check_engine_options(engine, grid, ENGINE_PARAMS)
    defaults = {s.name: s.default for s in ENGINE_PARAMS}
    protocols = grid["protocol"]
    for key, readers in PROTOCOL_KEYS.items():
        ignoring = [p for p in protocols if p not in readers]
        if grid[key] != (defaults[key],) and ignoring:
            raise SpineInputError(
                f"config key {key} = {list(grid[key])}: the {' and '.join(ignoring)} drive ignores it "
                f"(read only by {' and '.join(readers)}); remove it, or sweep that protocol separately"
            )


@functools.lru_cache(maxsize=4)
def _rig(spec, inputs: RigInputs):
    """The rig of a surface and a case's :class:`RigInputs` (cached: cases differing only in
    the protocol share it; the speed and the spring's stiffness set the engine step), built
    as :func:`spine_mj.sim.build_rig` builds it on the surface's sizing measured once
    (:func:`_sizing`: the grid's checks measured it before the cases, and a forked worker
    inherits it)."""
    surface = spec.make()
    check_planned_hfield(surface, inputs)
    sized = _sizing(spec, inputs.tip, tuple(inputs.sizing.items()))
    return rig_of_plan(plan_rig(surface, inputs, sized=sized), inputs.engine)


def case_inputs(case, surface=None) -> RigInputs:
    """The :class:`RigInputs` of a sweep case: the one place a case's parameters become a
    rig's inputs (its engine options, those its engine reads: its registry entry's).

    ``surface`` is ``case.surface.make()``, passed when the caller already has it (the tip
    radius is in its length unit)."""
    return _inputs(case.params, case.surface.make() if surface is None else surface)


def _inputs(p: dict, surface) -> RigInputs:
    reads = ENGINES[p["engine"]].options
    return RigInputs(
        engine=p["engine"],
        engine_options={s.option: p[s.name] for s in ENGINE_PARAMS if s.option in reads},
        mu=p["mu"],
        tip_radius_m=engine_tip_radius_m(
            surface, p["tip_radius"], length_scale_m=p["length_scale"], name="config key grid.tip_radius"
        ),
        mass_kg=p["mass"],
        preload_n=p["preload"],
        gravity_m_s2=p["gravity"],
        length_scale_m=p["length_scale"],
        hfield_resolution=p["hfield_resolution"],
        hfield_refinement=p["hfield_refinement"],
        ie=p["ie"],
        speed_m_s=p["speed"],
        stiffness_number=p["K"],
        stiffness_n_m=p["stiffness"],
    )


def case_rig(case, surface=None):
    """The (cached) rig a sweep case runs on (:func:`case_inputs`).

    ``surface`` is ``case.surface.make()``, passed when the caller already has it.
    """
    return _rig(case.surface, case_inputs(case, surface))


def _clear_caches() -> None:
    _rig.cache_clear()
    _SIZINGS.clear()
    _BASE_PLANS.clear()
    _STARTS_CHECKED.clear()


case_rig.cache_clear = _clear_caches


def _sizing(spec, tip, sizing: tuple):
    """The ``(tip, scales, hfield)`` of a surface, a tip and its sizing keywords (cached,
    the most recent within :data:`SIZING_CACHE_BYTES` of hfield samples: the cases of a grid
    that differ in the drive or the engine settings share it, so do the sweeps a validation
    runs together, and :func:`_rig` builds on it; the quick plan's quasistatic limit has 30
    sizings, which its checks measured 60 times, then each case once more as it ran)."""
    key = (spec, tip, sizing)
    if key in _SIZINGS:
        _SIZINGS.move_to_end(key)
        return _SIZINGS[key]
    sized = _SIZINGS[key] = rig_sizing(spec.make(), tip=tip, **dict(sizing))
    while len(_SIZINGS) > 1 and sum(s[2].data.nbytes for s in _SIZINGS.values()) > SIZING_CACHE_BYTES:
        _SIZINGS.popitem(last=False)
    return sized


#: Bytes of hfield samples the sizings :func:`_sizing` keeps may hold (the newest is kept
#: whatever its size).
SIZING_CACHE_BYTES = 2**27
#: :func:`_sizing`'s cache, oldest use first.
_SIZINGS: collections.OrderedDict = collections.OrderedDict()


def case_plan(case, surface=None):
    """What :func:`case_rig` would build for ``case``, without compiling it: a MuJoCo case's
    :class:`~spine_mj.sim.build.RigPlan` (its scales, tip and engine step), another
    engine's rig itself (Bullet's checks its heightfield's memory; its world is made at
    its first run). For the checks of a grid before any case runs.

    The cases of a grid that differ only in the drive's pace and spring (``ie``, ``speed``,
    ``K``, ``stiffness``, which bound the engine step) share everything else: its inputs
    checked, the hfield's limits and the surface's sizing (once per tip for every
    engine: a grid over both engines measured an 8000-a-side hfield twice), cached by
    :func:`_base_plan`; only the engine settings are made per case
    (:func:`~spine_mj.sim.build.plan_settings`). The same plan as
    :func:`~spine_mj.sim.build.plan_rig` of :func:`case_inputs` (tested)."""
    surface = case.surface.make() if surface is None else surface
    p = case.params
    key = values_key(p, _BASE_KEYS) + id(case.surface).to_bytes(8, "little")
    if key not in _BASE_PLANS:
        if len(_BASE_PLANS) >= 4096:  # bounded: a grid over many sizings plans each once anyway
            _BASE_PLANS.clear()
        base = {k: p[k] for k in _BASE_KEYS}
        _BASE_PLANS[key] = (case.surface, base, *_base_plan(case.surface, surface, base))  # held
    inputs, sized = _BASE_PLANS[key][2:]
    tip, scales, hfield = sized
    pace = {"ie": p["ie"], "speed_m_s": p["speed"], "rate_n_s": None}
    spring = {"stiffness_number": p["K"], "stiffness_n_m": p["stiffness"]}
    plan = RigPlan(surface, tip, scales, hfield, plan_settings(scales, inputs, pace=pace, spring=spring))
    if has_mujoco_model(inputs.engine):
        return plan
    rig_class = ENGINES[inputs.engine].rig_class()
    return rig_class(surface, tip=plan.tip, engine=plan.engine, sized=(plan.scales, plan.hfield))


#: :func:`case_plan`'s :func:`_base_plan` by the identities of the values and surface (held).
_BASE_PLANS: dict = {}
#: :func:`_on_starts` by the ids of the starts and scales (held, so the ids stay theirs):
#: a grid's cases share a few start sets (resolved once per source) and scales.
_STARTS_CHECKED: dict = {}


def _base_plan(spec, surface, base: dict) -> tuple:
    """``(inputs, sized)`` of a case's parameters ``base`` (:data:`_BASE_KEYS`) on
    ``surface`` (``spec.make()``): its :class:`RigInputs` without the drive's pace and
    spring, checked, and the surface's sizing, after the hfield's limits on the predicted
    sides."""
    inputs = _inputs({**base, **dict.fromkeys(_PACE_KEYS)}, surface)
    check_planned_hfield(surface, inputs)  # before the sizing: its limits on the predicted sides
    return inputs, _sizing(spec, inputs.tip, tuple(inputs.sizing.items()))


def case_scales(case, surface=None) -> sim.Scales:
    """The scales of the rig :func:`case_rig` would build for ``case`` (its tip radius,
    L_c, l_s), without building it: for checks of a config before any case runs."""
    surface = case.surface.make() if surface is None else surface
    inputs = case_inputs(case, surface)
    return sim.rig_scales(surface, tip=inputs.tip, **inputs.sizing)


def _engine(case, surface, starts, upstream):
    p = case.params
    rig = case_rig(case, surface)
    runs = _runs(rig, p, starts)
    # engine trouble is named by its kind: nan, engine_warning, penetration or diverged
    status = np.array([r.engine_trouble or "ok" for r in runs], dtype=object)
    reason = np.array([r.end_detail for r in runs], dtype=object)
    traj = run_trajectories(runs, rig.length_scale_m, p["record_every"])
    return AnalysisResult(
        metrics=run_metrics(rig, runs), trajectories=traj, status=status, reason=reason, data=(rig, runs)
    )


#: The parameters :func:`case_inputs` reads besides ``tip_radius``.
_RIG_KEYS = (
    "engine",
    "ie",  # the drive speed limits the engine step (impacts)
    "speed",
    "K",  # the drive spring's stiffness too (its period)
    "stiffness",
    "mass",
    "mu",
    "preload",
    "gravity",
    "length_scale",
    "hfield_resolution",
    "hfield_refinement",
    *(s.name for s in ENGINE_PARAMS if s.option is not None),  # every engine option
)
#: The drive's pace and spring among them: the keys a grid's cases differ in most.
_PACE_KEYS = ("ie", "speed", "K", "stiffness")
#: The other keys of a case's rig (:func:`_base_plan`).
_BASE_KEYS = tuple(k for k in (*_RIG_KEYS, "tip_radius") if k not in _PACE_KEYS)


def case_drive(rig, p: dict):
    """The drive of a case's parameters ``p`` on ``rig`` (:func:`spine_mj.sim.build_drive`)."""
    return sim.build_drive(
        rig.scales,
        p["protocol"],
        ie=p["ie"],
        speed_m_s=p["speed"],
        stiffness_number=p["K"],
        stiffness_n_m=p["stiffness"],
        duration_s=p["duration"],
        settle_time_s=p["settle_time"],
        start_force_n=p["start_force"],
        slide_distance_m=p["slide_distance"],
    )


def _runs(rig, p: dict, starts) -> list:
    """The runs of ``rig`` from every start with the case's drive."""
    drive = case_drive(rig, p)
    det = sim.Detection(kappa_cap=p["kappa_cap"])
    pts = [tuple(s) for s in starts]
    if p["protocol"] == "ramp":
        return [rig.run(drive, start=s, detection=det) for s in pts]
    return rig.run_batch(drive, pts, detection=det, nthread=CASE_THREADS.get())


#: The parameters :func:`_check_case` reads: the rig's and the drive's.
CHECK_READS = (
    *_RIG_KEYS,
    "tip_radius",
    "protocol",
    "duration",
    "settle_time",
    "start_force",
    "slide_distance",
    "kappa_cap",
)


#: The parameters :func:`precheck_case` reads: the hfield's sizing and the engine taking it.
PRECHECK_READS = ("engine", "tip_radius", "length_scale", "hfield_resolution", "hfield_refinement")


def precheck_case(case, surface) -> None:
    """The hfield's limits (sides, memory, the engine's own) on the sides the sizing rule
    will give (:func:`~spine_mj.sim.build.check_planned_hfield`), without sizing: run on
    every combination of a grid before any case is sized (a grid over both engines at an
    8000-a-side hfield sized MuJoCo's, 29 CPU-s and 2.3 GB, before refusing Bullet's)."""
    check_planned_hfield(surface, case_inputs(case, surface))


def _check_case(case, surface, starts) -> None:
    """The inputs' errors a run would meet, without running: the rig (tip, scales, engine),
    the drive and, for the open-loop drives, the length of the run from the first start."""
    rig = case_plan(case, surface)
    drive = case_drive(rig, case.params)
    rig.check_drive(drive)
    det, x0 = _on_starts(rig, starts, case.params["kappa_cap"])
    if case.params["protocol"] != "ramp" and x0 is not None:
        drive_steps(rig, drive, x0, det)


def _on_starts(rig, starts, kappa_cap) -> tuple:
    """``(detection, x0)``: the detection resolved on ``rig``'s scales and the first start's
    x [m] (None without starts), after refusing starts a run would end at once; once per
    start set, scales and cap (a grid's cases share a few)."""
    key = (id(starts), id(rig.scales), type(kappa_cap), kappa_cap)
    if key not in _STARTS_CHECKED:
        det = sim.Detection(kappa_cap=kappa_cap).resolve(rig.scales)
        rig.check_starts(starts, det.domain_margin_m)
        x0 = float(min(s[0] for s in starts)) * rig.length_scale_m if len(starts) else None
        _STARTS_CHECKED[key] = (starts, rig.scales, det, x0)  # held: the ids stay theirs
    return _STARTS_CHECKED[key][2:]


register_analysis(
    Analysis(
        "engine",
        _engine,
        ENGINE_PARAMS,
        doc="the rig of a registered engine (grid key engine) run from every start with the chosen "
        "drive: spine_mj.sim",
        check_config=check_speed,
        check_case=_check_case,
        check_reads=CHECK_READS,
        precheck_case=precheck_case,
        precheck_reads=PRECHECK_READS,
    )
)

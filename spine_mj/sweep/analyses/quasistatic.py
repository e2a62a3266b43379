"""The ``quasistatic`` analysis: a streamline (or ideal trajectory) from every start.

Touches the API of :mod:`spine_mj.theory.streamline` here only, so that a change there is a
change here in one place.
"""

from __future__ import annotations

import collections
import functools
import hashlib

import numpy as np

from spine_mj.sim.scales import resolve_tip_radius
from spine_mj.surfaces.dilation import dilate
from spine_mj.sweep.registry import (
    KAPPA_CAP_PARAM,
    MU_PARAM,
    TIP_RADIUS_PARAM,
    Analysis,
    AnalysisResult,
    ParamSpec,
    register_analysis,
)
from spine_mj.theory import streamline as sl
from spine_mj.theory.streamline_types import Outcome, StreamlineParams, StreamlineResult

QUASISTATIC_PARAMS = (
    MU_PARAM,
    TIP_RADIUS_PARAM,
    ParamSpec(
        "dl",
        "float",
        "streamline step in the surface's length unit (default: "
        f"{sl.DEFAULT_STEP_FRACTION:g} times the shorter side of the domain, as for spine-mj streamline)",
        None,
        0.0,
        exclusive=True,
    ),
    ParamSpec("max_steps", "int", "step cap per streamline", 200_000, 1),
    ParamSpec("trajectory", "str", "quasistatic path kind", "streamline", choices=("streamline", "ideal")),
    KAPPA_CAP_PARAM,
)


@functools.lru_cache(maxsize=8)  # the presets of sweeps run together (the map: five)
def _dilated(spec, radius: float):
    return dilate(spec.make(), radius)


#: Streamline results a worker process keeps (:func:`cached_trace`), enough for three traces
#: of every surface of the map's five presets run together; each holds its paths,
#: a few MB at most for a sweep case's starts.
TRACE_CACHE_SIZE = 32
_traces: collections.OrderedDict = collections.OrderedDict()


def clear_cache() -> None:
    """Forget the dilated surfaces and the streamlines traced in this process."""
    _dilated.cache_clear()
    _rig_tip_radius.cache_clear()
    _traces.clear()


def cached_trace(trace, surface_key, surface, starts, params: StreamlineParams) -> StreamlineResult:
    """``trace(surface, starts, params, store_paths=True)``, remembered in this process.

    Cases of a sweep that differ only in their drive (the boundary study's I_e ladder, the
    (I_e, K) map) trace the same streamlines from the same starts: the drive enters neither
    the quasistatic reference nor the facets' one. ``surface_key`` is hashable and names
    ``surface`` (a surface spec and tip radius, or :func:`hfield_key` of a rig's facets);
    the starts enter the key by value. The result is shared: callers must not change it.
    """
    starts = np.ascontiguousarray(starts, dtype=float)
    key = (trace.__name__, surface_key, starts.shape, starts.tobytes(), params)
    if key in _traces:
        _traces.move_to_end(key)
        return _traces[key]
    res = trace(surface, starts, params, store_paths=True)
    _traces[key] = res
    while len(_traces) > TRACE_CACHE_SIZE:
        _traces.popitem(last=False)
    return res


def hfield_key(hfield, tip_radius: float) -> tuple:
    """A key of :func:`cached_trace` for a rig's facets under a ball of ``tip_radius``: the
    digest of the hfield's samples, size and position (rigs of different drives share it)."""
    h = hashlib.blake2b(np.ascontiguousarray(hfield.data).tobytes(), digest_size=16)
    return (h.hexdigest(), tuple(hfield.size), tuple(hfield.pos), float(tip_radius))


def case_tip_radius(case, surface) -> float:
    """The tip radius of ``case`` [the surface's length unit]: its ``tip_radius``, or none
    given the rig's default at the case's sizing keys where the sweep has them (the one rule,
    :func:`spine_mj.sim.scales.resolve_tip_radius`): the tip the engine's analysis runs."""
    p = case.params
    if p["tip_radius"] is not None:
        return p["tip_radius"]
    return _rig_tip_radius(case.surface, p.get("length_scale"), p.get("hfield_resolution"))


@functools.lru_cache(maxsize=8)
def _rig_tip_radius(spec, length_scale_m, hfield_resolution) -> float:
    return resolve_tip_radius(
        spec.make(),
        None,
        length_scale_m=length_scale_m,
        hfield_resolution=hfield_resolution,
    )


def traced_surface(case, surface):
    """The surface the quasistatic analysis traces on for ``case``: ``surface`` dilated by
    the case's tip radius (:func:`case_tip_radius`; 0, a point, the surface itself)."""
    r = case_tip_radius(case, surface)
    return _dilated(case.surface, r) if r > 0 else surface


def streamline_params(case, surface) -> StreamlineParams:
    """The streamline parameters of ``case`` on ``surface`` (the traced one)."""
    p = case.params
    dl = p["dl"] if p["dl"] is not None else sl.default_step(surface)
    return StreamlineParams(mu=p["mu"], dl=dl, max_steps=p["max_steps"], kappa_cap=p["kappa_cap"])


def _check_case(case, surface, starts) -> None:
    """The inputs' errors a run would meet: the step on this surface (the parameters'
    own ranges are the schema's)."""
    dl = case.params["dl"]
    sl.check_step(surface, dl if dl is not None else sl.default_step(surface))


def _quasistatic(case, surface, starts, upstream):
    p = case.params
    surface = traced_surface(case, surface)
    params = streamline_params(case, surface)
    dl = params.dl
    func = sl.streamlines if p["trajectory"] == "streamline" else sl.ideal_trajectories
    res = cached_trace(func, (case.surface, case_tip_radius(case, surface)), surface, starts, params)
    names = np.array(["", *[o.name.lower() for o in Outcome]], dtype=object)
    metrics = {
        "outcome": names[res.outcome],
        "self_locked": res.self_locked,  # held: the self-lock region or the force cap
        "end_x": res.end_x,
        "end_y": res.end_y,
        "end_z": res.end_z,
        "n_steps": res.n_steps,
        "path_length": res.n_steps * dl,
        "max_kappa": res.max_kappa,
        "dl_used": np.full(len(res), dl),
    }
    return AnalysisResult(metrics=metrics, trajectories=path_table(res), data=res)


def path_table(res: StreamlineResult) -> dict[str, np.ndarray]:
    """The stored paths of ``res`` as a long table: ``start``, ``step``, ``x``, ``y``, ``z``,
    ``kappa``, ``region`` (surface units)."""
    counts = np.diff(res.offsets)
    return {
        "start": np.repeat(np.arange(len(res)), counts),
        "step": np.arange(res.x.size) - np.repeat(res.offsets[:-1], counts),
        "x": res.x,
        "y": res.y,
        "z": res.z,
        "kappa": res.kappa,
        "region": res.region.astype(np.int8),
    }


register_analysis(
    Analysis(
        "quasistatic",
        _quasistatic,
        QUASISTATIC_PARAMS,
        doc="quasistatic streamline (or ideal trajectory) from every start: spine_mj.theory.streamline",
        check_case=_check_case,
        check_reads=("dl",),
    )
)

"""The ``compare`` analysis: the streamline against MuJoCo per start, lengths over L_c.

Like for like (docs/physics.md §4): the reference streamline is traced on the surface the
MuJoCo tip touches, the rig's hfield facets under a ball of its tip radius, exactly
(:meth:`spine_mj.sim.Rig.contact_surface`), with the quasistatic analysis's mu_s, step and
force cap, and it ends where the engine's run ends (the domain margin from the edges), so
both sides share the geometry, the lock test and the domain. The comparison with the
quasistatic analysis's path (the smooth surface, or whatever it traced; retraced within
the same domain) is kept beside it (``*_smooth``), and the gap between the two streamlines
is the geometry part (``geometry_frechet``). A run that disagrees gets a ``miss_reason``
(:func:`spine_mj.theory.agreement.miss_reason`: the reference restarted along its path). A spring
drive is also compared with the compliant-drive streamline of its own spring
(``compliant_frechet``, ``agree_compliant``; :mod:`spine_mj.theory.compliant`), and where its
reference falls (``reference_slide_fraction`` > 0) with the fall-landing reference, each
fall replaced by the inertial tip on that spring until it lands (``agree_landing``,
``frechet_landing``, ``landing_falls``; :mod:`spine_mj.theory.fall_landing`). A spring
drive too fast for its stiffness to be quasistatic is refused before any run unless the
grid's ``dynamic_drive`` asks for it (:func:`_check_case`). Touches
the API of :mod:`spine_mj.theory.agreement` here only; needs the results of the ``quasistatic`` and
``engine`` analyses of the same case.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.sim.drives import stiffness_n_m
from spine_mj.sim.holding import spring_swing
from spine_mj.sweep.analyses.engine import CHECK_READS, case_drive, case_plan
from spine_mj.sweep.analyses.engine_metrics import peak_drive_over_fp
from spine_mj.sweep.analyses.quasistatic import (
    cached_trace,
    case_tip_radius,
    hfield_key,
    path_table,
    streamline_params,
    traced_surface,
)
from spine_mj.sweep.registry import Analysis, AnalysisResult, ParamSpec, register_analysis
from spine_mj.theory import agreement
from spine_mj.theory import streamline as sl
from spine_mj.theory.compliant import compliant_streamlines
from spine_mj.theory.drive_limits import SWING_BOUND_FP, spring_ie_limits
from spine_mj.theory.fall_landing import FallParams, landing_streamlines
from spine_mj.theory.streamline_types import Outcome, StreamlineResult


def _xy(res: StreamlineResult, i: int) -> np.ndarray:
    """Path ``i`` of ``res`` as ``(n, 2)`` x, y."""
    q = res.path(i)
    return np.column_stack([q["x"], q["y"]])


def _deviations(mpaths, qpaths: dict, lc: float, *, lateral: bool = True):
    """Frechet and (with ``lateral``) mean lateral deviation of MuJoCo path ``i`` from
    ``qpaths[i]`` (``(n, 2)``, its streamline) for each ``i`` in ``qpaths``; NaN elsewhere."""
    frechet = np.full(len(mpaths), np.nan)
    side = np.full(len(mpaths), np.nan)
    for i, qpath in qpaths.items():
        if mpaths[i].shape[0] == 0:
            continue
        frechet[i] = agreement.path_frechet(mpaths[i], qpath, length_scale=lc)
        if lateral:
            side[i] = agreement.mean_lateral_deviation(mpaths[i], qpath, length_scale=lc)
    return frechet, side


def _paths(res: StreamlineResult, idx) -> dict:
    """Path ``j`` of ``res`` under the run index ``idx[j]``."""
    return {int(i): _xy(res, j) for j, i in enumerate(idx)}


def _outcomes(qs: StreamlineResult, mj_locked, mj_end, lc: float) -> dict[str, np.ndarray]:
    """Outcome agreement; a reference that stalled decided nothing, so its run disagrees."""
    out = agreement.outcome_agreement(
        qs.self_locked, np.column_stack([qs.end_x, qs.end_y]), mj_locked, mj_end, length_scale=lc
    )
    out["agree"] = out["agree"] & (qs.outcome != Outcome.STALLED)
    return out


#: Checkpoints along a disagreeing MuJoCo path from which the reference is restarted to
#: tell why it disagrees (:func:`spine_mj.theory.agreement.miss_reason`): evenly spaced in arc
#: length, the first at the path's start, the last at its end.
MISS_CHECKPOINTS = 16


def _miss_reasons(contact, params, trace, mpaths, facets, mj_locked, mj_end, lc, miss):
    """``miss_reason`` and ``miss_offset`` of each run; empty and NaN where it agrees.

    The separatrix offset is one facet (the hfield spacing): closer to the reference than
    that, the engine's tip cannot follow it."""
    reason = np.full(len(mpaths), "", dtype=object)
    offset = np.full(len(mpaths), np.nan)
    stalled = miss & (facets.outcome == Outcome.STALLED)
    reason[stalled] = "reference_stalled"
    runs = [i for i in np.flatnonzero(miss & ~stalled) if mpaths[i].shape[0] > 0]
    if not runs:
        return reason, offset
    k = MISS_CHECKPOINTS
    xmin, xmax, ymin, ymax = contact.bounds
    points = []
    for i in runs:
        path = mpaths[i]
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
        at = np.minimum(np.searchsorted(arc, np.linspace(0.0, arc[-1], k)), len(path) - 1)
        # a tip that left the domain ends past its edge: its checkpoints there restart on it
        points.append(np.column_stack([np.clip(path[at, 0], xmin, xmax), np.clip(path[at, 1], ymin, ymax)]))
    restarts = trace(contact, np.vstack(points), params, store_paths=False)
    # a restart reaches the run's outcome as the reference agrees with it: a stall reaches none
    reaches = _outcomes(restarts, np.repeat(mj_locked[runs], k), np.repeat(mj_end[runs], k, axis=0), lc)[
        "agree"
    ]
    facet = float(contact.facets.x[1] - contact.facets.x[0]) / lc
    for n, i in enumerate(runs):
        reason[i], offset[i] = agreement.miss_reason(
            points[n],
            _xy(facets, i),
            reaches[n * k : (n + 1) * k],
            bool(mj_locked[i]),
            length_scale=lc,
            separatrix_offset=facet,
        )
    return reason, offset


def _compliant(reference, starts, runs, rig, mujoco, lead) -> dict:
    """MuJoCo (``mujoco``: the runs' ``(locked, end, paths, L_c)``) against the
    compliant-drive streamline of the run's own spring
    (:mod:`spine_mj.theory.compliant`, ``k / W`` from the run), traced like the rigid reference:
    what stiffness does is predicted there, what is left over is inertia. NaN for drives
    without a spring and for the starts not in ``lead`` (an ensemble's perturbed members, or every
    start where ``compliant_reference`` is off).
    ``stiffness_frechet`` is the compliant reference's distance from the rigid one,
    ``compliant_jumps`` its folds. The reference's carriage stops where the run's does
    (``carriage_end``); ``reference`` is the rigid one's ``(trace, contact, params, result)``."""
    _, contact, params, facets = reference
    mj_locked, mj_end, mpaths, lc = mujoco
    preload_n, s = rig.scales.preload_n, rig.length_scale_m
    n = len(runs)
    out = {
        k: np.full(n, np.nan)
        for k in ("compliant_frechet", "agree_compliant", "compliant_jumps", "stiffness_frechet")
    }
    k = runs[0].stiffness_n_m if n else 0.0
    if not (k > 0) or not lead.any():
        return out
    idx = np.flatnonzero(lead)
    starts = np.asarray(starts, float)[idx]
    runs = [runs[i] for i in idx]
    # where the run's drive ran out, the carriage stops where the run's did: a soft spring's
    # reference is not held at a force cap the engine's carriage never reached (a run that
    # ended on an event, a lock or the edge, has its own outcome to compare)
    travel = np.array(
        [
            (r.carriage_x_m[-1] - r.carriage_x_m[r.drive_start_index]) / s
            if r.end_reason.value == "completed"
            else np.inf
            for r in runs
        ]
    )
    end = starts[:, 0] + np.where(np.isfinite(travel), np.maximum(travel, 0.0), np.inf)
    ref = compliant_streamlines(contact, starts, params, stiffness=k * s / preload_n, carriage_end=end)
    out["compliant_frechet"] = _deviations(mpaths, _paths(ref, idx), lc, lateral=False)[0]
    out["agree_compliant"][idx] = _outcomes(ref, mj_locked[idx], mj_end[idx], lc)["agree"]
    out["compliant_jumps"][idx] = np.bincount(ref.folds.start, minlength=idx.size)
    out["stiffness_frechet"][idx] = [
        agreement.path_frechet(_xy(ref, j), _xy(facets, i), length_scale=lc) for j, i in enumerate(idx)
    ]
    return out


def fall_params(scales, *, stiffness_n_m, speed_m_s, timestep_s, length_scale_m, duration_s) -> FallParams:
    """The falls of a spring-drive run's landing reference
    (:mod:`spine_mj.theory.fall_landing`): the rig's own tip mass, load ``F_p``, spring and
    carriage pace, integrated at the engine's step, none longer than the run."""
    return FallParams(
        mass_kg=scales.mass_kg,
        load_n=scales.preload_n,
        spring_n_m=stiffness_n_m,
        speed_m_s=speed_m_s,
        length_scale_m=length_scale_m,
        timestep_s=timestep_s,
        max_fall_s=max(duration_s, timestep_s),
    )


def landing_verdicts(contact, params, trace, starts, fall: FallParams, mj_locked, mj_end, mpaths, lc) -> dict:
    """MuJoCo against the fall-landing reference from ``starts`` ``(m, 2)`` (traced with
    ``trace`` and ``params`` on ``contact``, as the facets' reference): ``agree_landing``
    (the outcome rule of :func:`_outcomes`), ``frechet_landing`` (over L_c) and
    ``landing_falls`` (falls the reference took), ``(m,)`` each; ``mj_locked``, ``mj_end``
    and ``mpaths`` are the runs' of those starts."""
    ref = landing_streamlines(contact, np.asarray(starts, float), params, fall, trace=trace)
    frechet = _deviations(mpaths, {j: _xy(ref, j) for j in range(len(ref))}, lc, lateral=False)[0]
    return {
        "agree_landing": _outcomes(ref, mj_locked, mj_end, lc)["agree"].astype(float),
        "frechet_landing": frechet,
        "landing_falls": ref.meta["falls"].astype(float),
    }


def _landing(reference, starts, runs, rig, mujoco, lead) -> dict:
    """The spring-drive runs of ``lead`` whose facets' reference (``(trace, contact, params,
    result)``) falls somewhere (:func:`spine_mj.theory.agreement.slide_fraction` > 0) against
    the fall-landing reference (:func:`landing_verdicts`; ``mujoco``: the runs' ``(locked,
    end, paths, L_c)``); NaN for the others and for drives without a spring."""
    trace, contact, params, facets = reference
    mj_locked, mj_end, mpaths, lc = mujoco
    n = len(runs)
    out = {k: np.full(n, np.nan) for k in ("agree_landing", "frechet_landing", "landing_falls")}
    falls = [
        i
        for i in np.flatnonzero(lead)
        if agreement.slide_fraction(_xy(facets, i), facets.path(i)["region"]) > 0
    ]
    idx = np.array(falls, dtype=np.int64)
    k = runs[0].stiffness_n_m if n else 0.0
    if not (k > 0) or not idx.size:
        return out
    r = runs[0]
    fall = fall_params(
        rig.scales,
        stiffness_n_m=k,
        speed_m_s=r.speed_m_s,
        timestep_s=r.engine.timestep_s,
        length_scale_m=rig.length_scale_m,
        duration_s=max(float(run.time_s[-1]) for run in runs),
    )
    got = landing_verdicts(
        contact,
        params,
        trace,
        np.asarray(starts, float)[idx],
        fall,
        mj_locked[idx],
        mj_end[idx],
        [mpaths[i] for i in idx],
        lc,
    )
    for key, v in got.items():
        out[key][idx] = v
    return out


def _pace(facets, runs, scales) -> dict:
    """Whether the paths are quasistatic at all: the share of the reference's path that
    gravity slides alone, and the engine tip's own peak speed as an inertia number (falls
    go at gravity's pace, whatever the drive's)."""
    return {
        "reference_slide_fraction": np.array(
            [agreement.slide_fraction(_xy(facets, i), facets.path(i)["region"]) for i in range(len(facets))]
        ),
        "tip_peak_ie": np.array(
            [scales.inertia_number(agreement.peak_speed(r.velocity_m_s[r.drive_start_index :])) for r in runs]
        ),
    }


def _references(case, surface, starts, quasistatic, rig, runs, lead):
    """The two references of a comparison (:func:`cached_trace`: the same for every drive):
    the smooth surface's streamline from the ensembles' first members and the facets' from
    every start, both ending where the engine's runs end, with the facets' parameters."""
    trace = sl.ideal_trajectories if quasistatic.ideal else sl.streamlines
    # both sides end where the engine's run ends, its domain margin from the edges (a path
    # traced to the very edge is a tip radius longer: measured on the random Gaussian, that
    # tail alone made the Frechet distance 0.12 L_c where the paths were 0.01-0.03 apart)
    margin = dataclasses.replace(
        quasistatic.params, edge_margin=runs[0].detection.domain_margin_m / rig.length_scale_m
    )
    smooth_surface = traced_surface(case, surface)
    smooth_key = (case.surface, case_tip_radius(case, surface))
    smooth = cached_trace(trace, smooth_key, smooth_surface, np.asarray(starts, float)[lead], margin)
    contact = rig.contact_surface()
    params = facet_params(margin, contact)
    facets = cached_trace(trace, hfield_key(rig.hfield, contact.radius), contact, starts, params)
    return trace, smooth, contact, params, facets


def facet_params(params, contact):
    """The facets' reference's parameters: ``params`` (with the run's domain margin as
    ``edge_margin``) with steps no longer than an eighth of the tip radius of ``contact``: a
    longer step can jump a crease between facets where the engine's tip wedges (measured on a
    fractal: dl = R/2 passed a crease of kappa > 20 where MuJoCo held; R/8 held within 0.003
    L_c)."""
    return dataclasses.replace(params, dl=min(params.dl, contact.radius / 8))


def facet_reference(case, surface, rig, domain_margin: float):
    """``(trace, contact, params)`` of the facets' reference of a stored ``case`` on its
    ``rig`` (:func:`spine_mj.sweep.analyses.engine.case_rig`), ending ``domain_margin``
    (surface units: the runs' domain margin) from the edges, as :func:`_compare` traces it:
    to judge stored runs again without running them."""
    traced = traced_surface(case, surface)
    trace = sl.streamlines if case.params["trajectory"] == "streamline" else sl.ideal_trajectories
    margin = dataclasses.replace(streamline_params(case, traced), edge_margin=domain_margin)
    contact = rig.contact_surface()
    return trace, contact, facet_params(margin, contact)


def _compare(case, surface, starts, upstream):
    rig, runs = upstream["engine"].data
    s = rig.length_scale_m
    # an ensemble's perturbed members (every start but each group's first) decide only their
    # outcome on both sides (validate.ensembles): the paths' distances, the smooth surface's
    # streamline, the compliant one and the miss reasons are the first member's alone
    members = int(case.params["ensemble_members"])
    lead = np.arange(len(runs)) % members == 0
    trace, smooth, contact, params, facets = _references(
        case, surface, starts, upstream["quasistatic"].data, rig, runs, lead
    )
    lc = rig.scales.char_length_m / s
    status = np.array(
        upstream["engine"].status if upstream["engine"].status is not None else np.full(len(runs), "ok"),
        dtype=object,
    )
    # a run the engine failed (diverged, stopped) has no path to compare: an empty one
    mpaths = [
        r.position_m[r.drive_start_index :, :2] / s if ok else np.empty((0, 2))
        for r, ok in zip(runs, status == "ok", strict=True)
    ]
    idx = np.flatnonzero(lead)
    smooth_paths = _paths(smooth, idx)
    frechet, lateral = _deviations(mpaths, {int(i): _xy(facets, i) for i in idx}, lc)
    frechet_smooth, _ = _deviations(mpaths, smooth_paths, lc, lateral=False)
    geometry = np.full(len(runs), np.nan)
    geometry[idx] = [agreement.path_frechet(_xy(facets, i), smooth_paths[i], length_scale=lc) for i in idx]
    mj_locked = np.array([r.end_reason.value == "self_lock" for r in runs])
    mj_end = np.array([r.position_m[-1, :2] / s for r in runs])
    agree = _outcomes(facets, mj_locked, mj_end, lc)
    agree_smooth = np.full(len(runs), np.nan) if members > 1 else np.zeros(len(runs), bool)
    agree_smooth[lead] = _outcomes(smooth, mj_locked[lead], mj_end[lead], lc)["agree"]
    explain = ~agree["agree"] & (status == "ok") & bool(case.params["miss_reasons"]) & lead
    miss_reason, miss_offset = _miss_reasons(
        contact, params, trace, mpaths, facets, mj_locked, mj_end, lc, explain
    )
    ref, mine = (trace, contact, params, facets), (mj_locked, mj_end, mpaths, lc)
    compliant = _compliant(ref, starts, runs, rig, mine, lead & bool(case.params["compliant_reference"]))
    peak = np.array([peak_drive_over_fp(r, rig.scales.preload_n) for r in runs])
    kap = agreement.kappa_agreement(facets.max_kappa, peak, kappa_cap=runs[0].detection.kappa_cap)
    metrics = {
        "frechet": frechet,
        "lateral_deviation": lateral,
        "end_distance": np.linalg.norm(np.column_stack([facets.end_x, facets.end_y]) - mj_end, axis=1) / lc,
        "agree_lock": agree["lock"],
        "agree_end": agree["end"],
        "same_trap": agree["same_trap"],
        "agree": agree["agree"],
        "miss_reason": miss_reason,
        "miss_offset": miss_offset,
        "reference_outcome": np.array(facets.outcome_names, dtype=object),
        "reference_max_kappa": facets.max_kappa,
        "frechet_smooth": frechet_smooth,
        "agree_smooth": agree_smooth,
        "geometry_frechet": geometry,
        **compliant,
        "kappa_ratio": kap["ratio"],
        "inertia_number": np.array([r.inertia_number for r in runs]),
        **_pace(facets, runs, rig.scales),
        **_landing(
            ref, starts, runs, rig, mine, lead & bool(case.params["landing_reference"]) & (status == "ok")
        ),
    }
    reason = np.where(
        status == "ok",
        "",
        f"{case.params['engine']} run: " + np.asarray(upstream["engine"].reason, dtype=object),
    ).astype(object)
    status = np.where(status == "ok", "ok", "dependency_failed").astype(object)
    # the trajectories are the facet-traced reference paths
    return AnalysisResult(metrics=metrics, trajectories=path_table(facets), status=status, reason=reason)


def _check_case(case, surface, starts) -> None:
    """Refuse a spring drive too fast for its stiffness to be compared with the quasistatic
    streamline (unless ``dynamic_drive``): its spring-block swing ``sqrt(I_e K L_c / l_s)``
    (:func:`spine_mj.sim.holding.spring_swing`) above
    :data:`~spine_mj.theory.drive_limits.SWING_BOUND_FP` preloads.

    Why (docs/physics.md §8): the swing is the force the spring rings with about what the tip
    holds, and ``2 pi`` swings are what the drive adds within one period of the spring. On the
    paper fractal (L_c / l_s = 29, I_e = 1e-4, 36 starts) a swing of 2.9 F_p (K = 3000) left
    the tip in contact 20 % of its run and 9.3 F_p (K = 30000) 7 %, against 66 % at 0.29 F_p
    (K = 30): the tip hops, and at K = 30000 the force cap fires at the ringing's turning
    points (the force averaged over a spring period below 1 F_p at 27 of 36 such locks).
    Outcome agreement fell from 34/36 to 25/36 and 11/36; K = 3000 at I_e = 1e-5 (0.93 F_p)
    agreed 34/36."""
    if case.params["protocol"] != "spring" or case.params["dynamic_drive"]:
        return
    rig = case_plan(case, surface)
    drive = case_drive(rig, case.params)
    sc = rig.scales
    k_number = sc.stiffness_number(stiffness_n_m(drive, sc))
    ie = sc.inertia_number(drive.speed_m_s)
    ratio = sc.char_length_m / sc.slope_length_m
    swing = spring_swing(ie, k_number, ratio)
    if swing > SWING_BOUND_FP:
        ie_max = spring_ie_limits(k_number, ratio)["swing-force"]
        raise SpineInputError(
            f"spring drive at I_e = {ie:.3g}, K = {k_number:.5g}: compared with the quasistatic "
            f"streamline it must swing at most {SWING_BOUND_FP:g} F_p (spring-block swing "
            f"sqrt(I_e K L_c / l_s), L_c / l_s = {ratio:.3g} here), got {swing:.3g} F_p, a drive "
            f"too fast for its stiffness (the tip rings and hops); use I_e <= {ie_max:.3g} at this "
            "K, or set compare's dynamic_drive = true to study the dynamic drive on purpose"
        )


register_analysis(
    Analysis(
        "compare",
        _compare,
        (
            ParamSpec(
                "miss_reasons",
                "bool",
                "tell why each disagreeing run disagrees (miss_reason): the reference restarted "
                f"from {MISS_CHECKPOINTS} points of its MuJoCo path, a trace each",
                True,
            ),
            ParamSpec(
                "compliant_reference",
                "bool",
                "also compare with the compliant-drive streamline of the run's own spring "
                "(agree_compliant, compliant_frechet, compliant_jumps, stiffness_frechet); off: "
                "those columns NaN (a refinement level, judged on the rigid reference alone: "
                "on a grit's facets the compliant reference creeps along creases and is most "
                "of a case's time)",
                True,
            ),
            ParamSpec(
                "landing_reference",
                "bool",
                "also compare the runs whose reference falls (reference_slide_fraction > 0) "
                "with the fall-landing reference, each fall replaced by the inertial tip on the "
                "run's spring until it lands (agree_landing, frechet_landing, landing_falls; "
                "spine_mj.theory.fall_landing); off (the default): those columns NaN. It "
                "steps each fall at the engine's step in Python: on the scan di-1 it took "
                "2187 of the quick plan's 2284 CPU-s",
                False,
            ),
            ParamSpec(
                "ensemble_members",
                "int",
                "starts come in ensembles of this many, a start and its perturbed copies "
                "(spine_mj.validate.ensembles): the copies get their outcome only, no path "
                "distances, smooth or compliant reference or miss reasons",
                1,
                1,
            ),
            ParamSpec(
                "dynamic_drive",
                "bool",
                "compare a spring drive too fast for its stiffness on purpose (spring-block swing "
                f"sqrt(I_e K L_c / l_s) above {SWING_BOUND_FP:g} F_p); off: such a case is refused "
                "before any run",
                False,
            ),
        ),
        requires=("quasistatic", "engine"),
        doc="MuJoCo against the streamline traced on the rig's facets dilated by its tip "
        "(like for like), and against the quasistatic analysis's own path (*_smooth); "
        "why a run disagrees (miss_reason, miss_offset); "
        "lengths over L_c: spine_mj.theory.agreement",
        check_case=_check_case,
        check_reads=(*CHECK_READS, "dynamic_drive"),
    )
)

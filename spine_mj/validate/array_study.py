"""Study: spine arrays, and the paper's staggered-array conjecture in dynamics.

The paper ends on arrays: "multi-spine arrays with staggered spatial layouts may increase
the probability that at least one spine samples a favorable concave region". On a random
Gaussian (paper-random-concave), a fractal (paper-fractal) and a sandpaper (P60) surface,
arrays of ``N = side^2`` spines (side 1 to 8) are dragged under displacement control
(the spring drive, ``K = 30`` per spine) over :data:`TRAVEL_LS` slope lengths, laid out as
an aligned grid, a staggered grid and a random pattern of one footprint at spacings in
multiples of ``l_s``. Each (surface, N, spacing) draws ``placements`` array centres once
(seeded) and runs every layout at the same centres, so the layouts are compared pairwise
on the same patches of surface.

**Holding, extrapolated to the quasistatic drive.** The holding force per spine is the
largest total spring force over the travel over ``N F_p`` (``ArrayResult.peak_ratio``),
the quantity the quasistatic reference computes (the maximum of its summed curve; the
let-go reading ``holding_ratio`` stops where the array first lets go, a single spine's
first slip, where the reference's curve goes on). Its dynamic excess over the quasistatic curve is the
spring-block swing, ``sqrt(I_e K L_c / l_s)`` per spine (:func:`~spine_mj.sim.holding.spring_swing`):
first order in ``sqrt(I_e)``, and 0.85 ``F_p`` on the fractal at ``I_e = 1e-3``
(``L_c / l_s = 24``). A pace whose swing is 1 % of the holding (~3 ``F_p`` there) or of
``mu F_p`` (mu 1.25) costs 30 to 70 times the steps of ``I_e = 1e-3``, so the study runs each
configuration at the plan's :attr:`ArrayPlan.paces`, each a
quarter of the one before (the carriage's speed halved, the swing halved), at the same
placements, and extrapolates each placement's holding to ``I_e -> 0`` by Richardson's
step of order 1 in ``sqrt(I_e)`` from the two slowest paces (:func:`extrapolate_to_rest`;
the order the swing predicts, never fitted). With three paces the observed order of the
means is reported beside it. A row's holding is *converged* when its extrapolation step
(the extrapolated mean minus the slowest pace's) lies inside the slowest pace's own 95 %
bootstrap interval (:func:`~spine_mj.validate.convergence.is_converged`): the pace moves
it less than the placements already leave open; otherwise it is marked unconverged. The
predicted swing at the slowest pace is stated beside it. Where the plan asks
(``dt_check``), the grid layout is run again at the fastest pace with the engine's step
halved (the contact's time constant kept), and each holding's change and verdict are
reported (``dt_halved``).

The probability that at least one spine self-locks (its spring at ``kappa_cap F_p`` while
stuck; Wilson interval, :func:`~spine_mj.validate.fractal_lock.lock_rate`) is read at the
slowest pace, with its change from the pace before and the same verdict, from MuJoCo
and from the quasistatic reference: each spine on its own compliant-drive streamline
(:func:`~spine_mj.theory.compliant.compliant_streamlines`, same friction, spring, force cap and
domain margin), the array's curve their sum (:mod:`spine_mj.theory.array_reference`). Like the
single spine's comparison, agreement is the share of spines whose lock verdict matches
(target :data:`~spine_mj.theory.targets.OUTCOME_TARGET`). The conjecture is answered by the
difference staggered - aligned (and random - aligned) in the lock probability (Newcombe's
interval from the two Wilson intervals) and in the extrapolated holding per spine
(paired bootstrap).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import bootstrap

from spine_mj import presets, sim
from spine_mj.sim.drives import stiffness_n_m
from spine_mj.sim.holding import spring_swing
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory.array_reference import compliant_spine_curves
from spine_mj.theory.compliant import compliant_streamlines
from spine_mj.theory.streamline_types import StreamlineParams
from spine_mj.theory.targets import OUTCOME_TARGET
from spine_mj.validate.convergence import is_converged, observed_order, richardson
from spine_mj.validate.fractal_lock import CONFIDENCE, lock_rate
from spine_mj.validate.intervals import newcombe_difference
from spine_mj.validate.plans import SANDPAPER_MU, ValidationPlan
from spine_mj.validate.sweep_configs import surface_inputs

__all__ = [
    "ARRAY_PLANS",
    "PACE_RATIO",
    "ArrayPlan",
    "ArrayStudyResult",
    "array_study",
    "extrapolate_to_rest",
]

#: Inertia number of the arrays' fastest pace (per spine, as the single rig's I_e).
ARRAY_IE = 1e-3
#: Each pace's I_e over the next slower one's: the carriage's speed halves, and with it the
#: spring-block swing (first order in sqrt(I_e)).
PACE_RATIO = 4.0
#: The holding's dynamic excess's order in ``sqrt(I_e)`` (the spring-block swing).
EXCESS_ORDER = 1.0
#: Carriage travel of each run, in slope lengths l_s.
TRAVEL_LS = 3.0
#: The study's surfaces: (key, preset, mu or None for the preset's own).
SURFACES = (
    ("random_gaussian", "paper-random-concave", None),
    ("fractal", "paper-fractal", None),
    ("sandpaper", "sandpaper-P60", SANDPAPER_MU),
)
LAYOUTS = ("grid", "staggered", "random")
#: The spacing unit is l_s, or this many tip radii where the tip is wider (the fractal's
#: l_s is 1.6 tip radii, the sandpaper's 0.66): spines never stand closer than 1.5 tip
#: diameters, and a random pattern of 1-diameter gaps covers at most 35 % of its footprint,
#: below the 55 % jamming limit. Spacings are reported in l_s as run.
MIN_SPACING_TIP_RADII = 3.0
#: The reference's step cap, in steps of dl per unit of carriage travel (the tip moves less
#: than the carriage; halved steps at creases and grit edges need the margin).
REFERENCE_STEPS_PER_TRAVEL = 4
#: Streamline step, in l_s.
DL_LS = 0.01


@dataclass(frozen=True)
class ArrayPlan:
    """The study's size: array sides (``N = side^2``), spacings (in units of
    ``max(l_s, MIN_SPACING_TIP_RADII r_tip)``), placements per configuration, surfaces,
    bootstrap resamples, the number of paces (from :data:`ARRAY_IE` down by
    :data:`PACE_RATIO`; two at least, for the extrapolation) and whether the grid layout is
    rerun with the engine's step halved (``dt_check``)."""

    sides: tuple[int, ...]
    spacings_ls: tuple[float, ...]
    placements: int
    surfaces: tuple[str, ...] = tuple(s[0] for s in SURFACES)
    bootstrap: int = 500
    hfield_resolution: int | None = 151
    n_paces: int = 2
    dt_check: bool = False

    @property
    def paces(self) -> tuple[float, ...]:
        """The paces' I_e, fastest first."""
        return tuple(ARRAY_IE / PACE_RATIO**i for i in range(self.n_paces))


def _median_rel_error(measured, reference) -> float:
    """Median of ``|measured / reference - 1|`` over the placements whose reference holds
    at all (a reference holding of 0 has no relative error: left out, not infinite)."""
    measured, reference = np.asarray(measured, float), np.asarray(reference, float)
    held = reference > 0
    if not held.any():
        return math.nan
    return float(np.nanmedian(np.abs(measured[held] / reference[held] - 1)))


def extrapolate_to_rest(slow, fast):
    """Richardson's extrapolation of a holding to ``I_e -> 0`` from two paces, ``fast`` at
    :data:`PACE_RATIO` times ``slow``'s I_e (arrays of equal shape, or floats): the excess
    is first order in ``sqrt(I_e)`` (:data:`EXCESS_ORDER`, the spring-block swing), so
    ``slow + (slow - fast) / (sqrt(PACE_RATIO) - 1)``."""
    return richardson(
        np.asarray(slow, float), np.asarray(fast, float), EXCESS_ORDER, ratio=math.sqrt(PACE_RATIO)
    )


ARRAY_PLANS = {
    "smoke": ArrayPlan(
        sides=(1, 2), spacings_ls=(1.0,), placements=3, surfaces=("fractal",), bootstrap=50, dt_check=True
    ),
    # the demo: 1 and 2 x 2 spines (4 x 4 cost four times both together)
    "quick": ArrayPlan(sides=(1, 2), spacings_ls=(1.0,), placements=6, bootstrap=300),
    # N = 64 would cost three times the rest of the study together (a run's cost grows as N
    # and the slowest of three paces runs four times the fastest's time): the full plan
    # stops at 4 x 4, as the quick one, with the second spacing, the third pace and dt / 2
    "full": ArrayPlan(
        sides=(1, 2, 4), spacings_ls=(1.0, 1.5), placements=6, bootstrap=1000, n_paces=3, dt_check=True
    ),
}


@dataclass
class ArrayStudyResult:
    """Rows per (surface, N, spacing, layout), the conjecture's differences, the plan and
    the holding's solution verification (``convergence``: ``pace``, the extrapolation's
    verdicts; ``dt_halved``, the step's, where the plan ran it)."""

    rows: list[dict] = field(default_factory=list)
    conjecture: list[dict] = field(default_factory=list)
    pooled: dict = field(default_factory=dict)
    plan: dict = field(default_factory=dict)
    convergence: dict = field(default_factory=dict)

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {"arrays": self.as_dict()}

    def as_dict(self) -> dict:
        return {
            "rows": self.rows,
            "conjecture": self.conjecture,
            "pooled": self.pooled,
            "plan": self.plan,
            "convergence": self.convergence,
        }


def _mean_ci(values, n_resamples: int, seed: int) -> tuple[float, float, float]:
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return math.nan, math.nan, math.nan
    if v.size < 2 or np.ptp(v) == 0:
        return float(v.mean()), float(v.mean()), float(v.mean())
    ci = bootstrap(
        (v,),
        np.mean,
        n_resamples=n_resamples,
        confidence_level=CONFIDENCE,
        method="percentile",
        random_state=seed,
    ).confidence_interval
    return float(v.mean()), float(ci.low), float(ci.high)


def _rig(preset: str, mu: float | None, plan: ArrayPlan, ie: float, *, timestep_factor: float = 1.0):
    """The surface's rig at pace ``ie`` (the engine's default step at that speed, times
    ``timestep_factor`` with the contact's time constant kept) and the carriage's speed."""
    surf = presets.make_surface(preset)
    mu = presets.resolve_mu(surf, mu)
    tip = sim.TipParams(mu_s=mu)
    res = plan.hfield_resolution if surf.unit == "1" else None
    sized = sim.Scales.with_hfield(surf, tip=tip, hfield_resolution=res)
    sc = sized[0]
    speed = sc.speed_for(ie)
    engine = sim.default_engine(sc, speed_m_s=speed)
    if timestep_factor != 1.0:
        engine = sim.default_engine(
            sc, speed_m_s=speed, timestep_s=engine.timestep_s * timestep_factor, solref=engine.solref
        )
    return sim.Rig(surf, tip=tip, engine=engine, sized=sized), speed


def _centres(
    rig, side: int, spacing: float, travel: float, count: int, seed: int
) -> list[tuple[float, float]]:
    """``count`` centres (surface units) where a ``side x side`` footprint of ``spacing``
    and the travel after it stay on the surface (two tip radii in)."""
    xmin, xmax, ymin, ymax = rig.surface.bounds
    half = side * spacing / 2 + 2 * rig.tip.tip_radius_m / rig.length_scale_m
    lo_x, hi_x = xmin + half, xmax - half - travel
    lo_y, hi_y = ymin + half, ymax - half
    if hi_x <= lo_x or hi_y <= lo_y:
        return []
    rng = np.random.default_rng(seed)
    return list(zip(rng.uniform(lo_x, hi_x, count), rng.uniform(lo_y, hi_y, count)))


def _reference(rig, drive, groups: list[list], travel: float, det) -> list[tuple[np.ndarray, np.ndarray]]:
    """Quasistatic holding ratio ``(P,)``, per-spine locks ``(P, N)`` and paths that ended
    before the travel ``(P, N)`` of each group of runs: every spine of every group on its
    compliant-drive streamline over the surface dilated by the tip (what its centre rides
    on), in one call (the streamline is vectorized over starts: one call costs about as
    much as one path), each stopped where its carriage's travel ends (``carriage_end``). A
    path that ended earlier (the domain's edge, the step cap) adds nothing past its end."""
    s = rig.length_scale_m
    c = stiffness_n_m(drive, rig.scales) * s / rig.scales.preload_n
    ls = rig.scales.slope_length_m / s
    params = StreamlineParams(
        mu=rig.tip.mu_s,
        dl=DL_LS * ls,
        kappa_cap=det.kappa_cap,
        edge_margin=det.domain_margin_m / s,
        max_steps=int(REFERENCE_STEPS_PER_TRAVEL * travel / (DL_LS * ls)) + 100,
    )
    starts = np.concatenate([r.start_xy for runs in groups for r in runs])
    traced = dilate(rig.surface, rig.tip.tip_radius_m / s)  # the surface the tip's centre rides on
    # the carriage runs two steps past the travel: a path's last point, where the carriage
    # stops mid-step, is not on the curve (the tip is left a step ahead of its equilibrium)
    end = starts[:, 0] + travel + 2 * params.dl
    paths = compliant_streamlines(traced, starts, params, stiffness=c, carriage_end=end)
    forces, locked = compliant_spine_curves(paths, np.linspace(0.0, travel, 400), kappa_cap=det.kappa_cap)
    short = np.isnan(forces[:, -1])  # the path ended (domain edge, step cap) before the travel did
    out, at = [], 0
    for runs in groups:
        n, p = runs[0].n_spines, len(runs)
        f = forces[at : at + n * p].reshape(p, n, -1)
        hold = np.array([np.nanmax(np.nansum(g, axis=0)) / n for g in f])
        out.append((hold, locked[at : at + n * p].reshape(p, n), short[at : at + n * p].reshape(p, n)))
        at += n * p
    return out


def _swing(rig, drive) -> float:
    """The spring-block swing ``sqrt(I_e K L_c / l_s)`` [F_p per spine] the holding (the
    largest force over the travel) can carry above the quasistatic one at ``drive``'s pace."""
    sc = rig.scales
    return spring_swing(
        sc.inertia_number(drive.speed_m_s),
        sc.stiffness_number(stiffness_n_m(drive, sc)),
        sc.char_length_m / sc.slope_length_m,
    )


def _surface_runs(rig, speed, plan: ArrayPlan, layouts=LAYOUTS):
    """Every MuJoCo array run on one surface at one pace: ``[(config, runs)]`` with
    ``config`` the (side, nominal spacing, spacing [l_s], layout, seed) and ``runs`` its
    placements (the same centres at every pace)."""
    ls = rig.scales.slope_length_m / rig.length_scale_m
    r_tip = rig.tip.tip_radius_m / rig.length_scale_m
    drive = sim.SpringDrive(speed_m_s=speed, duration_s=TRAVEL_LS * rig.scales.slope_length_m / speed)
    done = []
    for side in plan.sides:
        for nominal in plan.spacings_ls:
            spacing = nominal * max(1.0, MIN_SPACING_TIP_RADII * r_tip / ls)  # in l_s
            seed = 1000 * side + int(100 * nominal)
            centres = _centres(rig, side, spacing * ls, TRAVEL_LS * ls, plan.placements, seed)
            if not centres:
                continue
            for kind in layouts:
                if side == 1 and kind == "staggered":  # one spine: the staggered grid is the grid
                    done.append(((side, nominal, spacing, kind, seed), done[-1][1]))
                    continue
                lay = sim.Layout(
                    kind=kind, rows=side, cols=side, spacing=spacing, spacing_unit="l_s", seed=seed
                )
                runs = sim.ArrayRig(rig, lay).run_batch(drive, centres)
                done.append(((side, nominal, spacing, kind, seed), runs))
    return drive, done


def _holding(runs) -> tuple[np.ndarray, np.ndarray]:
    """Each placement's holding per spine (the curve's peak) and whether it ran cleanly."""
    ok = np.array([r.end_reason != "engine_trouble" for r in runs])
    return np.array([r.peak_ratio for r in runs]), ok


def _row(config, paced, reference, plan: ArrayPlan) -> dict:
    """One configuration's row from its runs at every pace (``paced``: ``[(ie, swing,
    runs)]``, fastest first), with the per-placement extrapolated holdings kept for the
    paired comparisons."""
    side, nominal, spacing, kind, seed = config
    qs_hold, qs_lock, qs_short = reference
    held = [_holding(runs) for _, _, runs in paced]
    ok = np.logical_and.reduce([k for _, k in held])
    by_pace = []
    for (ie, swing, _), (h, _) in zip(paced, held):
        m, lo, hi = _mean_ci(h[ok], plan.bootstrap, seed)
        by_pace.append({"ie": ie, "holding": m, "holding_ci": [lo, hi], "excess_predicted": swing})
    rest = extrapolate_to_rest(held[-1][0], held[-2][0])
    m, lo, hi = _mean_ci(rest[ok], plan.bootstrap, seed)
    slow = by_pace[-1]
    step = m - slow["holding"]
    means = [b["holding"] for b in by_pace]
    order = observed_order(*means[::-1][:3], ratio=math.sqrt(PACE_RATIO)) if len(means) >= 3 else math.nan
    runs = paced[-1][2]
    mj_lock = np.array([r.locked for r in runs])
    agree = (mj_lock == qs_lock)[ok]
    p_lock = lock_rate(mj_lock.any(axis=1), ok)
    p_lock_fast = lock_rate(np.array([r.locked for r in paced[-2][2]]).any(axis=1), ok)
    qm, qlo, qhi = _mean_ci(qs_hold, plan.bootstrap, seed)
    return {
        "layout": kind,
        "n_spines": side * side,
        "spacing_nominal_ls": nominal,
        "spacing_ls": spacing,
        "placements": len(runs),
        "holding_per_spine": m,
        "holding_ci": [lo, hi],
        "holding_by_pace": by_pace,
        "holding_extrapolation_step": step,
        "holding_observed_order": order,
        "holding_excess_predicted": slow["excess_predicted"],
        "holding_converged": is_converged(slow["holding"], step, slow["holding_ci"]),
        "holding_per_spine_qs": qm,
        "holding_qs_ci": [qlo, qhi],
        "holding_rel_error_median": _median_rel_error(rest[ok], qs_hold[ok]),
        "p_lock": p_lock,
        "p_lock_change": p_lock["rate"] - p_lock_fast["rate"] if ok.any() else math.nan,
        "p_lock_converged": is_converged(
            p_lock["rate"], p_lock["rate"] - p_lock_fast["rate"], (p_lock["ci_low"], p_lock["ci_high"])
        )
        if ok.any()
        else None,
        "p_lock_qs": lock_rate(qs_lock.any(axis=1)),
        "lock_agreement": float(agree.mean()) if agree.size else math.nan,
        "meets_outcome_target": bool(agree.size and agree.mean() >= OUTCOME_TARGET),
        "failed_runs": int((~ok).sum()),
        "reference_short_spines": int(qs_short.sum()),
        "_hold": rest.tolist(),
        "_ok": ok.tolist(),
    }


def _dt_halved(row: dict, fast_runs, halved_runs) -> dict:
    """The fastest pace's holding with the engine's step halved: its paired change (over
    the placements both ran cleanly) and whether the halved mean lies inside the default
    step's own 95 % interval."""
    h, ok = _holding(fast_runs)
    h2, ok2 = _holding(halved_runs)
    both = ok & ok2
    change = float((h2 - h)[both].mean()) if both.any() else math.nan
    fast = row["holding_by_pace"][0]
    return {
        "ie": fast["ie"],
        "runs": int(both.sum()),
        "holding_change": change,
        "converged": is_converged(fast["holding"], change, fast["holding_ci"]),
    }


def _paired(a: dict, b: dict, n_resamples: int, seed: int) -> dict:
    """Holding per spine ``a - b`` over the placements both ran cleanly (paired bootstrap)."""
    ok = np.array(a["_ok"]) & np.array(b["_ok"])
    d = (np.array(a["_hold"]) - np.array(b["_hold"]))[ok]
    m, lo, hi = _mean_ci(d, n_resamples, seed)
    return {"diff": m, "ci_low": lo, "ci_high": hi}


def _conjecture(rows: list[dict], plan: ArrayPlan) -> tuple[list[dict], dict]:
    """Staggered - grid and random - grid per (surface, N > 1, spacing), and pooled counts."""
    out = []
    pooled: dict = {}
    keyed = {(r["surface"], r["n_spines"], r["spacing_nominal_ls"], r["layout"]): r for r in rows}
    for (surf, n, sp, kind), base in keyed.items():
        if kind != "grid" or n == 1:
            continue
        for other in ("staggered", "random"):
            r = keyed[(surf, n, sp, other)]
            out.append(
                {
                    "surface": surf,
                    "n_spines": n,
                    "spacing_ls": sp,
                    "layout": other,
                    "p_lock_diff": newcombe_difference(r["p_lock"], base["p_lock"]),
                    "holding_diff": _paired(r, base, plan.bootstrap, n),
                }
            )
            pool = pooled.setdefault(other, {"locked": 0, "n_ok": 0, "locked_grid": 0, "n_ok_grid": 0})
            pool["locked"] += r["p_lock"]["locked"]
            pool["n_ok"] += r["p_lock"]["n_ok"]
            pool["locked_grid"] += base["p_lock"]["locked"]
            pool["n_ok_grid"] += base["p_lock"]["n_ok"]
    for pool in pooled.values():
        a = lock_rate([True] * pool["locked"] + [False] * (pool["n_ok"] - pool["locked"]))
        b = lock_rate([True] * pool["locked_grid"] + [False] * (pool["n_ok_grid"] - pool["locked_grid"]))
        pool.update(
            p_lock=a, p_lock_grid=b, diff=newcombe_difference(a, b) if a["n_ok"] and b["n_ok"] else None
        )
    return out, pooled


def _surface_rows(key: str, preset: str, mu, ap: ArrayPlan) -> list[dict]:
    """One surface's rows: every configuration at every pace, the reference, the step check."""
    paced = []
    for ie in ap.paces:
        rig, speed = _rig(preset, mu, ap, ie)
        drive, done = _surface_runs(rig, speed, ap)
        if not done:
            return []
        paced.append((ie, _swing(rig, drive), drive, done))
    det = sim.Detection().resolve(rig.scales)
    travel = TRAVEL_LS * rig.scales.slope_length_m / rig.length_scale_m
    refs = _reference(rig, drive, [runs for _, runs in done], travel, det)
    halved = {}
    if ap.dt_check:
        rig2, speed2 = _rig(preset, mu, ap, ap.paces[0], timestep_factor=0.5)
        halved = dict(_surface_runs(rig2, speed2, ap, layouts=("grid",))[1])
    rows = []
    for i, ((cfg, _), ref) in enumerate(zip(done, refs)):
        per_pace = [(ie, swing, d[i][1]) for ie, swing, _, d in paced]
        row = {"surface": key, **_row(cfg, per_pace, ref, ap)}
        if cfg in halved:
            row["dt_halved"] = _dt_halved(row, paced[0][3][i][1], halved[cfg])
        rows.append(row)
    return rows


def array_study(plan: ValidationPlan, runner=None) -> ArrayStudyResult:
    """Run the array study at the size of ``plan`` (:data:`ARRAY_PLANS` by its name)."""
    ap = ARRAY_PLANS.get(plan.name, ARRAY_PLANS["quick"])
    if runner is not None:
        runner.study = "arrays"
    rows = []
    for key, preset, mu in SURFACES:
        if key not in ap.surfaces:
            continue
        if runner is None:
            rows += _surface_rows(key, preset, mu, ap)
            continue
        with runner.phase(f"arrays on {key}"):
            # kept in the output folder: a resumed validation reads each surface's rows back
            inputs = {"surface": [key, preset, mu, surface_inputs(preset)], "plan": ap}
            compute = functools.partial(_surface_rows, key, preset, mu, ap)
            rows += runner.stored(f"arrays-{key}", inputs, compute)
    conj, pooled = _conjecture(rows, ap)
    for r in rows:
        r.pop("_hold"), r.pop("_ok")
    checked = [r["dt_halved"] for r in rows if "dt_halved" in r]
    plan_info = {
        "name": plan.name,
        "sides": list(ap.sides),
        "spacings_ls": list(ap.spacings_ls),
        "placements": ap.placements,
        "surfaces": list(ap.surfaces),
        "ie": list(ap.paces),
        "pace_ratio": PACE_RATIO,
        "travel_ls": TRAVEL_LS,
        "array_runs": len(ap.paces) * sum(r["placements"] for r in rows) + sum(c["runs"] for c in checked),
    }
    convergence = {
        "pace": _verdicts(
            [r["holding_converged"] for r in rows], [r["holding_extrapolation_step"] for r in rows]
        )
    }
    if checked:
        convergence["dt_halved"] = _verdicts(
            [c["converged"] for c in checked], [c["holding_change"] for c in checked]
        )
    return ArrayStudyResult(
        rows=rows, conjecture=conj, pooled=pooled, plan=plan_info, convergence=convergence
    )


def _verdicts(verdicts: list, changes: list) -> dict:
    """Rows checked, rows converged, the largest change and ``converged``: every decided
    verdict true (None where none was decided)."""
    known = [v for v in verdicts if v is not None]
    finite = [abs(c) for c in changes if math.isfinite(c)]
    return {
        "rows": len(verdicts),
        "rows_converged": sum(known),
        "max_abs_change": max(finite, default=math.nan),
        "converged": all(known) if known else None,
    }

"""Study: the closed forms in both engines, MuJoCo (soft contact) beside Bullet (hard contact).

Each check is a closed form the rig must reproduce, run the same way in both engines
(:func:`spine_mj.sim.build_rig`, the same surface, drive and detection), with the
tolerance the MuJoCo report states for it:

* **static kappa** on inclined planes (Eqs. 1-3): breakaway force / W against
  ``kappa(f_x, f_y, mu)``, within 5 % (the static map's target);
* **spring-block** (docs/physics.md §6): period against ``2 pi / w`` within 2 % (the
  ladder's), peak speed against ``2 V`` (shown; MuJoCo's soft friction rows flatten it);
* **Prandtl-Tomlinson** on a corrugation (s = 0.3, mu = 0.5, K* = 0.47): one slip per
  wavelength below K*, none above; and the largest onset force at K*/4 (I_e = 1e-4, the
  ground truth's) against ``W kappa`` at the fold, within 2 % (the MuJoCo report's);
* **crest lift-off** over the ground truth's Gaussian ridges (widths 0.35 and 0.5 L_c):
  contact kept at 0.6 I_e*, a flight by 1.6 I_e* (:func:`~spine_mj.validate.ground_truth.crest_check`,
  the MuJoCo test's tolerance);
* **V-groove wedge lock**: a tip in a groove rising at theta with flanks tilted by alpha'
  in the groove's plane holds ``tan(theta + arctan(mu / cos alpha'))`` (the single-contact
  rule says ``tan(theta + arctan mu)``), within 5 %, and self-locks once
  ``theta + arctan(mu / cos alpha') >= 90 deg``; :func:`groove`'s flanks, tilted by alpha
  across the x axis, have ``tan alpha' = tan alpha cos theta`` (:func:`flank_tilt`);
* **Dai's interlock** on a half-embedded sphere of radius R against a tip of radius r,
  pushed horizontally into it: self-lock possible iff ``R / r >= 1 / sin(arctan mu) - 1``,
  run at 0.9, 0.97, 1.03 and 1.1 times that threshold. Both engines collide with the
  sphere's heightfield facets (at most 4 samples per tip radius, the rig's rule), whose
  contact normal at the tip's rest differs from the smooth sphere's: the table gives the
  rule applied to the facets' normal too (the fair reference, as the streamline on the
  contact surface is for paths);
* **creep**: the drift speed of a held tip (tip radii per second) on a 20 deg plane and
  wedged against the sphere under a rising force.

Bullet's pitfalls run beside the rule's choice, each with its measured cause: the groove
without friction anchors (``friction_anchor="never"``: it creeps and reads as a slide) and
Dai's 0.97 without internal-edge normals (``internal_edges=False``: it releases as the
facets' rule says; with them Bullet self-locks).

* **fractal self-lock rate against H** (``--fractal N``): the validation's fractal study
  (:mod:`spine_mj.validate.fractal_lock`) at its corner I_e in both engines, N surfaces per H,
  one sweep with ``engine = ["mujoco", "bullet"]``, rates with Wilson intervals.

``spine-mj validate`` runs the closed forms as a study of its registry
(:func:`engines_study`, the plan's ``engines.checks``), its section "Engines side by side"
in ``report.md``, where the ``[bullet]`` extra is installed (without it the section says so
in one line). The longer comparisons run apart (:func:`compare_engines`):
``spine-mj compare-engines --out DIR [--quick] [--fractal N] [--headlines N]``
(``--headlines``: the quasistatic-limit corner per family in both engines,
:mod:`spine_mj.validate.engine_headlines`) writes ``engines.json`` and ``engines.md``; the
committed ``analysis/reports/engines.md`` is ``--fractal 6`` (the full plan's 30 took 855 s).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from spine_mj import presets, sim
from spine_mj.atomic import atomic_output
from spine_mj.choices import COMPARED_ENGINES
from spine_mj.errors import SpineInputError
from spine_mj.surfaces import inclined_plane
from spine_mj.theory import engagement
from spine_mj.theory.tomlinson import Corrugation
from spine_mj.validate.wedges import dai_start, dai_surface, dai_threshold, flank_tilt, groove

if TYPE_CHECKING:  # the study's runner imports the sweep's analyses (4 CPU-s), which
    # compare_engines needs only once its arguments have passed
    from spine_mj.validate.plans import ValidationPlan
    from spine_mj.validate.study_runner import StudyRunner

__all__ = [
    "CHECKS",
    "COMPARISON_FILES",
    "EnginesResult",
    "compare_engines",
    "engines_ground_truth",
    "engines_study",
]

MU = 0.5
STATIC_TOL = 0.05
PERIOD_TOL = 0.02
#: Planes of the static check: (slope, azimuth) [deg].
PLANES = ((0.0, 0.0), (10.0, 0.0), (-10.0, 0.0), (20.0, 45.0), (30.0, 0.0))
#: Dai's ratios, in thresholds.
DAI_FACTORS = (0.9, 0.97, 1.03, 1.1)
DAI_SPHERE_M = 4e-3
#: Ridge widths of the lift-off check (L_c), as the MuJoCo test's.
LIFTOFF_WIDTHS = (0.35, 0.5)
#: V-grooves: (theta, alpha) [deg]. The closed form takes the flanks' tilt in the groove's
#: own inclined plane; on ``groove`` it holds for moderate angles only, so no self-locking
#: groove (theta + arctan(mu / cos alpha) >= 90 deg needs steep ones) is run.
GROOVES = ((20.0, 30.0),)
#: The onset force's K / K* and tolerance: where the MuJoCo report states the largest onset
#: within 2 % of the fold (docs/physics.md §6), at the ground truth's I_e.
ONSET_FACTOR = 0.25
ONSET_TOL = 0.02


@dataclass(frozen=True)
class EnginesResult:
    """Rows of every check: ``check``, ``case``, the closed form, the fair reference where
    it differs, each engine's measurement and verdict, the tolerance; the engines run, their
    wall and CPU seconds; and ``missing``, the extras whose absence left the study unrun
    (``("bullet",)``: no rows)."""

    rows: list[dict]
    engines: tuple[str, ...]
    wall_s: dict
    fractal: list[dict] = ()
    cpu_s: dict = field(default_factory=dict)
    missing: tuple[str, ...] = ()

    def as_dict(self) -> dict:
        return {
            "rows": self.rows,
            "engines": list(self.engines),
            "wall_s": self.wall_s,
            "cpu_s": self.cpu_s,
            "fractal": list(self.fractal),
            "missing": list(self.missing),
        }

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {"engines": self.as_dict()}

    @classmethod
    def from_dict(cls, d: dict) -> EnginesResult:
        """The result :meth:`as_dict` wrote (``engines.json``)."""
        return cls(
            rows=d["rows"],
            engines=tuple(d["engines"]),
            wall_s=d["wall_s"],
            fractal=d.get("fractal", []),
            cpu_s=d.get("cpu_s", {}),
            missing=tuple(d.get("missing", ())),
        )


def _rig(engine, surface, mu=MU, **kw):
    return sim.build_rig(surface, engine=engine, mu=mu, **kw)


def _static_rows(engine: str) -> list[dict]:
    rows = []
    from spine_mj.validate.static_map import hold_force

    for slope, az in PLANES:
        t = math.tan(math.radians(slope))
        k, low, _ = hold_force(t * math.cos(math.radians(az)), t * math.sin(math.radians(az)), MU)
        hold = 0.5 * (low + k) if low > 0 else 0.0  # as the static map: where gravity alone slides
        rig = _rig(engine, inclined_plane(slope_deg=slope, azimuth_deg=az), ie=1e-2)
        drive = sim.build_drive(rig.scales, "static", ie=1e-2, start_force_n=hold * rig.scales.preload_n)
        run = rig.run(drive, start=(0.0, 0.0))
        rows.append(
            {
                "check": "static kappa",
                "case": f"plane {slope:g} deg, azimuth {az:g} deg",
                "closed_form": float(k),
                "measured": run.kappa_mj,
                "error": run.kappa_mj / float(k) - 1,
                "ok": abs(run.kappa_mj / float(k) - 1) <= STATIC_TOL,
                "tolerance": f"{STATIC_TOL:.0%}",
                "detail": run.end_detail,
            }
        )
    return rows


def _spring_block_rows(engine: str) -> list[dict]:
    from spine_mj.validate.ground_truth import spring_block_check

    b = spring_block_check(engine=engine)
    return [
        {
            "check": "spring-block period",
            "case": "k = 100 N/m, m = 10 g, V = 4 mm/s",
            "closed_form": b["period_predicted_s"],
            "measured": b["period_s"],
            "error": b["period_rel_error"],
            "ok": abs(b["period_rel_error"]) <= PERIOD_TOL,
            "tolerance": f"{PERIOD_TOL:.0%}",
            "detail": "",
        },
        {
            "check": "spring-block peak speed",
            "case": "k = 100 N/m, m = 10 g, V = 4 mm/s",
            "closed_form": 2.0,
            "measured": b["peak_speed_v"],
            "error": b["peak_speed_rel_error"],
            "ok": None,
            "tolerance": "shown",
            "detail": "in V",
        },
    ]


def _tomlinson_rows(engine: str, quick: bool) -> list[dict]:
    c = Corrugation(0.3, MU, tip_radius=0.01)
    k_star = c.critical_stiffness()
    waves = 2 if quick else 3
    surf = presets.make_surface("corrugation", slope_amplitude=0.3, points_per_wave=128, n_waves=waves + 1)
    rows = []
    for factor in (0.5, 2.0):
        k = factor * k_star
        run = _corrugation_run(engine, surf, k, 1e-3, waves)
        travel = (run.position_m[-1, 0] - run.position_m[0, 0]) / sim.DEFAULT_LENGTH_SCALE_M
        per_wave = len(run.slip_events) / travel if travel > 0 else math.nan
        expected = 1.0 if factor < 1 else 0.0
        # one slip per wavelength: the count within one of the wavelengths travelled
        ok = abs(len(run.slip_events) - expected * travel) < 1 if factor < 1 else not run.slip_events
        rows.append(
            {
                "check": "Prandtl-Tomlinson slips per wavelength",
                "case": f"s = 0.3, mu = {MU:g}, K = {factor:g} K* (I_e = 1e-3)",
                "closed_form": expected,
                "measured": per_wave,
                "error": per_wave - expected,
                "ok": bool(ok),
                "tolerance": "slips within 1 of the wavelengths travelled below K*, none above",
                "detail": f"{len(run.slip_events)} slips in {travel:.2f} wavelengths; {run.end_reason.value}",
            }
        )
    return [*rows, _onset_row(engine, c, surf, waves)]


def _corrugation_run(engine: str, surf, k: float, ie: float, waves: int):
    """The spring drive at stiffness number ``k`` and ``ie`` over ``waves`` wavelengths."""
    rig = _rig(engine, surf, tip_radius_m=0.01 * sim.DEFAULT_LENGTH_SCALE_M, ie=ie, stiffness_number=k)
    sc = rig.scales
    speed = sc.speed_for(ie)
    duration = waves * sim.DEFAULT_LENGTH_SCALE_M / speed
    drive = sim.SpringDrive(speed_m_s=speed, stiffness_n_m=sc.stiffness_for(k), duration_s=duration)
    return rig.run(drive, start=(0.75, 0.0))


def _onset_row(engine: str, c: Corrugation, surf, waves: int) -> dict:
    """The largest slip onset force at :data:`ONSET_FACTOR` K* and the ground truth's
    I_e against ``W kappa`` at the fold."""
    from spine_mj.validate.ground_truth import TOMLINSON_IE

    k = ONSET_FACTOR * c.critical_stiffness()
    run = _corrugation_run(engine, surf, k, TOMLINSON_IE, waves)
    fold = c.fold(k)[1]
    onset = max((e.onset_force_n for e in run.slip_events), default=math.nan) / run.scales.preload_n
    err = onset / fold - 1
    return {
        "check": "Prandtl-Tomlinson onset force at the fold",
        "case": f"s = 0.3, mu = {MU:g}, K = {ONSET_FACTOR:g} K* (I_e = {TOMLINSON_IE:g}), largest onset",
        "closed_form": fold,
        "measured": onset,
        "error": err,
        "ok": bool(abs(err) <= ONSET_TOL),
        "tolerance": f"{ONSET_TOL:.0%}",
        "detail": f"in F_p, {len(run.slip_events)} slips",
    }


def _with_settings(rig, settings: dict):
    """``rig`` with ``settings`` replacing fields of its engine settings (its scales and
    hfield kept): the measured cause of a Bullet pitfall, run beside the rule's choice."""
    import dataclasses

    if not settings:
        return rig
    engine = dataclasses.replace(rig.engine, **settings)
    return type(rig)(rig.surface, tip=rig.tip, engine=engine, sized=(rig.scales, rig.hfield))


def _settings_label(settings: dict) -> str:
    return "".join(f", {k} = {v}" for k, v in settings.items())


def _groove_rows(engine: str, **settings) -> list[dict]:
    """The groove checks in ``engine``; ``settings`` replace fields of its engine settings
    (Bullet's ``friction_anchor="never"``: the wedge's creep, docs/physics.md §11)."""
    rows = []
    for theta, alpha in GROOVES:
        wedge = math.radians(theta) + math.atan(MU / math.cos(flank_tilt(theta, alpha)))
        lock = wedge >= math.pi / 2
        kappa = math.inf if lock else math.tan(wedge)
        single = math.tan(math.radians(theta) + math.atan(MU))
        cap = 20.0 if lock else 2 * kappa
        rig = _with_settings(_rig(engine, groove(theta, alpha), ie=1e-2, tip_radius_m=2e-3), settings)
        det = sim.Detection(kappa_cap=cap)
        # where gravity alone would slide the tip down the groove it is held at twice the
        # force that holds it
        hold = 2 * max(
            0.0, math.tan(math.radians(theta) - math.atan(MU / math.cos(flank_tilt(theta, alpha))))
        )
        drive = sim.build_drive(rig.scales, "static", ie=1e-2, start_force_n=hold * rig.scales.preload_n)
        run = rig.run(drive, start=(0.0, 0.0), detection=det)
        locked = run.end_reason is sim.EndReason.SELF_LOCK
        row = {
            "check": "V-groove wedge",
            "case": f"theta {theta:g} deg, alpha {alpha:g} deg (single-contact rule: {single:.3g})"
            + _settings_label(settings),
            "closed_form": "self-lock" if lock else kappa,
            "measured": "self-lock" if locked else run.kappa_mj,
            "tolerance": "lock" if lock else f"{STATIC_TOL:.0%}",
            "detail": run.end_detail,
        }
        if lock:
            row.update(error=math.nan, ok=locked)
        else:
            err = run.kappa_mj / kappa - 1
            row.update(error=err, ok=bool(abs(err) <= STATIC_TOL))
        rows.append(row)
    return rows


def _dai_rows(engine: str, factors=DAI_FACTORS, **settings) -> list[dict]:
    """Dai's interlock at ``factors`` times the threshold; ``settings`` as for the groove
    (Bullet's ``internal_edges=False``: the contact normal at the floor-sphere kink)."""
    thr = dai_threshold(MU)
    rows = []
    for f in factors:
        tip_m = DAI_SPHERE_M / (f * thr)
        rig = _rig(engine, dai_surface(DAI_SPHERE_M, tip_m), ie=1.0, tip_radius_m=tip_m)
        rig = _with_settings(rig, settings)
        ball = rig.contact_surface()
        start = dai_start(ball, DAI_SPHERE_M, tip_m)
        gx, gy = ball.gradient(np.array([start[0]]), np.array([start[1]]))
        k_facets, region = engagement.kappa(float(gx[0]), float(gy[0]), MU)
        lock_facets = region == engagement.SELF_LOCK
        phi = math.asin(1.0 / (1.0 + f * thr))  # the smooth sphere's normal above the horizontal
        wedge = math.pi / 2 - phi + math.atan(MU)
        lock = wedge >= math.pi / 2
        kappa = math.inf if lock else math.tan(wedge)
        cap = 20.0 if lock_facets else float(min(1.5 * k_facets, 400.0))
        run = rig.run(
            sim.build_drive(rig.scales, "static", ie=1.0), start=start, detection=sim.Detection(kappa_cap=cap)
        )
        locked = run.end_reason is sim.EndReason.SELF_LOCK
        held = run.moving.size and ~run.moving[run.drive_start_index :]
        rows.append(
            {
                "check": "Dai interlock",
                "case": f"R / r = {f:g} x {thr:.3f}" + _settings_label(settings),
                "closed_form": "self-lock" if lock else kappa,
                "facets": "self-lock" if lock_facets else float(k_facets),
                "measured": "self-lock" if locked else run.kappa_mj,
                "error": math.nan,
                "ok": bool(locked == lock),
                "ok_facets": bool(locked == lock_facets),
                "tolerance": "lock iff R/r >= threshold",
                "detail": run.end_detail,
                "creep_radii_per_s": _creep(run, held) if locked else math.nan,
            }
        )
    return rows


def _liftoff_rows(engine: str) -> list[dict]:
    """Lift-off over the ground truth's Gaussian ridges: contact kept at
    :data:`~spine_mj.validate.ground_truth.LIFTOFF_BELOW` I_e*, a flight by
    :data:`~spine_mj.validate.ground_truth.LIFTOFF_ABOVE` I_e* (the MuJoCo test's tolerance)."""
    from spine_mj.validate.ground_truth import (
        LIFTOFF_ABOVE,
        LIFTOFF_BELOW,
        LIFTOFF_GAP_RADII,
        crest_check,
    )

    rows = []
    for width in LIFTOFF_WIDTHS:
        for factor, expect in ((LIFTOFF_BELOW, "contact"), (LIFTOFF_ABOVE, "flight")):
            ie, gap, flight = crest_check(width, factor, engine)
            if expect == "contact":
                ok = ie < 0.8 and gap < LIFTOFF_GAP_RADII and flight == 0.0
            else:
                ok = ie > 1.0 and gap > 2 * LIFTOFF_GAP_RADII and flight > 0.25
            rows.append(
                {
                    "check": "crest lift-off",
                    "case": f"Gaussian ridge, width {width:g} L_c, carriage at {factor:g} I_e*",
                    "closed_form": expect,
                    "measured": "flight" if flight > 0 else "contact",
                    "error": math.nan,
                    "ok": bool(ok),
                    "tolerance": "contact at 0.6 I_e*, a flight over 1/4 width at 1.6 I_e*",
                    "detail": f"crest I_e {ie:.3g} I_e*, gap {gap:.3g} tip radii, flight {flight:.3g} widths",
                }
            )
    return rows


def _creep(run, held) -> float:
    """Drift speed [tip radii / s] of the tip over the rows it is held (not moving)."""
    rows = np.flatnonzero(held) + run.drive_start_index
    if rows.size < 2:
        return math.nan
    a, b = rows[0], rows[-1]
    drift = np.linalg.norm(run.position_m[b, :2] - run.position_m[a, :2])
    return float(drift / run.tip.tip_radius_m / (run.time_s[b] - run.time_s[a]))


def _creep_rows(engine: str) -> list[dict]:
    rig = _rig(engine, inclined_plane(slope_deg=20.0), ie=1e-2)
    drive = sim.SpringDrive(speed_m_s=1e-9, stiffness_n_m=1e-9, duration_s=0.5)
    run = rig.run(drive, start=(0.0, 0.0))
    speed = _creep(run, ~run.moving[run.drive_start_index :])
    return [
        {
            "check": "creep of a held tip",
            "case": "20 deg plane, mu 0.5, no drive, 0.5 s",
            "closed_form": 0.0,
            "measured": speed,
            "error": speed,
            "ok": None,
            "tolerance": "shown (tip radii / s)",
            "detail": "",
        }
    ]


def engines_ground_truth(
    *,
    quick: bool = False,
    engines=COMPARED_ENGINES,
    checks: tuple[str, ...] | None = None,
    progress: Callable[[str], None] | None = None,
) -> EnginesResult:
    """Every check (or those named in ``checks``, keys of :data:`CHECKS`) in every engine of
    ``engines``; rows merged by (check, case)."""
    by_key: dict[tuple, dict] = {}
    wall, cpu = {}, {}
    chosen = _checks(quick)
    if checks is not None:
        unknown = sorted(set(checks) - set(chosen))
        if unknown:
            raise SpineInputError(
                f"engines checks must be among {', '.join(chosen)}, got {', '.join(unknown)}"
            )
        chosen = {k: v for k, v in chosen.items() if k in checks}
    for engine in engines:
        t0, c0 = time.perf_counter(), time.process_time()
        for name, check in chosen.items():
            if progress is not None:
                progress(f"{engine}: {name}")
            for row in check(engine):
                key = (row["check"], row["case"])
                merged = by_key.setdefault(
                    key,
                    {k: row[k] for k in ("check", "case", "closed_form", "tolerance") if k in row}
                    | ({"facets": row["facets"]} if "facets" in row else {}),
                )
                for k in ("measured", "error", "ok", "detail", "ok_facets", "creep_radii_per_s"):
                    if k in row:
                        merged[f"{engine}_{k}"] = row[k]
        wall[engine] = round(time.perf_counter() - t0, 1)
        cpu[engine] = round(time.process_time() - c0, 1)
    return EnginesResult(rows=list(by_key.values()), engines=tuple(engines), wall_s=wall, cpu_s=cpu)


#: The names of the checks, in the order they run (:func:`engines_ground_truth`).
CHECKS = (
    "static kappa",
    "spring-block",
    "V-groove",
    "V-groove, Bullet's friction anchors never",
    "Dai interlock",
    "Dai interlock, Bullet's internal edges off",
    "crest lift-off",
    "creep",
    "Prandtl-Tomlinson",
)


def _checks(quick: bool) -> dict:
    """Each check of :data:`CHECKS` as ``engine -> rows``."""
    checks = {
        "static kappa": _static_rows,
        "spring-block": _spring_block_rows,
        "V-groove": _groove_rows,
        "V-groove, Bullet's friction anchors never": lambda e: (
            _groove_rows(e, friction_anchor="never") if e == "bullet" else []
        ),
        "Dai interlock": _dai_rows,
        "Dai interlock, Bullet's internal edges off": lambda e: (
            _dai_rows(e, (0.97,), internal_edges=False) if e == "bullet" else []
        ),
        "crest lift-off": _liftoff_rows,
        "creep": _creep_rows,
        "Prandtl-Tomlinson": lambda e: _tomlinson_rows(e, quick),
    }
    assert tuple(checks) == CHECKS
    return checks


def engines_study(plan: ValidationPlan, runner: StudyRunner) -> EnginesResult:
    """The study in ``spine-mj validate``: :func:`engines_ground_truth` of the plan's checks
    (``plan.engines.checks``; ``plan.engines.quick``: fewer corrugation wavelengths) in both
    engines, where the ``[bullet]`` extra is installed; without it a result that says so
    (``missing``) and runs nothing."""
    from spine_mj import extras

    runner.study = "engines"
    if extras.missing("bullet"):
        return EnginesResult(rows=[], engines=(), wall_s={}, missing=("bullet",))
    checks = CHECKS if plan.engines.checks is None else plan.engines.checks
    with runner.phase("closed forms in MuJoCo and Bullet", total=len(COMPARED_ENGINES) * len(checks)) as tick:
        return engines_ground_truth(quick=plan.engines.quick, checks=checks, progress=lambda _: tick())


#: What :func:`compare_engines` writes into its folder (beside its resumable ``sweeps/``).
COMPARISON_FILES = ("engines.json", "engines.md")


def compare_engines(
    out: Path,
    *,
    quick: bool = False,
    fractal_surfaces: int = 0,
    headlines_starts: int = 0,
    headlines_plan: str = "quick",
    workers: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> str:
    """``spine-mj compare-engines``: the comparisons too long for a validation plan.

    The closed forms in both engines (:func:`engines_ground_truth`; ``quick``: fewer
    corrugation wavelengths), with ``fractal_surfaces`` > 0 the fractal self-lock rate
    against H in both engines (:func:`~spine_mj.validate.fractal_lock.fractal_engines`, that
    many surfaces per H) and with ``headlines_starts`` > 0 the quasistatic-limit corner per
    family in both engines and the full report's soft-contact misses rerun
    (:mod:`spine_mj.validate.engine_headlines`, that many y starts per surface of
    ``headlines_plan``'s corner, written to its :data:`~spine_mj.validate.engine_headlines.RESULT_FILE`).
    Writes :data:`COMPARISON_FILES` into ``out`` and returns the markdown of ``engines.md``.

    Every argument, the folder and the ``[bullet]`` extra are checked before any work
    (:class:`~spine_mj.errors.SpineInputError`); ``progress`` hears a line per step.
    """
    import dataclasses

    from spine_mj import extras
    from spine_mj.atomic import writable_path
    from spine_mj.choices import PLAN_NAMES
    from spine_mj.workers import check_workers

    out = Path(out)
    for name, value in (("--fractal", fractal_surfaces), ("--headlines", headlines_starts)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise SpineInputError(f"{name}: must be an integer >= 0, got {value!r}")
    if headlines_plan not in PLAN_NAMES:
        raise SpineInputError(
            f"--headlines-plan must be one of {', '.join(PLAN_NAMES)}, got {headlines_plan!r}"
        )
    if workers is not None:
        check_workers(workers)
    if out.exists() and not out.is_dir():
        raise SpineInputError(f"--out {out}: is a file, expected a folder")
    extras.require("bullet", "compare-engines (it runs both engines)")
    for name in COMPARISON_FILES:
        writable_path(out / name)
    # the studies' modules only now: importing them takes seconds the checks must not wait for
    from spine_mj.jsonio import write_json
    from spine_mj.validate.engine_headlines import RESULT_FILE, run_engine_headlines
    from spine_mj.validate.fractal_lock import fractal_engines
    from spine_mj.validate.report.engine_headlines import section as headlines_section
    from spine_mj.validate.report.engines import section

    say = progress or (lambda _: None)
    res = engines_ground_truth(quick=quick, progress=say)
    if fractal_surfaces:
        t0 = time.perf_counter()
        fractal = fractal_engines(out, surfaces_per_hurst=fractal_surfaces, workers=workers)
        wall = dict(res.wall_s, fractal=round(time.perf_counter() - t0, 1))
        res = dataclasses.replace(res, fractal=fractal, wall_s=wall)
    headlines = None
    if headlines_starts:
        say("headlines: the corner per family and the soft-contact misses, both engines")
        headlines = run_engine_headlines(
            out, plan=headlines_plan, starts_per_surface=headlines_starts, workers=workers
        )
        write_json(out / RESULT_FILE, headlines.as_dict())
    write_json(out / "engines.json", res.as_dict())
    text = section(res) + headlines_section(headlines)
    with atomic_output(out / "engines.md") as tmp:
        tmp.write_text(text)
    return text


if __name__ == "__main__":  # the study's entry point before it became a command
    import sys

    sys.stderr.write(
        "Error: python -m spine_mj.validate.engines is no longer a command, got "
        f"{' '.join(sys.argv[1:]) or 'no arguments'}: run `spine-mj compare-engines` with the "
        "same options (spine-mj compare-engines --help)\n"
    )
    raise SystemExit(2)

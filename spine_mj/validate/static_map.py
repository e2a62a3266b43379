"""Study 1: the static probe on inclined planes against the analytic engagement ratio.

The breakaway ratio ``kappa_mj / kappa`` over slope angle and azimuth (engaged, self-lock
and slip regions, Eqs. 1-3), per engine setting of the plan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from spine_mj import sim, surface_io, sweep
from spine_mj.surfaces import inclined_plane
from spine_mj.sweep.analyses.engine import case_rig
from spine_mj.theory import engagement, multicontact
from spine_mj.validate.convergence import REFINEMENTS
from spine_mj.validate.intervals import TARGET_SLACK
from spine_mj.validate.plans import GRAVITY, MASS_KG, STATIC_TARGET, ValidationPlan
from spine_mj.validate.study_runner import StudyRunner
from spine_mj.validate.sweep_configs import (
    RELATIVE_ENGINE_KEYS,
    engine_default,
    relative_engine_keys,
    rig_engine,
)

__all__ = [
    "KAPPA_FLOOR",
    "PLANE_START",
    "StaticMapResult",
    "breakaway_contacts",
    "equivalent_tilt_deg",
    "hold_force",
    "kappa_error",
    "kappa_tilt_gain",
    "plane_table",
    "static_map",
]

#: Where the probe starts on every plane (metres).
PLANE_START = (3.1e-4, 2.7e-4)
#: The inertia number of the probe's force ramp.
PROBE_IE = 1e-2
#: Samples a side of each plane's grid (an engine setting's ``hfield_factor`` refines its
#: hfield, the tip kept: a plane's facets are the plane at any resolution, so the breakaway
#: must not move).
PLANE_SAMPLES = 41
#: Where the static map's error turns from relative to absolute (:func:`kappa_error`):
#: ``tan 15 deg = 2 - sqrt 3``. In the drive's section ``kappa = tan(psi)``,
#: ``psi = theta + arctan mu``; a tilt ``delta`` of the contact normal (a facet's, a soft
#: contact's) moves ``kappa`` by ``delta sec^2 psi`` and ``ln kappa`` by
#: ``delta / (sin psi cos psi) = delta (1 + kappa^2) / kappa``. That relative gain is least,
#: 2 per radian, at ``kappa = 1`` and twice that at ``kappa = 2 -+ sqrt 3``; below the
#: floor it grows as ``1 / kappa`` (a relative error near ``kappa = 0`` is ill-conditioned)
#: while the absolute gain stays within 8 % of 1. Above ``2 + sqrt 3`` the relative gain
#: grows too, but a holding force's error counts in proportion to it: the error stays
#: relative there and its amplification is stated as a tilt (:func:`equivalent_tilt_deg`).
KAPPA_FLOOR = 2.0 - math.sqrt(3.0)


@dataclass(frozen=True)
class StaticMapResult:
    """Result of :func:`static_map`.

    Attributes
    ----------
    rows : list of dict
        One per (plane, engine setting): ``engine``, ``slope_deg``, ``azimuth_deg``,
        ``region`` (``engaged`` / ``self_lock`` / ``slip``), ``kappa``, ``kappa_mj``,
        ``ratio``, ``kappa_gain_per_deg`` (:func:`kappa_tilt_gain`), ``equivalent_tilt_deg``
        (:func:`equivalent_tilt_deg`: the plane's error as a tilt), ``end_reason``,
        ``hold_over_w``, ``region_agrees``.
    per_engine : dict
        Engine label -> ``engaged_planes``, ``engaged_breakaways``, ``max_rel_error`` and
        ``mean_rel_error`` of ``|kappa_mj / kappa - 1|`` over the engaged planes,
        ``max_error`` and ``mean_error`` by the map's rule (:func:`kappa_error`), the same
        as tilts (``max_equivalent_tilt_deg``, ``mean_equivalent_tilt_deg``: the facet cause
        quantified plane by plane), ``region_agreement``.
    mu : float
    static_kappa_max_rel_error : float
        ``max_rel_error`` of the default (first) setting; inf when an engaged plane did not
        break away.
    convergence : dict
        Refinement key (``dt_halved``, ``hfield_doubled``) -> the change of the default setting's
        ``max_rel_error`` and ``region_agreement`` under it, and ``converged``
        (:func:`static_convergence`); empty where the plan refines nothing.
    planes : list of dict
        One per engaged plane (:func:`plane_table`): kappa, MuJoCo's at every refinement,
        errors, what held the tip at breakaway, ``converged`` and ``cause``.
    """

    rows: list[dict]
    per_engine: dict[str, dict]
    mu: float
    static_kappa_max_rel_error: float
    convergence: dict = field(default_factory=dict)
    planes: list[dict] = field(default_factory=list)

    def plane_summary(self) -> dict:
        """The per-plane verdict in numbers: the error rule, the largest error by it at the
        default settings, and how many engaged planes converged."""
        errs = [abs(p["error"]) for p in self.planes if np.isfinite(p["error"])]
        return {
            "error_rule": (
                f"(kappa_mj - kappa) / max(kappa, {KAPPA_FLOOR:.4f}): relative where kappa >= "
                f"{KAPPA_FLOOR:.4f} (tan 15 deg), absolute in F_p over it below"
            ),
            "kappa_floor": KAPPA_FLOOR,
            "max_error": float(max(errs)) if errs else float("nan"),
            "planes": len(self.planes),
            "converged_planes": sum(bool(p["converged"]) for p in self.planes),
            "edge_catches": sum("edge catch" in p["cause"] for p in self.planes),
        }

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {
            "static_kappa_max_rel_error": self.static_kappa_max_rel_error,
            "static_by_engine": self.per_engine,
            "static_convergence": self.convergence,
            "static_planes": self.planes,
            "static_plane_summary": self.plane_summary(),
        }

    def as_dict(self) -> dict:
        return {
            "rows": self.rows,
            "per_engine": self.per_engine,
            "mu": self.mu,
            "static_kappa_max_rel_error": self.static_kappa_max_rel_error,
            "planes": self.planes,
        }


def hold_force(fx: float, fy: float, mu: float) -> tuple[float, float, int]:
    """Analytic kappa, the smallest drive force / W that holds the tip, and the region."""
    k, region = engagement.kappa(fx, fy, mu)
    a, b, c = (float(v) for v in engagement.quadratic_coefficients(fx, fy, mu))
    # the tip holds where A' k^2 + B' k + C' <= 0; C' > 0 means gravity alone slides it, and
    # the smallest positive root is then the force that starts to hold it
    low = 0.0
    if c > 0:
        roots = np.roots([a, b, c]) if abs(a) > 1e-12 else np.array([-c / b])
        pos = [float(r.real) for r in np.atleast_1d(roots) if abs(r.imag) < 1e-12 and r.real > 0]
        low = min(pos) if pos else 0.0
    return float(k), low, int(region)


def kappa_tilt_gain(slope_deg: float, azimuth_deg: float, mu: float, *, step_deg: float = 0.01) -> float:
    """``d ln(kappa) / d(slope)`` [1/deg] of a plane tilted about its own azimuth: how much
    relative error in kappa one degree of tilt makes. In the drive's section (azimuth 0)
    ``kappa = tan(theta + phi)`` gives ``2 / sin(2 (theta + phi))`` per radian, which grows
    without bound at the self-lock pole ``theta + phi -> 90 deg`` (and at the slip edge
    ``theta + phi -> 0``): there a fixed small tilt of the contact normal (a facet's, the
    soft contact's) makes a large relative error. NaN outside the engaged region."""
    lo = hold_force(*_slopes(slope_deg - step_deg, azimuth_deg), mu)
    hi = hold_force(*_slopes(slope_deg + step_deg, azimuth_deg), mu)
    if lo[2] != engagement.ENGAGED or hi[2] != engagement.ENGAGED or not (lo[0] > 0 and hi[0] > 0):
        return float("nan")
    return (math.log(hi[0]) - math.log(lo[0])) / (2 * step_deg)


def equivalent_tilt_deg(ratio: float, gain_per_deg: float) -> float:
    """The tilt of the plane [deg] that would explain a breakaway ratio ``kappa_mj / kappa``
    to first order, ``ln(ratio) / gain``: a number comparable across planes where the
    relative error is not (it is amplified by :func:`kappa_tilt_gain` near the pole)."""
    if not (np.isfinite(ratio) and ratio > 0 and np.isfinite(gain_per_deg) and gain_per_deg != 0):
        return float("nan")
    return math.log(ratio) / gain_per_deg


def kappa_error(kappa_mj: float, kappa: float) -> float:
    """The static map's signed error of a breakaway ``kappa_mj`` against ``kappa``:
    relative, ``(kappa_mj - kappa) / kappa``, where ``kappa >= KAPPA_FLOOR``, and below
    it absolute in F_p over the floor, ``(kappa_mj - kappa) / KAPPA_FLOOR`` (continuous
    there; the target's 5 % is 0.0134 F_p below it). :data:`KAPPA_FLOOR` derives the rule."""
    return (kappa_mj - kappa) / max(kappa, KAPPA_FLOOR)


def _slopes(slope_deg: float, azimuth_deg: float) -> tuple[float, float]:
    t = math.tan(math.radians(slope_deg))
    return t * math.cos(math.radians(azimuth_deg)), t * math.sin(math.radians(azimuth_deg))


def static_map(plan: ValidationPlan, runner: StudyRunner, *, mu: float = 0.5) -> StaticMapResult:
    """Study 1: static probe on inclined planes against the analytic kappa (Eqs. 1-3).

    Every plane is a surface file under ``out/surfaces``; the probe starts at rest with the
    smallest holding force plus half the gap to the breakaway force (where gravity alone
    would slide the tip) and ramps the force at ``I_e = PROBE_IE`` until breakaway.

    Parameters
    ----------
    plan : ValidationPlan
        The validation's sizes (:data:`PLANS`).
    runner : StudyRunner
        Runs the study's sweeps into resumable stores under the output folder.
    mu : float
        The planes' friction coefficient mu_s.

    Returns
    -------
    StaticMapResult
    """
    runner.study = "static"
    rows = []
    for slope in plan.static.slopes_deg:
        for az in plan.static.azimuths_deg:
            if slope == 0.0 and az != plan.static.azimuths_deg[0]:
                continue
            rows += _plane_rows(plan, runner, slope, az, mu)
    per_engine = {
        label: _engine_summary([r for r in rows if r["engine"] == label]) for label, _ in plan.static.engines
    }
    first = per_engine[plan.static.engines[0][0]]
    max_err = first["max_rel_error"]
    if first["engaged_breakaways"] < first["engaged_planes"]:
        max_err = float("inf")  # an engaged plane that did not break away is no agreement
    return StaticMapResult(
        rows=rows,
        per_engine=per_engine,
        mu=mu,
        static_kappa_max_rel_error=max_err,
        convergence=static_convergence(plan, per_engine),
        planes=plane_table(rows, plan.static.engines),
    )


def static_convergence(plan: ValidationPlan, per_engine: dict) -> dict:
    """The default setting's numbers under each refinement the plan's static settings hold
    (an engine setting whose overrides are a :data:`~spine_mj.validate.convergence.REFINEMENTS`
    entry): the change of ``max_rel_error`` and ``region_agreement``, and ``converged``
    when the error moves by at most the target rule's slack on a length,
    ``TARGET_SLACK x STATIC_TARGET`` (one probe per plane: no interval of its own), and no
    plane changes region."""
    base = per_engine[plan.static.engines[0][0]]
    out = {}
    for label, ov in plan.static.engines[1:]:
        key = next((k for k, v in REFINEMENTS.items() if tuple(v) == tuple(ov)), None)
        if key is None:
            continue
        ref = per_engine[label]
        change = ref["max_rel_error"] - base["max_rel_error"]
        regions = ref["region_agreement"] - base["region_agreement"]
        out[key] = {
            "setting": label,
            "max_rel_error_change": change,
            "region_agreement_change": regions,
            "converged": bool(
                np.isfinite(change) and abs(change) <= TARGET_SLACK * STATIC_TARGET and regions == 0
            ),
        }
    return out


def _plane_rows(plan: ValidationPlan, runner: StudyRunner, slope: float, az: float, mu: float) -> list[dict]:
    """The probe on one plane under every engine setting of the plan."""
    region_names = engagement.REGION_NAMES
    engines = plan.static.engines
    fx, fy = _slopes(slope, az)
    k, low, region = hold_force(fx, fy, mu)
    gain = kappa_tilt_gain(slope, az, mu)
    hold = 0.5 * (low + k) if (low > 0 and np.isfinite(k)) else (1.5 * low if low > 0 else 0.0)
    keys = sorted({k_ for _, ov in engines for k_, _ in ov} - {*RELATIVE_ENGINE_KEYS, "hfield_factor"})
    normal = np.array([-fx, -fy, 1.0]) / math.sqrt(1.0 + fx * fx + fy * fy)
    rows = []
    for label, ov in engines:
        # the cap must lie above the breakaway force, or a steep engaged plane
        # reads as self-locked
        cap = max(10.0, 1.5 * k) if np.isfinite(k) else 10.0
        grid = {"mu": mu, "kappa_cap": float(f"{cap:.4g}")}
        # every setting's sweep states the keys the others vary (a default of None: the rule's)
        grid.update({k_: engine_default(k_) for k_ in keys if engine_default(k_) is not None})
        rest = dict(ov)
        path = _plane_file(runner.out_dir, slope, az)
        if "hfield_factor" in rest:  # the plane's hfield refined, the tip kept
            grid["hfield_refinement"] = int(rest.pop("hfield_factor"))
        grid.update(
            relative_engine_keys(
                rest,
                lambda path=path: rig_engine(
                    surface_io.load_surface(path), tip=None, mu=mu, ie=PROBE_IE, hfield_resolution=None
                ),
            )
        )
        grid.update(rest)
        doc = {
            "sweep": {
                "name": f"static-s{slope:g}-a{az:g}",
                "seed": 1,
                "analyses": ["engine"],
                # the probe's steps: where it first slipped and what held it at breakaway
                "store_trajectories": True,
            },
            "surfaces": [{"file": str(path)}],
            "starts": {"frame": "absolute", "points": [list(PLANE_START)]},
            "drive": {"protocol": "static", "ie": PROBE_IE, "start_force": hold * MASS_KG * GRAVITY},
            "grid": grid,
        }
        tag = "-".join(f"{k_}{v}" for k_, v in ov) or "default"
        df, store = runner(doc, f"static/s{slope:g}-a{az:g}-{tag}", workers=1)
        r = df.iloc[0]
        kmj = float(r.get("kappa_mj", np.nan))
        end = str(r.get("end_reason", r["status"]))
        mj_region = {"breakaway": "engaged", "self_lock": "self_lock", "slid": "slip"}.get(end, end)
        engaged = region == engagement.ENGAGED and k > 0
        ratio = kmj / k if engaged else float("nan")
        row = {
            "engine": label,
            "slope_deg": float(slope),
            "azimuth_deg": float(az),
            "region": region_names[region],
            "kappa": k,
            "kappa_mj": kmj,
            "ratio": ratio,
            "error": kappa_error(kmj, k) if engaged else float("nan"),
            "abs_error_fp": kmj - k if engaged else float("nan"),
            # the facet cause, plane by plane: the pole's amplification of a tilt and
            # the tilt that explains this plane's error
            "kappa_gain_per_deg": gain,
            "equivalent_tilt_deg": equivalent_tilt_deg(ratio, gain),
            "end_reason": end,
            "hold_over_w": hold,
            "region_agrees": mj_region == region_names[region],
        }
        if engaged and np.isfinite(kmj):
            rig = case_rig(sweep.expand_cases(sweep.parse_config(doc, base_dir=runner.out_dir))[0])
            traj = sweep.load_trajectories(store, str(r["case_id"]), analysis="engine")
            row.update(breakaway_contacts(rig, traj, kmj, normal, mu))
            # the probe reads its force once a step: the resolution of kappa_mj
            row["force_step_fp"] = float(r["speed_m_s"] * r["timestep_s"] / rig.scales.char_length_m)
        rows.append(row)
    return rows


#: The most stuck steps between a probe's first slip and its breakaway whose contacts
#: :func:`breakaway_contacts` collects (each a collision of the tip with every prism under
#: it: ~8 ms at hfield x 4 on a loaded machine).
HELD_SAMPLES = 32
#: A contact normal further than this from the plane's [deg] is tilted (the hfield's
#: float32 heights leave a plane's facet normals within ~1e-5 deg of it).
TILT_NOISE_DEG = 0.01


def breakaway_contacts(rig, traj, kappa_mj: float, plane_normal, mu: float) -> dict:
    """What held the probe when it broke away, from its recorded steps ``traj`` (the sweep's
    trajectory table: ``x, y, z`` in surface units, ``drive_force_n``, ``moving``).

    The breakaway step is the one whose drive force ``kappa_mj`` reads (the last stuck step
    before the tip moved the breakaway distance, :func:`spine_mj.sim.detection.probe_candidates`).
    There the contacts MuJoCo finds (:meth:`~spine_mj.sim.model.RigModel.contacts_at`), how
    many; and over the stuck steps from the first slip to the breakaway (the breakaway alone
    where the tip had not slipped before; at most :data:`HELD_SAMPLES`), the most of them,
    how far their normals tilt from the plane's ``plane_normal`` and the drive they would
    hold together
    (:func:`~spine_mj.theory.multicontact.hold_kappa`, the closed form of a block on the
    plane when there is one contact with the plane's normal). And the first slip: the force
    at the last stuck step before the tip first came unstuck (a step's displacement along the
    plane over its ``time_s`` faster than the detection's stick speed; a block on the plane
    slips there), and how far it slid before the breakaway step, in tip radii (a tip that
    slipped and was caught again broke away later than the plane lets it).

    Returns
    -------
    dict
        ``breakaway_contacts``, ``held_contacts`` (the most), ``contact_tilt_deg`` (the
        largest), ``contacts_lock_kappa``,
        ``first_slip_kappa``, ``slid_before_r_tip`` (0 where the tip first came unstuck at the
    breakaway itself).
    """
    fp = rig.scales.preload_n
    f = traj["drive_force_n"].to_numpy() / fp
    at = np.flatnonzero(f == kappa_mj)
    j = int(at[-1]) if at.size else int(np.argmin(np.abs(f - kappa_mj)))
    pos = traj[["x", "y", "z"]].to_numpy() * rig.length_scale_m

    # unstuck as the breakaway reading has it: faster than the detection's stick speed along
    # the plane (the soft contact's depth grows with the load: the normal motion is no slip)
    n = np.asarray(plane_normal, dtype=float)
    step = np.diff(pos, axis=0)
    step -= np.outer(step @ n, n)
    speed = np.linalg.norm(step, axis=1) / np.diff(traj["time_s"].to_numpy())
    stick = sim.Detection().resolve(rig.scales).stick_speed_m_s
    onset = np.flatnonzero((speed > stick) & (f[1:] > f[0])) + 1
    i = int(onset[0]) if onset.size else j + 1
    slipped = i - 1 < j
    # what held it again between the first slip and the breakaway: the contacts at its stuck
    # steps there (a grazing contact may come and go from step to step), at most
    # HELD_SAMPLES of them evenly spread, the breakaway's last; the breakaway's alone where
    # it had not slipped before
    held = np.flatnonzero(speed[min(i - 1, j) : j] <= stick) + min(i - 1, j) + 1
    held = np.unique(np.append(held[held < j], j))
    held = held[np.unique(np.linspace(0, held.size - 1, min(held.size, HELD_SAMPLES)).round().astype(int))]
    found = [rig.contacts_at(pos[k])[1] for k in held]
    every = np.concatenate(found)
    tilt = np.degrees(np.arccos(np.clip(every @ n, -1.0, 1.0)))
    normals = np.unique(np.round(every, 4), axis=0)  # the lock's: alike within ~0.006 deg, one
    return {
        "breakaway_contacts": len(found[-1]),
        "held_contacts": max(len(c) for c in found),
        "contact_tilt_deg": float(tilt.max()) if tilt.size else float("nan"),
        "contacts_lock_kappa": multicontact.hold_kappa(normals, mu) if len(normals) else float("nan"),
        "first_slip_kappa": float(f[i - 1]),
        "slid_before_r_tip": float(np.linalg.norm(pos[j] - pos[i - 1]) / rig.tip.tip_radius_m)
        if slipped
        else 0.0,
    }


#: The ladders of a plane's convergence: its hfield refined, its step refined (keys of
#: :data:`~spine_mj.validate.convergence.REFINEMENTS`, coarse to fine after the default).
LADDERS = {"hfield": ("hfield_doubled", "hfield_quadrupled"), "dt": ("dt_halved", "dt_quartered")}


def plane_table(rows: list[dict], engines) -> list[dict]:
    """One row per engaged plane: its analytic ``kappa``, the default setting's ``kappa_mj``,
    ``error`` (:func:`kappa_error`), ``abs_error_fp`` and what held the tip
    (:func:`breakaway_contacts`), each refinement's ``kappa_mj_<key>`` and ``error_<key>``,
    each ladder's last change (``change_hfield``, ``change_dt``: the finest level against
    the one before it) and ``converged``: every last change within its tolerance, the target
    rule's slack on the error (``TARGET_SLACK x STATIC_TARGET``) plus both readings'
    resolution (one ramp step each, ``force_step_fp``, over ``max(kappa, KAPPA_FLOOR)``).
    ``cause``: per setting whose error misses the target or whose change breaks
    convergence, what held the tip there (:func:`setting_cause`); ``-`` where none does.
    ``engines``: the plan's static settings, the first the default."""
    default = engines[0][0]
    label_of = {
        key: label for label, ov in engines[1:] for key, v in REFINEMENTS.items() if tuple(v) == tuple(ov)
    }
    planes = {}
    for r in rows:
        planes.setdefault((r["slope_deg"], r["azimuth_deg"]), {})[r["engine"]] = r
    out = []
    for (slope, az), by in planes.items():
        base = by.get(default)
        if base is None or base["region"] != "engaged":
            continue
        row = {
            "slope_deg": slope,
            "azimuth_deg": az,
            "kappa": base["kappa"],
            "error_kind": "relative" if base["kappa"] >= KAPPA_FLOOR else "absolute / KAPPA_FLOOR",
            **{k: base.get(k, np.nan) for k in _PLANE_KEYS},
        }
        for key, label in label_of.items():
            row[f"kappa_mj_{key}"] = by[label]["kappa_mj"]
            row[f"error_{key}"] = by[label]["error"]
        converged, moved = True, []
        for ladder, keys in LADDERS.items():
            levels = [base] + [by[label_of[k]] for k in keys if k in label_of]
            if len(levels) < 2:
                continue
            a, b = levels[-2], levels[-1]
            change = b["error"] - a["error"]
            tol = change_tolerance(
                base["kappa"], a.get("force_step_fp", np.nan), b.get("force_step_fp", np.nan)
            )
            row[f"change_{ladder}"] = change
            row[f"tolerance_{ladder}"] = tol
            ok = bool(np.isfinite(change) and abs(change) <= tol)
            converged &= ok
            if not ok:
                moved.append(b["engine"])
        row["converged"] = bool(converged)
        misses = [
            lab
            for lab, r in by.items()
            if (lab == default or lab in label_of.values())
            and (lab in moved or not (abs(r["error"]) <= STATIC_TARGET))
        ]
        row["cause"] = "; ".join(f"{lab}: {setting_cause(by[lab])}" for lab in misses) or "-"
        out.append(row)
    return out


def change_tolerance(kappa: float, step_a_fp: float, step_b_fp: float) -> float:
    """How far two readings of a plane's error (:func:`kappa_error`) may differ and count as
    the same: the target rule's slack on the error, ``TARGET_SLACK x STATIC_TARGET`` (one
    probe per plane: no interval of its own), plus each reading's resolution, one ramp step
    [F_p] over ``max(kappa, KAPPA_FLOOR)``."""
    return TARGET_SLACK * STATIC_TARGET + (step_a_fp + step_b_fp) / max(kappa, KAPPA_FLOOR)


_PLANE_KEYS = (
    "kappa_mj",
    "error",
    "abs_error_fp",
    "force_step_fp",
    "breakaway_contacts",
    "held_contacts",
    "contact_tilt_deg",
    "contacts_lock_kappa",
    "first_slip_kappa",
    "slid_before_r_tip",
)


def setting_cause(row: dict) -> str:
    """What held the probe of one setting's ``row`` (:func:`breakaway_contacts`):
    ``edge catch`` where the tip first came unstuck measurably below the breakaway read
    (their errors differ by more than :func:`change_tolerance`) and contacts tilted from the
    plane held it again (a neighbouring hfield prism's, whose normal its side wall tilts);
    ``caught`` where it slipped and was held again by contacts of the plane's own normal;
    ``tilted contacts`` where such contacts held it from the start; ``one contact`` where a
    contact with the plane's own normal did (what remains is the soft contact and the
    reading); ``no breakaway``."""
    if not np.isfinite(row.get("kappa_mj", np.nan)) or "breakaway_contacts" not in row:
        return "no breakaway"
    k, n, tilt = row["kappa"], row["held_contacts"], row["contact_tilt_deg"]
    tilted = n >= 2 and tilt > TILT_NOISE_DEG
    lock = row["contacts_lock_kappa"]
    held = f"up to {n} contacts tilted up to {tilt:.2g} deg, whose lock is kappa {lock:.3g}"
    first, step = row["first_slip_kappa"], row["force_step_fp"]
    late = kappa_error(row["kappa_mj"], k) - kappa_error(first, k)
    if row["slid_before_r_tip"] > 0 and late > change_tolerance(k, step, step):
        slip = (
            f"slipped at kappa {first:.4g} ({kappa_error(first, k):+.2%}), "
            f"slid {row['slid_before_r_tip']:.2g} r_tip, held again by {held}"
        )
        return f"edge catch: {slip}" if tilted else f"caught: {slip}"
    if tilted:
        return f"tilted contacts: {held}"
    return f"one contact with the plane's normal ({n} found)" if n else "no contact at breakaway"


def _plane_file(out_dir, slope: float, az: float):
    """The plane's surface file under ``out_dir/surfaces`` (written once), its grid
    :data:`PLANE_SAMPLES` a side."""
    n = PLANE_SAMPLES
    name = f"plane_s{slope:g}_a{az:g}" + (f"_n{n}" if n != 41 else "")
    path = out_dir / "surfaces" / f"{name}.npz"
    if not path.is_file():
        surface_io.save_surface(inclined_plane(slope_deg=slope, azimuth_deg=az, n=n), path)
    return path


def _engine_summary(sel: list[dict]) -> dict:
    """Breakaway errors over the engaged planes and region agreement of one setting's rows."""
    eng = [abs(r["ratio"] - 1) for r in sel if r["region"] == "engaged"]
    eng_f = [e for e in eng if np.isfinite(e)]
    tilts = [abs(r.get("equivalent_tilt_deg", np.nan)) for r in sel if r["region"] == "engaged"]
    tilts = [t for t in tilts if np.isfinite(t)]
    errs = [abs(r["error"]) for r in sel if r["region"] == "engaged" and np.isfinite(r.get("error", np.nan))]
    return {
        "max_error": float(max(errs)) if errs else float("nan"),
        "mean_error": float(np.mean(errs)) if errs else float("nan"),
        "max_equivalent_tilt_deg": float(max(tilts)) if tilts else float("nan"),
        "mean_equivalent_tilt_deg": float(np.mean(tilts)) if tilts else float("nan"),
        "engaged_planes": len(eng),
        "engaged_breakaways": len(eng_f),
        "max_rel_error": float(max(eng_f)) if eng_f else float("nan"),
        "mean_rel_error": float(np.mean(eng_f)) if eng_f else float("nan"),
        "region_agreement": float(np.mean([r["region_agrees"] for r in sel])),
    }

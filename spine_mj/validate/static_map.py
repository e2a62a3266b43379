"""Study 1: the static probe on inclined planes against the analytic engagement ratio.

The breakaway ratio ``kappa_mj / kappa`` over slope angle and azimuth (engaged, self-lock
and slip regions, Eqs. 1-3), per engine setting of the plan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from spine_mj import sim, surface_io
from spine_mj.theory import engagement
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
    "PLANE_START",
    "StaticMapResult",
    "equivalent_tilt_deg",
    "hold_force",
    "kappa_tilt_gain",
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
        ``mean_rel_error`` of ``|kappa_mj / kappa - 1|`` over the engaged planes, the same
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
    """

    rows: list[dict]
    per_engine: dict[str, dict]
    mu: float
    static_kappa_max_rel_error: float
    convergence: dict = field(default_factory=dict)

    def validation_keys(self) -> dict:
        """This study's keys of ``validation.json``."""
        return {
            "static_kappa_max_rel_error": self.static_kappa_max_rel_error,
            "static_by_engine": self.per_engine,
            "static_convergence": self.convergence,
        }

    def as_dict(self) -> dict:
        return {
            "rows": self.rows,
            "per_engine": self.per_engine,
            "mu": self.mu,
            "static_kappa_max_rel_error": self.static_kappa_max_rel_error,
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
                "store_trajectories": False,
            },
            "surfaces": [{"file": str(path)}],
            "starts": {"frame": "absolute", "points": [list(PLANE_START)]},
            "drive": {"protocol": "static", "ie": PROBE_IE, "start_force": hold * MASS_KG * GRAVITY},
            "grid": grid,
        }
        tag = "-".join(f"{k_}{v}" for k_, v in ov) or "default"
        df, _ = runner(doc, f"static/s{slope:g}-a{az:g}-{tag}", workers=1)
        r = df.iloc[0]
        kmj = float(r.get("kappa_mj", np.nan))
        end = str(r.get("end_reason", r["status"]))
        mj_region = {"breakaway": "engaged", "self_lock": "self_lock", "slid": "slip"}.get(end, end)
        ratio = kmj / k if (region == engagement.ENGAGED and k > 0) else float("nan")
        rows.append(
            {
                "engine": label,
                "slope_deg": float(slope),
                "azimuth_deg": float(az),
                "region": region_names[region],
                "kappa": k,
                "kappa_mj": kmj,
                "ratio": ratio,
                # the facet cause, plane by plane: the pole's amplification of a tilt and
                # the tilt that explains this plane's error
                "kappa_gain_per_deg": gain,
                "equivalent_tilt_deg": equivalent_tilt_deg(ratio, gain),
                "end_reason": end,
                "hold_over_w": hold,
                "region_agrees": mj_region == region_names[region],
            }
        )
    return rows


def _plane_file(out_dir, slope: float, az: float):
    """The plane's surface file under ``out_dir/surfaces`` (written once), its grid
    :data:`PLANE_SAMPLES` a side."""
    n = PLANE_SAMPLES
    name = f"plane_s{slope:g}_a{az:g}" + (f"_n{n}" if n != 41 else "")
    path = out_dir / "surfaces" / f"{name}.npz"
    if not path.is_file():
        surface_io.save_surface(sim.inclined_plane(slope_deg=slope, azimuth_deg=az, n=n), path)
    return path


def _engine_summary(sel: list[dict]) -> dict:
    """Breakaway errors over the engaged planes and region agreement of one setting's rows."""
    eng = [abs(r["ratio"] - 1) for r in sel if r["region"] == "engaged"]
    eng_f = [e for e in eng if np.isfinite(e)]
    tilts = [abs(r.get("equivalent_tilt_deg", np.nan)) for r in sel if r["region"] == "engaged"]
    tilts = [t for t in tilts if np.isfinite(t)]
    return {
        "max_equivalent_tilt_deg": float(max(tilts)) if tilts else float("nan"),
        "mean_equivalent_tilt_deg": float(np.mean(tilts)) if tilts else float("nan"),
        "engaged_planes": len(eng),
        "engaged_breakaways": len(eng_f),
        "max_rel_error": float(max(eng_f)) if eng_f else float("nan"),
        "mean_rel_error": float(np.mean(eng_f)) if eng_f else float("nan"),
        "region_agreement": float(np.mean([r["region_agrees"] for r in sel])),
    }

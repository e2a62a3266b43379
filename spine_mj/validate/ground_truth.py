"""Study: ground truth for the dynamics. MuJoCo's spring drive against the closed forms of
:mod:`spine_mj.theory.tomlinson`, each with its measured error:

* the spring-block on a flat plane: the period ``2 pi / w`` and peak speed ``2 V`` of the
  speed swing after breakaway (one direct run of :class:`spine_mj.sim.Rig`: a plane has no
  characteristic length for a sweep's scales);
* Prandtl-Tomlinson on corrugations (slope amplitudes x mu x K / K*): slip events per
  wavelength (none above K*, one below) and the onset force against the fold's;
* lift-off over Gaussian ridges of several widths: the I_e at which the tip first leaves
  the crest against ``1 / (L_c c)``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from spine_mj import sim, sweep
from spine_mj.choices import DEFAULT_ENGINE, ENGINES
from spine_mj.roughness import characteristic_length
from spine_mj.surface_io import save_surface
from spine_mj.surfaces import GridSurface, inclined_plane
from spine_mj.theory.tomlinson import (
    SLOPE_LENGTH_PER_WAVELENGTH,
    Corrugation,
    gaussian_ridge_path_curvature,
    liftoff_inertia_number,
    spring_block_period_s,
)
from spine_mj.theory.tomlinson_dynamics import PTParams, SineProfile, integrate
from spine_mj.validate.plans import GRAVITY, MASS_KG, ValidationPlan
from spine_mj.validate.study_runner import StudyRunner

__all__ = ["GroundTruthResult", "crest_check", "ground_truth", "spring_block_check", "spring_block_ladder"]

#: I_e of the Prandtl-Tomlinson runs (the quasistatic corner).
TOMLINSON_IE = 1e-4
#: Tip radius of the corrugation runs over the wavelength (the rig's default L_c / 100).
TOMLINSON_TIP = 0.01
#: hfield samples per wavelength: facet kinks then add bursts of at most ~2 V to a slide.
POINTS_PER_WAVE = 128
#: Ridge height (surface units) and tip radius [m]; the crest's path curvature is
#: ``1 / (sigma^2 / A + r)``.
RIDGE_HEIGHT = 0.5
RIDGE_TIP_M = 5e-4
#: The ridge runs' time step and contact time constant [s]: a quarter of the default step
#: with the default's contact softness (2 default steps), so the tip's approach on the flat
#: stays within 0.2 tip radii of the surface (measured; a contact as stiff as 2 of these
#: steps bounces it by a tip radius) and a hop is the crest's.
RIDGE_TIMESTEP_S = 1.25e-4
RIDGE_SOLREF_S = 1e-3
#: Stiffness number of the ridge runs: stiff enough that the tip crosses the crest at the
#: carriage's speed within ~20 % (at K = 30 it swung between 0.6 and 1.5 V there).
RIDGE_K = 300.0
#: The tip has left the crest when its centre rises this many tip radii above its path.
LIFTOFF_GAP_RADII = 0.5
#: The lift-off check's tolerance, in carriage I_e over I_e*: contact holds at the first and
#: is lost by the second (the scan measured the crest I_e that first left within
#: 0.85-1.11 I_e* at width 0.5 and 1.23-1.66 I_e* at width 0.35).
LIFTOFF_BELOW, LIFTOFF_ABOVE = 0.6, 1.6


@dataclass(frozen=True)
class GroundTruthResult:
    """Result of :func:`ground_truth`.

    Attributes
    ----------
    spring_block : dict
        Measured and predicted period [s] and peak speed [V], with relative errors.
    tomlinson : list of dict
        Per (slope amplitude, mu, K / K*): K*, K, slip events, wavelengths travelled,
        events per wavelength, the fold's kappa, the largest and mean onset force [F_p] and
        their relative errors, the largest speed [V] and the stuck fraction.
    liftoff : list of dict
        Per ridge width: the predicted I_e*, the I_e values run and the I_e of the speed
        measured at the crest, the crest gap of each and its largest gap on the flat
        approach (the harness's own hop) [tip radii], the bracket of the
        crest I_e (last that held, first that left) and its ratios to the prediction.
    spring_block_ladder : list of dict
        :func:`spring_block_check` at each of :data:`SPRING_BLOCK_K` (the engine step's
        spring rule, from the softest drive to the stiffest).
    """

    spring_block: dict
    tomlinson: list[dict]
    liftoff: list[dict]
    spring_block_ladder: list[dict] = dataclasses.field(default_factory=list)

    def as_dict(self) -> dict:
        return {
            "spring_block": self.spring_block,
            "spring_block_ladder": self.spring_block_ladder,
            "tomlinson": self.tomlinson,
            "liftoff": self.liftoff,
        }

    def validation_keys(self) -> dict:
        """This study's key of ``validation.json``."""
        return {"ground_truth": self.as_dict()}


def ground_truth(plan: ValidationPlan, runner: StudyRunner) -> GroundTruthResult:
    """Run the three closed-form checks of ``plan`` (its ``ground_truth_*`` sizes)."""
    runner.study = "ground_truth"
    with runner.phase("spring-block on a flat plane"):
        block = spring_block_check()
        ladder = spring_block_ladder()
    corrugations = [
        Corrugation(s, mu, tip_radius=TOMLINSON_TIP)
        for s in plan.ground_truth.slopes
        for mu in plan.ground_truth.mus
    ]
    ks = [
        [float(f"{f * c.critical_stiffness():.6g}") for f in plan.ground_truth.k_factors]
        for c in corrugations
    ]
    names = [f"ground-truth/pt-s{c.slope_amplitude:g}-mu{c.mu:g}" for c in corrugations]
    jobs = [
        (corrugation_doc(name, c.slope_amplitude, c.mu, k, TOMLINSON_IE, plan.ground_truth.waves), name)
        for c, k, name in zip(corrugations, ks, names)
    ]
    # the corrugations' sweeps at once: the workers stay busy across the sweeps' ends
    done = runner.many(jobs, "Prandtl-Tomlinson corrugations")
    rows = []
    for c, (df, _) in zip(corrugations, done):
        rows += _tomlinson(c, df[df["analysis"] == "engine"])
    lift = [_liftoff(plan, runner, w) for w in plan.ground_truth.ridge_widths]
    return GroundTruthResult(spring_block=block, tomlinson=rows, liftoff=lift, spring_block_ladder=ladder)


#: Stiffness numbers of the spring-block ladder (K = k l_s / F_p; on a plane l_s = L_c): the
#: step rule must keep the period and peak speed right from the softest drive to the stiffest.
SPRING_BLOCK_K = (3.0, 30.0, 300.0, 3000.0, 30000.0)


def spring_block_check(
    speed_m_s: float = 0.004,
    stiffness_n_m: float | None = 100.0,
    mu: float = 0.5,
    *,
    stiffness_number: float | None = None,
    periods: int = 12,
    engine: str = DEFAULT_ENGINE,
) -> dict:
    """The spring-block on a flat plane after breakaway: the period of the speed swing
    (autocorrelation's first peak, refined between steps by a parabola through its three
    highest lags) and its peak (mean plus the fundamental's amplitude: the contact adds
    step-to-step noise on top) against ``2 pi / w`` and ``2 V``. The period tests the
    engine step (its error grows as ``(omega dt)^2 / 24``); the peak also the friction: the
    swing's force amplitude ``V sqrt(k m)`` is small beside ``mu W`` on a soft spring, where
    MuJoCo's velocity-dependent (soft) friction rows flatten it. The rig is built for the
    spring (the step rule's ``omega dt``), the run lasts until ``periods`` swings after the
    predicted breakaway. ``stiffness_number`` (K) replaces ``stiffness_n_m`` when given;
    ``engine`` is one of :data:`spine_mj.choices.ENGINES`."""
    surface = inclined_plane(slope_deg=0.0, half_width=0.05, n=101)
    tip = sim.TipParams(tip_radius_m=5e-4, mu_s=mu, mass_kg=MASS_KG)
    scales = sim.Scales.for_surface(surface, tip=tip)
    k = scales.stiffness_for(stiffness_number) if stiffness_number is not None else stiffness_n_m
    rig = sim.build_rig(
        surface,
        engine=engine,
        tip_radius_m=5e-4,
        mu=mu,
        mass_kg=MASS_KG,
        speed_m_s=speed_m_s,
        stiffness_n_m=k,
    )
    period = spring_block_period_s(k, tip.mass_kg)
    breakaway = mu * scales.preload_n / (k * speed_m_s)
    res = rig.run(
        sim.SpringDrive(speed_m_s=speed_m_s, stiffness_n_m=k, duration_s=1.05 * breakaway + periods * period),
        start=(-0.04, 0.0),
    )
    i0 = res.drive_start_index + int(np.argmax(res.moving[res.drive_start_index :]))
    vx, t = res.velocity_m_s[i0:, 0], res.time_s[i0:]
    dt = float(t[1] - t[0])
    dv = vx - vx.mean()
    ac = np.correlate(dv, dv, "full")[dv.size - 1 :]
    lags = np.arange(max(2, int(0.5 * period / dt)), min(int(1.5 * period / dt), ac.size - 1))
    j = int(lags[np.argmax(ac[lags])])
    a, b, c = ac[j - 1], ac[j], ac[j + 1]
    measured = float((j + 0.5 * (a - c) / (a - 2 * b + c)) * dt)
    n = int((t[-1] - t[0]) // measured * measured / dt)
    ph = 2 * np.pi * (t[:n] - t[0]) / measured
    amp = 2 * np.hypot((dv[:n] * np.cos(ph)).mean(), (dv[:n] * np.sin(ph)).mean())
    peak = float((vx[:n].mean() + amp) / speed_m_s)
    return {
        "stiffness_number_K": scales.stiffness_number(k),
        "stiffness_n_m": k,
        "period_s": measured,
        "period_predicted_s": period,
        "period_rel_error": measured / period - 1,
        "peak_speed_v": peak,
        "peak_speed_rel_error": peak / 2 - 1,
        "slip_events": len(res.slip_events),
        "timestep_s": rig.engine.timestep_s,
        "omega_dt": sim.spring_omega_dt(k, tip.mass_kg, rig.engine.timestep_s),
        "steps": res.simulated_steps,
        "end_reason": res.end_reason.value,
    }


def spring_block_ladder(stiffness_numbers=SPRING_BLOCK_K) -> list[dict]:
    """:func:`spring_block_check` at each stiffness number: the step rule's check."""
    return [spring_block_check(stiffness_number=float(kn)) for kn in stiffness_numbers]


def _tomlinson(c: Corrugation, df) -> list[dict]:
    """The rows of one corrugation's MuJoCo runs ``df`` (one per K)."""
    s, mu = c.slope_amplitude, c.mu
    k_star = c.critical_stiffness()
    rows = []
    for _, r in df.sort_values("K").iterrows():
        k = float(r["K"])
        travel = float(r["end_x"]) - CORRUGATION_START
        row = {
            "slope_amplitude": s,
            "mu": mu,
            "k_star": k_star,
            "K": k,
            "k_over_k_star": k / k_star,
            "slope_length_rel_error": float(r["slope_length"]) / SLOPE_LENGTH_PER_WAVELENGTH - 1,
            "slip_events": int(r["slip_events"]),
            "waves": travel,
            "events_per_wave": int(r["slip_events"]) / travel if travel > 0 else math.nan,
            "max_speed_v": float(r["max_speed_over_drive"]),
            "stuck_fraction": float(r["stuck_fraction"]),
            "status": str(r["status"]),
        }
        if k < k_star:
            fold = c.fold(k)[1]
            row.update(_reference(c, r, k, travel))
            row.update(
                fold_kappa=fold,
                onset_max_fp=float(r["slip_onset_fp_max"]),
                onset_mean_fp=float(r["slip_onset_fp_mean"]),
                onset_max_rel_error=float(r["slip_onset_fp_max"]) / fold - 1,
                onset_mean_rel_error=float(r["slip_onset_fp_mean"]) / fold - 1,
            )
        rows.append(row)
    return rows


def _reference(c: Corrugation, r, k: float, travel: float) -> dict:
    """The reference integrator (:mod:`spine_mj.theory.tomlinson_dynamics`, a point tip on the
    smooth profile) with the MuJoCo run's m, k, W, V, over its travel: events per
    wavelength, onset errors against the fold and the longest jump [wavelengths]."""
    unit, w = sim.DEFAULT_LENGTH_SCALE_M, MASS_KG * GRAVITY
    p = PTParams(MASS_KG, k * w / (float(r["slope_length"]) * unit), w, float(r["speed_m_s"]), c.mu)
    stretch = w * c.kappa_range()[1] / p.stiffness_n_m
    run = integrate(
        p,
        SineProfile(c.slope_amplitude, unit),
        CORRUGATION_START * unit,
        (max(travel, 1.0) * unit + stretch) / p.speed_m_s,
        0.01 * 2 * math.pi / p.omega_rad_s,
    )
    fold = c.fold(k)[1]
    onsets = np.array([e.onset_force_n / w for e in run.events]) / fold - 1
    waves = (run.x_m[-1] - run.x_m[0]) / unit
    return {
        "ref_events_per_wave": len(run.events) / waves if waves > 0 else math.nan,
        "ref_onset_max_rel_error": float(onsets.max()) if onsets.size else math.nan,
        "ref_onset_mean_rel_error": float(onsets.mean()) if onsets.size else math.nan,
        "ref_max_jump_waves": max((e.jump_length_m / unit for e in run.events), default=math.nan),
    }


#: Where the corrugation runs start (x over the wavelength; y = 0): a quarter wavelength
#: before a crest's steepest rising point.
CORRUGATION_START = 0.75


def corrugation_runs(runner: StudyRunner, name: str, s: float, mu: float, ks, ie, waves: int):
    """The ``engine`` rows of :func:`corrugation_doc`'s sweep, stored as ``name``."""
    df, _ = runner(corrugation_doc(name, s, mu, ks, ie, waves), name)
    return df[df["analysis"] == "engine"]


def corrugation_doc(name: str, s: float, mu: float, ks, ie, waves: int) -> dict:
    """The sweep config of the spring drive on a corrugation (slope amplitude ``s``, unit
    wavelength, :data:`POINTS_PER_WAVE`, ``waves`` wavelengths) at stiffness numbers ``ks``
    and I_e ``ie`` (one or a list), from :data:`CORRUGATION_START`."""
    return {
        "sweep": {"name": name.replace("/", "-"), "seed": 1, "analyses": ["engine"]},
        "surfaces": [
            {
                "preset": "corrugation",
                "set": {"slope_amplitude": s, "points_per_wave": POINTS_PER_WAVE, "n_waves": waves},
            }
        ],
        "starts": {"frame": "absolute", "x": [CORRUGATION_START], "y": [0.0]},
        "drive": {"protocol": "spring", "ie": ie, "K": list(ks)},
        "grid": {"mu": mu, "tip_radius": TOMLINSON_TIP, "record_every": 50},
    }


def ridge(width: float, height: float = RIDGE_HEIGHT) -> GridSurface:
    """A Gaussian ridge ``A exp(-x^2 / 2 sigma^2)`` uniform in y, crest at x = 0, on
    x in [-6, 3] (a long flat approach), 80 samples per unit."""
    x = np.linspace(-6.0, 3.0, 721)
    y = np.linspace(-0.5, 0.5, 81)
    h = np.broadcast_to(height * np.exp(-(x**2) / (2 * width**2)), (y.size, x.size)).copy()
    return GridSurface(
        heights=h, x=x, y=y, unit="1", metadata={"generator": "ridge", "params": {"width": width}}
    )


def _liftoff(plan: ValidationPlan, runner: StudyRunner, width: float) -> dict:
    """The lift-off scan of one ridge width: a stiff spring drive (K = :data:`RIDGE_K`,
    the tip pushed at nearly the carriage's speed) at the plan's fractions of the predicted
    I_e*; per run the crest gap and the I_e of the speed measured at the crest."""
    surf = ridge(width)
    folder = runner.out_dir / "ground-truth"
    folder.mkdir(parents=True, exist_ok=True)
    path = save_surface(surf, folder / f"ridge-{width:g}.npz")
    unit = sim.DEFAULT_LENGTH_SCALE_M
    lc_m = characteristic_length(surf) * unit
    ie_star = liftoff_inertia_number(
        gaussian_ridge_path_curvature(RIDGE_HEIGHT * unit, width * unit, RIDGE_TIP_M), lc_m
    )
    ies = [float(f"{f * ie_star:.6g}") for f in plan.ground_truth.liftoff_factors]
    doc = {
        "sweep": {"name": f"ridge-{width:g}", "seed": 1, "analyses": ["engine"]},
        "surfaces": [{"file": str(Path(path).relative_to(runner.out_dir))}],
        "starts": {"frame": "absolute", "x": [-5.0], "y": [0.0]},
        "drive": {"protocol": "spring", "ie": ies, "K": RIDGE_K},
        "grid": {
            "mu": 0.3,
            "tip_radius": RIDGE_TIP_M / unit,
            "timestep": RIDGE_TIMESTEP_S,
            "solref_timeconst": RIDGE_SOLREF_S,
        },
    }
    df, store = runner(doc, f"ground-truth/ridge-{width:g}")
    runs = []
    for _, r in df[df["analysis"] == "engine"].iterrows():
        tr = sweep.load_trajectories(store, r["case_id"], analysis="engine", columns=["x", "z", "time_s"])
        tr = tr.sort_values("step")
        x, z, t = tr["x"].to_numpy(), tr["z"].to_numpy(), tr["time_s"].to_numpy()
        crest = np.abs(x) < 0.1 * width
        v = np.gradient(x, t)[crest].mean() * unit if crest.sum() > 1 else math.nan
        ie = float(r["ie"])
        tip = RIDGE_TIP_M / unit
        flat = (x > -4.0) & (x < -3.0)  # the approach, where the surface is flat
        approach = float(((z[flat] - tip) / tip).max()) if flat.any() else math.nan
        runs.append((ie, ie * (v / float(r["speed_m_s"])) ** 2, _crest_gap(x, z, width, tip), approach))
    runs.sort()
    # the bracket in the I_e of the speed at the crest (what the criterion reads; a spring
    # run's crest speed need not rise with the carriage's)
    first = min((run[1] for run in runs if run[2] > LIFTOFF_GAP_RADII), default=math.nan)
    held = [run[1] for run in runs if run[2] <= LIFTOFF_GAP_RADII and not run[1] > first]
    last_held = max(held, default=math.nan)
    return {
        "width": width,
        "height": RIDGE_HEIGHT,
        "ie_star_predicted": ie_star,
        "ie_values": [run[0] for run in runs],
        "crest_ie_values": [run[1] for run in runs],
        "crest_gap_radii": [run[2] for run in runs],
        "approach_gap_radii": [run[3] for run in runs],
        "last_held_crest_ie": last_held,
        "first_liftoff_crest_ie": first,
        "ratio_low": last_held / ie_star,
        "ratio_high": first / ie_star,
    }


def crest_check(width: float, factor: float, engine: str = DEFAULT_ENGINE) -> tuple[float, float, float]:
    """One carriage over :func:`ridge` of ``width`` at ``factor`` times the predicted I_e* in
    ``engine`` (the scan's tip, spring, mu and step; its contact time constant where the
    engine reads one): ``(crest I_e / I_e*, largest crest gap [tip radii], longest flight
    [widths])``, the crest I_e that of the speed measured at the crest."""
    surf = ridge(width)
    unit = sim.DEFAULT_LENGTH_SCALE_M
    ie_star = liftoff_inertia_number(
        gaussian_ridge_path_curvature(RIDGE_HEIGHT * unit, width * unit, RIDGE_TIP_M),
        characteristic_length(surf) * unit,
    )
    ie = factor * ie_star
    soft = {"solref_timeconst_s": RIDGE_SOLREF_S} if "solref_timeconst_s" in ENGINES[engine].options else {}
    rig = sim.build_rig(
        surf, engine=engine, mu=0.3, tip_radius_m=RIDGE_TIP_M, timestep_s=RIDGE_TIMESTEP_S, ie=ie, **soft
    )
    res = rig.run(sim.build_drive(rig.scales, ie=ie, stiffness_number=RIDGE_K), start=(-2.0, 0.0))
    x, z = res.position_m[:, 0] / unit, res.position_m[:, 2] / unit
    crest_speed = res.velocity_m_s[np.abs(x) < 0.1 * width, 0].mean()
    xs, gaps = crest_gaps(x, z, width, RIDGE_TIP_M / unit)
    return factor * (crest_speed / res.speed_m_s) ** 2, float(gaps.max()), longest_flight(xs, gaps) / width


def _crest_gap(x, z, width: float, tip: float) -> float:
    """Largest height of the tip centre above its path on the ridge within half a width of
    the crest, in tip radii (surface units in)."""
    _, gaps = crest_gaps(x, z, width, tip)
    return float(gaps.max()) if gaps.size else math.nan


def crest_gaps(x, z, width: float, tip: float) -> tuple[np.ndarray, np.ndarray]:
    """The recorded steps within half a width of the crest of :func:`ridge` (height
    :data:`RIDGE_HEIGHT`): their x and the height of the tip centre above its path there,
    in tip radii, in recording order (positions and ``tip`` in surface units)."""
    x, z = np.asarray(x, float), np.asarray(z, float)
    near = np.abs(x) < 0.5 * width
    f = RIDGE_HEIGHT * np.exp(-(x[near] ** 2) / (2 * width**2))
    fp = -x[near] / width**2 * f
    return x[near], (z[near] - f - tip * np.sqrt(1 + fp * fp)) / tip


def longest_flight(x, gaps, threshold: float = LIFTOFF_GAP_RADII) -> float:
    """The x-length of the longest run of consecutive steps whose gap exceeds ``threshold``
    tip radii (0 when none): a flight, which one step's contact chatter is not."""
    above = np.concatenate([[False], np.asarray(gaps) > threshold, [False]])
    edges = np.flatnonzero(above[1:] != above[:-1])
    x = np.asarray(x, float)
    return max((float(x[b - 1] - x[a]) for a, b in zip(edges[0::2], edges[1::2])), default=0.0)

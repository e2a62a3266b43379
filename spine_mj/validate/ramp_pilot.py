"""Duration of a ramp-with-reset run, planned from a pilot run's per-cycle slip.

A capped ramp covers only part of the path to the domain edge; :func:`ramp_duration` sets
the duration that would cover it (capped at a step budget) and says how much the cap
leaves, and :func:`pilot_rig` builds the rig a sweep case would build for the pilot.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from spine_mj import presets, sim
from spine_mj.validate.plans import MASS_KG

__all__ = ["RampPlan", "pilot_rig", "ramp_duration"]


@dataclass(frozen=True)
class RampPlan:
    """Duration of a ramp-with-reset run from a pilot run's per-cycle slip (one I_e).

    Attributes
    ----------
    ie_equivalent : float
        ``m v_eq^2 / (F_p L_c)`` with ``v_eq = L_c rate / F_p``: the speed at which a
        rate-limited force would move the tip by ``L_c`` while it grows by ``F_p``
        (:meth:`spine_mj.sim.Rig.inertia_number`). This is the ramp's ``I_e``.
    rate_n_s : float
    target_lc : float
        Distance along x to cover: from the start to the domain edge, in L_c.
    slip_per_cycle_lc : float
        Measured x advance per ramp cycle (slip onset to reset) in the pilot; NaN when the
        pilot saw no slip.
    cycle_s : float
        Measured time per cycle (ramp to breakaway + slip + settle).
    required_s : float
        ``cycle_s * target_lc / slip_per_cycle_lc`` (inf without a slip).
    duration_s : float
        ``min(required_s, max_steps * dt)``.
    capped : bool
    coverage_expected : float
        Fraction of the target the capped duration should cover.
    """

    ie_equivalent: float
    rate_n_s: float
    target_lc: float
    slip_per_cycle_lc: float
    cycle_s: float
    required_s: float
    duration_s: float
    timestep_s: float
    capped: bool
    coverage_expected: float

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["required_steps"] = (
            self.required_s / self.timestep_s if math.isfinite(self.required_s) else float("inf")
        )
        return d


def pilot_rig(preset: str, seed, mu: float, tip: float, resolution: int):
    """The rig a sweep case builds for these keys (default engine from the scales).

    Parameters
    ----------
    preset : str
        The surface's preset.
    seed : int or None
        Its seed (None: the preset's).
    mu : float
        Static friction coefficient mu_s.
    tip : float
        Tip radius in surface units.
    resolution : int
        Samples a side of an analytic surface's hfield.

    Returns
    -------
    (Rig, float)
        The rig and the surface unit in metres.
    """
    surface = presets.make_surface(preset, **({} if seed is None else {"seed": int(seed)}))
    unit_m = sim.DEFAULT_LENGTH_SCALE_M if surface.unit == "1" else 1.0
    rig = sim.build_rig(
        surface, mu=mu, tip_radius_m=tip * unit_m, mass_kg=MASS_KG, hfield_resolution=resolution, driven=False
    )
    return rig, unit_m


def ramp_duration(
    rig, start, ie: float, *, target_lc: float, max_steps: int, slide_lc: float = 0.1, pilot_cycles: int = 6
) -> RampPlan:
    """Duration of a ramp-with-reset run at ``ie`` that covers ``target_lc`` along x.

    A pilot run from ``start`` (at most ``max_steps // 4`` steps, or ``pilot_cycles`` ramp
    cycles estimated at 3 F_p / rate + settle each) measures the x advance and time per
    cycle. The duration is three times the time that many cycles take to cover the target
    (cycles lengthen along the path as kappa, the force each ramp must reach, grows) plus
    one ramp to the self-lock cap ``kappa_cap F_p`` (a trapped tip must get there to count as
    locked), capped at ``max_steps`` engine steps. A run that leaves the domain or locks
    ends early. The cap is the honest limit of a run here: see the report.

    Parameters
    ----------
    rig : Rig
        The rig the run uses.
    start : tuple of float
        The start (surface units).
    ie : float
        The ramp's equivalent inertia number.
    target_lc : float
        Distance along x to cover, in L_c.
    max_steps : int
        Cap on the run's engine steps.
    slide_lc : float
        The ramp's slide distance before the force drops, in L_c.
    pilot_cycles : int
        Ramp cycles of the pilot run.
    """
    sc = rig.scales
    dt = rig.engine.timestep_s
    # sqrt(I_e F_p L_c / m) as written here, not Scales.speed_for (equal but for the last
    # bits): the committed validation numbers were measured with it
    speed = math.sqrt(ie * sc.preload_n * sc.char_length_m / sc.mass_kg)
    rate = sc.force_rate_for(speed)
    settle = 200 * dt
    pilot = min(pilot_cycles * (3 * sc.preload_n / rate + settle), max(max_steps // 4, 10) * dt)
    r = rig.run(
        sim.RampDrive(rate_n_s=rate, duration_s=pilot, slide_distance_m=slide_lc * sc.char_length_m),
        start=start,
    )
    i0 = r.drive_start_index
    onsets = [e for e in r.events if e.kind == "move_onset"]
    resets = [e for e in r.events if e.kind == "reset"]
    dx = (r.position_m[-1, 0] - r.position_m[i0, 0]) / sc.char_length_m
    cap = max_steps * dt
    if onsets and dx > 0:
        # advance and time per completed cycle (up to the last reset when there is one)
        if resets:
            k = resets[-1].index
            n_cyc = len(resets)
            adv = (r.position_m[k, 0] - r.position_m[i0, 0]) / sc.char_length_m
            t_cyc = (r.time_s[k] - r.time_s[i0]) / n_cyc
        else:
            n_cyc, adv, t_cyc = len(onsets), dx, r.time_s[-1] - r.time_s[i0]
        per = adv / n_cyc if adv > 0 else dx / len(onsets)
        lock_s = sim.Detection().kappa_cap * sc.preload_n / rate
        required = 3 * t_cyc * target_lc / per + lock_s if per > 0 else float("inf")
    else:
        per, t_cyc, required = float("nan"), float("nan"), float("inf")
    duration = float(f"{min(required, cap):.4g}")
    covered = (duration / t_cyc * per / target_lc) if (np.isfinite(per) and t_cyc > 0) else 0.0
    return RampPlan(
        ie_equivalent=float(rig.scales.inertia_number(speed)),
        rate_n_s=rate,
        target_lc=float(target_lc),
        slip_per_cycle_lc=float(per),
        cycle_s=float(t_cyc),
        required_s=float(required),
        duration_s=duration,
        timestep_s=dt,
        capped=bool(required > cap),
        coverage_expected=float(min(covered, 1.0)),
    )

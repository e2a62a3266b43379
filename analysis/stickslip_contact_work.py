"""Where MuJoCo's energy goes in a slip (issue 42 item 5): one spring-drive run of the
``abbm`` preset's seed 1 at K 10 and dt / 2 (the ``dt2a`` cell's run over x 22 550-22 600,
``stickslip_engines.py``'s rig and drive), stepped by the package's plain ``mj_step``
reference (``backend="python"``) with each step's contact forces recorded, so that the
work of the contact's normal force (nonzero only through the soft contact's penetration
speed), of its friction force, and Coulomb's ``mu int N |v_t| dt`` are split per slip.
``--dampratio r`` reruns it with the contact's damping ratio lowered to r at the same
contact stiffness: ``solref = (2 dt / r, r)`` (MuJoCo's stiffness goes as ``1 / (tc r)^2``,
its damping as ``1 / tc``; the rule's is ``(2 dt, 1)``); ``--impratio i`` sets MuJoCo's
frictional-to-normal impedance ratio (the rule's 1). Stepped without the package's
refine-on-penetration rerun, so that each row is the rig asked for. Run from the repository
root (each damping ratio ~300 CPU s)::

    python analysis/stickslip_contact_work.py --dampratio 1,0.5,0.2

Writes ``analysis/reports/stickslip/contact_work.json`` and prints a table.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from stickslip_engines import MU, _positive, abbm_prefix, crop

import spine_mj.sim.lanes as lanes
from spine_mj.sim.build import build_rig
from spine_mj.validate.slip_catalog import TrackUnits, engine_drop_rows, track_landscape
from spine_mj.validate.stickslip_outputs import pre_stretched_drive

OUT = Path(__file__).resolve().parent / "reports" / "stickslip" / "contact_work.json"
SEED, K, IE, FLOOR = 1, 10.0, 7.3e-6, 1.7e-4  # the dt2a cell's plan
A, B, SEGMENT = 22550.0, 22572.0, 50.0  # the cell's run from 22 550, to past the 46.8 L_c slip
#: Per-step columns: engine time, tip x, z, speeds x, y, z, summed normal force, normal
#: power, friction power, Coulomb's ``mu N |v_t|``, the actuators' power (spring, preload)
#: and the other smooth forces' (model units).
COLS = ("t", "x", "z", "vx", "vy", "vz", "N", "Pn", "Pt", "Pc", "Pa", "Po", "Pq", "dKE")
_pieces: list[np.ndarray] = []


def _recording_steps(model, init, warm, ctrl, state, sens):
    """:func:`spine_mj.sim.lanes.python_steps`, plus each step's contact work."""
    import mujoco

    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    d = mujoco.MjData(model)
    mujoco.mj_setState(model, d, init, full)
    d.qacc_warmstart[:] = warm
    nv, mu = model.nv, float(model.geom_friction[1, 0])
    rec = np.zeros((ctrl.shape[0], len(COLS)))
    first_warn = None
    for i in range(ctrl.shape[0]):
        d.ctrl[:] = ctrl[i, : model.nu]
        d.mocap_pos[:] = ctrl[i, model.nu :].reshape(-1, 3)
        v0 = d.qvel.copy()
        mujoco.mj_step(model, d)
        mujoco.mj_getState(model, d, state[i], full)
        sens[i] = d.sensordata
        row = rec[i]
        row[0], row[1], row[2] = d.time, d.xpos[1, 0], d.xpos[1, 2]
        row[3:6] = d.qvel[:3]
        vm = 0.5 * (v0 + d.qvel)
        row[10] = float(d.qfrc_actuator @ vm)
        row[11] = float((d.qfrc_passive - d.qfrc_bias + d.qfrc_applied) @ vm)
        row[12] = float(d.qfrc_constraint @ vm)
        row[13] = 0.5 * float(model.body_mass[1]) * float(d.qvel @ d.qvel - v0 @ v0)
        if d.ncon and d.nefc:
            adr = d.contact.efc_address[: d.ncon]
            adr = adr[adr >= 0]  # contacts in the margin but not active have no rows
            jac = d.efc_J.reshape(-1)[: d.nefc * nv].reshape(d.nefc, nv)
            vel = jac @ (0.5 * (v0 + d.qvel))  # the mean speed: sum P dt = the change in KE
            f = d.efc_force[: d.nefc]
            fn, vt1, vt2 = f[adr], vel[adr + 1], vel[adr + 2]
            row[6] = fn.sum()
            row[7] = float(fn @ vel[adr])
            row[8] = float(f[adr + 1] @ vt1 + f[adr + 2] @ vt2)
            row[9] = -mu * float(fn @ np.hypot(vt1, vt2))
        if first_warn is None and lanes.warning_total(d):
            first_warn = (i, lanes.warning_text(d))
    _pieces.append(rec)
    return d.qacc_warmstart.copy(), first_warn


def _steps() -> np.ndarray:
    """The recorded steps in engine time (a fast-forward climb the runner dropped and
    redid from an earlier state is cut at the redo)."""
    kept: list[np.ndarray] = []
    for rec in _pieces:
        t0 = rec[0, 0]
        while kept and kept[-1][0, 0] >= t0:
            kept.pop()
        if kept:
            kept[-1] = kept[-1][kept[-1][:, 0] < t0]
        kept.append(rec)
    return np.concatenate(kept)


def run(dampratio: float, noslip: int | None, b: float = B, impratio: float | None = None) -> dict:
    whole = abbm_prefix(SEED, b + SEGMENT)
    surf = crop(whole, A - SEGMENT / 4, b + SEGMENT / 4)
    base = build_rig(surf, engine="mujoco", mu=MU, ie=IE, stiffness_number=K)
    dt = base.engine.timestep_s / 2  # the dt2 variant: the rule sets solref = (2 dt, ...)
    options = {"noslip_iterations": noslip} if noslip is not None else {}
    options |= {"impratio": impratio} if impratio is not None else {}
    rig = build_rig(
        surf,
        engine="mujoco",
        mu=MU,
        ie=IE,
        stiffness_number=K,
        timestep_s=dt,
        solref_timeconst_s=2 * dt / dampratio,
        solref_dampratio=dampratio,
        **options,
    )
    units = TrackUnits.of(rig.scales, IE)
    land = track_landscape(surf, MU, units.tip_radius, (A, b))
    drive = pre_stretched_drive(rig.scales, units, land, K, IE, b - A)
    _pieces.clear()
    lanes.python_steps, plain = _recording_steps, lanes.python_steps
    c0 = time.process_time()
    try:
        result = rig.run_batch([drive], [(A, 0.0)], backend="python", refine=False)[0]
    finally:
        lanes.python_steps = plain
    cpu = time.process_time() - c0
    steps = _steps()
    drops = engine_drop_rows(result, units, "mujoco", K, FLOOR)
    to_units = rig.units.length_m / units.length_scale_m  # model length -> surface units
    x = steps[:, 1] * to_units
    mass = float(rig.model.body_mass[1])
    load = float(np.median(steps[steps[:, 6] > 0, 6]))  # W in model force units (at rest)
    slips = []
    for x0, size in zip(np.asarray(drops["start_x_lc"]), np.asarray(drops["size_lc"])):
        xa, xb = x0 * units.char_length, (x0 + size) * units.char_length
        i, j = int(np.searchsorted(np.maximum.accumulate(x), [xa, xb])[0]), None
        j = int(np.searchsorted(np.maximum.accumulate(x), xb))
        seg = steps[i : j + 1]
        dtt = rig.model.opt.timestep
        coulomb_flat = MU * load * (xb - xa) / to_units
        ke = 0.5 * mass * seg[:, 3:6] ** 2
        slips.append(
            {
                "start_x": float(xa),
                "size_lc": float(size),
                "force_drop_fp": float(np.asarray(drops["force_drop_fp"])[len(slips)]),
                "steps": int(seg.shape[0]),
                "friction_work": float(seg[:, 8].sum() * dtt / coulomb_flat),
                "coulomb_work": float(seg[:, 9].sum() * dtt / coulomb_flat),
                "normal_work": float(seg[:, 7].sum() * dtt / coulomb_flat),
                "peak_ke_x": float(ke[:, 0].max() / coulomb_flat),
                "peak_ke_z": float(ke[:, 2].max() / coulomb_flat),
                "peak_ke_y": float(ke[:, 1].max() / coulomb_flat),
                "spring_work": float(seg[:, 10].sum() * dtt / coulomb_flat),
                "gravity_work": float(seg[:, 11].sum() * dtt / coulomb_flat),
                "ke_change": float(seg[:, 13].sum() / coulomb_flat),
                "flight_share": float(np.mean(seg[:, 6] == 0)),
                "landings": int(np.sum((seg[1:, 6] > 0) & (seg[:-1, 6] == 0))),
            }
        )
    return {
        "dampratio": dampratio,
        "noslip_iterations": int(rig.model.opt.noslip_iterations),
        "impratio": float(rig.model.opt.impratio),
        "timestep_s": dt,
        "cpu_s": cpu,
        "end": result.end_reason.value,
        "engine_trouble": result.engine_trouble,
        "solref": list(rig.engine.solref),
        "steps": int(steps.shape[0]),
        "whole_run": {
            "friction_over_coulomb": float(steps[:, 8].sum() / steps[:, 9].sum()),
            "normal_over_friction": float(steps[:, 7].sum() / steps[:, 8].sum()),
        },
        "flight_share": float(np.mean(steps[:, 6] == 0)),
        "landings": int(np.sum((steps[1:, 6] > 0) & (steps[:-1, 6] == 0))),
        "slips": slips,
        "trace": _trace(result, units),
    }


def _trace(result, units: TrackUnits, points: int = 400) -> dict:
    """The run's tip x [units] and drive force [F_p] at ``points`` times from the drive's
    start (where each slip stopped)."""
    s = result.drive_start_index
    idx = np.linspace(s, len(result.time_s) - 1, points).astype(int)
    return {
        "x": np.round(result.position_m[idx, 0] / units.length_scale_m, 3).tolist(),
        "force_fp": np.round(result.drive_force_n[idx] / units.preload_n, 6).tolist(),
    }


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dampratio", default="1,0.5,0.2", help="solref damping ratios, comma-separated")
    p.add_argument("--noslip", type=int, default=None, help="noslip iterations (default: the rule's)")
    p.add_argument("--end", type=float, default=B, help="the run's end x (a shorter check)")
    p.add_argument(
        "--impratio",
        type=_positive("--impratio"),
        default=None,
        help="MuJoCo's impratio (default: the rule's 1)",
    )
    p.add_argument("--out", type=Path, default=OUT)
    args = p.parse_args(argv)
    out = args.out
    rows = [run(float(r), args.noslip, args.end, args.impratio) for r in args.dampratio.split(",")]
    saved = json.loads(out.read_text()) if out.exists() else []

    def key(r):
        return r["dampratio"], r["noslip_iterations"], r.get("impratio", 1.0)

    keep = {key(r) for r in rows}
    saved = [r for r in saved if key(r) not in keep] + rows
    out.write_text(json.dumps(saved, indent=1) + "\n")
    for r in rows:
        print(
            f"dampratio {r['dampratio']:g}, noslip {r['noslip_iterations']}, impratio {r['impratio']:g}: "
            f"{r['cpu_s']:.0f} CPU s, "
            f"{r['steps']} steps, end {r['end']}, "
            f"friction / Coulomb {r['whole_run']['friction_over_coulomb']:.6f}, "
            f"normal / friction {r['whole_run']['normal_over_friction']:.2e}"
        )
        for s in r["slips"]:
            print(
                f"  x {s['start_x']:.1f} size {s['size_lc']:.1f} L_c drop {s['force_drop_fp']:.2e}: "
                f"friction {s['friction_work']:.5f} coulomb {s['coulomb_work']:.5f} "
                f"normal {s['normal_work']:.2e} "
                f"peak KE x {s['peak_ke_x']:.2e} z {s['peak_ke_z']:.2e}, spring {s['spring_work']:.4f} "
                f"gravity {s['gravity_work']:.4f} dKE {s['ke_change']:.1e} (of mu W S), "
                f"flight {s['flight_share']:.3f}, landings {s['landings']}"
            )


if __name__ == "__main__":
    main()

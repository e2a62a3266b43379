"""The rig in Bullet (spine_mj.sim.bullet, built by spine_mj.sim.build_rig from the engine
registry): the same surface, rules and results as MuJoCo's, the closed forms, and each
Bullet pitfall measured with its fix."""

import dataclasses
import json
import math
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from sweep_support import write_config

from spine_mj import extras, sim, sweep
from spine_mj.choices import COMPARED_ENGINES
from spine_mj.cli import main
from spine_mj.errors import SpineInputError
from spine_mj.sim.run_folder import load_run
from spine_mj.surfaces import GridSurface, TriangulatedSurface, from_hfield, inclined_plane
from spine_mj.theory import engagement

pytest.importorskip("pybullet", reason="the Bullet engine needs the [bullet] extra (pybullet)")

from spine_mj.sim.bullet import SENSOR_SIZE, BulletRig
from spine_mj.sim.bullet_settings import default_bullet_engine

MU = 0.5


def plane_rig(slope_deg=0.0, azimuth_deg=0.0, **engine):
    surf = inclined_plane(slope_deg=slope_deg, azimuth_deg=azimuth_deg)
    tip = sim.TipParams(mu_s=MU)
    if not engine:
        return BulletRig(surf, tip=tip)
    sc = sim.Scales.for_surface(surf, tip=tip)
    return BulletRig(surf, tip=tip, engine=default_bullet_engine(sc, **engine))


def test_the_heightfield_is_mujocos_triangles():
    """Bullet splits its cells along the other diagonal; the quarter turn makes them MuJoCo's."""
    import pybullet as pb

    rng = np.random.default_rng(3)
    x, y = np.linspace(-0.02, 0.02, 9), np.linspace(-0.015, 0.015, 7)
    surf = GridSurface(heights=rng.normal(0, 2e-3, (7, 9)), x=x, y=y, unit="m")
    rig = BulletRig(surf, tip=sim.TipParams(tip_radius_m=3e-3, mu_s=MU))
    w = rig.world()
    facets = TriangulatedSurface.from_grid(from_hfield(rig.hfield, unit="m"))
    px, py = rng.uniform(-0.0199, 0.0199, 200), rng.uniform(-0.0149, 0.0149, 200)
    lu = rig.units.length_m
    hits = pb.rayTestBatch(
        [[a / lu, b / lu, 10.0] for a, b in zip(px, py)],
        [[a / lu, b / lu, -10.0] for a, b in zip(px, py)],
        physicsClientId=w.cid,
    )
    z = np.array([h[3][2] for h in hits]) * lu
    np.testing.assert_allclose(z, facets.height(px, py), atol=1e-8)


@pytest.mark.parametrize(("slope", "az"), [(0.0, 0.0), (10.0, 0.0), (-10.0, 0.0), (20.0, 45.0)])
def test_static_probe_on_inclined_planes_matches_the_closed_form(slope, az):
    rig = plane_rig(slope, az)
    t = math.tan(math.radians(slope))
    k, _ = engagement.kappa(t * math.cos(math.radians(az)), t * math.sin(math.radians(az)), MU)
    run = rig.run(sim.build_drive(rig.scales, "static", ie=1e-2), start=(0.0, 0.0))
    assert run.end_reason is sim.EndReason.BREAKAWAY
    assert run.kappa_mj == pytest.approx(float(k), rel=5e-3)
    assert run.engine.to_dict()["engine"] == "bullet"
    # same result record as MuJoCo's: every column, one row per recorded step
    assert run.position_m.shape == (run.n, 3) and run.motion.shape == (run.n,)
    assert run.time_s[1] - run.time_s[0] == pytest.approx(rig.engine.timestep_s)


def test_cone_friction_pitfall():
    """Bullet's two friction rows alone form a pyramid: on a plane whose fall line is at 45
    deg to the drive, the tip holds more than mu allows; the cone holds the closed form."""
    t = math.tan(math.radians(20.0))
    k, _ = engagement.kappa(t / math.sqrt(2), t / math.sqrt(2), MU)
    kappas = {}
    for cone in (True, False):
        rig = plane_rig(20.0, 45.0, cone_friction=cone)
        run = rig.run(sim.build_drive(rig.scales, "static", ie=1e-2), start=(0.0, 0.0))
        kappas[cone] = run.kappa_mj
    assert kappas[True] == pytest.approx(float(k), rel=5e-3)
    assert kappas[False] > 1.02 * float(k)


def test_a_held_tip_does_not_creep():
    """On a slope below the friction angle the tip holds: drift below 1e-9 tip radii per
    time scale (placed touching; a tip started sunk by the slop crept at ~5e-4 v_c)."""
    rig = plane_rig(20.0, 0.0)
    drive = sim.SpringDrive(speed_m_s=1e-9, duration_s=0.2)  # a carriage that barely moves
    run = rig.run(dataclasses.replace(drive, stiffness_n_m=1e-9), start=(0.0, 0.0))
    drift = np.abs(run.position_m[-1, :2] - run.position_m[10, :2]).max()
    per_tau = drift / rig.tip.tip_radius_m / ((run.time_s[-1] - run.time_s[10]) / rig.scales.time_s)
    assert per_tau < 1e-9
    assert not run.moving[10:].any()


def test_friction_anchor_pitfall():
    """A tip resting in a V-groove on two contacts: without friction anchors the load sits on
    one flank at a time and the tip creeps down the groove (a static probe reads it as a
    slide); with anchors while held (the rule) it holds and breaks away at the wedge's kappa."""
    from spine_mj.validate.wedges import flank_tilt, groove

    rig = sim.build_rig(groove(20.0, 30.0), engine="bullet", mu=MU, tip_radius_m=2e-3, ie=1e-2)
    assert rig.engine.friction_anchor == "held"
    wedge = math.tan(math.radians(20) + math.atan(MU / math.cos(flank_tilt(20.0, 30.0))))
    runs = {}
    for anchor in ("held", "never"):
        r = BulletRig(
            rig.surface,
            tip=rig.tip,
            engine=dataclasses.replace(rig.engine, friction_anchor=anchor),
            sized=(rig.scales, rig.hfield),
        )
        runs[anchor] = r.run(sim.build_drive(r.scales, "static", ie=1e-2), start=(0.0, 0.0))
    assert runs["held"].end_reason is sim.EndReason.BREAKAWAY
    assert runs["held"].kappa_mj == pytest.approx(wedge, rel=0.05)
    assert runs["never"].end_reason is sim.EndReason.SLID
    with pytest.raises(SpineInputError, match="friction_anchor must be one of held, never, always"):
        dataclasses.replace(rig.engine, friction_anchor=True)


def test_internal_edge_pitfall():
    """A frictionless tip slid fast over a flat triangulated plane: with the heightfield's
    internal-edge info it stays on the plane; without it, the triangles' shared edges
    kick it up (measured: 5 % of its speed at 3 L_c / tau)."""
    import pybullet as pb

    surf = inclined_plane(slope_deg=0.0)
    tip = sim.TipParams(mu_s=0.0)
    sc = sim.Scales.for_surface(surf, tip=tip)
    hops = {}
    for edges in (True, False):
        rig = BulletRig(surf, tip=tip, engine=default_bullet_engine(sc, internal_edges=edges))
        w = rig.world()
        run = w.start(rig.place(-0.012, -0.01), 1)
        v = 3.0  # L_c / tau
        pb.resetBaseVelocity(w.tip, [0.8 * v, 0.6 * v, 0.0], physicsClientId=w.cid)
        state, sens = np.zeros(7), np.zeros(SENSOR_SIZE)
        up, i = 0.0, 0
        while state[1] * rig.units.length_m < 0.012:  # on the plane, 1.5 L_c of sliding
            run.step(i, np.zeros(6), 0.0, 0.0, state, sens)
            up, i = max(up, abs(state[6]) if i > 2 else 0.0), i + 1
        hops[edges] = up / v
    assert hops[True] < 1e-4
    assert hops[False] > 1e-2


def test_landings_do_not_bounce():
    """Restitution 0: a tip landing at the fastest speed the step rule plans for (half the
    contact breaking distance a step) leaves with under 1 % of its speed; with restitution
    0.5 (Bullet's combined value of two bodies at 0.7) it bounces."""
    import pybullet as pb

    rig = plane_rig()
    u, e = rig.units, rig.engine
    v = 0.5 * e.contact_breaking_m / e.timestep_s / u.speed_m_s
    w = rig.world()
    bounce = {}
    for restitution in (0.0, 0.7):
        run = w.start(rig.place(0.0, 0.0) + np.array([0.0, 0.0, 0.02]), 1)
        for body in (w.tip, w.ground):
            pb.changeDynamics(body, -1, restitution=restitution, physicsClientId=w.cid)
        pb.resetBaseVelocity(w.tip, [0.0, 0.0, -v], physicsClientId=w.cid)
        state, sens = np.zeros(7), np.zeros(SENSOR_SIZE)
        up = 0.0
        for i in range(400):
            run.step(i, np.zeros(6), 0.0, 0.0, state, sens)
            up = max(up, state[6])
        bounce[restitution] = up / v
    assert bounce[0.0] < 0.01
    assert bounce[0.7] > 0.3


def test_spring_block_period_and_peak_speed():
    """On a flat plane, after breakaway, the tip's speed swings between 0 and 2 V with period
    2 pi / w (docs/physics.md §6). A spring 100 times stiffer runs 2 substeps a row (omega dt = 0.3):
    its period still holds to the row it is read in, and its swing is MuJoCo's."""
    from spine_mj.validate.ground_truth import spring_block_check

    got = spring_block_check(stiffness_n_m=100.0, engine="bullet")
    assert abs(got["period_rel_error"]) < 0.01
    assert abs(got["peak_speed_rel_error"]) < 0.01
    stiff = {e: spring_block_check(stiffness_n_m=1e4, engine=e) for e in COMPARED_ENGINES}
    resolution = stiff["bullet"]["timestep_s"] / stiff["bullet"]["period_predicted_s"]
    assert abs(stiff["bullet"]["period_rel_error"]) < 0.01 + resolution
    assert stiff["bullet"]["peak_speed_v"] == pytest.approx(stiff["mujoco"]["peak_speed_v"], rel=0.05)


def test_the_force_ramp_with_reset_runs_and_resets():
    rig = plane_rig()
    drive = sim.build_drive(rig.scales, "ramp", ie=1e-1, duration_s=0.6)
    run = rig.run(drive, start=(-0.012, 0.0))
    assert [e.kind for e in run.events].count("reset") >= 1
    # breaks away at mu plus the ramp's lag over the slip detection (MuJoCo: 0.521)
    assert run.breakaway_kappas[:2] == pytest.approx(MU, rel=0.06)


def test_build_rig_gives_the_same_scales_and_step_in_both_engines():
    surf = inclined_plane(slope_deg=5.0)
    rigs = {e: sim.build_rig(surf, engine=e, mu=MU, ie=1e-3) for e in COMPARED_ENGINES}
    assert rigs["mujoco"].scales == rigs["bullet"].scales
    assert rigs["mujoco"].engine.timestep_s == rigs["bullet"].engine.timestep_s
    with pytest.raises(SpineInputError, match="impratio: not read by engine bullet"):
        sim.build_rig(surf, engine="bullet", mu=MU, impratio=10.0)
    with pytest.raises(SpineInputError, match="engine must be one of mujoco, bullet, got 'ode'"):
        sim.build_rig(surf, engine="ode", mu=MU)


def test_the_scales_and_hfield_are_measured_once_and_shared(monkeypatch):
    """Bullet's rig takes the scales and hfield build_rig measured (``sized=``), as
    MuJoCo's does: one measurement, the same hfield samples as MuJoCo's."""
    from spine_mj import presets

    surf = presets.make_surface("paper-single-peak")
    real = sim.Scales.with_hfield.__func__
    calls = []

    def counted(cls, *args, **kwargs):
        calls.append(kwargs.get("hfield_resolution"))
        return real(cls, *args, **kwargs)

    monkeypatch.setattr(sim.Scales, "with_hfield", classmethod(counted))
    rig = sim.build_rig(surf, engine="bullet", mu=MU, ie=1e-3, hfield_resolution=61)
    assert rig.hfield.nrow == 61
    assert calls == [61]
    assert rig.scales.hfield_resolution == 61 and not hasattr(rig.engine, "hfield_resolution")
    mj = sim.build_rig(surf, engine="mujoco", mu=MU, ie=1e-3, hfield_resolution=61)
    np.testing.assert_array_equal(rig.hfield.data, mj.hfield.data)


def test_simulate_engine_bullet_writes_the_same_run_folder(tmp_path):
    folders = {}
    for engine in COMPARED_ENGINES:
        out = tmp_path / engine
        res = CliRunner().invoke(
            main,
            [
                "simulate",
                "paper-single-peak",
                "--engine",
                engine,
                "--start",
                "-3,-1",
                "--resolution",
                "61",
                "--duration",
                "0.2",
                "--out",
                str(out),
            ],
        )
        assert res.exit_code == 0, res.output
        folders[engine] = out
    names = {e: sorted(p.name for p in f.iterdir()) for e, f in folders.items()}
    assert names["bullet"] == names["mujoco"]
    tables = {e: pd.read_parquet(f / "trajectory.parquet") for e, f in folders.items()}
    assert list(tables["bullet"].columns) == list(tables["mujoco"].columns)
    summary = json.loads((folders["bullet"] / "summary.json").read_text())
    assert summary["engine"]["engine"] == "bullet"
    assert set(summary) == set(json.loads((folders["mujoco"] / "summary.json").read_text()))
    rig, track = load_run(folders["bullet"])  # replayed on MuJoCo's model of the same surface
    assert isinstance(rig, sim.model.RigModel) and rig.tip.tip_radius_m == summary["tip"]["tip_radius_m"]
    np.testing.assert_array_equal(
        track.position_m, tables["bullet"][["position_x_m", "position_y_m", "position_z_m"]]
    )
    res = CliRunner().invoke(
        main,
        [
            "simulate",
            "paper-single-peak",
            "--engine",
            "bullet",
            "--render",
            "--start",
            "-3,-1",
            "--out",
            str(tmp_path / "r"),
        ],
    )
    assert res.exit_code == 2 and "--render draws with MuJoCo's renderer" in res.output


def test_without_the_extra_bullet_is_one_error_line(monkeypatch, tmp_path):
    monkeypatch.setitem(extras.EXTRAS, "bullet", ("no_such_module_spine_mj",))
    res = CliRunner().invoke(
        main,
        [
            "simulate",
            "paper-single-peak",
            "--engine",
            "bullet",
            "--start",
            "-3,-1",
            "--out",
            str(tmp_path / "r"),
        ],
    )
    assert res.exit_code == 2
    assert res.output.strip().splitlines() == [
        "Error: --engine bullet needs the optional extra 'bullet' (no_such_module_spine_mj not installed): "
        "pip install 'spine-mj[bullet]'"
    ]
    assert not (tmp_path / "r").exists()


ENGINE_SWEEP = """
[sweep]
name = "engines"
analyses = ["engine"]

[[surfaces]]
preset = "paper-single-peak"

[starts]
frame = "absolute"
points = [[-3.0, -1.0], [-3.0, 1.0]]

[drive]
protocol = "spring"
ie = 1e-3
duration = 0.1

[grid]
engine = ["mujoco", "bullet"]
hfield_resolution = 61
"""


def _run_cases_alone(cfg):
    """Each case of ``cfg`` run on its own (no sweep, no store): run_id -> end_x."""
    got = {}
    for case in sweep.expand_cases(sweep.load_config(cfg)):
        rows, _ = sweep.run_case(case)
        got.update(rows.to_pandas().set_index("run_id")["end_x"].to_dict())
    return got


KILL_SWEEP = ENGINE_SWEEP.replace("points = [[-3.0, -1.0], [-3.0, 1.0]]", "points = [[-3.0, -1.0]]").replace(
    "hfield_resolution = 61", "hfield_resolution = 61\nmu = [0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3]"
)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="kills a process group")
def test_a_sweep_over_both_engines_killed_midway_resumes_to_the_same_results(tmp_path):
    """The CLI sweep over ``engine = ["mujoco", "bullet"]`` killed (SIGKILL) once some cases
    are stored, then resumed: every run stored once, the stored numbers those of each case
    run on its own, in both engines."""
    cfg = write_config(tmp_path, KILL_SWEEP)
    out = tmp_path / "out"
    cmd = [
        sys.executable,
        "-m",
        "spine_mj.cli",
        "sweep",
        str(cfg),
        "--out",
        str(out),
        "--workers",
        "1",
        "--quiet",
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)

    def n_done():
        return len([p for p in (out / "runs").glob("*.parquet") if not p.name.startswith(".")])

    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None and n_done() < 2:
            time.sleep(0.005)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read()
    killed_at = n_done()
    assert 2 <= killed_at < 16, "the sweep must be killed midway"

    summary = sweep.run_sweep(cfg, out, workers=1)
    assert summary.skipped_cases == killed_at and summary.run_cases == 16 - killed_at
    runs = sweep.load_runs(out)
    assert len(runs) == 16 and runs.run_id.is_unique and (runs["status"] == "ok").all()
    assert sorted(runs["engine"].unique()) == ["bullet", "mujoco"]
    alone = _run_cases_alone(cfg)
    np.testing.assert_allclose(
        runs.set_index("run_id").loc[list(alone), "end_x"], list(alone.values()), rtol=1e-9
    )


def test_a_sweep_over_both_engines_on_a_dask_cluster_stores_what_one_process_stores(tmp_path):
    """The Dask path runs Bullet cases too (threads of a local cluster, one pybullet client
    per rig): the same rows as one worker process."""
    from distributed import LocalCluster
    from sweep_support import metrics_frame

    cfg = write_config(tmp_path, ENGINE_SWEEP)
    sweep.run_sweep(cfg, tmp_path / "w1", workers=1)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        summary = sweep.run_sweep(cfg, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert summary.run_cases == 2
    ref = metrics_frame(tmp_path / "w1")
    assert sorted(ref["engine"]) == ["bullet", "bullet", "mujoco", "mujoco"] and (ref["status"] == "ok").all()
    pd.testing.assert_frame_equal(metrics_frame(tmp_path / "dask"), ref)


def test_pybullet_s_build_banner_does_not_reach_the_user(tmp_path):
    """pybullet's C code prints "pybullet build time: ..." at import; a Bullet run's output
    is ours alone."""
    code = "from spine_mj.sim.bullet import _pybullet; _pybullet(); print('ours')"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout == "ours\n" and "build time" not in out.stderr


def test_a_heightfield_past_pybullet_s_upload_buffer_is_refused_in_one_line(tmp_path, monkeypatch):
    """pybullet copies a heightfield's float32 heights through an 8 MiB buffer and reads
    garbage past it (a 2048 x 2048 fractal's 1767 x 1767 hfield: every run fell through):
    1024 x 2048 samples pass, one more column is refused, naming the user's grid, before
    the surface is sampled (the sizing's stages, each reported here, are never heard: it
    took 4-7 CPU-s on a 2048 x 2048 fractal); in a sweep, before the first run."""
    from spine_mj import presets
    from spine_mj.sim import build, scales
    from spine_mj.sim.bullet import BULLET_MAX_SAMPLES, check_bullet_hfield

    if sys.platform != "darwin":
        assert BULLET_MAX_SAMPLES == 1024 * 2048
    check_bullet_hfield(1, BULLET_MAX_SAMPLES)
    with pytest.raises(SpineInputError, match="of 1 x 2097153 samples is more than pybullet takes"):
        check_bullet_hfield(1, BULLET_MAX_SAMPLES + 1)
    monkeypatch.setattr(scales, "PROGRESS_MIN_SAMPLES", 0)
    monkeypatch.setattr(build, "PROGRESS_MIN_SAMPLES", 0)
    heard = []
    side = math.isqrt(BULLET_MAX_SAMPLES) + 1
    surf = presets.make_surface("paper-single-peak")
    refused = rf"^Bullet's heightfield of {side} x {side} samples .* at most"
    with pytest.raises(SpineInputError, match=refused):
        sim.build_rig(
            surf, engine="bullet", mu=1.0, hfield_resolution=side, progress=lambda *a: heard.append(a)
        )
    x = np.linspace(0.0, 10.0, side)  # a grid keeps its samples
    grid = GridSurface(np.sin(30 * x)[None, :] * np.cos(30 * x)[:, None], x, x)  # L_c / 100 < a spacing
    with pytest.raises(SpineInputError, match=refused):
        sim.build_rig(grid, engine="bullet", mu=1.0, progress=lambda *a: heard.append(a))
    assert heard == []
    # a tip wide enough that the rule coarsens the grid under the limit passes the early check
    inputs = sim.RigInputs(mu=1.0, engine="bullet", tip_radius_m=10 * 10.0 / side * 0.01)
    build.check_planned_hfield(grid, inputs)
    assert max(scales.planned_hfield_sides(grid, tip=inputs.tip)) < side
    cfg = write_config(
        tmp_path,
        f"""
        [sweep]
        analyses = ["engine"]
        [[surfaces]]
        preset = "paper-single-peak"
        [starts]
        x = [0.05]
        y = [0.5]
        [grid]
        engine = "bullet"
        hfield_resolution = [41, {side}]
        """,
    )
    res = CliRunner().invoke(main, ["sweep", str(cfg), "--out", str(tmp_path / "runs"), "--quiet"])
    assert res.exit_code == 2 and res.output.count("\n") == 1, res.output
    assert f"Bullet's heightfield of {side} x {side} samples" in res.output
    assert not (tmp_path / "runs").exists()

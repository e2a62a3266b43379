"""Batches: the pieced native rollout equals one run at a time, the Python reference and one
uninterrupted rollout; stopping decided runs early changes no result."""

from __future__ import annotations

import mujoco
import numpy as np
from mujoco import rollout
from sim_rigs import flat_rig, plane_rig

from spine_mj import presets, sim
from spine_mj.sim import Detection, EndReason, SpringDrive, StaticProbe
from spine_mj.sim.drives import settle_steps
from spine_mj.validate.ramp_pilot import pilot_rig


def test_batch_equals_one_at_a_time_and_python_reference():
    rig = flat_rig()
    drives = [
        SpringDrive(speed_m_s=0.01, duration_s=0.15),
        SpringDrive(speed_m_s=0.03, duration_s=0.15, stiffness_n_m=50.0),
        StaticProbe(rate_n_s=5 * rig.scales.preload_n),
    ]
    starts = [(-0.02, 0.0), (0.01, 0.013), (0.0, -0.01)]
    batch = rig.run_batch(drives, starts, nthread=2)
    for drive, start, b in zip(drives, starts, batch):
        one = rig.run(drive, start=start)
        ref = rig.run(drive, start=start, backend="python")
        for other in (one, ref):
            assert other.end_reason is b.end_reason and other.n == b.n
            np.testing.assert_allclose(other.position_m, b.position_m, rtol=0, atol=1e-12)
            np.testing.assert_allclose(other.drive_force_n, b.drive_force_n, rtol=1e-9, atol=1e-12)


def test_controls_are_the_drives_profile_shifted_by_the_start():
    """Spring: the anchor and carriage sit at the start through the settle phase, then move
    at the drive's speed; probe: the push climbs from its start force at its rate to the
    force cap. Every start of one drive adds its position to the same profile (a batch
    computes the profile once)."""
    rig = flat_rig()
    det = Detection().resolve(rig.scales)
    u, dt = rig.units, rig.engine.timestep_s
    spring = SpringDrive(speed_m_s=0.01, duration_s=0.05)
    probe = StaticProbe(rate_n_s=5 * rig.scales.preload_n, start_force_n=0.1 * rig.scales.preload_n)
    qs = [rig.place(*s) for s in [(-0.02, 0.0), (0.01, 0.013)]]
    for drive in (spring, probe):
        ns = settle_steps(drive, dt)
        for q in qs:
            c = rig.controls(drive, q, det)
            t = dt * np.arange(1, c.shape[0] - ns + 1)  # [s] since the drive started
            np.testing.assert_array_equal(c[:, 4], q[1])
            np.testing.assert_allclose(c[:, 5], q[2] + 2 * rig.tip.tip_radius_m / u.length_m, rtol=1e-15)
            np.testing.assert_allclose(c[:, 2], -rig.tip.preload_n / u.force_n, rtol=1e-15)
            if drive is spring:
                np.testing.assert_array_equal(c[:, 0], c[:, 3])
                np.testing.assert_array_equal(c[:ns, 0], q[0])
                np.testing.assert_allclose(c[ns:, 0] * u.length_m, q[0] * u.length_m + 0.01 * t, rtol=1e-12)
                np.testing.assert_array_equal(c[:, 1], 0.0)
            else:
                np.testing.assert_array_equal(c[:, 0], 0.0)
                np.testing.assert_array_equal(c[:, 3], q[0])
                cap = det.kappa_cap * rig.scales.preload_n * (1 + 1e-9)  # just past: the cap rule sees it
                force = np.minimum(probe.start_force_n + probe.rate_n_s * t, cap)
                np.testing.assert_allclose(c[ns:, 1] * u.force_n, force, rtol=1e-9)
                np.testing.assert_allclose(c[:ns, 1] * u.force_n, probe.start_force_n, rtol=1e-12)
        a, b = (rig.controls(drive, q, det) for q in qs)
        np.testing.assert_allclose(b - a, np.broadcast_to(b[0] - a[0], a.shape), rtol=0, atol=1e-12)


def _one_rollout(rig, drive, start):
    """Tip positions [m] of ``drive`` from ``start`` by one ``mujoco.rollout`` call."""
    det = Detection().resolve(rig.scales)
    q = rig.place(*start)
    ctrl = rig.controls(drive, q, det)[None]
    model = rig.model_for(drive)
    init = np.zeros((1, mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)))
    init[0, 1:4] = q
    spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)
    zero = np.zeros((1, model.nv))
    _, sens = rollout.rollout(
        model, mujoco.MjData(model), init, ctrl, control_spec=spec, initial_warmstart=zero
    )
    adr = rig.sensor_adr["tip_pos"]
    return sens[0, :, adr : adr + 3] * rig.units.length_m


def test_pieces_continue_bit_for_bit_as_one_uninterrupted_rollout():
    rig, _ = pilot_rig("paper-single-peak", None, 1.23, 0.1, 61)  # coarse hfield: fast
    drive = SpringDrive(speed_m_s=rig.scales.speed_for(1e-2), duration_s=600 * rig.engine.timestep_s)
    starts = [(-3.0, -1.0), (-3.0, -2.0), (-2.5, 0.3)]
    runs = rig.run_batch(drive, starts, nthread=2, stop_early=False)
    for start, res in zip(starts, runs):
        # pieces of 328 (the settle phase and 128), 256 and 216 steps: continued from the saved state and
        # warm start, the trajectory is the uninterrupted one to the last bit
        assert res.simulated_steps == 800 and res.n > 700
        np.testing.assert_array_equal(res.position_m, _one_rollout(rig, drive, start)[: res.n])
    assert {r.end_reason for r in runs} == {EndReason.COMPLETED, EndReason.SELF_LOCK}


def _same_run(a, b):
    assert (a.end_reason, a.end_detail, a.engine_trouble, a.n) == (
        b.end_reason,
        b.end_detail,
        b.engine_trouble,
        b.n,
    )
    assert a.events == b.events
    np.testing.assert_array_equal(a.kappa_mj, b.kappa_mj)  # NaN equals NaN here
    for name in (
        "time_s",
        "position_m",
        "velocity_m_s",
        "normal",
        "drive_force_n",
        "normal_force_n",
        "moving",
    ):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def _stiff_spring_rig():
    """The single peak with a 10 ms step: a 1e12 N/m spring makes MuJoCo warn (bad qacc);
    its refusal (:meth:`RigModel.check_drive`) is switched off to reach that ending."""
    surface = presets.make_surface("paper-single-peak")
    tip = sim.TipParams(mu_s=1.23)
    scales = sim.Scales.for_surface(surface, tip=tip, hfield_resolution=61)
    engine = sim.default_engine(scales, timestep_s=0.01)
    rig = sim.Rig(surface, tip=tip, engine=engine, hfield_resolution=61)
    rig.check_drive = lambda drive: None  # run the spring the rig would refuse (model.check_drive)
    return rig


def test_stopping_decided_runs_early_changes_no_result():
    """Runs with every kind of ending, in batches with several groups: stopped as soon as
    their outcome is decided, each has the recording, events and ending of the run
    simulated to its planned end and then cut (exactly: pieces continue bit for bit)."""
    flat, steep = flat_rig(), plane_rig(70.0)  # 70 + arctan(0.5) > 90 deg: self-lock
    fp = flat.scales.preload_n
    cases = [
        (
            flat,
            [
                SpringDrive(speed_m_s=0.02, duration_s=1.0),  # runs off the +x edge
                SpringDrive(speed_m_s=0.01, duration_s=0.1),  # completes
                StaticProbe(rate_n_s=5 * fp, fast_forward=False),  # breaks away
                StaticProbe(rate_n_s=5 * fp),  # breaks away, fast-forwarded
            ],
            [(0.04, 0.0), (-0.02, 0.0), (0.0, -0.01), (0.0, 0.01)],
            None,
        ),
        (flat, [SpringDrive(speed_m_s=0.01, duration_s=1.0)], [(-0.04, 0.0)], Detection(kappa_cap=0.3)),
        (steep, [SpringDrive(speed_m_s=0.02, duration_s=1.0), StaticProbe()], [(0.0, 0.0), (0.0, 0.0)], None),
        (plane_rig(40.0), [StaticProbe()], [(0.0, 0.0)], None),  # steeper than arctan(0.5): slides
        (_stiff_spring_rig(), [SpringDrive(speed_m_s=0.01, stiffness_n_m=1e12)], [(-3.0, -1.0)], None),
    ]
    seen, steps = set(), [0, 0]
    for rig, drives, starts, det in cases:
        early = rig.run_batch(drives, starts, detection=det, nthread=2)
        plain = rig.run_batch(drives, starts, detection=det, nthread=2, stop_early=False)
        for a, b in zip(early, plain):
            _same_run(a, b)
            assert a.n <= a.simulated_steps <= b.simulated_steps
            seen.add(
                (a.end_reason, a.end_detail.split(":")[0] if a.end_reason is EndReason.SELF_LOCK else "")
            )
            steps[0] += a.simulated_steps
            steps[1] += b.simulated_steps
    assert seen == {
        (EndReason.LEFT_DOMAIN, ""),
        (EndReason.COMPLETED, ""),
        (EndReason.BREAKAWAY, ""),
        (EndReason.SELF_LOCK, "force cap"),
        (EndReason.SELF_LOCK, "lock rule"),
        (EndReason.SLID, ""),
        (EndReason.ENGINE_TROUBLE, ""),
    }
    assert steps[0] < 0.5 * steps[1]


def test_worker_lanes_hand_back_a_pieces_exception_and_close_with_pieces_queued():
    import threading

    from spine_mj.sim.lanes import NativeLanes

    lanes = NativeLanes(2)
    release = threading.Event()
    ran = []

    def piece(i):
        release.wait(5)
        ran.append(i)
        if i == 1:
            raise ValueError("piece 1 failed")
        return i

    try:
        for i in range(2):
            lanes.put(piece, (i,))
        release.set()
        try:
            lanes.take(2)
        except ValueError as exc:
            assert "piece 1" in str(exc)
        else:
            raise AssertionError("the worker's exception was not handed back")
        release.clear()
        for i in range(2, 40):  # two block in the workers, the rest wait in the queue
            lanes.put(piece, (i,))
        closing = threading.Thread(target=lanes.close)
        closing.start()
        while not lanes.cancelled:
            closing.join(0.001)
    finally:
        release.set()
    closing.join(10)
    assert not closing.is_alive() and not any(t.is_alive() for t in lanes.threads)
    assert set(ran) <= {0, 1, 2, 3}  # at most the two pieces under way finished; the queued ones were dropped

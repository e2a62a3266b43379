"""The compiled window analysis (:mod:`spine_mj.sim._window_kernel`) against its numpy
reference (Recording.from_sensors, end_marks, normal_lock_marks): the same columns, marks
and lock-rule carry, to the last bit, on recorded runs cut into windows and on rows with
engine trouble."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from mujoco import rollout
from sim_rigs import plane_rig

from spine_mj.sim import Detection, SpringDrive
from spine_mj.sim.recording import COLUMNS
from spine_mj.sim.results import GroupAnalysis
from spine_mj.validate.ramp_pilot import pilot_rig


def _recorded(rig, drive, starts):
    """State, sensordata and carriage (engine units) of ``drive`` from ``starts``, one rollout."""
    det = Detection().resolve(rig.scales)
    q = [rig.place(*s) for s in starts]
    ctrl = np.stack([rig.controls(drive, qi, det) for qi in q])
    model = rig.model_for(drive)
    init = np.zeros((len(starts), mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)))
    init[:, 1:4] = q
    spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)
    state, sens = rollout.rollout(
        model, mujoco.MjData(model), init, ctrl, control_spec=spec, initial_warmstart=np.zeros((len(q), 3))
    )
    return det, state, sens, ctrl[:, :, 3]


def _both(rig, drive, starts, det, state, sens, carriage, windows, runs=None):
    """The two analyses of the same windows; ``runs``: the run indices each window adds."""
    out = []
    for compiled in (True, False):
        ga = GroupAnalysis(rig, [drive] * len(starts), starts, det, carriage, compiled=compiled)
        decided = []
        for a, b in windows:
            rows = slice(None) if runs is None else runs
            decided.append(ga.add(rows, a, b, state, sens))
        out.append((ga, decided))
    return out


def _assert_same(fast, ref, rows):
    (ga, dec), (gr, der) = fast, ref
    end = int(ga.rows[rows].max())  # the columns hold the rows added
    for k in COLUMNS:
        np.testing.assert_array_equal(
            getattr(ga.cols, k)[rows, :end], getattr(gr.cols, k)[rows, :end], err_msg=k
        )
    assert ga.marks.keys() == gr.marks.keys()
    for k in ga.marks:
        np.testing.assert_array_equal(ga.marks[k], gr.marks[k], err_msg=k)
    np.testing.assert_array_equal(ga.held_from_n, gr.held_from_n)
    for a, b in zip(dec, der):
        np.testing.assert_array_equal(a, b)


@pytest.fixture(scope="module")
def peak_runs():
    rig, _ = pilot_rig("paper-single-peak", None, 1.23, 0.1, 61)  # coarse hfield: fast
    drive = SpringDrive(speed_m_s=rig.scales.speed_for(1e-2), duration_s=3000 * rig.engine.timestep_s)
    starts = [(-3.0, -1.0), (-3.0, -2.0), (-2.5, 0.3), (-3.0, -0.5)]
    return rig, drive, starts, *_recorded(rig, drive, starts)


def test_recorded_runs_in_windows_give_the_reference_to_the_last_bit(peak_runs):
    rig, drive, starts, det, state, sens, carriage = peak_runs
    n = state.shape[1]
    windows = [(0, 37), (37, 800), (800, 801), (801, n)]
    fast, ref = _both(rig, drive, starts, det, state, sens, carriage, windows)
    _assert_same(fast, ref, slice(None))
    marks = fast[0].marks
    assert (marks["lock"] >= 0).sum() == 2 and (marks["out"] >= 0).sum() == 2  # held, or passed the peak


def test_runs_added_by_index_arrays(peak_runs):
    rig, drive, starts, det, state, sens, carriage = peak_runs
    runs = np.array([0, 2])
    fast, ref = _both(rig, drive, starts, det, state, sens, carriage, [(0, 200), (200, 1500)], runs=runs)
    _assert_same(fast, ref, runs)


def test_runs_each_with_its_own_window_in_one_call(peak_runs):
    """As the batch runner adds them: every run its own rows in one call (one compiled
    pass; the reference one window at a time), the same as adding them window by window."""
    rig, drive, starts, det, state, sens, carriage = peak_runs
    n = state.shape[1]
    runs = np.arange(len(starts))
    steps = [(np.array([0, 0, 0, 0]), np.array([37, 120, 37, 800])), (None, np.array([800, 801, n, n]))]
    out = []
    for compiled in (True, False):
        ga = GroupAnalysis(rig, [drive] * len(starts), starts, det, carriage, compiled=compiled)
        decided = []
        for a, b in steps:
            a = ga.rows[runs].copy() if a is None else a
            decided.append(ga.add(runs, a, b, state, sens))
        out.append((ga, decided))
    (fast, dec_fast), (ref, dec_ref) = out
    np.testing.assert_array_equal(fast.rows, ref.rows)
    for r in runs:  # each run's own rows (the columns beyond them were never written)
        for k in COLUMNS:
            np.testing.assert_array_equal(getattr(fast.run(r), k), getattr(ref.run(r), k), err_msg=k)
    for k in fast.marks:
        np.testing.assert_array_equal(fast.marks[k], ref.marks[k], err_msg=k)
    np.testing.assert_array_equal(fast.held_from_n, ref.held_from_n)
    np.testing.assert_array_equal(dec_fast, dec_ref)
    by_window = _both(
        rig, drive, starts, det, state, sens, carriage, [(0, 800), (800, n)], runs=np.array([3])
    )
    for k in COLUMNS:
        np.testing.assert_array_equal(getattr(out[0][0].cols, k)[3], getattr(by_window[0][0].cols, k)[3])


def test_rows_with_engine_trouble(peak_runs):
    """NaN and inf in the sensors and the state, a time reset, a deep contact, a flipped
    normal, a tip far outside the domain and far too fast: every mark and column agrees."""
    rig, drive, starts, det, state, sens, carriage = peak_runs
    state, sens = state.copy(), sens.copy()
    a = rig.sensor_adr
    cd, p, v = a["contact_deepest"], a["tip_pos"], a["tip_vel"]
    sens[0, 400, cd + 5] = np.nan
    sens[0, 401, cd + 6] = np.inf
    sens[1, 350, cd + 7] *= -1
    sens[1, 360, cd + 1] = -1e3
    state[2, 420, 0] = 0.0
    sens[2, 430, p] = 1e6
    sens[3, 440, v + 2] = -1e9
    sens[3, 450, p + 2] = -1e6
    state[3, 460, 2] = np.nan
    with np.errstate(over="ignore", invalid="ignore"):  # the reference's arithmetic on inf
        fast, ref = _both(rig, drive, starts, det, state, sens, carriage, [(0, 410), (410, state.shape[1])])
    _assert_same(fast, ref, slice(None))
    m = fast[0].marks
    for key in ("nonfinite", "reset", "out", "fast", "sank"):
        assert (m[key] >= 0).any(), key


def test_a_plane_in_the_self_lock_region_is_locked_by_both():
    """A 70 deg plane (beyond 90 deg - arctan mu): stuck on a self-locking normal, the
    drive's rise of 1 F_p trips the lock rule on both sides at the same row."""
    rig = plane_rig(70.0)
    drive = SpringDrive(speed_m_s=0.02, duration_s=0.5)
    starts = [(0.0, 0.0)]
    det, state, sens, carriage = _recorded(rig, drive, starts)
    fast, ref = _both(rig, drive, starts, det, state, sens, carriage, [(0, 50), (50, state.shape[1])])
    _assert_same(fast, ref, slice(None))
    assert fast[0].marks["lock_rule"][0] > 0

"""The resumable store: layout, manifest, partial reads, resume, kill -9, failures recorded."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest
from sweep_support import metrics_frame, peak_config, write_config

from spine_mj import sweep
from spine_mj.errors import SpineInputError


def test_store_layout_manifest_and_partial_trajectory_reads(tmp_path):
    cfg = peak_config(tmp_path, nmu=2, ny=3)
    out = tmp_path / "out"
    summary = sweep.run_sweep(cfg, out, workers=1)
    assert (summary.total_cases, summary.run_cases, summary.ok_runs) == (2, 2, 6)
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["config_hash"] == sweep.load_config(cfg).hash
    assert manifest["n_runs"] == 6 and manifest["seeds"]["master"] == 0
    assert set(manifest["versions"]) >= {"spine_mj", "mujoco", "numpy"}
    assert "commit" in manifest["git"]
    runs = sweep.load_runs(out)
    assert len(runs) == 6 and set(runs.status) == {"ok"}
    assert {"mu", "dl", "end_x", "max_kappa", "self_locked", "time_s"} <= set(runs.columns)
    case_id = runs.case_id.iloc[0]
    one = sweep.load_trajectories(out, case_id, analysis="quasistatic", start=2, columns=["x", "kappa"])
    assert list(one.columns) == ["analysis", "start", "step", "x", "kappa"]
    assert set(one.start) == {2} and one.step.tolist() == list(range(len(one)))
    row = runs[(runs.case_id == case_id) & (runs.start == 2)].iloc[0]
    assert len(one) == row.n_steps + 1
    assert one.x.iloc[-1] == pytest.approx(row.end_x)


def test_resume_skips_finished_runs_and_refuses_another_config(tmp_path):
    cfg = peak_config(tmp_path, nmu=4, ny=2)
    out = tmp_path / "out"
    sweep.run_sweep(cfg, out, workers=1)
    before = metrics_frame(out)
    files = sorted((out / "runs").glob("*.parquet"))
    mtimes = {f: f.stat().st_mtime_ns for f in files}
    files[1].unlink()
    (out / "runs.parquet").unlink()
    seen = []
    summary = sweep.run_sweep(cfg, out, workers=1, progress=seen.append)
    assert (summary.run_cases, summary.skipped_cases, summary.skipped_runs) == (1, 3, 6)
    assert seen[0].skipped_cases == 3 and seen[-1].finished_cases == 1
    assert all(f.stat().st_mtime_ns == mtimes[f] for f in files if f != files[1])
    pd.testing.assert_frame_equal(metrics_frame(out), before)
    assert len(json.loads((out / "manifest.json").read_text())["sessions"]) == 2

    other = peak_config(tmp_path, nmu=5, ny=2, name="other")
    with pytest.raises(SpineInputError, match=r"holds a sweep of another config.*--overwrite"):
        sweep.run_sweep(other, out, workers=1)
    pd.testing.assert_frame_equal(metrics_frame(out), before)
    summary = sweep.run_sweep(other, out, workers=1, overwrite=True)
    assert summary.skipped_cases == 0 and len(sweep.load_runs(out)) == 10


def test_kill_9_midway_then_resume_loses_and_duplicates_nothing(tmp_path):
    cfg = peak_config(tmp_path, nmu=150, ny=8, dl=0.01)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "spine_mj.cli",
            "sweep",
            str(cfg),
            "--out",
            str(out),
            "--workers",
            "2",
            "--quiet",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    deadline = time.monotonic() + 60
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            done = [p for p in (out / "runs").glob("*.parquet") if not p.name.startswith(".")]
            if len(done) >= 10:
                break
            time.sleep(0.005)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read()
    n_done = len([p for p in (out / "runs").glob("*.parquet") if not p.name.startswith(".")])
    assert 10 <= n_done < 150, "the sweep must be killed midway"
    assert not (out / "runs.parquet").exists()

    summary = sweep.run_sweep(cfg, out, workers=2)
    assert summary.skipped_cases >= n_done and summary.run_cases == 150 - summary.skipped_cases
    runs = sweep.load_runs(out)
    expected = {
        f"{c.case_id}-quasistatic-{i}" for c in sweep.expand_cases(sweep.load_config(cfg)) for i in range(8)
    }
    assert len(runs) == len(expected) == 1200
    assert runs.run_id.is_unique and set(runs.run_id) == expected
    assert set(runs.status) == {"ok"}
    assert not list((out / "runs").glob(".*")) and not list((out / "trajectories").glob(".*"))
    # the stored numbers are those of the cases run on their own
    config = sweep.load_config(cfg)
    for case in sweep.expand_cases(config)[::50]:
        rows, _ = sweep.run_case(case)
        ref = rows.to_pandas().set_index("run_id")
        got = runs.set_index("run_id").loc[ref.index]
        # worker processes may differ from this one in the last bits (numpy's SIMD paths)
        np.testing.assert_allclose(got.end_x, ref.end_x, rtol=1e-12, atol=0)
        np.testing.assert_array_equal(got.n_steps, ref.n_steps)


def test_failing_runs_are_recorded_and_the_sweep_goes_on(tmp_path):
    body = """
        [sweep]
        name = "failures"
        [[surfaces]]
        preset = "paper-single-peak"
        starts = { frame = "absolute", points = [[-4.0, 0.0], [40.0, 0.0]] }
        [[surfaces]]
        preset = "paper-single-valley"
        [starts]
        points = [[0.05, 0.5], [0.05, 0.3]]
        [grid]
        mu = [0.5, 1.25]
    """
    cfg = write_config(tmp_path, body)
    out = tmp_path / "out"
    summary = sweep.run_sweep(cfg, out, workers=2)
    assert summary.status_counts == {"ok": 4, "failed": 4}
    assert (summary.ok_runs, summary.failed_runs) == (4, 4)
    runs = sweep.load_runs(out)
    failed = runs[runs.status == "failed"]
    assert set(failed.surface) == {"paper-single-peak"}
    assert failed.reason.str.contains("SpineInputError: starts must lie inside").all()
    ok = runs[runs.status == "ok"]
    assert set(ok.surface) == {"paper-single-valley"} and ok.end_x.notna().all()
    # a finished store with failures is not re-run unless asked
    assert sweep.run_sweep(cfg, out, workers=1).run_cases == 0
    assert sweep.run_sweep(cfg, out, workers=1, retry_failed=True).run_cases == 2
    # a surface file that cannot be read refuses the sweep before anything runs (it was a
    # bad_surface row per run, the sweep exiting 0)
    (tmp_path / "broken.npz").write_bytes(b"not a zip file at all" * 10)
    cfg = write_config(
        tmp_path, body.replace("[starts]", '[[surfaces]]\n        file = "broken.npz"\n        [starts]')
    )
    with pytest.raises(
        SpineInputError, match=r"sweep case \(broken, mu = 0.5\): .*broken.npz is not a readable"
    ):
        sweep.run_sweep(cfg, tmp_path / "out2", workers=1)
    assert not (tmp_path / "out2").exists()


def test_a_store_held_by_a_running_sweep_is_refused_at_once_and_free_when_it_ends(tmp_path):
    cfg = peak_config(tmp_path, nmu=2, ny=2)
    out = tmp_path / "out"
    sweep.run_sweep(cfg, out, workers=1)
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; from pathlib import Path; from spine_mj.sweep.store import store_lock\n"
            f"with store_lock(Path({str(out)!r})):\n"
            "    print('held', flush=True); time.sleep(120)",
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(SpineInputError, match="another sweep is writing to it"):
            sweep.run_sweep(cfg, out, workers=1)
    finally:
        holder.kill()
        holder.wait()
    assert sweep.run_sweep(cfg, out, workers=1).skipped_cases == 2

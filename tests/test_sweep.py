"""Sweeps: config validation, grid expansion, the resumable store (kill -9 included),
failures recorded, identical metrics whatever the executor, and the CLI."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from spine_mj import sweep
from spine_mj.cli import main
from spine_mj.errors import SpineInputError

PEAK_QS = """
[sweep]
name = "{name}"
analyses = ["quasistatic"]

[[surfaces]]
preset = "paper-single-peak"

[starts]
x = [0.05]
y = {{ linspace = [0.1, 0.9], num = {ny} }}

[grid]
mu = {{ linspace = [0.4, 1.6], num = {nmu} }}
dl = {dl}
"""


def write_config(tmp_path, text, name="sweep.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def peak_config(tmp_path, *, nmu=4, ny=3, dl=0.02, name="peak"):
    return write_config(tmp_path, PEAK_QS.format(name=name, nmu=nmu, ny=ny, dl=dl))


def metrics_frame(out_dir):
    df = sweep.load_runs(out_dir).drop(columns=["time_s", "cpu_s"])
    return df.sort_values("run_id").reset_index(drop=True)


BASE = {
    "sweep": {"analyses": ["quasistatic"]},
    "surfaces": [{"preset": "paper-single-peak"}],
    "starts": {"points": [[0.1, 0.5]]},
    "grid": {"mu": 0.5},
}


def with_(**changes):
    doc = json.loads(json.dumps(BASE))
    for path, value in changes.items():
        *head, last = path.split("__")
        node = doc
        for key in head:
            node = node[int(key)] if isinstance(node, list) else node.setdefault(key, {})
        if value is None:
            del node[last]
        else:
            node[last] = value
    return doc


# --------------------------------------------------------------------------- config


@pytest.mark.parametrize(
    "doc, match",
    [
        (with_(extra=1), r"config key extra: unknown; allowed keys: sweep, surfaces"),
        (
            with_(sweep__analyses=["quasistatic", "nope"]),
            r"sweep.analyses: allowed values are .*'quasistatic'.*, got 'nope'",
        ),
        (with_(sweep__analyses=["compare"]), r"sweep.analyses: 'compare' needs"),
        (with_(sweep__seed=-1), r"sweep.seed: must be a non-negative integer, got -1"),
        (with_(grid__mu=-0.5), r"grid.mu: must be a finite number > 0 .*got -0.5"),
        (with_(grid__mu=None), r"grid.mu: required by analyses \['quasistatic'\]"),
        (with_(grid__mu=[0.5, 0.5]), r"grid.mu: repeated value"),
        (with_(grid__speed=1.0), r"grid.speed: unknown parameter .*allowed: .*mu"),
        (with_(grid__trajectory="curvy"), r"grid.trajectory: must be one of 'streamline', 'ideal'"),
        (with_(grid__max_steps=1.5), r"grid.max_steps: must be an integer >= 1"),
        (with_(grid__mu={"logspace": [0, 1], "num": 3}), r"grid.mu.logspace: end values must be > 0"),
        (with_(grid__mu={"linspace": [0.1, 1]}), r"grid.mu: a table must be \{linspace"),
        (with_(surfaces=[]), r"config key surfaces: must be a non-empty array"),
        (with_(surfaces__0__preset="nope"), r"surfaces\[0\].preset: allowed values are .*got 'nope'"),
        (with_(surfaces__0__seeds=[1, 2]), r"surfaces\[0\]: 'paper-single-peak' takes no seed"),
        (with_(surfaces__0__file="x.npz"), r"surfaces\[0\]: give exactly one of preset or file"),
        (with_(surfaces__0__set={"nope": 1}), r"unknown parameter\(s\) \['nope'\]"),
        (with_(starts=None), r"config key starts: required"),
        (with_(starts__points=[[1.5, 0.5]]), r"starts.points: coordinates must be numbers in \[0, 1\]"),
        (with_(starts__x=[0.5]), r"config key starts: give exactly one of points, x and y, or random"),
        (with_(starts__frame="polar"), r"starts.frame: allowed values are 'relative', 'absolute'"),
    ],
)
def test_config_errors_name_key_allowed_values_and_what_arrived(doc, match):
    with pytest.raises(SpineInputError, match=match):
        sweep.parse_config(doc)


def test_config_file_errors(tmp_path):
    with pytest.raises(SpineInputError, match="config file not found"):
        sweep.load_config(tmp_path / "missing.toml")
    bad = write_config(tmp_path, "[sweep\nname=1")
    with pytest.raises(SpineInputError, match="is not valid TOML"):
        sweep.load_config(bad)
    missing_file = write_config(
        tmp_path,
        """
        [[surfaces]]
        file = "nowhere.npz"
        [starts]
        points = [[0.5, 0.5]]
        [grid]
        mu = 0.5
    """,
    )
    with pytest.raises(SpineInputError, match=r"surfaces\[0\].file: no such file"):
        sweep.load_config(missing_file)


# --------------------------------------------------------------------------- expansion


def test_grid_expansion_counts_ids_and_seeds():
    doc = with_(
        grid__mu=[0.5, 1.0, 1.5],
        grid__trajectory=["streamline", "ideal"],
        grid__tip_radius={"logspace": [0.01, 1.0], "num": 3},
    )
    doc["surfaces"] = [
        {"preset": "paper-single-peak"},
        {"preset": "paper-random-convex", "seeds": [3, 4]},
        {"preset": "paper-random-concave", "n_seeds": 2},
    ]
    config = sweep.parse_config(doc)
    cases = sweep.expand_cases(config)
    assert len(cases) == 5 * 3 * 2 * 3
    assert set(config.swept) == {"mu", "trajectory", "tip_radius"}
    assert dict(config.grid)["tip_radius"] == pytest.approx((0.01, 0.1, 1.0))
    assert len({c.case_id for c in cases}) == len(cases)
    assert len({c.seed for c in cases}) == len(cases)
    assert [c.index for c in cases] == list(range(len(cases)))
    labels = sorted({c.surface.label for c in cases})
    assert "paper-random-convex#3" in labels and "paper-single-peak" in labels
    # ids are a function of the parameters only: same after re-parsing, a changed master
    # seed changes the case seeds (and the derived surface seeds) but not explicit ids
    again = sweep.expand_cases(sweep.parse_config(json.loads(json.dumps(doc))))
    assert [c.case_id for c in again] == [c.case_id for c in cases]
    assert [c.seed for c in again] == [c.seed for c in cases]
    doc["sweep"]["seed"] = 7
    other = sweep.expand_cases(sweep.parse_config(doc))
    explicit = [c for c in cases if c.surface.source != "paper-random-concave"]
    assert {c.case_id for c in explicit} <= {c.case_id for c in other}
    assert not {c.seed for c in cases} & {c.seed for c in other}
    assert sweep.parse_config(doc).hash != config.hash


def test_config_hash_ignores_comments_and_key_order(tmp_path):
    a = peak_config(tmp_path, name="h")
    b = write_config(
        tmp_path,
        "# a comment\n" + a.read_text().replace("[grid]\nmu", "[grid]\n# another\nmu"),
        name="b.toml",
    )
    assert sweep.load_config(a).hash == sweep.load_config(b).hash


def test_relative_and_random_starts():
    doc = with_(starts={"random": 4})
    case = sweep.expand_cases(sweep.parse_config(doc))[0]
    bounds = case.surface.make().bounds
    pts = case.starts.resolve(bounds, case.seed)
    assert pts.shape == (4, 2)
    assert np.all((pts[:, 0] >= bounds[0]) & (pts[:, 0] <= bounds[1]))
    np.testing.assert_array_equal(pts, case.starts.resolve(bounds, case.seed))
    rel = sweep.StartsSpec(frame="relative", points=((0.0, 1.0), (0.5, 0.5)))
    np.testing.assert_allclose(rel.resolve((-5, 5, -2, 2), 0), [[-5, 2], [0, 0]])


# --------------------------------------------------------------------------- store


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
        np.testing.assert_array_equal(got.end_x, ref.end_x)
        np.testing.assert_array_equal(got.n_steps, ref.n_steps)


def test_failing_runs_are_recorded_and_the_sweep_goes_on(tmp_path):
    (tmp_path / "broken.npz").write_bytes(b"not a zip file at all" * 10)
    cfg = write_config(
        tmp_path,
        """
        [sweep]
        name = "failures"
        [[surfaces]]
        preset = "paper-single-peak"
        starts = { frame = "absolute", points = [[-4.0, 0.0], [40.0, 0.0]] }
        [[surfaces]]
        file = "broken.npz"
        [[surfaces]]
        preset = "paper-single-valley"
        [starts]
        points = [[0.05, 0.5], [0.05, 0.3]]
        [grid]
        mu = [0.5, 1.25]
    """,
    )
    out = tmp_path / "out"
    summary = sweep.run_sweep(cfg, out, workers=2)
    assert summary.status_counts == {"ok": 4, "failed": 4, "bad_surface": 4}
    assert (summary.ok_runs, summary.failed_runs) == (4, 8)
    runs = sweep.load_runs(out)
    failed = runs[runs.status == "failed"]
    assert set(failed.surface) == {"paper-single-peak"}
    assert failed.reason.str.contains("SpineInputError: starts must lie inside").all()
    bad = runs[runs.status == "bad_surface"]
    assert set(bad.surface) == {"broken"} and bad.reason.str.len().gt(10).all()
    assert bad.end_x.isna().all()
    ok = runs[runs.status == "ok"]
    assert set(ok.surface) == {"paper-single-valley"} and ok.end_x.notna().all()
    # a finished store with failures is not re-run unless asked
    assert sweep.run_sweep(cfg, out, workers=1).run_cases == 0
    assert sweep.run_sweep(cfg, out, workers=1, retry_failed=True).run_cases == 4


RANDOM_QS = """
[sweep]
name = "random"
seed = 11
[[surfaces]]
preset = "paper-random-convex"
n_seeds = 2
set = { n_peaks = 30 }
[starts]
random = 3
[grid]
mu = [2.0, 3.0]
trajectory = ["streamline", "ideal"]
dl = 0.05
"""


def test_same_metrics_with_one_or_two_workers_and_on_a_dask_cluster(tmp_path):
    from distributed import LocalCluster

    cfg = write_config(tmp_path, RANDOM_QS)
    sweep.run_sweep(cfg, tmp_path / "w1", workers=1)
    sweep.run_sweep(cfg, tmp_path / "w2", workers=2)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        summary = sweep.run_sweep(cfg, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert summary.workers is None and summary.run_cases == 8
    ref = metrics_frame(tmp_path / "w1")
    assert len(ref) == 24 and set(ref.status) == {"ok"}
    assert ref.self_locked.any() and not ref.self_locked.all()
    pd.testing.assert_frame_equal(metrics_frame(tmp_path / "w2"), ref)
    pd.testing.assert_frame_equal(metrics_frame(tmp_path / "dask"), ref)
    manifest = json.loads((tmp_path / "dask" / "manifest.json").read_text())
    assert manifest["sessions"][0]["scheduler"].startswith(("tcp://", "inproc://"))


# --------------------------------------------------------------------------- CLI


def run_cli(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_cli_sweep_status_report(tmp_path):
    cfg = peak_config(tmp_path, nmu=3, ny=2)
    out = tmp_path / "out"
    result = run_cli("sweep", cfg, "--out", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert "done 6, failed 0, skipped 0" in result.output
    result = run_cli("sweep", cfg, "--out", out, "--workers", 1, "--quiet")
    assert "done 0, failed 0, skipped 6" in result.output
    result = run_cli("sweep", "status", out)
    assert result.exit_code == 0 and "cases 3/3, runs 6/6 - complete" in result.output
    result = run_cli("report", out, "-o", tmp_path / "r.html")
    assert result.exit_code == 0, result.output
    html = (tmp_path / "r.html").read_text()
    assert "data:image/png;base64," in html and "max_kappa" in html
    for args in (
        ["sweep", "--help"],
        ["sweep", "status", "--help"],
        ["sweep", cfg, "--help"],
        ["report", "--help"],
    ):
        result = run_cli(*args)
        assert result.exit_code == 0 and "Usage" in result.output


@pytest.mark.parametrize(
    "text, message",
    [
        (
            PEAK_QS.format(name="x", nmu=2, ny=2, dl=0.02).replace("mu =", "mu_s ="),
            "Error: config key grid.mu_s: unknown parameter",
        ),
        ("[sweep\n", "is not valid TOML"),
        (PEAK_QS.format(name="x", nmu=2, ny=2, dl=-1), "Error: config key grid.dl: must be"),
    ],
)
def test_cli_bad_config_exits_2_with_one_line_and_writes_nothing(tmp_path, text, message):
    cfg = write_config(tmp_path, text)
    proc = subprocess.run(
        [sys.executable, "-m", "spine_mj.cli", "sweep", str(cfg), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and message in proc.stderr
    assert not (tmp_path / "out").exists()


def test_cli_refuses_another_config_in_dir(tmp_path):
    out = tmp_path / "out"
    assert (
        run_cli("sweep", peak_config(tmp_path, nmu=2), "--out", out, "--workers", 1, "--quiet").exit_code == 0
    )
    other = peak_config(tmp_path, nmu=3, name="other")
    result = run_cli("sweep", other, "--out", out, "--workers", 1)
    assert result.exit_code == 2 and "holds a sweep of another config" in result.output
    assert run_cli("sweep", other, "--out", out, "--workers", 1, "--overwrite", "--quiet").exit_code == 0
    assert run_cli("sweep", "status", tmp_path / "nowhere").exit_code == 2


# --------------------------------------------------------------------------- mujoco


MJ = """
[sweep]
name = "mujoco"
analyses = ["quasistatic", "mujoco", "compare"]
[[surfaces]]
preset = "paper-single-peak"
[starts]
frame = "absolute"
points = [[-4.0, 0.0], [-4.0, 1.0]]
[drive]
protocol = "spring"
ie = [0.01, 0.1]
[grid]
mu = 1.25
dl = 0.02
"""


def test_mujoco_and_compare_runs_match_the_rig_run_directly(tmp_path):
    from spine_mj import presets, sim

    cfg = write_config(tmp_path, MJ)
    out = tmp_path / "out"
    summary = sweep.run_sweep(cfg, out, workers=1)
    assert summary.total_runs == 12
    runs = sweep.load_runs(out)
    mj = runs[runs.analysis == "mujoco"]
    assert mj.status.isin(["ok", "diverged", "engine_warning"]).all()
    np.testing.assert_allclose(mj.inertia_number, mj.ie, rtol=1e-9)
    # the start on the peak's ridge self-locks quasistatically; compare's outcome agreement
    # is that of the two rows it compares
    qs = runs[runs.analysis == "quasistatic"].set_index(["case_id", "start"])
    assert qs.self_locked.xs(0, level="start").astype(bool).all()
    mjs = mj.set_index(["case_id", "start"])
    cmp_ = runs[runs.analysis == "compare"].set_index(["case_id", "start"])
    expected = qs.self_locked.astype(bool) == mjs.self_locked.astype(bool)
    assert (cmp_.agree_lock.astype(bool) == expected.loc[cmp_.index]).all()
    assert (cmp_.status == np.where(mjs.status.loc[cmp_.index] == "ok", "ok", "dependency_failed")).all()
    ran = mjs.status.loc[cmp_.index] == "ok"
    assert cmp_.frechet[ran].notna().all() and (cmp_.frechet[ran] >= 0).all()
    # the stored run is the rig's own run at that speed
    case_id = mj.case_id[mj.ie == 0.01].iloc[0]
    rig = sim.Rig(presets.make_surface("paper-single-peak"), tip=sim.TipParams(mu_s=1.25))
    sc = rig.scales
    speed = (0.01 * sc.preload_n * sc.char_length_m / sc.mass_kg) ** 0.5
    direct = rig.run_batch(sim.SpringDrive(speed_m_s=speed), [(-4.0, 1.0)], nthread=1)[0]
    row = mj[(mj.case_id == case_id) & (mj.start == 1)].iloc[0]
    assert row.end_x == pytest.approx(direct.position_m[-1, 0] / rig.length_scale_m, abs=1e-12)
    traj = sweep.load_trajectories(out, case_id, analysis="mujoco", start=1, columns=["x"])
    assert len(traj) == direct.n
    np.testing.assert_allclose(traj.x, direct.position_m[:, 0] / rig.length_scale_m)


def test_mujoco_config_checks():
    doc = with_(sweep__analyses=["mujoco"], grid__ie=0.1, grid__speed=0.01)
    with pytest.raises(SpineInputError, match=r"grid.ie and grid.speed: give one of them"):
        sweep.parse_config(doc)
    doc = with_(sweep__analyses=["mujoco"], drive__protocol="pull")
    with pytest.raises(SpineInputError, match=r"drive.protocol: must be one of 'spring', 'ramp'"):
        sweep.parse_config(doc)
    doc = with_(sweep__analyses=["quasistatic"], drive__protocol="spring")
    with pytest.raises(SpineInputError, match=r"drive.protocol: unknown drive parameter"):
        sweep.parse_config(doc)

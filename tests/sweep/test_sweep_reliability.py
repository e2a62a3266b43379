"""Reliability of the sweep store and CLI: --overwrite touches only the store, a resume
refuses changed inputs, limits are checked before anything is written, corrupt case files
are named and run again, mu defaults to the preset's calibrated one."""

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from sweep_support import peak_config, with_, write_config

from spine_mj import presets, surface_io, sweep
from spine_mj.cli import main
from spine_mj.errors import SpineInputError


def run_cli(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "spine_mj.cli", *map(str, args)], capture_output=True, text=True, timeout=120
    )


def test_overwrite_refuses_a_folder_that_is_not_a_store_and_removes_only_store_files(tmp_path):
    mine = tmp_path / "mine"
    (mine / "runs").mkdir(parents=True)
    for name in (".bashrc", "report.html", "runs/notes.txt"):
        (mine / name).write_text("keep me")
    cfg = peak_config(tmp_path, nmu=2, ny=2)
    with pytest.raises(SpineInputError, match=r"holds no sweep manifest.*--overwrite replaces only"):
        sweep.run_sweep(cfg, mine, workers=1, overwrite=True)
    assert all((mine / n).read_text() == "keep me" for n in (".bashrc", "report.html", "runs/notes.txt"))
    assert not (mine / ".sweep.lock").exists(), "a refused folder is left as it was"

    out = tmp_path / "out"
    sweep.run_sweep(cfg, out, workers=1)
    (out / ".keep").write_text("mine")
    (out / "runs" / "notes.txt").write_text("mine")
    old_ids = {p.stem for p in (out / "runs").glob("*.parquet")}
    other = peak_config(tmp_path, nmu=3, ny=2, name="other")
    sweep.run_sweep(other, out, workers=1, overwrite=True)
    assert (out / ".keep").read_text() == "mine" and (out / "runs" / "notes.txt").read_text() == "mine"
    new_ids = {p.stem for p in (out / "runs").glob("*.parquet")}
    assert len(new_ids) == 3 and not (old_ids - new_ids) & {p.stem for p in (out / "trajectories").iterdir()}
    assert set(sweep.load_runs(out).case_id) == new_ids


def file_config(tmp_path, surface_file):
    return write_config(
        tmp_path,
        f"""
        [sweep]
        name = "from-file"
        [[surfaces]]
        file = "{surface_file.name}"
        [starts]
        points = [[0.1, 0.5], [0.2, 0.4]]
        [grid]
        mu = [0.5, 1.0, 1.5]
        """,
    )


def test_a_resume_refuses_a_changed_surface_file_and_overwrite_recomputes(tmp_path):
    surf = tmp_path / "surf.npz"
    surface_io.save_surface(presets.make_surface("paper-single-peak"), surf)
    cfg = file_config(tmp_path, surf)
    out = tmp_path / "out"
    sweep.run_sweep(cfg, out, workers=1)
    before = sweep.load_runs(out)
    next(iter((out / "runs").glob("*.parquet"))).unlink()  # as after a kill
    surface_io.save_surface(presets.make_surface("paper-single-valley"), surf)
    result = run_cli("sweep", cfg, "--out", out, "--workers", 1, "--quiet")
    assert result.exit_code == 2 and "computed on other inputs: file:" in result.output
    assert "surf.npz changed" in result.output
    result = run_cli("sweep", cfg, "--out", out, "--workers", 1, "--quiet", "--overwrite")
    assert result.exit_code == 0 and "skipped 0" in result.output, result.output
    after = sweep.load_runs(out)
    assert len(after) == len(before) == 6
    ref = {
        r["run_id"]: r["end_z"]
        for r in sweep.run_case(sweep.expand_cases(sweep.load_config(cfg))[0])[0].to_pylist()
    }
    got = after.set_index("run_id").end_z
    assert all(got[k] == v for k, v in ref.items())


def test_a_resume_refuses_an_edited_preset(tmp_path, monkeypatch):
    shipped = presets.presets_dir()
    mine = tmp_path / "presets"
    mine.mkdir()
    text = (shipped / "paper-single-peak.toml").read_text()
    (mine / "paper-single-peak.toml").write_text(text)
    monkeypatch.setenv("SPINE_MJ_SURFACES", str(mine))
    cfg = peak_config(tmp_path, nmu=2, ny=2)
    out = tmp_path / "out"
    sweep.run_sweep(cfg, out, workers=1)
    (mine / "paper-single-peak.toml").write_text(text + "\n[extra]\nnote = 'edited'\n")
    with pytest.raises(SpineInputError, match="preset:paper-single-peak changed"):
        sweep.run_sweep(cfg, out, workers=1)


@pytest.mark.parametrize(
    "args, message",
    [
        (["--workers", "100000"], "--workers: must be an integer from 1 to"),
        (["--scheduler", "not a url"], "--scheduler: must be a Dask scheduler address"),
    ],
)
def test_workers_and_scheduler_are_checked_before_anything_is_written(tmp_path, args, message):
    proc = cli("sweep", peak_config(tmp_path, nmu=2, ny=2), "--out", tmp_path / "out", *args)
    assert proc.returncode == 2 and proc.stderr.strip().splitlines() == [proc.stderr.strip()]
    assert message in proc.stderr
    assert not (tmp_path / "out").exists()


def test_a_grid_too_large_is_refused_with_its_size_before_allocating(tmp_path):
    doc = with_(
        grid__mu={"linspace": [0.1, 2.0], "num": 1000},
        grid__tip_radius={"linspace": [0, 1], "num": 1_000_000},
    )
    with pytest.raises(SpineInputError, match=r"1,000,000,000 cases .* 300 GB; the limit is 1,000,000 cases"):
        sweep.parse_config(doc)
    with pytest.raises(
        SpineInputError, match=r"grid.mu.num: must be less than or equal to 1000000, got 1000000000000"
    ):
        sweep.parse_config(with_(grid__mu={"linspace": [0.1, 2.0], "num": 10**12}))
    with pytest.raises(
        SpineInputError, match=r"starts.random: must be less than or equal to 10000000, got 1000000000000"
    ):
        sweep.parse_config(with_(starts={"random": 10**12}))


def test_corrupt_case_files_are_named_read_around_and_run_again(tmp_path):
    cfg = peak_config(tmp_path, nmu=3, ny=2)
    out = tmp_path / "out"
    sweep.run_sweep(cfg, out, workers=1)
    before = sweep.load_runs(out).drop(columns=["time_s", "cpu_s"]).sort_values("run_id")
    bad = sorted((out / "runs").glob("*.parquet"))[1]
    bad.write_bytes(bad.read_bytes()[:40])
    (out / "runs.parquet").unlink()  # as in a sweep killed before its end
    st = sweep.store_status(out)
    assert st.corrupt_cases == (bad.stem,) and st.finished_cases == 2 and not st.complete
    result = run_cli("sweep", "status", out)
    assert result.exit_code == 0 and f"runs/{bad.stem}.parquet" in result.output
    assert len(sweep.load_runs(out)) == 4
    result = run_cli("report", out, "-o", tmp_path / "r.html")
    assert result.exit_code == 0, result.output
    result = run_cli("sweep", cfg, "--out", out, "--workers", 1, "--quiet", "--retry-failed")
    assert (
        result.exit_code == 0
        and f"ran again 1 case(s) whose stored rows could not be read: {bad.stem}" in result.output
    )
    after = sweep.load_runs(out).drop(columns=["time_s", "cpu_s"]).sort_values("run_id")
    np.testing.assert_allclose(after.end_x.to_numpy(), before.end_x.to_numpy(), rtol=1e-9)
    assert sweep.store_status(out).complete


def test_mu_defaults_to_the_preset_calibrated_mu_and_is_required_otherwise(tmp_path):
    config = sweep.parse_config(with_(grid__mu=None))
    (case,) = sweep.expand_cases(config)
    calibrated = presets.preset_mu("paper-single-peak")
    assert calibrated is not None and case.params["mu"] == calibrated
    rows, _ = sweep.run_case(case)
    assert rows["status"].to_pylist() == ["ok"] and rows["mu"].to_pylist() == [calibrated]
    surf = tmp_path / "s.npz"
    surface_io.save_surface(presets.make_surface("paper-single-peak"), surf)
    doc = with_(grid__mu=None, surfaces=[{"file": str(surf)}])
    with pytest.raises(SpineInputError, match=r"grid.mu: required .* s has no calibrated mu"):
        sweep.parse_config(doc)
    with pytest.raises(SpineInputError, match=r"grid.mu: required .* sandpaper-P60 has no calibrated mu"):
        sweep.parse_config(with_(grid__mu=None, surfaces=[{"preset": "sandpaper-P60"}]))


def test_sweep_help_shows_the_options_of_run(tmp_path):
    result = run_cli("sweep", "--help")
    assert result.exit_code == 0
    for option in ("--out", "--workers", "--scheduler", "--overwrite", "--retry-failed", "--quiet"):
        assert option in result.output

"""The sweep, sweep status and report commands."""

import subprocess
import sys

import pytest
from click.testing import CliRunner
from sweep_support import PEAK_QS, peak_config, write_config

from spine_mj import sweep
from spine_mj.cli import main


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
        (
            PEAK_QS.format(name="x", nmu=2, ny=2, dl=0.02).replace("num = 2 }", "num = 2, step = 1 }", 1),
            "Error: config key starts.y.step: unknown key; allowed: linspace, logspace, num",
        ),
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


STIFF_SPRING = """
[sweep]
name = "stiff"
analyses = ["quasistatic", "engine", "compare"]
[[surfaces]]
preset = "paper-fractal"
seeds = [1]
set = { hurst = 0.7 }
[starts]
frame = "relative"
x = [0.05]
y = [0.2, 0.5, 0.8]
[drive]
protocol = "spring"
ie = 1e-4
K = 30000.0
"""


def test_cli_refuses_a_stiff_spring_too_fast_to_compare_with_the_streamline(tmp_path):
    """K = 30000 at I_e = 1e-4 on the fractal swings 9.3 F_p (docs/physics.md §8): one
    line naming the drive, the bound, the swing and the I_e that would do; nothing written."""
    cfg = write_config(tmp_path, STIFF_SPRING)
    proc = subprocess.run(
        [sys.executable, "-m", "spine_mj.cli", "sweep", str(cfg), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: sweep case (paper-fractal")
    assert "spring drive at I_e = 0.0001, K = 30000: compared with the quasistatic streamline" in lines[0]
    assert (
        "swing at most 1 F_p" in lines[0] and "got 9.3 F_p" in lines[0] and "dynamic_drive = true" in lines[0]
    )
    assert not (tmp_path / "out").exists()


def test_cli_sweep_a_stiff_spring_on_the_fractal_runs_without_an_engine_stop(tmp_path):
    """K = 3000 on the paper fractal at the I_e its swing allows (1e-5: 0.93 F_p): the step
    rule resolves the spring (omega dt <= 0.3), so no run ends in engine trouble. At the
    contact's own step MuJoCo stopped 8 of 12 such runs near step 213 (issue 32)."""
    text = STIFF_SPRING.replace("K = 30000.0", "K = 3000.0\nduration = 0.1").replace("ie = 1e-4", "ie = 1e-5")
    cfg = write_config(tmp_path, text.replace('"quasistatic", "engine", "compare"', '"engine"'))
    out = tmp_path / "out"
    result = run_cli("sweep", cfg, "--out", out, "--workers", 1, "--quiet")
    assert result.exit_code == 0, result.output
    runs = sweep.load_runs(out)
    assert len(runs) == 3 and (runs.status == "ok").all(), runs.end_detail.tolist()
    assert (runs.n_steps > 1500).all() and (
        runs.timestep_s * (runs.stiffness_n_m / runs.mass) ** 0.5 <= 0.3
    ).all()

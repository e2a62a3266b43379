"""``tip_radius`` has one meaning and one unit in every command and config key: a radius in
the surface's length unit; absent, the rig's default tip; 0, a point, which a streamline
traces and an engine refuses (its tip is a ball). The rule: ``spine_mj.sim.scales``
(``check_tip_radius``, ``resolve_tip_radius``, ``engine_tip_radius_m``)."""

import json

import pandas as pd
import pytest
from click.testing import CliRunner

from spine_mj import presets, sweep
from spine_mj.cli import main
from spine_mj.sim.scales import resolve_tip_radius

PRESET = "paper-single-peak"


def _simulated(tmp_path, args) -> float:
    """The tip radius [surface units] ``spine-mj simulate`` runs with ``args``."""
    out = tmp_path / "run"
    res = CliRunner().invoke(
        main, ["simulate", PRESET, "--start", "-3,-1", "--duration", "0.002", "--out", str(out), *args]
    )
    assert res.exit_code == 0, res.output
    summary = json.loads((out / "summary.json").read_text())
    return summary["tip"]["tip_radius_m"] / summary["scales"]["length_scale_m"]


def _traced(tmp_path, args) -> float:
    """The tip radius [surface units] ``spine-mj streamline`` traces with ``args``."""
    out = tmp_path / "paths"
    res = CliRunner().invoke(
        main, ["streamline", PRESET, "--start", "-3,-1", "--format", "csv", "--out", str(out), *args]
    )
    assert res.exit_code == 0, res.output
    (radius,) = pd.read_csv(out / "streamlines.csv").tip_radius.unique()
    return float(radius)


def _swept(tmp_path, grid) -> tuple[float, float]:
    """The tip radii [surface units] a sweep's engine and quasistatic analyses take of ``grid``."""
    from spine_mj.sweep.analyses.engine import case_rig
    from spine_mj.sweep.analyses.quasistatic import case_tip_radius

    doc = {
        "sweep": {"analyses": ["quasistatic", "engine"]},
        "surfaces": [{"preset": PRESET}],
        "starts": {"points": [[0.1, 0.5]]},
        "drive": {"protocol": "spring", "ie": 1e-3},
        "grid": grid,
    }
    (case,) = sweep.expand_cases(sweep.parse_config(doc, base_dir=tmp_path))
    rig = case_rig(case)
    return rig.tip.tip_radius_m / rig.length_scale_m, case_tip_radius(case, case.surface.make())


@pytest.mark.parametrize("given", [None, 0.2])
def test_simulate_streamline_and_a_sweep_take_one_tip(tmp_path, given):
    args = [] if given is None else ["--tip-radius", str(given)]
    simulated = _simulated(tmp_path, args)
    expected = resolve_tip_radius(presets.make_surface(PRESET), None) if given is None else given
    assert simulated == pytest.approx(expected, rel=1e-12)
    assert _traced(tmp_path, args) == pytest.approx(simulated, rel=1e-12)
    engine, quasistatic = _swept(tmp_path, {} if given is None else {"tip_radius": given})
    assert engine == pytest.approx(simulated, rel=1e-12)
    assert quasistatic == pytest.approx(simulated, rel=1e-12)


def test_a_point_is_traced_and_refused_where_an_engine_runs(tmp_path):
    assert _traced(tmp_path, ["--tip-radius", "0"]) == 0.0
    res = CliRunner().invoke(
        main, ["simulate", PRESET, "--start", "-3,-1", "--tip-radius", "0", "--out", str(tmp_path / "r")]
    )
    assert res.exit_code == 2 and res.output.startswith("Error: --tip-radius 0 is a point tip")
    assert not (tmp_path / "r").exists()
    info = CliRunner().invoke(main, ["surface", "info", PRESET, "--tip-radius", "0", "--json"])
    assert info.exit_code == 0, info.output

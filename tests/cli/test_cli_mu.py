"""One mu rule for every command: the preset's calibrated mu, else a given one; mu = 0 and a
surface without a calibrated mu are refused alike (``spine_mj.presets.resolve_mu``)."""

import pytest
from click.testing import CliRunner

from spine_mj import presets
from spine_mj.cli import main
from spine_mj.errors import SpineInputError
from spine_mj.surface_io import save_surface
from spine_mj.surfaces import single_gaussian


def test_the_rule_takes_the_given_mu_else_the_presets():
    assert presets.resolve_mu("paper-single-peak") == presets.calibrated_mu("paper-single-peak")
    assert presets.resolve_mu("paper-single-peak", 0.7) == 0.7
    for bad in (0, 0.0, -1.0, float("nan"), float("inf"), "x"):
        with pytest.raises(SpineInputError, match="must be"):
            presets.resolve_mu("paper-single-peak", bad, name="--mu")
    with pytest.raises(SpineInputError, match="--mu is required"):
        presets.resolve_mu(single_gaussian(), None, name="--mu")


@pytest.mark.parametrize(
    "command",
    [
        ["kappa", "SURFACE", "-o", "OUT/k.png"],
        ["streamline", "SURFACE", "--start", "-3,-1", "--out", "OUT/s"],
        ["simulate", "SURFACE", "--start", "-3,-1", "--resolution", "41", "--out", "OUT/r"],
        ["sim", "export", "SURFACE", "--resolution", "41", "-o", "OUT/rig.xml"],
    ],
)
def test_every_command_refuses_mu_zero_and_a_missing_mu_alike(tmp_path, command):
    save_surface(single_gaussian(), tmp_path / "peak.npz")  # no preset: no calibrated mu

    def run(surface, *extra):
        args = [a.replace("SURFACE", surface).replace("OUT", str(tmp_path)) for a in command]
        return CliRunner().invoke(main, [*args, *extra])

    for result, message in [
        (
            run("paper-single-peak", "--mu", "0"),
            "--mu (static friction coefficient mu_s) must be finite and > 0",
        ),
        (
            run(str(tmp_path / "peak.npz")),
            "--mu is required for a surface whose preset has no [engagement] mu",
        ),
    ]:
        assert result.exit_code == 2, result.output
        lines = result.output.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("Error:") and message in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["peak.npz"]

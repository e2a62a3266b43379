"""The shipped examples (``example:NAME``): found from any folder, in any file argument."""

import pytest
from click.testing import CliRunner

from spine_mj import examples, sweep
from spine_mj.cli import main
from spine_mj.errors import SpineInputError


def test_every_readme_example_file_ships_and_resolves():
    found = examples.list_examples()
    assert {"plu-1.plu", "di-1.di"} <= {n for n, (k, _) in found.items() if k == "scan"}
    assert {"mujoco-ie.toml", "paper-quasistatic.toml", "penetration-check.toml"} <= set(found)
    for name, (_, path) in found.items():
        assert examples.resolve(examples.PREFIX + name) == str(path) and path.is_file()
    assert examples.resolve("scan.plu") == "scan.plu"


def test_an_unknown_example_names_the_ones_there_are():
    with pytest.raises(SpineInputError, match=r"'example:nope.plu': no such example; .*example:plu-1.plu"):
        examples.resolve("example:nope.plu")


def test_examples_run_from_a_folder_outside_the_repository(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    runner = CliRunner()
    listed = runner.invoke(main, ["examples"])
    assert listed.exit_code == 0 and "example:plu-1.plu" in listed.output
    info = runner.invoke(main, ["surface", "info", "example:di-1.di"])
    assert info.exit_code == 0 and "rms height" in info.output, info.output
    made = runner.invoke(main, ["surface", "make", "--from-file", "example:di-1.di", "-o", "scan.npz"])
    assert made.exit_code == 0 and (tmp_path / "scan.npz").is_file(), made.output
    # every shipped config reads from here, its own example scans included
    for name, (kind, _) in examples.list_examples().items():
        if kind == "sweep":
            sweep.load_config(examples.resolve(examples.PREFIX + name))


def test_a_config_names_a_shipped_scan_as_an_example(tmp_path):
    doc = {"surfaces": [{"file": "example:plu-1.plu"}], "starts": {"random": 1}, "grid": {"mu": 0.5}}
    config = sweep.parse_config(doc, base_dir=tmp_path)
    assert config.surfaces[0].source == str(examples.list_examples()["plu-1.plu"][1].resolve())
    doc["surfaces"][0]["file"] = "example:nope.di"
    with pytest.raises(SpineInputError, match=r"surfaces\[0\].file: 'example:nope.di': no such example"):
        sweep.parse_config(doc, base_dir=tmp_path)

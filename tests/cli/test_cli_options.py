"""The options several commands share (spine_mj.cli.options): one declaration, the
library's own name list."""

from click.testing import CliRunner

from spine_mj import choices, surface_io
from spine_mj.cli import main


def _option(path: list[str], name: str):
    cmd = main
    for part in path:
        cmd = cmd.get_command(None, part)
    return next(p for p in cmd.params if p.name == name)


def test_fill_is_one_option_with_surface_io_s_methods_in_make_and_hold():
    """`hold --fill` and `surface make --fill` each listed the methods by hand."""
    assert surface_io.FILL_METHODS is choices.FILL_METHODS
    for path in (["surface", "make"], ["hold"]):
        fill = _option(path, "fill")
        assert tuple(fill.type.choices) == choices.FILL_METHODS and fill.default == "refuse"


def test_an_unknown_fill_method_is_one_error_line_naming_the_choices(tmp_path):
    res = CliRunner().invoke(main, ["hold", "paper-fractal", "--fill", "zero", "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and res.output.count("\n") == 1, res.output
    assert res.output.startswith("Error:") and "'zero'" in res.output
    assert all(m in res.output for m in choices.FILL_METHODS)
    assert not (tmp_path / "o").exists()

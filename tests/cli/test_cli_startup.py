"""The CLI starts at once: ``import spine_mj``, ``import spine_mj.cli`` and every ``--help``
import none of the heavy libraries (an import-graph check in a fresh interpreter, not a
timer: ``make bench`` times them); a SIGTERM while a command starts unwinds quietly; and
every example in the help texts parses."""

import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from spine_mj.cli import app, main

#: Libraries that take a noticeable time to import; a command imports them when it runs.
HEAVY = (
    "mujoco",
    "dask",
    "distributed",
    "pandas",
    "numba",
    "scipy.stats",
    "scipy.ndimage",
    "trimesh",
    "matplotlib",
    "pyarrow",
    "SurfaceTopography",
    "pybullet",
)


def heavy_imports(code: str) -> list[str]:
    """The :data:`HEAVY` modules loaded after running ``code`` in a fresh interpreter."""
    probe = f"{code}\nimport sys\nprint('loaded:', *(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return out.stdout.splitlines()[-1].split()[1:]


def all_commands(group=main, path=()):
    """``(path, command)`` of every command and group under ``group`` (loading each module)."""
    ctx = click.Context(group)
    for name in group.list_commands(ctx):
        cmd = group.get_command(ctx, name)
        yield (*path, name), cmd
        if isinstance(cmd, click.Group):
            yield from all_commands(cmd, (*path, name))


@pytest.mark.parametrize("code", ["import spine_mj", "import spine_mj.cli"])
def test_importing_the_package_loads_no_heavy_library(code):
    assert heavy_imports(code) == []


def test_every_help_page_loads_no_heavy_library():
    code = (
        "import click\n"
        "from spine_mj.cli import main\n"
        "def walk(group, path):\n"
        "    for name in group.list_commands(click.Context(group)):\n"
        "        cmd = group.get_command(click.Context(group), name)\n"
        "        try:\n"
        "            main([*path, name, '--help'])\n"
        "        except SystemExit:\n"
        "            pass\n"
        "        if isinstance(cmd, click.Group):\n"
        "            walk(cmd, [*path, name])\n"
        "walk(main, [])"
    )
    assert heavy_imports(code) == []


def test_the_public_names_still_import_from_the_package():
    import spine_mj

    code = f"from spine_mj import {', '.join(n for n in spine_mj.__all__ if n != '__version__')}"
    subprocess.run([sys.executable, "-c", code], check=True)
    # the root's name loads its home module (the theory package imports its modules on demand,
    # so the name comes first: the other order failed whenever no earlier test had imported it)
    assert spine_mj.streamlines is spine_mj.theory.streamline.streamlines


def test_the_root_lists_every_command_it_loads_lazily():
    names = {path[0] for path, _ in all_commands()}
    assert names == set(app._Root.lazy_commands)
    assert set(main.commands) == names  # each module registered the commands it is listed for


def help_examples():
    """``(command path, example line)`` of every ``spine-mj ...`` line in a help text."""
    for path, cmd in all_commands():
        for line in (cmd.help or "").splitlines():
            for part in line.split("&&"):
                part = part.strip()
                if part.startswith("spine-mj "):
                    yield " ".join(path), part


def parse_only(argv: list[str]) -> None:
    """Parse ``argv`` down to its leaf command as the CLI would, without running it."""
    cmd, ctx = main, main.make_context("spine-mj", list(argv))
    while isinstance(cmd, click.Group):
        name, cmd, rest = cmd.resolve_command(ctx, [*ctx._protected_args, *ctx.args])
        ctx = cmd.make_context(name, rest, parent=ctx)


@pytest.mark.parametrize(("where", "example"), list(help_examples()))
def test_every_help_example_parses(where, example, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for folder in ("run", "runs/qs"):  # what an example names as an existing folder
        (tmp_path / folder).mkdir(parents=True)
    parse_only(shlex.split(example)[1:])


def test_the_help_examples_are_found():
    examples = dict(help_examples())
    assert {"streamline", "replay", "sweep", "simulate", "array"} <= set(examples)


def test_the_help_states_the_library_defaults():
    from spine_mj import sweep
    from spine_mj.theory.streamline_outputs import TABLE_FORMATS

    result = CliRunner().invoke(main, ["sweep", "run", "--help"])
    assert f"[default: {sweep.DEFAULT_WORKER_WAIT_S:g}]" in " ".join(result.output.split())
    fmt = next(p for p in main.get_command(None, "streamline").params if p.name == "fmt")
    assert tuple(fmt.type.choices) == TABLE_FORMATS


@pytest.mark.parametrize("fail", [True, False])
def test_library_warnings_never_print_before_the_error_line(fail):
    import warnings

    from spine_mj.errors import SpineInputError

    @click.group(cls=app._Group)
    def root():
        pass

    @root.command()
    def work():
        warnings.warn("a library's note\n  and its source line", UserWarning, stacklevel=1)
        if fail:
            raise SpineInputError("bad input")
        click.echo("done")

    lines = CliRunner().invoke(root, ["work"]).output.splitlines()
    if fail:
        assert lines == ["Error: bad input"]
    else:
        assert lines == ["done", "Warning: UserWarning: a library's note and its source line"]


@pytest.mark.parametrize("delay_s", [0.3, 1.0, 2.0, 3.5])
def test_sigterm_while_simulate_starts_unwinds_quietly(tmp_path, delay_s):
    out = tmp_path / "run"
    spine = Path(sys.executable).with_name("spine-mj")
    args = ["simulate", "paper-single-peak", "--start", "-3,-1", "--ie", "1e-6", "--out", str(out)]
    proc = subprocess.Popen([str(spine), *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay_s)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode in (128 + signal.SIGTERM, -signal.SIGTERM), (proc.returncode, stderr)
    assert "Traceback" not in stderr and "Error" not in stderr, stderr
    assert not out.exists() or not any(out.iterdir())


def test_a_sigterm_a_library_swallowed_stops_the_command_at_its_next_progress_report(monkeypatch):
    from spine_mj.cli import app

    monkeypatch.setattr(app, "_TERMINATED", [signal.SIGTERM])
    with pytest.raises(SystemExit) as stop:
        app.Progress("simulating", quiet=True).update(1, 10)
    assert stop.value.code == 128 + signal.SIGTERM


def test_a_quick_preparation_prints_nothing_and_a_long_one_shows_its_stages(capsys):
    """The CLI's progress display with a delay: updates before it show no bar (the small
    cases' one-line refusals stay one line), after it they do."""
    from spine_mj.cli import app

    quick = app.Progress("preparing", delay_s=3600.0)
    quick.update(0, 1, "sampling the hfield")
    assert quick.bar is None and capsys.readouterr().err == ""
    with app.Progress("preparing", delay_s=0.0) as shown:
        shown.update(3, 6, "fall height")
        assert shown.bar is not None
    assert "fall height" in capsys.readouterr().err


@pytest.mark.parametrize("module", ["spine_mj", "spine_mj.cli"])
def test_python_m_runs_the_program(module, tmp_path):
    """``python -m spine_mj`` is ``spine-mj``: its help, and a refusal in one line, exit 2."""
    out = subprocess.run([sys.executable, "-m", module, "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "simulate" in out.stdout, out.stderr
    bad = subprocess.run(
        [sys.executable, "-m", module, "surface", "info", str(tmp_path / "missing.npz")],
        capture_output=True,
        text=True,
    )
    lines = (bad.stdout + bad.stderr).strip().splitlines()
    assert bad.returncode == 2 and len(lines) == 1 and lines[0].startswith("Error:"), lines

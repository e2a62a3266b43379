"""``spine-mj compare-engines``: every bad argument, the folder and the missing [bullet]
extra refused in one Error line before any work, nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from spine_mj.cli import main


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--fractal", "-1"], "--fractal"),
        (["--headlines", "-1"], "--headlines"),
        (["--fractal", "abc"], "'abc' is not a valid integer"),
        (["--workers", "0"], "--workers"),
        (["--headlines-plan", "huge"], "--headlines-plan"),
        (["--bogus"], "No such option '--bogus'"),
        ("no --out", "Missing option '--out'"),
        ("a file", "is a file, expected a folder"),
        ("under a file", "is a file, not a folder"),
    ],
)
def test_every_bad_argument_is_one_error_line_before_any_work(tmp_path, args, fragment):
    (tmp_path / "afile").write_text("")
    if args == "no --out":
        argv = []
    elif args == "a file":
        argv = ["--out", str(tmp_path / "afile")]
    elif args == "under a file":
        # without the extra the command refuses first for it (one Error line too, another message)
        pytest.importorskip("pybullet", reason="the missing [bullet] extra is refused before this")
        argv = ["--out", str(tmp_path / "afile" / "sub")]
    else:
        argv = ["--out", str(tmp_path / "out"), *args]
    res = CliRunner().invoke(main, ["compare-engines", *argv])
    assert res.exit_code == 2, res.output
    assert res.stdout == ""  # no check ran
    (line,) = res.stderr.splitlines()
    assert line.startswith("Error: ") and fragment in line, line
    assert not (tmp_path / "out").exists()


def test_without_the_bullet_extra_the_command_is_refused_before_any_work(monkeypatch, tmp_path):
    from spine_mj import extras

    monkeypatch.setitem(extras.EXTRAS, "bullet", ("no_such_module_spine_mj",))
    res = CliRunner().invoke(main, ["compare-engines", "--out", str(tmp_path / "out")])
    assert res.exit_code == 2 and res.stdout == ""
    assert res.stderr.strip() == (
        "Error: compare-engines (it runs both engines) needs the optional extra 'bullet' "
        "(no_such_module_spine_mj not installed): pip install 'spine-mj[bullet]'"
    )
    assert not (tmp_path / "out").exists()


def _unwritable_folders(tmp_path):
    """Folders no user can write, root included: procfs takes no new files (Linux); and, for
    a user other than root, a folder without write permission."""
    import os
    import sys

    if sys.platform.startswith("linux"):
        yield Path(f"/proc/{os.getpid()}/spine_mj_out")
    if hasattr(os, "geteuid") and os.geteuid() != 0:
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        yield locked / "out"


def test_an_unwritable_out_is_one_error_line_before_any_work(tmp_path):
    pytest.importorskip("pybullet", reason="the missing [bullet] extra is refused before this")
    folders = list(_unwritable_folders(tmp_path))
    if not folders:
        pytest.skip("no folder this user cannot write on this system")
    for out in folders:
        res = CliRunner().invoke(main, ["compare-engines", "--out", str(out)])
        assert res.exit_code == 2, res.output
        assert res.stdout == ""  # no check ran, no progress line came
        (line,) = res.stderr.splitlines()
        assert line.startswith(f"Error: cannot write {out / 'engines.json'}: "), line  # + the system's reason
        assert not out.exists()

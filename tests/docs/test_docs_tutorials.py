"""The tutorials run as written: every command of their shell blocks, in order, in one
empty folder per tutorial, with the TOML files they tell the reader to save and the Python
blocks they show (a block marked ``# not run by the tests: WHY`` excepted). The commands
run in this process (click's runner), as ``spine-mj`` would run them. Marked ``docs``:
``make docs`` runs them (minutes), ``make test`` does not."""

import os
import shlex
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "tools"))

import doccommands  # noqa: E402

TUTORIALS = sorted((ROOT / "docs" / "tutorials").glob("*.md"))
TUTORIALS = [p for p in TUTORIALS if p.name != "index.md"]


def _expected_exit(comment: str) -> int:
    """0, or the code a line's comment announces (``# exits 2: ...``)."""
    return int(comment[len("exits ") :].split(":")[0]) if comment.startswith("exits ") else 0


def _steps(text: str):
    """(kind, payload) in page order: ("file", (name, body)), ("sh", (line, exit code)),
    ("python", body)."""
    for lang, body in doccommands.blocks(text):
        if lang == "toml":
            first = body.splitlines()[0]
            assert first.startswith("# ") and first.endswith(".toml"), "a TOML block names its file"
            yield "file", (first[2:].strip(), body)
        elif lang in ("sh", "bash"):
            for line, comment in doccommands.shell_commands(body):
                yield "sh", (line, _expected_exit(comment))
        elif lang == "python" and "# not run by the tests:" not in body.splitlines()[0]:
            yield "python", body


@pytest.mark.docs
@pytest.mark.timeout(1200)
@pytest.mark.parametrize("page", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_tutorial_runs(page, tmp_path):
    steps = list(_steps(page.read_text()))
    assert any(kind == "sh" for kind, _ in steps)
    from spine_mj.cli import main

    cluster = None
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        for kind, payload in steps:
            if kind == "file":
                name, body = payload
                (tmp_path / name).write_text(body)
            elif kind == "python":
                exec(compile(payload, f"{page.name}:python", "exec"), {"__name__": "tutorial"})
            else:
                line, code = payload
                words = shlex.split(line.rstrip("&").strip())
                if words[0] == "dask":
                    # the tutorial's scheduler and workers: a local cluster stands in
                    if cluster is None:
                        from distributed import LocalCluster

                        cluster = LocalCluster(
                            n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
                        )
                    continue
                assert words[0] == "spine-mj", f"{page.name}: a shell line that is not spine-mj: {line}"
                if cluster is not None:
                    words = [w.replace("tcp://HOST:8786", cluster.scheduler_address) for w in words]
                done = CliRunner().invoke(main, words[1:], prog_name="spine-mj")
                assert done.exit_code == code, f"{page.name}: {line}\n{done.output}\n{done.exception!r}"
    finally:
        os.chdir(cwd)
        if cluster is not None:
            cluster.close()

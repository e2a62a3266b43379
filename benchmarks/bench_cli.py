"""How fast the command line answers (issue 36): wall time of ``spine-mj --help``, of every
command's ``--help``, and of commands that touch no engine (``surface list``,
``examples``, ``kappa`` on a preset), each run as a user would, a fresh process each time.

Targets: every help page within 0.5 s, each engine-free command within 1.5 s (on an idle
machine; the row gives the load). The test suite checks what makes this hold, that no heavy
library is imported before a command runs (``tests/cli/test_cli_startup.py``), not the time.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_common import target_cell

SPINE = str(Path(sys.executable).with_name("spine-mj"))
HELP_TARGET_S = 0.5
COMMAND_TARGET_S = 1.5


def _commands() -> list[list[str]]:
    """Every command path (``["surface", "make"]``, ...) of the CLI."""
    import click

    from spine_mj.cli import main

    out = []

    def walk(group, path):
        for name in group.list_commands(click.Context(group)):
            cmd = group.get_command(click.Context(group), name)
            out.append([*path, name])
            if isinstance(cmd, click.Group):
                walk(cmd, [*path, name])

    walk(main, [])
    return out


def _wall(args: list[str], repeats: int, cwd: str) -> dict:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        subprocess.run([SPINE, *args], cwd=cwd, check=True, capture_output=True)
        times.append(time.perf_counter() - t)
    return {"median_s": round(statistics.median(times), 3), "min_s": round(min(times), 3)}


def bench_cli(quick: bool) -> dict:
    repeats = 3 if quick else 5
    with tempfile.TemporaryDirectory() as tmp:
        helps = {"spine-mj --help": _wall(["--help"], repeats, tmp)}
        for path in _commands():
            helps[f"spine-mj {' '.join(path)} --help"] = _wall([*path, "--help"], repeats, tmp)
        commands = {
            "spine-mj surface list": _wall(["surface", "list"], repeats, tmp),
            "spine-mj examples": _wall(["examples"], repeats, tmp),
            "spine-mj kappa paper-single-peak -o map.png": _wall(
                ["kappa", "paper-single-peak", "-o", "map.png"], repeats, tmp
            ),
        }
    slowest = max(helps, key=lambda k: helps[k]["median_s"])
    return {"help": helps, "commands": commands, "slowest_help": slowest, "repeats": repeats}


def markdown(res: dict | None) -> list[str]:
    """The README table's rows for :func:`bench_cli`'s results."""
    if not res:
        return []
    ld = f"{res['load_before']}-{res['load_after']}"
    root, slowest = res["help"]["spine-mj --help"], res["help"][res["slowest_help"]]
    lines = [
        f"| `spine-mj --help`, median of {res['repeats']} | {root['median_s']:.2f} s | "
        f"{target_cell(root['median_s'], '<=', HELP_TARGET_S, ' s')} | {ld} |",
        f"| slowest of the {len(res['help'])} help pages (`{res['slowest_help']}`), median | "
        f"{slowest['median_s']:.2f} s | "
        f"{target_cell(slowest['median_s'], '<=', HELP_TARGET_S, ' s')} | {ld} |",
    ]
    for name, r in res["commands"].items():
        lines.append(
            f"| `{name}`, median of {res['repeats']} | {r['median_s']:.2f} s | "
            f"{target_cell(r['median_s'], '<=', COMMAND_TARGET_S, ' s')} | {ld} |"
        )
    return lines


if __name__ == "__main__":
    import json

    print(json.dumps(bench_cli(quick="--quick" in sys.argv), indent=2))

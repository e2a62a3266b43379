"""Peak resident memory and wall time of the main jobs, each in a process of its own.

Jobs (issue 36): ``simulate`` (one run), a sweep case (quasistatic + mujoco + compare, one
worker), ``validate --quick`` (the full bench only: it takes minutes), the dilation of an
801 x 801 grid by a tip 110 samples wide, ``array``, and (issue 44) a 2048 x 2048 fractal
made (predicted by ``fbm_bytes``: 288 MiB above the interpreter) and exported as a streamed
STL, and one run in each engine on a 1448 x 1448 fractal (Bullet's heightfield takes about
30 times MuJoCo's hfield: pybullet's rendering mesh). Each runs as the command a user
types, in a temporary folder; its peak is the ``ru_maxrss`` that ``os.wait4`` returns for
it: the largest resident set of the job's process or of any process it waited for (a
sweep's workers). A job whose peak grew by more than :data:`GROWTH_LIMIT` against the
committed ``benchmarks/results.json`` is marked, like a missed target.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from spine_mj import extras

#: A peak more than this factor above the committed one is marked as grown.
GROWTH_LIMIT = 1.2

_SWEEP = """
[sweep]
name = "bench-memory"
seed = 1
analyses = ["quasistatic", "engine", "compare"]

[[surfaces]]
preset = "paper-single-peak"

[starts]
frame = "relative"
x = [0.05]
y = { linspace = [0.3, 0.7], num = 4 }

[drive]
protocol = "spring"
ie = [1e-3]
"""

_DILATE = (
    "import numpy as np; from spine_mj.surfaces import GridSurface, dilate; x = np.arange(801.0); "
    "g = GridSurface(heights=np.random.default_rng(0).normal(size=(801, 801)), x=x, y=x.copy()); "
    "dilate(g, 55.0)"
)


_STL = (
    "from spine_mj.surfaces import fractal_fbm; from spine_mj.surface_io import write_stl; "
    "write_stl(fractal_fbm(nx=2048, rng=0), 'f.stl')"
)


def _jobs(quick: bool) -> dict[str, list[str]]:
    cli = [sys.executable, "-m", "spine_mj.cli"]
    jobs = {
        "simulate": [
            *cli,
            *("simulate", "paper-single-peak", "--start", "-3,-1"),
            *("--duration", "0.05", "--resolution", "41", "--out", "sim"),
        ],
        "sweep case": [*cli, "sweep", "sweep.toml", "--out", "runs", "--workers", "1", "--quiet"],
        "dilate 801^2 by a 110-sample tip": [sys.executable, "-c", _DILATE],
        "array": [*cli, "array", "paper-random-concave", "--rows", "2", "--cols", "2", "--out", "arr"],
        # issue 44: the large inputs, each within its predicted peak (fbm_bytes) or refused
        "surface make paper-fractal nx=2048": [
            *cli,
            *("surface", "make", "paper-fractal", "--set", "nx=2048", "-o", "f2048.npz"),
        ],
        "fractal 2048^2 exported as STL (streamed)": [sys.executable, "-c", _STL],
    }
    # issue 44: one run in each engine on a fractal of 1448 x 1448 samples, the most that
    # pybullet's heightfield takes (Bullet's run on 2048 a side peaked at 6.8 GB before)
    jobs["surface make paper-fractal nx=1448"] = [
        *cli,
        *("surface", "make", "paper-fractal", "--set", "nx=1448", "-o", "f1448.npz"),
    ]
    run = ["f1448.npz", "--start", "-5,0", "--mu", "1.25", "--duration", "0.05"]
    for engine in ["mujoco"] + ([] if extras.missing("bullet") else ["bullet"]):
        jobs[f"simulate on the fractal 1448^2 ({engine})"] = [
            *cli,
            *("simulate", *run, "--engine", engine, "--out", f"sim-{engine}"),
        ]
    if not quick:
        jobs["validate --quick"] = [*cli, "validate", "--quick", "--out", "val"]
    return jobs


def measure(argv: list[str], cwd: Path) -> dict:
    """Wall time and peak resident set (MiB) of one command run to its end.

    Through a fresh launcher (this file's ``__main__``): Linux keeps a forking parent's
    peak in its child's ``ru_maxrss`` across ``exec``, so a job forked straight from a bench
    process that already holds a gigabyte would report that gigabyte."""
    out = subprocess.run(
        [sys.executable, __file__, "--launch", *argv], cwd=cwd, capture_output=True, text=True, check=False
    )
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} failed: {out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def _launch(argv: list[str]) -> None:
    """Run ``argv``, print its wall time and peak as JSON (the launcher's job)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    stderr = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        sys.stderr.write(f"exited {os.waitstatus_to_exitcode(status)}: {stderr.decode()[-2000:]}")
        sys.exit(1)
    print(json.dumps({"wall_s": round(wall, 2), "peak_rss_mib": round(usage.ru_maxrss / 1024, 1)}))


def bench_memory(quick: bool, committed: dict | None = None) -> dict:
    """Each job's wall time and peak, with the committed peak and whether it grew."""
    jobs = {}
    with tempfile.TemporaryDirectory(prefix="spine-mj-bench-") as tmp:
        cwd = Path(tmp)
        (cwd / "sweep.toml").write_text(_SWEEP)
        for name, argv in _jobs(quick).items():
            row = measure(argv, cwd)
            old = ((committed or {}).get("jobs") or {}).get(name)
            if old:
                row["committed_peak_rss_mib"] = old["peak_rss_mib"]
                row["grew"] = row["peak_rss_mib"] > GROWTH_LIMIT * old["peak_rss_mib"]
            jobs[name] = row
            print(f"    {name}: {row['wall_s']} s, peak {row['peak_rss_mib']} MiB", flush=True)
    return {"jobs": jobs, "growth_limit": GROWTH_LIMIT}


def markdown(res: dict | None, missed: str) -> list[str]:
    """The memory section of the benchmark report; a grown peak ends in ``missed``."""
    if not res:
        return []
    out = [
        "",
        "**Memory**: peak resident set of each main job, run as a user runs it (the largest of "
        "its processes), beside its wall time; marked where it grew by more than "
        f"{res['growth_limit'] - 1:.0%} against the committed figures:",
        "",
        "| job | wall [s] | peak [MiB] | committed peak [MiB] |",
        "| --- | --- | --- | --- |",
    ]
    for name, r in res["jobs"].items():
        old = r.get("committed_peak_rss_mib")
        mark = f" {missed}" if r.get("grew") else ""
        out.append(f"| {name} | {r['wall_s']} | {r['peak_rss_mib']}{mark} | {old if old else '-'} |")
    return out


if __name__ == "__main__":
    if sys.argv[1:2] == ["--launch"]:
        _launch(sys.argv[2:])
    else:
        print(json.dumps(bench_memory(quick="--quick" in sys.argv), indent=2))

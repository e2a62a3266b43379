"""Every benchmark in one run: one JSON, one markdown table, and the site's Performance page.

    python benchmarks/run_all.py [--quick] [--gpu] [--out FILE.json]       # into benchmarks/out/
    python benchmarks/run_all.py --update [--readme]   # the committed results.json, README
    python benchmarks/run_all.py --readme --from-json benchmarks/results.json   # no new run

Sections (each records the machine's load average before and after it):

* ``streamline``: steps/s of the compiled kernel (analytic single Gaussian, gridded
  fractal) and of the plain numpy reference (``backend="numpy"``) on the same starts; and
  steps per CPU second of the facet streamline (compare's reference on the P600 facets),
  compiled and numpy (target 4e4).
* ``rollout``: ``Rig.run_batch`` against bare ``mujoco.rollout`` (same model, controls and
  recording, runs that do not end early), paired runs in alternating order; the median of
  the per-pair ratios of wall time (the target) and of the process's CPU time; the calling
  thread's own CPU per batch (both less sensitive to a shared machine than the wall
  ratio). And the steps and time ``Rig.run_batch`` saves by stopping decided runs
  (``stop_early``) on a fractal where most runs self-lock.
* ``fastforward``: the static probe and the force ramp with and without stick-phase
  fast-forward (``benchmarks/bench_fastforward.py``): breakaway forces, steps; and the
  cost of a spring run (steps and CPU seconds) against I_e and K with and without it.
* ``sweep``: the one-worker sweep against bare rollout, and its two-worker efficiency.
* ``cost``: steps per spring-drive run against I_e and the spring stiffness K on the single
  peak and on a fractal, with a fitted cost model (see :func:`fit_cost`).
* ``compliant``: the compliant-drive reference's compiled loop against its numpy loop, and
  the P600 sandpaper ``compare`` analysis it made slow (``benchmarks/bench_compliant.py``).
* ``hold``: ``spine-mj hold sandpaper-P600 --mu 0.5`` as a user runs it: wall time, CPU
  seconds, the starts it ran and its verdict (``benchmarks/bench_hold.py``).
* ``array``: an array of N spines against N single-spine runs of the same length
  (``benchmarks/bench_array.py``): the median wall-time ratio, target at most about 1.
* ``cli``: wall time of ``spine-mj --help``, of every command's help and of the commands
  that touch no engine (``benchmarks/bench_cli.py``): targets 0.5 s and 1.5 s.
* ``prepare``: what a sweep of 999,999 cases (``--quick``: 99,999) costs before its first
  case: listing, checking every combination and writing the manifest, CPU seconds and peak
  memory (``benchmarks/bench_prepare.py``): target 60 us a case.
* ``plan_cost``: ``spine-mj validate --quick`` (``--quick``: the smoke plan) as a user runs
  it, its wall time and CPU seconds, and each study's CPU seconds (the command and its
  workers) and those of its sweeps' runs (``benchmarks/bench_plan_cost.py``): target
  ``make demo`` within 5 min. Also the same command again on its finished folder (what a
  resume costs: every store, the corners and the arrays' rows read back), the numba
  kernels compiled from an empty cache (CPU seconds on one process, wall on two) and the
  committed quick and full reports' wall time (the full plan: target 30 min).
* ``memory``: wall time and peak resident memory of the main jobs, each in a process of
  its own (``benchmarks/bench_memory.py``), marked where a peak grew by more than 20 %
  against the committed ``benchmarks/results.json``.
* ``gpu`` (``--gpu``): the static kappa error on inclined planes (breakaway force / F_p
  against ``tan(theta + arctan mu)``) of the CPU engine with noslip, of the CPU engine
  without noslip at a high impratio (what a noslip-less engine sees), and of MuJoCo Warp
  with both settings where a CUDA device exists; and GPU against CPU throughput.
* ``engines`` (with the ``[bullet]`` extra): Bullet against MuJoCo on the same runs
  (``benchmarks/bench_engines.py``): steps per second and cost per compared run.

Timings are the best (streamline) or the median (ratios) of repeats: the machine is shared.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import os
import platform
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # the bench modules beside this file

import bench_array  # noqa: E402
import bench_cli  # noqa: E402
import bench_compliant  # noqa: E402
import bench_cost  # noqa: E402
import bench_engines  # noqa: E402
import bench_fastforward  # noqa: E402
import bench_gpu  # noqa: E402
import bench_hold  # noqa: E402
import bench_memory  # noqa: E402
import bench_plan_cost  # noqa: E402
import bench_prepare  # noqa: E402
import bench_rollout  # noqa: E402
import bench_stickslip  # noqa: E402
import bench_streamline  # noqa: E402
import bench_sweep  # noqa: E402
from bench_common import MISSED, load, section  # noqa: E402

README = HERE.parent / "docs" / "user_guide" / "performance.md"
BEGIN, END = "<!-- bench:begin (generated by benchmarks/run_all.py --readme) -->", "<!-- bench:end -->"

#: Section name -> its module (each has ``bench_<name>(quick)`` and ``markdown(result)``), in
#: the order they run; the Performance page lists them in :data:`REPORT_ORDER`.
SECTIONS = {
    "streamline": bench_streamline,
    "rollout": bench_rollout,
    "sweep": bench_sweep,
    "cost": bench_cost,
    "compliant": bench_compliant,
    "hold": bench_hold,
    "fastforward": bench_fastforward,
    "array": bench_array,
    "cli": bench_cli,
    "prepare": bench_prepare,
    "plan_cost": bench_plan_cost,
    "engines": bench_engines,
    "gpu": bench_gpu,
    "memory": bench_memory,
    "stickslip": bench_stickslip,
}
REPORT_ORDER = (
    "streamline",
    "rollout",
    "sweep",
    "cost",
    "compliant",
    "hold",
    "array",
    "engines",
    "fastforward",
    "cli",
    "prepare",
    "plan_cost",
    "gpu",
    "memory",
    "stickslip",
)


def markdown(res: dict) -> str:
    """The results as the README's Performance section (markdown)."""
    m = res["machine"]
    lines = [
        f"Measured by `python benchmarks/run_all.py{' --quick' if res['quick'] else ''}` on "
        f"{m['date']}: {m['cpu_count']} cores, load average {m['load_start']} at the start "
        f"(the machine is shared: every row gives the load around its section). Python "
        f"{m['python']}, MuJoCo {m['mujoco']}. Raw numbers: `benchmarks/results.json`.",
        "",
        "| what | measured | target | load |",
        "| --- | --- | --- | --- |",
    ]
    for name in REPORT_ORDER:
        extra = (MISSED,) if name == "memory" else ()
        lines += SECTIONS[name].markdown(res.get(name), *extra)
    return "\n".join(lines) + "\n"


def rewrite_readme(text: str, readme: Path = README) -> None:
    """Replace the README's text between the bench markers with ``text``."""
    from spine_mj.atomic import atomic_output
    from spine_mj.errors import SpineInputError

    doc = readme.read_text()
    if BEGIN not in doc or END not in doc:
        raise SpineInputError(f"{readme} lacks the markers {BEGIN!r} ... {END!r}")
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    with atomic_output(readme) as tmp:
        tmp.write_text(f"{head}{BEGIN}\n{text}{END}{tail}")


def machine() -> dict:
    import mujoco

    return {
        "date": datetime.date.today().isoformat(),
        "cpu_count": os.cpu_count(),
        "load_start": load(),
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "platform": platform.platform(),
    }


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="CI-size runs (about a minute)")
    ap.add_argument("--gpu", action="store_true", help="also the GPU backend's kappa error and throughput")
    ap.add_argument(
        "--out",
        type=Path,
        default=None,
        help="JSON path, markdown beside it (default: benchmarks/out/results.json, untracked; "
        "with --update the committed benchmarks/results.json)",
    )
    ap.add_argument(
        "--update", action="store_true", help="write the committed benchmarks/results.json and results.md"
    )
    ap.add_argument(
        "--readme",
        action="store_true",
        help="rewrite the Performance page, docs/user_guide/performance.md (needs --update)",
    )
    ap.add_argument("--from-json", type=Path, default=None, help="no new run: report this results file")
    ap.add_argument("--only", nargs="*", default=None, help="sections to run (default: all)")
    args = ap.parse_args(argv)
    if args.readme and not (args.update or args.from_json is not None):
        ap.error("--readme cites the committed benchmarks/results.json: give --update (or --from-json)")
    if args.out is None:
        args.out = HERE / "results.json" if args.update else HERE / "out" / "results.json"
    from spine_mj.jsonio import write_json

    if args.from_json is not None:
        res = json.loads(args.from_json.read_text())
    else:
        res = {"quick": args.quick, "machine": machine()}
        skip = set() if importlib.util.find_spec("pybullet") is not None else {"engines"}  # [bullet]
        skip |= set() if args.gpu else {"gpu"}
        sections = {name: getattr(mod, f"bench_{name}") for name, mod in SECTIONS.items() if name not in skip}
        committed = HERE / "results.json"
        baseline = json.loads(committed.read_text()).get("memory") if committed.is_file() else None
        for name, fn in sections.items():
            if args.only is None or name in args.only:
                extra = (baseline,) if name == "memory" else ()
                res[name] = section(fn, args.quick, *extra)
        write_json(args.out, res)
    text = markdown(res)
    if args.from_json is None:
        md = args.out.with_suffix(".md")
        from spine_mj.atomic import atomic_output

        with atomic_output(md) as tmp:
            tmp.write_text(text)
        print(f"wrote {args.out} and {md}")
    if args.readme:
        rewrite_readme(text)
        print(f"rewrote the Performance section of {README}")
    print(text)
    missed = [line for line in text.splitlines() if MISSED in line]
    if missed:
        print(f"{len(missed)} target(s) missed:")
        for line in missed:
            print("  " + line.strip("| ").split(" | ")[0])


if __name__ == "__main__":
    main()

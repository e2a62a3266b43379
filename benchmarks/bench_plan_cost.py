"""What a validation plan costs, study by study (issue 32, item 7: ``make demo`` within 5 min).

``spine-mj validate --quick`` (``--quick`` here: the ``smoke`` plan) runs as a user runs it,
in a fresh process, into a temporary folder. Reported per study: its wall time (the
report's ``timings_s``), its CPU seconds (the report's ``cpu_s``: the command's process and
the workers it forked, whatever they did: sweeps, predicted limits, bootstraps, figures,
numba kernels compiled or loaded), the CPU seconds its sweeps' cases took (the stores'
per-run ``cpu_s``, summed: engine, references and comparisons, whichever worker ran them)
and its runs; and for the whole command its wall time and CPU seconds (from
``getrusage``: its imports and start-up included).

Target: the quick plan within :data:`QUICK_WALL_TARGET_S` on an idle 2-core machine with
AVX-512, which leaves ``make demo`` (the virtualenv from the pip cache, ~40 s, and the
plan) within 5 min on a 2-core CPU without AVX-512 (measured ~1.4 times slower).
Measured on a busy machine the wall time says little: the CPU seconds are the number to
compare.

    python benchmarks/bench_plan_cost.py [FOLDER]   # the cost of a validation folder already run
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_common import target_cell

SPINE = str(Path(sys.executable).with_name("spine-mj"))
QUICK_WALL_TARGET_S = 140.0


def study_of(store_name: str) -> str:
    """The study a sweep store belongs to: its first folder under ``sweeps/``, as
    ``timings_s`` names it (``limit-refined``, ``boundary-refined``: a study's refinements)."""
    head = store_name.split("/")[0].replace("-", "_")
    return head.removesuffix("_refined")


def plan_cost(out_dir: Path) -> dict:
    """Per study of the validation in ``out_dir``: ``wall_s`` (``timings_s``), ``cpu_s`` (its
    ``cpu_s``, None in a report without them), ``sweep_cpu_s`` and ``runs`` (MuJoCo runs: rows
    of the ``engine`` analysis) from its sweep stores."""
    from spine_mj import sweep

    out_dir = Path(out_dir)
    doc = json.loads((out_dir / "validation.json").read_text())
    timings, cpu = doc["timings_s"], doc.get("cpu_s", {})  # cpu_s: reports written since 2026-11-29
    studies = {
        k: {"wall_s": v, "cpu_s": cpu.get(k), "sweep_cpu_s": 0.0, "runs": 0}
        for k, v in timings.items()
        if k != "total"
    }
    if "report" in cpu:  # the figures and report.md, after the studies
        studies["report"] = {"wall_s": None, "cpu_s": cpu["report"], "sweep_cpu_s": 0.0, "runs": 0}
    for manifest in sorted((out_dir / "sweeps").rglob("manifest.json")):
        store = manifest.parent
        df = sweep.load_runs(store, columns=["analysis", "cpu_s"])
        row = studies.setdefault(
            study_of(str(store.relative_to(out_dir / "sweeps"))),
            {"wall_s": None, "cpu_s": None, "sweep_cpu_s": 0.0, "runs": 0},
        )
        row["sweep_cpu_s"] += float(df["cpu_s"].sum())
        row["runs"] += int((df["analysis"] == "engine").sum())
    for row in studies.values():
        row["sweep_cpu_s"] = round(row["sweep_cpu_s"], 1)
    return {"studies": studies, "wall_s": timings.get("total")}


def bench_plan_cost(quick: bool) -> dict:
    plan = "smoke" if quick else "quick"
    with tempfile.TemporaryDirectory() as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(
            [SPINE, "validate", "--plan", plan, "--out", tmp, "--quiet"], check=True, capture_output=True
        )
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        out = plan_cost(Path(tmp))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    swept = sum(r["sweep_cpu_s"] for r in out["studies"].values())
    out.update(
        plan=plan,
        command_wall_s=round(wall, 1),
        cpu_s=round(cpu, 1),
        outside_cases_cpu_s=round(cpu - swept, 1),
        target_wall_s=QUICK_WALL_TARGET_S if plan == "quick" else None,
    )
    return out


def markdown(res: dict | None) -> list[str]:
    """The benchmark table's rows for :func:`bench_plan_cost`'s results."""
    if not res:
        return []
    ld = f"{res['load_before']}-{res['load_after']}"
    target = res.get("target_wall_s")
    goal = target_cell(res["command_wall_s"], "<=", target, " s") if target else ""
    cases = res["cpu_s"] - res["outside_cases_cpu_s"]
    rows = [
        f"| `spine-mj validate`, {res['plan']} plan: wall, start-up included | "
        f"{res['command_wall_s']:.0f} s | {goal} | {ld} |",
        f"| {res['plan']} plan: CPU of the command and its workers (in the sweeps' cases {cases:.0f} s, "
        f"outside them {res['outside_cases_cpu_s']:.0f} s) | {res['cpu_s']:.0f} s | | {ld} |",
    ]
    for name, r in res["studies"].items():
        wall = f"{r['wall_s']:.0f} s wall" if r["wall_s"] is not None else "no wall time"
        cases = f"{r['sweep_cpu_s']:.0f} s in {r['runs']} MuJoCo runs' cases" if r["runs"] else "no sweep"
        cpu = f"{r['cpu_s']:.0f} s" if r.get("cpu_s") is not None else "not recorded"
        rows.append(f"| {res['plan']} plan, study `{name}` ({wall}; {cases}): CPU | {cpu} | | {ld} |")
    return rows


if __name__ == "__main__":
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else None
    print(json.dumps(plan_cost(folder) if folder else bench_plan_cost(quick=False), indent=1))

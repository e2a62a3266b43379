"""What a validation plan costs, study by study (issue 32, item 7: ``make demo`` within 5 min).

``spine-mj validate --quick`` (``--quick`` here: the ``smoke`` plan) runs as a user runs it,
in a fresh process, into a temporary folder. Reported per study: its wall time (the
report's ``timings_s``), its CPU seconds (the report's ``cpu_s``: the command's process and
the workers it forked, whatever they did: sweeps, predicted limits, bootstraps, figures,
numba kernels compiled or loaded), the CPU seconds its sweeps' cases took (the stores'
per-run ``cpu_s``, summed: engine, references and comparisons, whichever worker ran them)
and its runs; and for the whole command its wall time and CPU seconds (from
``getrusage``: its imports and start-up included), then again on its finished folder: a
resume, which reads every sweep store, the limit study's corners and the arrays' rows back.

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


#: The full plan's target (issue 41: within 30 min on an idle 2-core machine).
FULL_WALL_TARGET_S = 1800.0
#: The committed reports whose wall time is tracked against the targets (no new run: the
#: full plan takes tens of minutes; the lead regenerates them on an idle machine).
REPORTS = Path(__file__).resolve().parents[1] / "analysis" / "reports"


def committed_reports() -> dict:
    """Wall time (``timings_s.total``) and CPU seconds (``cpu_s.total``, None in a report
    written before it) of the committed quick and full reports."""
    out = {}
    for plan in ("quick", "full"):
        f = REPORTS / f"validation-{plan}" / "validation.json"
        if f.is_file():
            doc = json.loads(f.read_text())
            out[plan] = {
                "wall_s": doc["timings_s"].get("total"),
                "cpu_s": (doc.get("cpu_s") or {}).get("total"),
            }
    return out


_COMPILE = """
import json, resource, sys, time
from spine_mj.sweep.kernel_warmup import warm_kernels
t = time.perf_counter()
warm_kernels(int(sys.argv[1]))
ch = resource.getrusage(resource.RUSAGE_CHILDREN)
cpu = time.process_time() + ch.ru_utime + ch.ru_stime
print(json.dumps({"wall_s": time.perf_counter() - t, "cpu_s": cpu}))
"""


def kernel_compile() -> dict:
    """What a fresh clone pays to compile the numba kernels
    (:func:`spine_mj.sweep.kernel_warmup.warm_kernels`), each in a fresh process with an
    empty numba cache: on one process (``one``: its CPU seconds are the compile's) and
    spread over two (``two``: the wall time a 2-core demo waits)."""
    import os

    out = {}
    for name, workers in (("one", 1), ("two", 2)):
        with tempfile.TemporaryDirectory() as cache:
            env = {**os.environ, "NUMBA_CACHE_DIR": cache}
            res = subprocess.run(
                [sys.executable, "-c", _COMPILE, str(workers)],
                env=env,
                capture_output=True,
                text=True,
                check=True,
            )
        out[name] = {k: round(v, 1) for k, v in json.loads(res.stdout.strip().splitlines()[-1]).items()}
    return out


def _validate(plan: str, folder: str) -> tuple[float, float]:
    """Wall and CPU seconds (the command and its workers) of ``spine-mj validate`` of
    ``plan`` into ``folder``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(
        [SPINE, "validate", "--plan", plan, "--out", folder, "--quiet"], check=True, capture_output=True
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def bench_plan_cost(quick: bool) -> dict:
    plan = "smoke" if quick else "quick"
    with tempfile.TemporaryDirectory() as tmp:
        wall, cpu = _validate(plan, tmp)
        out = plan_cost(Path(tmp))
        # the same command again on the finished folder: what a resume pays beyond reading
        # its stores back (the reports, figures and whatever a study does not keep)
        resumed_wall, resumed_cpu = _validate(plan, tmp)
    swept = sum(r["sweep_cpu_s"] for r in out["studies"].values())
    out.update(
        plan=plan,
        command_wall_s=round(wall, 1),
        cpu_s=round(cpu, 1),
        outside_cases_cpu_s=round(cpu - swept, 1),
        resumed={"wall_s": round(resumed_wall, 1), "cpu_s": round(resumed_cpu, 1)},
        target_wall_s=QUICK_WALL_TARGET_S if plan == "quick" else None,
        compile=kernel_compile(),
        committed=committed_reports(),
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
    if "resumed" in res:
        r = res["resumed"]
        rows.append(
            f"| {res['plan']} plan run again on its finished folder (a resume: every store read back): "
            f"CPU (wall) | {r['cpu_s']:.0f} s ({r['wall_s']:.0f} s) | | {ld} |"
        )
    if "compile" in res:
        one, two = res["compile"]["one"], res["compile"]["two"]
        rows.append(
            f"| numba kernels compiled from an empty cache (`sweep.kernel_warmup`, what a fresh clone's "
            f"`make demo` pays once): CPU on one process (wall on two) | {one['cpu_s']:.0f} s "
            f"({two['wall_s']:.0f} s) | | {ld} |"
        )
    for plan, r in res.get("committed", {}).items():
        target = FULL_WALL_TARGET_S if plan == "full" else None
        goal = target_cell(r["wall_s"], "<=", target, " s") if target else ""
        cpu = f", {r['cpu_s']:.0f} CPU-s" if r.get("cpu_s") is not None else ""
        rows.append(
            f"| committed `analysis/reports/validation-{plan}` (its own machine and load): wall{cpu} | "
            f"{r['wall_s']:.0f} s | {goal} | |"
        )
    for name, r in res["studies"].items():
        wall = f"{r['wall_s']:.0f} s wall" if r["wall_s"] is not None else "no wall time"
        cases = f"{r['sweep_cpu_s']:.0f} s in {r['runs']} MuJoCo runs' cases" if r["runs"] else "no sweep"
        cpu = f"{r['cpu_s']:.0f} s" if r.get("cpu_s") is not None else "not recorded"
        rows.append(f"| {res['plan']} plan, study `{name}` ({wall}; {cases}): CPU | {cpu} | | {ld} |")
    return rows


if __name__ == "__main__":
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else None
    print(json.dumps(plan_cost(folder) if folder else bench_plan_cost(quick=False), indent=1))

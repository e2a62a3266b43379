"""What a large sweep costs before its first case (issue 44): listing its cases, checking
every combination of its grid (``spine_mj.sweep.preflight``) and writing its store's
manifest, for the issue's grid of 999,999 cases (I_e 999 values x K 1001, the engine on the
single peak; ``--quick``: 99,999 cases, I_e 99 values x K 1010), in a process of its own:
its CPU seconds, split by the steps the sweep announces, and its peak resident memory.

Target: at most 60 us of CPU a case (a minute for the 999,999), on an idle machine (the row
gives the load). The tests check that every combination is still checked
(``tests/sweep/test_sweep_preflight.py``), not the time.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys

from bench_common import target_cell

#: CPU a case may take to prepare [us].
TARGET_US_PER_CASE = 60.0

_CHILD = r"""
import json, resource, sys, tempfile, time
from pathlib import Path
from spine_mj.sweep import parse_config, session
config = parse_config(json.loads(sys.argv[1]))
steps, t0 = {}, time.process_time()
def say(text):
    for step in ("listing", "checking", "writing"):
        if step in text and step not in steps:
            steps[step] = time.process_time() - t0
cases = session._checked_cases(config, say)
with tempfile.TemporaryDirectory() as tmp, session._locked(Path(tmp)):
    say("writing the store's manifest")
    session._open_store(config, cases, Path(tmp), {"started": "bench"}, overwrite=False, retry_failed=False)
    end = time.process_time() - t0
print(json.dumps({"cases": len(cases), "list_s": steps["checking"] - steps["listing"],
                  "check_s": steps["writing"] - steps["checking"], "store_s": end - steps["writing"],
                  "total_s": end, "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024}))
"""


def _config(n_ie: int, n_k: int) -> dict:
    return {
        "sweep": {"name": "prepare", "analyses": ["engine"]},
        "surfaces": [{"preset": "paper-single-peak"}],
        "starts": {"x": [0.05], "y": [0.5]},
        "drive": {
            "ie": [round(1e-5 * (1 + i * 1e-3), 9) for i in range(n_ie)],
            "K": [round(30 + 0.01 * i, 4) for i in range(n_k)],
        },
    }


def bench_prepare(quick: bool) -> dict:
    config = _config(99, 1010) if quick else _config(999, 1001)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, json.dumps(config)], capture_output=True, text=True, check=True
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = {k: round(v, 2) if isinstance(v, float) else v for k, v in json.loads(out.stdout).items()}
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    res.update(
        process_cpu_s=round(cpu, 1),
        us_per_case=round(1e6 * res["total_s"] / res["cases"], 1),  # not the start-up's imports
    )
    return res


def markdown(res: dict | None) -> list[str]:
    """The README table's row for :func:`bench_prepare`'s results."""
    if not res:
        return []
    ld = f"{res['load_before']}-{res['load_after']}"
    return [
        f"| preparing a sweep of {res['cases']:,} cases before its first (listing {res['list_s']:.1f}, "
        f"checking {res['check_s']:.1f}, manifest {res['store_s']:.1f} CPU-s; peak "
        f"{res['peak_rss_mb']:,} MB; the process {res['process_cpu_s']:.1f} CPU-s) | "
        f"{res['total_s']:.1f} CPU-s, {res['us_per_case']:.0f} us a case | "
        f"{target_cell(res['us_per_case'], '<=', TARGET_US_PER_CASE, ' us')} | {ld} |"
    ]

"""What ``spine-mj hold`` costs a user on a sandpaper (issue 41, items 6-7): the P600 grit at
its defaults, as a user runs it, in a fresh process and a temporary folder.

Reported: the wall time and CPU seconds of the command and its worker processes
(``getrusage``), the MuJoCo starts it ran (asked, and added where too few were paired), and
whether the verdict converged. The references are most of a case's cost on this grit
(the facet streamline with its two-contact rules; the compliant reference is not run by
hold). ``--quick``: 8 starts and 4 added from 12 places, a verdict it cannot reach (the rule asks for
30 paired starts), its cost per start the number to compare.

    python benchmarks/bench_hold.py [--quick]
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_common import fmt

SPINE = str(Path(sys.executable).with_name("spine-mj"))


def bench_hold(quick: bool) -> dict:
    extra = ["--starts", "8", "--reference-starts", "12"] if quick else []
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "hold"
        t0 = time.perf_counter()
        cmd = [SPINE, "hold", "sandpaper-P600", "--mu", "0.5", "--out", str(out), "--quiet", *extra]
        subprocess.run(cmd, check=True, capture_output=True)
        wall = time.perf_counter() - t0
        summary = json.loads((out / "summary.json").read_text())
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {
        "wall_s": round(wall, 1),
        "cpu_s": round(cpu, 1),
        "starts": summary["mujoco_starts"],
        "converged": bool(summary["converged"]),
        "agreement": summary["agreement"]["value"],
        "n_well_conditioned": summary["agreement"]["n_well_conditioned"],
    }


def markdown(res: dict | None) -> list[str]:
    """The hold command's row of the Performance table."""
    if not res:
        return []
    ld = f"{res['load_before']}-{res['load_after']}"
    st = res["starts"]
    verdict = "converged" if res["converged"] else "not converged"
    return [
        f"| `spine-mj hold sandpaper-P600 --mu 0.5` ({st['asked']} starts asked, {st['run']} run; "
        f"the same command took 945 s for 64 starts with the compliant reference and numpy's "
        f"two-contact rules) | {res['wall_s']:.0f} s wall, {res['cpu_s']:.0f} CPU-s; agreement "
        f"{fmt(res['agreement'])} on {res['n_well_conditioned']} well-conditioned starts, {verdict} "
        f"| | {ld} |",
    ]


if __name__ == "__main__":
    print(json.dumps(bench_hold(quick="--quick" in sys.argv[1:]), indent=1))

"""The benchmark report's statistics (``benchmarks/bench_common.py``) and its driver
(``benchmarks/run_all.py``)."""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from bench_common import median_interval


def test_median_interval_is_the_binomial_order_statistics_and_covers_the_median():
    assert median_interval(list(range(1, 22))) == (6, 16)  # n = 21: P(Bin <= 5) = 0.013, <= 6: 0.039
    assert median_interval(list(range(1, 12))) == (2, 10)  # n = 11
    assert median_interval([3.0, 1.0, 2.0, 5.0, 4.0]) is None  # n = 5: even min-max covers only 94 %
    rng = np.random.default_rng(0)
    hits = 0
    for _ in range(2000):
        lo, hi = median_interval(list(rng.standard_cauchy(21)))  # heavy tails: distribution-free
        hits += lo <= 0.0 <= hi
    assert 0.95 <= hits / 2000 <= 0.99  # exact coverage 0.973


def test_a_missed_target_is_marked_and_a_met_one_is_not():
    from bench_common import MISSED, target_cell

    assert target_cell(0.833, ">=", 0.85) == f">= 0.85 {MISSED}"
    assert target_cell(0.863, ">=", 0.85) == ">= 0.85"
    assert target_cell(4.6e7, ">=", 2e7) == ">= 2e7"
    assert target_cell(61.0, "<=", 60, " s") == f"<= 60 s {MISSED}"


def test_bench_writes_an_untracked_folder_unless_asked_to_update(tmp_path):
    """`make bench` must leave the tree clean: its default output is git-ignored."""
    import subprocess

    root = Path(__file__).resolve().parents[1]
    probe = "benchmarks/out/results.json"
    ignored = subprocess.run(["git", "check-ignore", "-q", probe], cwd=root, check=False)
    if ignored.returncode == 128:  # not a git checkout (an sdist): nothing to check
        return
    assert ignored.returncode == 0
    out = subprocess.run(
        [sys.executable, str(root / "benchmarks" / "run_all.py"), "--readme"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert out.returncode == 2 and "give --update" in out.stderr


def test_a_peak_grown_by_more_than_a_fifth_is_marked():
    from bench_common import MISSED
    from bench_memory import GROWTH_LIMIT
    from bench_memory import markdown as memory_markdown

    jobs = {
        "kept": {"wall_s": 1.0, "peak_rss_mib": 119.0, "committed_peak_rss_mib": 100.0, "grew": False},
        "grown": {"wall_s": 1.0, "peak_rss_mib": 121.0, "committed_peak_rss_mib": 100.0, "grew": True},
    }
    rows = {
        line.split(" | ")[0].strip("| "): line
        for line in memory_markdown({"jobs": jobs, "growth_limit": GROWTH_LIMIT}, MISSED)
    }
    assert MISSED in rows["grown"] and MISSED not in rows["kept"]
    assert 121.0 > GROWTH_LIMIT * 100.0 > 119.0


def test_the_plan_cost_puts_each_sweep_store_under_its_study():
    from bench_plan_cost import study_of

    from spine_mj.validate.studies import STUDIES

    names = {s.name for s in STUDIES}
    for store, study in [
        ("limit/paper-fractal", "limit"),
        ("limit-refined/dt_halved/sandpaper-P600", "limit"),
        ("boundary-refined/dt_halved-spring-paper-single-peak", "boundary"),
        ("fractal-lock-refined/dt_halved", "fractal_lock"),
        ("fractal-lock/corner", "fractal_lock"),
        ("ground-truth/pt-s0.1-mu0.5", "ground_truth"),
        ("stick-slip", "stick_slip"),
        ("stiffness_map/paper-fractal-deep", "stiffness_map"),
    ]:
        assert study_of(store) == study and study in names


def test_the_bench_modules_import_one_another_without_a_cycle():
    # run_all drives the sections; a section module never imports run_all or a later driver
    here = Path(__file__).resolve().parents[1] / "benchmarks"
    names = {p.stem for p in here.glob("*.py")}
    graph = {}
    for path in here.glob("*.py"):
        deps = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                deps |= {a.name for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module:
                deps.add(node.module)
        graph[path.stem] = deps & names - {path.stem}
    done: set[str] = set()

    def reach(node, stack):
        assert node not in stack, " -> ".join([*stack, node])
        if node not in done:
            for nxt in graph[node]:
                reach(nxt, [*stack, node])
            done.add(node)

    for node in graph:
        reach(node, [])
    assert graph["run_all"] >= {"bench_streamline", "bench_rollout", "bench_common"}

"""spine-mj hold's library (spine_mj.validate.hold): the summary it writes, and a run killed
between two levels that resumes from its stores."""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner

from spine_mj.cli import main
from spine_mj.errors import SpineInputError
from spine_mj.surface_io import save_surface
from spine_mj.surfaces import single_gaussian
from spine_mj.validate.hold import MIN_PAIRED_STARTS, HoldSettings, hold_to


class _Killed(Exception):
    pass


@pytest.mark.slow
def test_a_killed_hold_resumes_from_its_stores_and_writes_every_key(tmp_path):
    """Killed as its first refinement starts, a hold leaves no summary; run again (from
    the CLI), it reruns none of its corner's MuJoCo cases, adds starts where too few are
    paired, and writes the summary's keys."""
    path = save_surface(single_gaussian(), tmp_path / "bump.npz")
    out = tmp_path / "hold"

    def kill(p):
        if p.step == "dt_halved":
            raise _Killed

    settings = HoldSettings(mu=0.8, starts=2, reference_starts=4)
    with pytest.raises(_Killed):
        hold_to(single_gaussian(), out, settings, workers=1, progress=kill)
    assert not (out / "summary.json").exists() and not (out / "report.md").exists()
    base = sorted((out / "sweeps" / "base").glob("*/*.parquet"))  # the cases' runs and trajectories
    assert len(base) >= 2
    stamps = {p: p.stat().st_mtime_ns for p in base}

    args = ["hold", str(path), "--mu", "0.8", "--out", str(out), "--starts", "2", "--reference-starts", "4"]
    res = CliRunner().invoke(main, [*args, "--workers", "1", "--quiet"])
    assert res.exit_code == 0, res.output
    assert {p: p.stat().st_mtime_ns for p in base} == stamps  # the corner's cases were not run again
    s = json.loads((out / "summary.json").read_text())
    assert set(s["corner"]) >= {"ie", "K"} and s["corner"]["ie"] > 0 and s["corner"]["K"] > 0
    assert set(s["self_lock_share"]) >= {"value", "low", "high", "n"} and s["self_lock_share"]["n"] == 4
    assert set(s["agreement"]) >= {"value", "low", "high", "n_well_conditioned"}
    share = s["self_lock_share"]
    assert share["low"] <= share["value"] <= share["high"]
    assert [r["level"] for r in s["refinements"]][:1] == ["dt / 2"]
    assert all(
        {"change", "well_conditioned_runs", "reference_stalled"} <= set(r)
        for r in s["refinements"]
        if r["run"]
    )
    # two starts cannot make a verdict: the rule asks for 30 paired ones; the hold adds
    # starts from its places (at most doubling a round) until none are left
    assert s["converged"] is False and f"fewer than the {MIN_PAIRED_STARTS}" in s["why_unconverged"]
    assert s["mujoco_starts"] == {"run": 4, "asked": 2, "added_rounds": 1}
    assert s["agreement"]["starts"] == 4 and "no more places" in s["why_unconverged"]
    assert s["verdict"] in res.output and s["verdict"].endswith(".")
    assert (out / "report.md").read_text().startswith("# Will a spine hold") and (
        out / "hold.png"
    ).stat().st_size


def test_starts_are_added_at_the_yield_so_far_until_30_paired_or_the_budget_says_no():
    from spine_mj.validate.hold import _more_starts

    assert _more_starts(30, 40, 400, 1e9, 1.0) == (0, "")
    # 27 of 40 paired: 40 * 1.25 * 30 / 27 = 55.6 -> 16 more
    assert _more_starts(27, 40, 400, 1e9, 1.0) == (16, "")
    assert _more_starts(0, 40, 400, 1e9, 1.0)[0] == 40  # at most doubling a round
    assert _more_starts(27, 40, 45, 1e9, 1.0)[0] == 5  # the places left
    add, why = _more_starts(27, 40, 400, 100.0, 10.0)
    assert add == 0 and why == "16 more starts would take 160 s, past the budget (100 s left)"
    # a budget the corner and base level already overran is said so, never as negative seconds
    add, why = _more_starts(27, 40, 400, -2784.4, 10.0)
    assert add == 0 and why.endswith("past the budget (spent 2784 s over)")
    assert _more_starts(27, 40, 40, 1e9, 1.0) == (
        0,
        "no more places to add starts from (--reference-starts 40)",
    )


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"starts": 0}, "--starts must be an integer >= 1, got 0"),
        (
            {"starts": 20, "reference_starts": 10},
            r"--reference-starts \(10\) must be at least --starts \(20\)",
        ),
        ({"budget_s": math.nan}, "--budget must be a finite number of seconds > 0, got nan"),
        ({"tip_radius": -1.0}, "--tip-radius must be a finite number >= 0 in the surface's length unit"),
        ({"tip_radius": 0.0}, "--tip-radius 0 is a point tip, and an engine's tip is a ball"),
    ],
)
def test_bad_settings_are_refused_by_the_options_name(kwargs, match):
    with pytest.raises(SpineInputError, match=match):
        HoldSettings(mu=0.5, **kwargs)


def test_the_budget_is_checked_after_the_corners_first_case_and_the_corner_reports_progress(
    tmp_path, monkeypatch
):
    """The corner's first case of starts runs; the rest of the starts asked for run only
    where, at its pace, they end within --budget (here spent: they do not, and the verdict
    says so). The corner reports its progress before the self-lock share."""
    from spine_mj.validate import hold

    monkeypatch.setattr(hold, "_CASE_STARTS", 1)  # a case of one start: the first case is one start
    steps = []
    settings = HoldSettings(mu=0.8, starts=2, reference_starts=4, budget_s=1e-6)
    s = hold_to(
        single_gaussian(), tmp_path / "hold", settings, workers=1, progress=lambda p: steps.append(p.step)
    )
    assert steps.index("corner") < steps.index("self-lock share")  # the corner reported once placed
    assert s["mujoco_starts"] == {"run": 1, "asked": 2, "added_rounds": 0}
    assert "the corner's other 1 starts would take" in s["why_unconverged"] and s["converged"] is False
    assert not (tmp_path / "hold" / "sweeps" / "base-2").exists()
    assert all(not r["run"] for r in s["refinements"])  # no level fits a spent budget either

    # resumed, the first case is read from its store: paced at the seconds it took, not ~0
    again = hold_to(single_gaussian(), tmp_path / "hold", settings, workers=1)
    first_s = s["timings_s"]["base_level"]
    assert again["timings_s"]["base_level"] == pytest.approx(first_s, rel=0.5)
    assert again["why_unconverged"] == s["why_unconverged"] or "would take" in again["why_unconverged"]

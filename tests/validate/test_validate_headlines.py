"""Verdicts that hold on any machine: inputs moved at the rounding level (what another CPU's
last bits do to a path) leave the headline numbers inside their intervals."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.validate.headlines import check_reproduction, headline_numbers
from spine_mj.validate.plans import PLANS, FamilySpec, relative_starts
from spine_mj.validate.quasistatic_limit import quasistatic_limit
from spine_mj.validate.study_runner import StudyRunner

#: A small plan of the quick plan's kind: the fractal corner (chaotic paths, creases) with
#: ensembles of 3 on both sides, one surface.
FAMILY = FamilySpec("fractal", ("paper-fractal",), (2,), relative_starts(4), variants=((("hurst", 0.9),),))
PLAN = dataclasses.replace(
    PLANS["quick"],
    families=(FAMILY,),
    hfield_resolution=101,
    limit=dataclasses.replace(PLANS["quick"].limit, variations=(), ensemble_members=3, corner=()),
)


def _nudged(fam: FamilySpec) -> FamilySpec:
    """``fam`` with every start moved by one unit in the last place (up, in x and y)."""
    t = fam.starts_table()
    up = {k: tuple(float(np.nextafter(v, np.inf)) for v in t[k]) for k in ("x", "y")}
    return dataclasses.replace(fam, starts=(("frame", t["frame"]), ("x", up["x"]), ("y", up["y"])))


def test_rounding_level_changes_of_the_inputs_keep_the_verdicts_inside_their_intervals(tmp_path):
    runs = {}
    for tag, fam in (("as_is", FAMILY), ("nudged", _nudged(FAMILY))):
        plan = dataclasses.replace(PLAN, families=(fam,))
        runs[tag] = quasistatic_limit(plan, StudyRunner(tmp_path / tag, 1, None, time.perf_counter()))
    a = runs["as_is"].families["fractal"]
    b = runs["nudged"].families["fractal"]
    assert a["starts"] == b["starts"] == 4 and a["members"] == 3
    for fam, other in ((a, b), (b, a)):
        lo, hi = fam["agreement_ci"]
        if other["well_conditioned_runs"]:
            assert lo <= other["agreement_well_conditioned"] <= hi
        lo, hi = fam["median_frechet_ci"]
        assert lo <= other["median_frechet"] <= hi
        assert fam["meets_target"] == other["meets_target"]


def _validation(agree, ci, median, median_ci, meets, ie=None, ie_ci=(0.01, 0.01)):
    fam = {
        "agreement_well_conditioned": agree,
        "agreement_ci": list(ci),
        "outcome_agreement": agree,
        "outcome_agreement_ci": list(ci),
        "median_frechet": median,
        "median_frechet_ci": list(median_ci),
        "meets_target": meets,
    }
    return {
        "limit_families": {"fractal": fam},
        "ie_star": {"spring": {"value": ie, "ci_low": ie_ci[0], "ci_high": ie_ci[1]}},
    }


def test_headline_numbers_carry_their_intervals_and_verdicts():
    h = headline_numbers(_validation(0.9, (0.8, 0.95), 0.01, (0.009, 0.012), False, 0.12, (0.1, 0.13)))
    assert h["limit.fractal.agreement_well_conditioned"].interval == (0.8, 0.95)
    assert h["limit.fractal.median_frechet"].value == 0.01
    assert h["limit.fractal.median_frechet"].verdict is False
    assert h["ie_star.spring"].interval == (0.1, 0.13)


def test_a_number_outside_its_interval_or_a_changed_verdict_fails_the_check():
    committed = _validation(0.9, (0.8, 0.95), 0.01, (0.009, 0.012), False)
    same = check_reproduction(_validation(0.85, (0.7, 0.9), 0.011, (0.01, 0.02), False), committed)
    assert all(r.ok for r in same)
    moved = {
        r.key: r for r in check_reproduction(_validation(0.7, (0.6, 0.8), 0.011, (0, 1), False), committed)
    }
    assert not moved["limit.fractal.agreement_well_conditioned"].inside
    assert moved["limit.fractal.median_frechet"].inside
    flipped = check_reproduction(_validation(0.9, (0.8, 0.95), 0.01, (0.009, 0.012), True), committed)
    assert not any(r.verdict_kept for r in flipped if r.key.startswith("limit."))
    # I_e* below the grid on both runs agrees; a value against none does not
    assert {r.key: r for r in same}["ie_star.spring"].inside
    bracketed = _validation(0.9, (0.8, 0.95), 0.01, (0.009, 0.012), False, 0.5, (0.4, 0.6))
    assert not {r.key: r for r in check_reproduction(bracketed, committed)}["ie_star.spring"].inside


def test_headline_numbers_refuse_what_is_not_a_validation():
    with pytest.raises(SpineInputError, match="limit_families"):
        headline_numbers({"plan": "quick"})

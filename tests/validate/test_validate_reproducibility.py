"""Verdicts that hold on any machine: inputs moved at the rounding level (what another CPU's
last bits do to a path) leave the headline numbers inside their intervals."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from spine_mj.validate.plans import PLANS, FamilySpec, relative_starts
from spine_mj.validate.quasistatic_limit import quasistatic_limit
from spine_mj.validate.study_runner import StudyRunner

#: A small plan of the quick plan's kind: the fractal corner (chaotic paths, creases) with
#: ensembles of 3 on both sides, one surface.
FAMILY = FamilySpec("fractal", ("paper-fractal",), (2,), relative_starts(4), variants=((("hurst", 0.9),),))
PLAN = dataclasses.replace(
    PLANS["quick"],
    families=(FAMILY,),
    limit_variations=(),
    hfield_resolution=101,
    ensemble_members=3,
    corner=(),
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

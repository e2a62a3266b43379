"""The quasistatic-limit headlines in both engines (spine_mj.validate.engine_headlines): the
soft-contact misses' starts, the engines' pairing, and a small corner run in MuJoCo and Bullet."""

import dataclasses
import time

import numpy as np
import pandas as pd
import pytest

from spine_mj import presets
from spine_mj.validate import engine_headlines as study
from spine_mj.validate.ensembles import ensemble_family
from spine_mj.validate.plans import PLANS, FamilySpec, paper_starts
from spine_mj.validate.report.engine_headlines import section


def _surface_units(fam, miss, point):
    if fam.starts_table()["frame"] != "relative":
        return point
    kw = {} if miss.seed is None else {"seed": miss.seed}
    xmin, xmax, ymin, ymax = presets.make_surface(miss.preset, **kw, **dict(miss.variant)).bounds
    return xmin + point[0] * (xmax - xmin), ymin + point[1] * (ymax - ymin)


@pytest.mark.parametrize("miss", study.SOFT_CONTACT_MISSES, ids=lambda m: m.label)
def test_each_soft_contact_miss_is_the_full_reports_start_with_its_ensemble(miss):
    full = study.REPORTED_FULL  # the sample the committed full report ran
    fam = study.miss_family(full, miss)
    pts = fam.starts_table()["points"]
    assert len(pts) == full.limit.ensemble_members and fam.presets == (miss.preset,)
    # the start the report's run table shows, to its rounding
    x, y = _surface_units(fam, miss, pts[0])
    assert (round(x, 2), round(y, 2)) == pytest.approx(miss.shown)
    # and the very ensemble the plan ran: the whole family's stencil
    (whole,) = [f for f in full.families if f.name == miss.family]
    members = full.limit.ensemble_members
    ens = ensemble_family(full.limit.corner_family(whole), miss.preset, members).starts_table()["points"]
    assert [tuple(p) for p in pts] == [
        tuple(p) for p in ens[miss.start * members : (miss.start + 1) * members]
    ]


def _starts(agree, well, held, end_x, lc=1.0):
    n = len(agree)
    idx = pd.MultiIndex.from_arrays([["s"] * n, [1.0] * n, [0.0] * n, np.arange(n, dtype=float)])
    return pd.DataFrame(
        {"agree": agree, "well": well, "held": held, "end_x": end_x, "end_y": 0.0, "lc": lc}, index=idx
    )


def test_pairs_count_which_engine_the_streamline_supports():
    a = _starts([True, True, False, False, True], [True] * 4 + [False], [1, 0, 1, 0, 1], [0, 5, 0, 9, 0])
    b = _starts([True, False, True, False, False], [True] * 5, [1, 1, 0, 0, 1], [0.1, 5, 3, 2, 0])
    p = study._pairs(a, b)
    # the fifth start is ill-conditioned in the first engine: left out
    assert p == {
        "starts": 4,
        "both_agree": 1,
        "only_first": 1,
        "only_second": 1,
        "neither": 1,
        # held alike at 0.1 L_c apart; free both (where they end does not matter)
        "engines_alike": 2,
    }


def test_pairs_judge_each_surface_at_its_own_length_scale():
    # both held 0.5 apart: the same trap on a surface of L_c = 10, not on one of L_c = 1
    lc = [10.0, 1.0]
    a = _starts([True, True], [True, True], [1, 1], [0.0, 0.0], lc)
    b = _starts([True, True], [True, True], [1, 1], [0.5, 0.5], lc)
    assert study._pairs(a, b)["engines_alike"] == 1


def test_each_corner_sweep_runs_in_both_engines():
    pytest.importorskip("pybullet", reason="a bullet case is refused without the [bullet] extra (pybullet)")
    from spine_mj.sweep import expand_cases, parse_config

    plan = dataclasses.replace(PLANS["quick"], families=PLANS["quick"].families[:1])
    docs, corners = study._corner_docs(plan, 2, ("mujoco", "bullet"))
    assert set(corners["single_peak_valley"]) == {"paper-single-peak", "paper-single-valley"}
    assert {f.name for f, _, _ in docs} == {"single_peak_valley"}
    # each surface at its own corner, as the quasistatic-limit study runs it
    drives = {(d["drive"]["ie"], d["drive"]["K"]) for _, _, d in docs}
    assert drives == {(c["ie"], c["K"]) for c in corners["single_peak_valley"].values()}
    for fam, name, doc in docs:
        assert name.startswith("engines-limit/")
        assert len(fam.starts_table()["y"]) == 2
        cases = expand_cases(parse_config(doc))
        engines = [c.params["engine"] for c in cases]
        assert engines.count("mujoco") == engines.count("bullet") == len(cases) // 2


def test_the_corner_and_a_miss_run_in_both_engines(tmp_path):
    pytest.importorskip("pybullet", reason="the Bullet engine needs the [bullet] extra (pybullet)")
    from spine_mj.jsonio import write_json
    from spine_mj.validate.study_runner import StudyRunner

    fam = FamilySpec("single_peak_valley", ("paper-single-peak",), None, paper_starts([-2.0]))
    plan = dataclasses.replace(
        PLANS["smoke"], families=(fam,), limit=dataclasses.replace(PLANS["smoke"].limit, ensemble_members=2)
    )
    miss = study.MissStart("single_peak_valley", "paper-single-peak", None, (), 0, (-3.0, -2.0))
    res = study.engine_headlines(
        plan, StudyRunner(tmp_path, 1, None, time.perf_counter()), rechecks=(miss,), recheck_plan=plan
    )
    f = res.families["single_peak_valley"]
    for e in ("mujoco", "bullet"):
        assert f[e]["starts"] == 1 and f[e]["members"] == 2
        lo, hi = f[e]["agreement_ci"]
        assert lo <= f[e]["agreement_well_conditioned"] <= hi
        assert res.cpu_s["single_peak_valley"][e]["runs"] == 2
        assert res.cpu_s["single_peak_valley"][e]["engine"] > 0
    p = f["pairs"]
    assert p["starts"] == p["both_agree"] + p["only_first"] + p["only_second"] + p["neither"] <= 1
    d = f["difference"]
    assert d["ci_low"] <= d["diff"] <= d["ci_high"]
    assert [(r["engine"], r["start"]) for r in res.rechecks] == [
        ("mujoco", miss.label),
        ("bullet", miss.label),
    ]
    write_json(tmp_path / study.RESULT_FILE, res.as_dict())
    text = section(study.load(tmp_path))
    assert text == section(res)  # the report from the file is the one from the run
    assert "## Engines side by side: the headlines" in text
    assert text.count("| single_peak_valley | streamline") == 2

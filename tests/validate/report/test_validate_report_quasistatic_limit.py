"""The quasistatic-limit section of the report (report/quasistatic_limit.py)."""

from spine_mj.validate import BoundaryResult, QuasistaticLimitResult


def test_falls_note_splits_the_runs_at_the_lower_end_of_the_ie_star_bracket(validation_results):
    from spine_mj.validate.report.quasistatic_limit import falls_note as _falls_note

    res = validation_results
    runs = [
        {"family": "single_peak_valley", "agree": True, "frechet": 0.01, "tip_peak_ie": 5e-5},
        {"family": "single_peak_valley", "agree": True, "frechet": 0.03, "tip_peak_ie": 1e-4},
        {"family": "single_peak_valley", "agree": False, "frechet": 0.5, "tip_peak_ie": 0.3},
    ]
    fam = dict(
        res["limit"].families["single_peak_valley"],
        slide_runs=1,
        landing_runs=1,
        landing_explained=1,
        landing_lost=0,
        outcome_agreement_streamline=1 / 3,
    )
    limit = QuasistaticLimitResult({"single_peak_valley": fam}, runs, {}, {}, 1e-4)
    text = "\n".join(_falls_note(limit, res["boundary"]))
    row = next(line for line in text.splitlines() if line.startswith("| single_peak_valley"))
    # the bracket's lower end is 1e-4: the run at exactly 1e-4 is on the slow side
    assert [c.strip() for c in row.strip("|").split("|")] == [
        "single_peak_valley",
        "1/3",
        "0.0001 (5e-05-0.3)",
        "2/2, 0.02",
        "0/1, 0.5",
        "1: +1 / -0 (streamline 0.333)",
    ]
    no_star = BoundaryResult(curves={}, ie_star={}, skip_rate={}, families=[])
    assert _falls_note(limit, no_star) == []

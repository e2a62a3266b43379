"""The report of the engines' headlines (spine_mj.validate.report.engine_headlines): its
table rows from a hand-made result."""

from spine_mj.validate import engine_headlines as study
from spine_mj.validate.report.engine_headlines import section


def test_no_result_no_section():
    assert section(None) == ""


def _summary(agreeing, well, starts):
    from spine_mj.validate.intervals import wilson

    return {
        "starts": starts,
        "members": 3,
        "well_conditioned_runs": well,
        "agreement_well_conditioned": agreeing / well,
        "agreement_ci": list(wilson(agreeing, well)),
        "ill_conditioned_share": {"mujoco": 0.0, "reference": (starts - well) / starts},
        "stopped_starts": 0,
        "median_frechet": 0.01,
        "median_frechet_ci": [0.009, 0.012],
        "failed_runs": {},
        "misses": {"engine_held": {"runs": well - agreeing, "offsets": []}},
        "meets_target": False,
    }


def test_the_section_has_a_row_per_family_and_engine():
    res = study.EngineHeadlinesResult(
        plan="quick",
        lowest_ie=1e-4,
        starts_per_surface=2,
        engines=("mujoco", "bullet"),
        families={"fractal": {"mujoco": _summary(9, 10, 12), "bullet": _summary(10, 10, 12)}},
        rechecks=[],
        recheck_plan="full",
        cpu_s={"fractal": {e: {"engine": 2.0, "reference": 3.0, "runs": 36} for e in ("mujoco", "bullet")}},
        wall_s=10.0,
    )
    text = section(res)
    assert "| fractal | streamline, >= 0.95 | mujoco | 0.900 [0.596, 0.982] | 9 / 10 (12) |" in text
    assert "| fractal | streamline, >= 0.95 | bullet | 1.000 [0.722, 1.000] | 10 / 10 (12) |" in text

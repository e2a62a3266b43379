"""Study results of every kind the validation report renders, small enough to check by eye."""

import numpy as np
import pytest

from spine_mj.validate import (
    BoundaryCurve,
    BoundaryResult,
    LimitPath,
    QuasistaticLimitResult,
    SandpaperResult,
    StaticMapResult,
    StickSlipResult,
)


@pytest.fixture
def validation_results():
    t = np.linspace(0, 1, 20)
    path = np.column_stack([np.linspace(-3, 5, 20), np.linspace(-2, -3, 20)])
    curve = BoundaryCurve(
        ie=[1e-4, 1.0],
        agreement=[0.9, 0.5],
        frechet=[0.05, 1.2],
        median_frechet=[0.04, 0.9],
        lateral=[0.01, 0.2],
        engine_trouble=[0.0, 0.5],
        runs_per_ie=10,
        frechet_kind="Frechet",
    )
    star = {"kind": "bracketed", "value": 0.01, "low": 1e-4, "high": 1.0, "ci_low": 1e-4, "ci_high": 1.0}
    star |= {"criterion": "outcome agreement >= 95 %", "ie_used": [1e-4, 1.0]}
    star["by_criterion"] = {"outcome": dict(star)}
    fam = {"runs": 10, "ok_runs": 9, "outcome_agreement": 0.9, "mean_frechet": 0.05, "median_frechet": 0.04}
    fam |= {"failed_runs": {"penetration": 1}, "reference_stalled": 2}
    return {
        "static": StaticMapResult(rows=[], per_engine={}, mu=1.0, static_kappa_max_rel_error=0.01),
        "limit": QuasistaticLimitResult(
            families={"single_peak_valley": fam | {"meets_target": False}},
            runs=[],
            variations={},
            paths={"paper-single-peak": [LimitPath(path, path, path, (-3.0, -2.0))]},
            lowest_ie=1e-4,
        ),
        "boundary": BoundaryResult(
            curves={"spring": curve},
            ie_star={"spring": star},
            skip_rate={"spring": [0.0, 0.5]},
            families=["x"],
        ),
        "stick": StickSlipResult(
            rows=[{"ie": 0.01, "stiffness_fp_per_lc": 2.0, "runs": 2}],
            traces={(0.01, 19.37): (t, np.sin(t))},
            surface="paper-random-concave#1",
        ),
        # every sandpaper run failed: no paths, so no figure and no link to one
        "sand": SandpaperResult(
            rows=[{"grit": "P36", "runs": 2, "failed_runs": 2, "failures": ["diverged"]}],
            paths={"P36": []},
            mu=0.5,
        ),
    }

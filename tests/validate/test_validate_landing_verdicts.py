"""Runs whose reference falls are judged against the fall-landing reference, the
streamline's verdict kept beside it."""

from __future__ import annotations

import numpy as np
import pandas as pd

from spine_mj.validate.landing_verdicts import landing_judged, landing_summary


def _judged_rows():
    return pd.DataFrame(
        {
            "agree": [True, False, False, True, True],
            "frechet": [0.01, 0.5, 0.6, 0.02, 0.03],
            "reference_slide_fraction": [0.0, 0.3, 0.2, 0.1, 0.0],
            "agree_landing": [np.nan, 1.0, 0.0, 0.0, np.nan],
            "frechet_landing": [np.nan, 0.02, 0.4, 0.3, np.nan],
            "landing_falls": [np.nan, 1.0, 3.0, 2.0, np.nan],
        }
    )


def test_a_run_whose_reference_falls_is_judged_against_the_landing_reference():
    out = landing_judged(_judged_rows())
    assert list(out["agree"]) == [True, True, False, False, True]
    np.testing.assert_array_equal(out["frechet"], [0.01, 0.02, 0.4, 0.3, 0.03])
    assert list(out["agree_streamline"]) == [True, False, False, True, True]  # the plain verdict kept
    np.testing.assert_array_equal(out["frechet_streamline"], [0.01, 0.5, 0.6, 0.02, 0.03])
    assert landing_summary(out) == {
        "landing_runs": 3,
        "outcome_agreement_streamline": 0.6,
        "median_frechet_streamline": 0.03,
        "landing_explained": 1,
        "landing_lost": 1,
    }


def test_rows_written_before_the_landing_reference_keep_the_streamline_verdict():
    old = _judged_rows().drop(columns=["agree_landing", "frechet_landing", "landing_falls"])
    out = landing_judged(old)
    assert list(out["agree"]) == list(old["agree"]) and list(out["frechet"]) == list(old["frechet"])
    assert out["agree_landing"].isna().all() and landing_summary(out)["landing_runs"] == 0

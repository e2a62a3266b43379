"""The quasistatic-limit study's misses: each disagreeing run gets its physical cause."""

from __future__ import annotations

import numpy as np
import pandas as pd

from spine_mj.validate.miss_causes import FALL_IE_FACTOR, MISS_CAUSES, miss_cause
from spine_mj.validate.quasistatic_limit import _misses

_CAP = "force cap: drive force reached kappa_cap * F_p = 1.962 N without slip (held with ...)"
_RULE = "lock rule: stuck on a contact normal in the self-lock region while ..."


def _rows():
    ie = 1e-4
    base = {"end_detail": "", "reference_slide_fraction": 0.0, "tip_peak_ie": 2 * ie, "inertia_number": ie}
    rows = [
        {"miss_reason": "separatrix", "miss_offset": 0.001},
        {"miss_reason": "engine_held", "end_detail": _CAP, "miss_offset": np.nan},
        {"miss_reason": "engine_held", "end_detail": _RULE, "miss_offset": np.nan},
        {"miss_reason": "engine_passed", "miss_offset": np.nan},
        {"miss_reason": "diverged", "reference_slide_fraction": 0.05, "miss_offset": 0.2},
        {"miss_reason": "diverged", "tip_peak_ie": 2 * FALL_IE_FACTOR * ie, "miss_offset": 0.3},
        {"miss_reason": "diverged", "miss_offset": 0.1},
        {"miss_reason": "reference_stalled", "miss_offset": np.nan},
        {
            "miss_reason": "diverged",
            "reference_slide_fraction": 0.3,
            "miss_offset": 0.4,
            "agree_landing": 1.0,
        },
        {"miss_reason": ""},  # agrees
    ]
    return pd.DataFrame([{**base, "case_id": "c", "start": i, **r} for i, r in enumerate(rows)])


def test_every_miss_gets_its_cause():
    comp = _rows()
    causes = [miss_cause(r) for _, r in comp.iloc[:-1].iterrows()]
    assert causes == [
        "ill_conditioned",
        "wedge",
        "soft_contact",
        "soft_contact",
        "fall",
        "fall",
        "inertia",
        "reference_stalled",
        "fall_landed",
    ]
    assert set(causes) == set(MISS_CAUSES)


def test_misses_record_each_miss_with_its_cause_by_reason():
    out = _misses(_rows())
    assert out["engine_held"]["causes"] == {"wedge": 1, "soft_contact": 1}
    assert out["diverged"]["runs"] == 4 and out["diverged"]["offsets"] == [0.1, 0.2, 0.3, 0.4]
    assert out["diverged"]["causes"] == {"fall_landed": 1, "fall": 2, "inertia": 1}
    assert [m["start"] for m in out["diverged"]["misses"]] == [4, 5, 6, 8]
    assert sum(r["runs"] for r in out.values()) == 9  # the agreeing run is no miss

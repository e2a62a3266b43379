"""Runs whose reference falls, judged like for like: against the fall-landing reference
(:mod:`spine_mj.theory.fall_landing`, traced by the sweep's ``compare`` analysis), the plain
streamline's verdict kept beside it so that the change stays visible."""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["LANDING_COLUMNS", "landing_judged", "landing_summary"]

#: The columns of the fall-landing reference in ``compare`` rows (NaN where it was not traced).
LANDING_COLUMNS = ("agree_landing", "frechet_landing", "landing_falls")


def landing_judged(rows: pd.DataFrame) -> pd.DataFrame:
    """``compare`` rows judged like for like: a run whose reference falls
    (``reference_slide_fraction`` > 0, where ``compare`` traced the fall-landing reference,
    :mod:`spine_mj.theory.fall_landing`) gets that reference's ``agree`` and ``frechet``; the
    plain streamline's stay in ``agree_streamline`` and ``frechet_streamline``. Rows of a
    store written before ``compare`` had it keep the streamline's verdict (NaN landing
    columns)."""
    out = rows.copy()
    for c in LANDING_COLUMNS:
        if c not in out:
            out[c] = np.nan
    out["agree_streamline"] = out["agree"]
    out["frechet_streamline"] = out["frechet"]
    landed = out["agree_landing"].notna()
    out["agree"] = np.where(landed, out["agree_landing"] == 1, out["agree"].astype(bool))
    out["frechet"] = np.where(landed, out["frechet_landing"], out["frechet"])
    return out


def landing_summary(comp) -> dict:
    """What judging the falling runs against the fall-landing reference changed: the runs so
    judged, the streamline's verdicts (``outcome_agreement_streamline``,
    ``median_frechet_streamline``), its misses the landing explains and its agreements the
    landing loses."""
    landed = comp["agree_landing"].notna()
    plain = comp["agree_streamline"].fillna(False).astype(bool)
    agree = comp["agree_landing"] == 1
    return {
        "landing_runs": int(landed.sum()),
        "outcome_agreement_streamline": float(plain.mean()) if len(comp) else float("nan"),
        "median_frechet_streamline": float(np.nanmedian(comp["frechet_streamline"]))
        if comp["frechet_streamline"].notna().any()
        else float("nan"),
        "landing_explained": int((landed & ~plain & agree).sum()),
        "landing_lost": int((landed & plain & ~agree).sum()),
    }

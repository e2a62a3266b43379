"""The summary of ``spine-mj hold`` (:mod:`spine_mj.validate.hold`): ``summary.json``'s
keys from the corner, the self-lock share, the headlines and the refinement levels, and its
one-sentence verdict."""

from __future__ import annotations

__all__ = ["hold_summary", "interval_bounds", "verdict_sentence"]


def interval_bounds(interval) -> dict:
    """``{"low", "high"}`` of an interval."""
    low, high = interval
    return {"low": float(low), "high": float(high)}


def hold_summary(label, settings, corner, limits, tip, share, summ, verdicts, levels, converged, why) -> dict:
    """``summary.json``'s contents: the surface ``label`` and its settings, the corner and its
    limits, the self-lock ``share``, the agreement over the well-conditioned starts, the
    median Frechet distance, each refinement level run or skipped, whether converged and
    ``why`` not, and the verdict (:func:`verdict_sentence`)."""
    agreement = {
        "value": summ["agreement_well_conditioned"],
        **interval_bounds(summ["agreement_ci"]),
        "n_well_conditioned": int(verdicts["well_conditioned_runs"]),
        "starts": int(verdicts["starts"]),
        "ill_conditioned_starts": int(verdicts["ill_conditioned_starts"]),
        "all_starts": summ["outcome_agreement"],
        "all_starts_interval": list(summ["outcome_agreement_ci"]),
    }
    refinements = [
        {
            "level": lv["label"],
            "key": lv["key"],
            "run": lv["run"],
            **(
                {
                    "from": lv["from"],
                    "runs": lv["runs"],
                    "well_conditioned_runs": lv["well_conditioned_runs"],
                    "reference_stalled": lv["reference_stalled"],
                    "change": lv["agreement_well_conditioned"]["change"],
                    "median_frechet_change": lv["median_frechet"]["change"],
                    "failed_runs": lv["failed_runs"],
                    "converged": lv["converged"],
                }
                if lv["run"]
                else {"note": lv["note"]}
            ),
        }
        for lv in levels
    ]
    out = {
        "surface": label,
        "mu": settings.mu,
        "tip_radius": tip,
        "corner": corner.as_dict(),
        "drive_limits": limits.as_dict(),
        "self_lock_share": share,
        "agreement": agreement,
        "median_frechet": {"value": summ["median_frechet"], **interval_bounds(summ["median_frechet_ci"])},
        "failed_runs": summ["failed_runs"],
        "converged": bool(converged),
        "why_unconverged": why,
        "refinements": refinements,
    }
    out["verdict"] = verdict_sentence(out)
    return out


def verdict_sentence(s: dict) -> str:
    """The summary's one-sentence verdict."""
    sh, ag, c = s["self_lock_share"], s["agreement"], s["corner"]
    hold = (
        f"a spine pulled along x holds from {sh['value']:.1%} of {sh['n']} places "
        f"[{sh['low']:.1%}, {sh['high']:.1%}] on {s['surface']} at mu_s {s['mu']:g}"
    )
    check = (
        f"MuJoCo at I_e {c['ie']:.3g}, K {c['K']:.3g} agrees on {ag['value']:.3f} "
        f"[{ag['low']:.2f}, {ag['high']:.2f}] of {ag['n_well_conditioned']} well-conditioned starts"
    )
    run = [r["level"] for r in s["refinements"] if r.get("run")]
    if s["converged"]:
        return f"{hold.capitalize()}; {check}, converged under {', '.join(run)}."
    return f"{hold.capitalize()}; {check}, not converged: {s['why_unconverged']}."

"""The validation's headline in a few lines of text (what ``spine-mj validate`` prints): the
static kappa error, each family's agreement at the lowest inertia number, the fractal
self-lock rates, the arrays' pooled differences, I_e* per protocol and the engines side by
side, read from the result
:func:`~spine_mj.validate.run_validation` returns (the content of ``validation.json``)."""

from __future__ import annotations

from spine_mj.validate.convergence import refinement_note, unconverged_mark
from spine_mj.validate.report.common import corner_text

__all__ = ["summary_lines"]


def summary_lines(result: dict) -> list[str]:
    """The headline lines of a validation ``result`` (a loaded ``validation.json``); the
    studies a plan did not run (fractal lock rate, arrays) give no line."""
    lines = [
        f"static kappa max rel. error (engaged, default settings): {result['static_kappa_max_rel_error']:.3g}"
    ]
    for fam, summ in result["limit_families"].items():
        stops = ", ".join(f"{k} {n}" for k, n in summ["failed_runs"].items()) or "none"
        conv = result.get("convergence", {}).get(fam)
        at = (result.get("corner") or {}).get(fam) or {"ie": result["lowest_ie"], "K": 30.0}
        lines.append(
            f"I_e, K = {corner_text(at)}, {fam}: outcome agreement {summ['outcome_agreement']:.0%}"
            f"{unconverged_mark(conv, 'outcome_agreement')} of {summ['runs']}, median Frechet "
            f"{summ['median_frechet']:.3g} L_c{unconverged_mark(conv, 'median_frechet')}, "
            f"engine stops: {stops}"
        )
    for row in result.get("fractal_lock_rate", {}).get("rows", []):
        rates = ", ".join(
            f"{k} {row[f'rate_{k}']:.2f} ({row[f'locked_{k}']}/{row[f'n_ok_{k}']})"
            + unconverged_mark(row.get(f"convergence_{k}"))
            for k in ("streamline", "mujoco_corner", "mujoco_dynamic")
            if f"rate_{k}" in row
        )
        lines.append(f"fractal self-lock rate, H = {row['hurst']:g}: {rates}")
    for kind, pool in result.get("arrays", {}).get("pooled", {}).items():
        if pool.get("diff"):
            d = pool["diff"]
            lines.append(
                f"arrays: P(at least one spine locks), {kind} - aligned = {d['diff']:+.3f} "
                f"[{d['ci_low']:+.3f}, {d['ci_high']:+.3f}] ({pool['locked']}/{pool['n_ok']} against "
                f"{pool['locked_grid']}/{pool['n_ok_grid']})"
            )
    for proto, s in result["ie_star"].items():
        lines.extend(_ie_star_lines(proto, s))
    if result.get("engines"):
        lines.append(_engines_line(result["engines"]))
    return lines


def _engines_line(eng: dict) -> str:
    """The engines study in one line: per engine, the closed forms judged within tolerance."""
    if eng.get("missing"):
        return "engines side by side: not run, Bullet is not installed (pip install 'spine-mj[bullet]')"
    counts = []
    for e in eng["engines"]:
        judged = [r[f"{e}_ok"] for r in eng["rows"] if r.get(f"{e}_ok") is not None]
        counts.append(f"{e} {sum(judged)} of {len(judged)}")
    return "engines side by side, closed forms within their tolerance: " + ", ".join(counts)


def _ie_star_lines(proto: str, s: dict) -> list[str]:
    """I_e* of one protocol, by its main criterion and by departure when it has one."""
    if s.get("valid") is False:
        return [f"I_e* ({proto}) {s['note']}"]
    lines = []
    for star in (s, s["by_criterion"].get("departure")):
        if star is None:
            continue
        lines.append(f"I_e* ({proto}) criterion: {star['criterion']}")
        note = refinement_note(s.get("convergence")) if star is s else ""
        if star["kind"] == "bracketed":
            lines.append(f"  I_e* = {star['value']:.3g} in [{star['low']:.3g}, {star['high']:.3g}]{note}")
        elif star["kind"] == "above":
            lines.append(f"  I_e* > {star['low']:.3g} (agreement holds on the whole grid){note}")
        else:
            lines.append(f"  I_e* < {star['high']:.3g} (no agreement at the lowest I_e){note}")
    return lines

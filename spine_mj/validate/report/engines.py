"""The report of the engines study (:mod:`spine_mj.validate.engines`): the section "Engines
side by side: the closed forms", each closed form beside MuJoCo's and Bullet's measurement,
and the fractal self-lock rate against H in both engines.
"""

from __future__ import annotations

import math

__all__ = ["section", "summary_lines"]

TITLE = "## Engines side by side: the closed forms"


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, str):
        return v
    if isinstance(v, bool):
        return "yes" if v else "**no**"
    if isinstance(v, float) and not math.isfinite(v):
        return "n/a"
    return f"{v:.4g}"


def summary_lines(validation: dict) -> list[str]:
    """The study in one line: per engine, the closed forms judged within tolerance (or that
    Bullet is not installed)."""
    eng = validation.get("engines")
    if not eng:
        return []
    if eng.get("missing"):
        return ["engines side by side: not run, Bullet is not installed (pip install 'spine-mj[bullet]')"]
    counts = []
    for e in eng["engines"]:
        judged = [r[f"{e}_ok"] for r in eng["rows"] if r.get(f"{e}_ok") is not None]
        counts.append(f"{e} {sum(judged)} of {len(judged)}")
    return ["engines side by side, closed forms within their tolerance: " + ", ".join(counts)]


def section(res, ctx=None) -> str:
    """The report section "Engines side by side: the closed forms" of ``res``, an
    :class:`~spine_mj.validate.engines.EnginesResult` ("" without one; one line where a
    missing extra left it unrun). ``ctx``: the report's context (the section draws no figure)."""
    if res is None:
        return ""
    if res.missing:
        extras = ", ".join(f"[{m}]" for m in res.missing)
        return (
            f"{TITLE}\n\nBullet is not installed (the {extras} extra: pip install 'spine-mj{extras}'), "
            "so the closed forms ran in no second engine.\n"
        )
    engines = res.engines
    head = ["check", "case", "closed form", "facets' rule"]
    for e in engines:
        head += [f"{e}", f"{e} error", f"{e} within"]
    head += ["tolerance"]
    lines = [
        TITLE,
        "",
        "Each closed form run the same way in MuJoCo (soft contact) and Bullet (hard contact; "
        "docs/physics.md §11), with the tolerance the MuJoCo report states. The facets' rule is "
        "the closed form applied to the contact normal of the heightfield's facets at the start "
        "(what both engines collide with).",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    for r in res.rows:
        cells = [r["check"], r["case"], _fmt(r["closed_form"]), _fmt(r.get("facets"))]
        for e in engines:
            err = r.get(f"{e}_error")
            err_s = (
                "-" if err is None or (isinstance(err, float) and not math.isfinite(err)) else f"{err:+.2%}"
            )
            ok = r.get(f"{e}_ok")
            if "facets" in r:
                ok_f = r.get(f"{e}_ok_facets")
                ok_s = f"{_fmt(ok)} (facets: {_fmt(ok_f)})"
            else:
                ok_s = _fmt(ok)
            cells += [_fmt(r.get(f"{e}_measured")), err_s, ok_s]
        cells.append(r["tolerance"])
        lines.append("| " + " | ".join(cells) + " |")
    creep = [r for r in res.rows if r["check"] == "Dai interlock"]
    if creep:
        lines += [
            "",
            "Creep while locked against the sphere (tip radii / s): "
            + "; ".join(
                f"{r['case']}: " + ", ".join(f"{e} {_fmt(r.get(f'{e}_creep_radii_per_s'))}" for e in engines)
                for r in creep
            )
            + ".",
        ]
    lines += ["", "Wall time: " + ", ".join(f"{e} {s:g} s" for e, s in res.wall_s.items()) + "."]
    if res.cpu_s:
        lines[-1] += " CPU time: " + ", ".join(f"{e} {s:g} s" for e, s in res.cpu_s.items()) + "."
    lines += _fractal_lines(res.fractal)
    return "\n".join(lines) + "\n"


def _fractal_lines(rows) -> list[str]:
    """The fractal self-lock rate against H, the engines side by side."""
    if not rows:
        return []
    engines = list(dict.fromkeys(r["engine"] for r in rows))
    head = ["H", *[f"{e} self-lock rate (95 % interval; locked / ok runs; failed)" for e in engines]]
    out = [
        "",
        "### Fractal self-lock rate against H, both engines",
        "",
        f"The validation's fractal study (paper-fractal, Fig. 9 height scale and seeds, one start "
        f"per surface, default spring K = 30) at I_e = {rows[0]['ie']:g} in each engine.",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    for h in dict.fromkeys(r["hurst"] for r in rows):
        cells = [f"{h:g}"]
        for e in engines:
            (r,) = [r for r in rows if r["hurst"] == h and r["engine"] == e]
            cells.append(
                f"{_fmt(r['rate'])} ({_fmt(r['ci_low'])}-{_fmt(r['ci_high'])}; {r['locked']} / {r['n_ok']}; "
                f"{r['failed_runs']})"
            )
        out.append("| " + " | ".join(cells) + " |")
    return out

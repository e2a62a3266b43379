"""Why the sandpaper and fractal runs of the quasistatic corner disagree (issue 11).

Rebuilds, for the full plan's sandpaper and fractal families at the lowest I_e, what the
sweep's ``compare`` analysis compared before its contact surface became exact
(:class:`spine_mj.surfaces.BallOnFacets`): the MuJoCo runs (the ``engine`` analysis of each
case, about a minute for both families) and the reference streamline traced on the facets
dilated by the tip and sampled at R/8 under a spline (``spine_mj.surfaces.dilation.dilate``), with
the same mu_s, step and force cap. Then, per run that disagrees or whose reference stalls or holds:

* the reference with fixed steps (``max_halvings = 0``, the integrator before the step
  control) and with the step control, and with fixed steps of dl / 2, dl / 4;
* at the reference's end: how far MuJoCo's path passes, the contact surface's spline slopes
  and kappa, and the exact dilated facets there (brute force over the tip's footprint:
  the highest ball centre touching the facets, the contact point and its slope and kappa);
* for the fractal misses, the reference on the facets dilated at R/16 and R/32 instead of R/8.

Run: ``nice -n 19 .venv/bin/python analysis/groove_diagnosis.py`` (11 minutes on one core of
the shared machine, most of it the brute-force contacts and the R/32 dilation); prints the
tables that docs/physics.md §2 and §4 quote.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from spine_mj.sim.model import from_hfield
from spine_mj.surfaces import TriangulatedSurface
from spine_mj.surfaces.dilation import dilate
from spine_mj.sweep import ANALYSES, expand_cases, parse_config
from spine_mj.sweep.analyses.engine import case_rig
from spine_mj.theory import agreement
from spine_mj.theory import streamline as sl
from spine_mj.theory.engagement import kappa
from spine_mj.theory.streamline_types import StreamlineParams
from spine_mj.validate.plans import FRACTAL, PLANS, SANDPAPER
from spine_mj.validate.quasistatic_limit import limit_doc


def exact_contact(facets, c, radius, n=321):
    """Height of the dilated facets at ``c`` (shifted down by the radius, as
    :func:`spine_mj.surfaces.dilation.dilate`) and the slope from the highest contact, by brute
    force over ``n x n`` points of the tip's footprint."""
    u = np.linspace(-radius, radius, n)
    x, y = np.meshgrid(c[0] + u, c[1] + u)
    d2 = (x - c[0]) ** 2 + (y - c[1]) ** 2
    inside = d2 <= radius * radius
    f = facets.height(x[inside], y[inside])
    top = f + np.sqrt(radius * radius - d2[inside])
    i = int(np.nanargmax(top))
    p = np.array([x[inside][i], y[inside][i]])
    slope = (p - c) / (top[i] - f[i]) if top[i] > f[i] else np.zeros(2)
    return top[i] - radius, slope


def trace(contact, starts, params, **changes):
    return sl.streamlines(contact, starts, dataclasses.replace(params, max_steps=4_000_000, **changes))


def _xy(res, i):
    q = res.path(i)
    return np.column_stack([q["x"], q["y"]])


def _case(case):
    """MuJoCo's runs of one case and what its reference is traced with."""
    surface = case.surface.make()
    starts = case.starts.resolve(surface.bounds, case.seed)
    rig = case_rig(case, surface)
    runs = ANALYSES["engine"].func(case, surface, starts, {}).data[1]
    s = rig.length_scale_m
    facets = TriangulatedSurface.from_grid(from_hfield(rig.hfield, unit=surface.unit))
    contact = dilate(facets, rig.tip.tip_radius_m / s)  # the spline surface compare used to trace on
    p = case.params
    return {
        "tag": f"{case.surface.label} {dict(case.surface.overrides) or ''}".strip(),
        "starts": starts,
        "lc": rig.scales.char_length_m / s,
        "mpaths": [r.position_m[r.drive_start_index :, :2] / s for r in runs],
        "held": np.array([r.end_reason.value == "self_lock" for r in runs]),
        "end": np.array([r.position_m[-1, :2] / s for r in runs]),
        "contact": contact,
        "facets": facets,
        "radius": rig.tip.tip_radius_m / s,
        "params": StreamlineParams(mu=p["mu"], dl=min(p["dl"], *contact.spacing), kappa_cap=p["kappa_cap"]),
        "dl": p["dl"],
    }


def _end_line(d, name, res, i, agree, frechet):
    """One reference's end: outcome, agreement, where MuJoCo passes, spline and exact slopes."""
    lc, radius, mu = d["lc"], d["radius"], d["params"].mu
    c = np.array([res.end_x[i], res.end_y[i]])
    near = np.hypot(*(d["mpaths"][i] - c).T).min() / lc
    _, sfx, sfy = d["contact"].evaluate(c[:1], c[1:], order=1)
    ks = kappa(sfx, sfy, mu)[0][0]
    z, slope = exact_contact(d["facets"], c, radius)
    ke = kappa(slope[:1], slope[1:], mu)[0][0]
    return (
        f"  {name:11s} {res.outcome_names[i]:11s} end ({c[0] / lc:.3f}, {c[1] / lc:.3f}) L_c, agree {agree}, "
        f"Frechet {frechet:.3f}; MuJoCo passes {near:.4f} L_c away\n"
        f"      spline slope ({sfx[0]:.2f}, {sfy[0]:.2f}) kappa {ks:.3g}, "
        f"height {res.end_z[i] / radius:+.3f} R; "
        f"exact slope ({slope[0]:.2f}, {slope[1]:.2f}) kappa {ke:.3g}, height {z / radius:+.3f} R"
    )


def _finer_sampling(d, i):
    """The fractal miss's reference on the facets dilated at R/16 and R/32."""
    lc = d["lc"]
    for m in (16, 32):
        finer = dilate(d["facets"], d["radius"], spacing=d["radius"] / m)
        r = trace(finer, d["starts"][i : i + 1], d["params"], dl=min(d["dl"], *finer.spacing))
        f = agreement.path_frechet(d["mpaths"][i], _xy(r, 0), length_scale=lc)
        print(
            f"  facets dilated at R/{m}: {r.outcome_names[0]} end ({r.end_x[0] / lc:.3f}, "
            f"{r.end_y[0] / lc:.3f}) L_c, Frechet {f:.3f}, max kappa {r.max_kappa[0]:.3g}"
        )


def _family(plan, fam):
    counts = {"fixed": [], "controlled": []}
    for preset in fam.presets:
        for case in expand_cases(parse_config(limit_doc(plan, fam, preset, f"limit-{preset}"))):
            d = _case(case)
            contact, starts, params, lc = d["contact"], d["starts"], d["params"], d["lc"]
            refs = {
                "fixed": trace(contact, starts, params, max_halvings=0),
                "controlled": trace(contact, starts, params),
                "fixed dl/2": trace(contact, starts, params, max_halvings=0, dl=params.dl / 2),
                "fixed dl/4": trace(contact, starts, params, max_halvings=0, dl=params.dl / 4),
            }
            agree = {
                k: agreement.outcome_agreement(
                    r.self_locked, np.column_stack([r.end_x, r.end_y]), d["held"], d["end"], length_scale=lc
                )["agree"]
                for k, r in refs.items()
            }
            for i in range(len(starts)):
                fr = {
                    k: agreement.path_frechet(d["mpaths"][i], _xy(r, i), length_scale=lc)
                    for k, r in refs.items()
                }
                for k in counts:
                    counts[k].append((bool(agree[k][i]), fr[k]))
                if all(agree[k][i] for k in refs) and fr["controlled"] <= 0.1:
                    continue
                mj = d["end"][i] / lc
                print(
                    f"\n{d['tag']} start ({starts[i, 0]:.6g}, {starts[i, 1]:.6g}); MuJoCo "
                    f"{'held' if d['held'][i] else 'moved'} at ({mj[0]:.3f}, {mj[1]:.3f}) L_c"
                )
                for k, r in refs.items():
                    print(_end_line(d, k, r, i, bool(agree[k][i]), fr[k]))
                if fam is FRACTAL and not agree["controlled"][i]:
                    _finer_sampling(d, i)
    for k, v in counts.items():
        a = np.array(v)
        print(
            f"\n{fam.name} ({k} steps): outcome agreement {int(a[:, 0].sum())}/{len(a)}, "
            f"median Frechet {np.median(a[:, 1]):.3f} L_c"
        )


def main():
    plan = PLANS["full"]
    for fam in (SANDPAPER, FRACTAL):
        _family(plan, fam)


if __name__ == "__main__":
    main()

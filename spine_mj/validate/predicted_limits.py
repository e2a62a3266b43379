"""Predicted drive limits of the validation's families (:mod:`spine_mj.theory.drive_limits`),
set beside the measured boundary of the (I_e, K) map.

Each family's prediction is made on the surfaces the map runs (its presets, first seed
and generator variant: :func:`spine_mj.validate.stiffness_map.subset_starts`), with the
family's mu_s and traced on the surface dilated by the rig's tip radius
(:func:`spine_mj.validate.paths.tip_radius`), i.e. what the MuJoCo tip's centre rides on.
The family's ``K*`` is the largest of its surfaces' and its ``I_e*`` the smallest.
"""

from __future__ import annotations

from spine_mj import presets
from spine_mj.theory.drive_limits import drive_limits
from spine_mj.validate.paths import tip_radius
from spine_mj.validate.plans import FamilySpec, ValidationPlan

__all__ = ["family_limits"]


def family_limits(plan: ValidationPlan, fam: FamilySpec, *, n_starts: int = 8) -> dict:
    """``{"k_star", "ie_star", "limit", "presets": {preset: DriveLimits.as_dict()}}`` of
    ``fam`` on its first seed and variant (see module), from ``n_starts x n_starts`` paths
    per surface."""
    seed = fam.seeds[0] if fam.seeds else None
    variant = dict(fam.variants[0]) if fam.variants else {}
    per = {}
    for preset in fam.presets:
        overrides = dict(variant, **({} if seed is None else {"seed": seed}))
        surface = presets.make_surface(preset, **overrides)
        mu = fam.mu if fam.mu is not None else presets.calibrated_mu(preset)
        tip = tip_radius(preset, None if seed is None else (seed,), plan.hfield_resolution)
        limits = drive_limits(surface, mu, tip_radius=tip, n_starts=n_starts)
        per[preset] = dict(limits.as_dict(), tip_radius=tip)
    worst = min(per.values(), key=lambda d: d["ie_star"])
    return {
        "k_star": max(d["k_star"] for d in per.values()),
        "ie_star": worst["ie_star"],
        "limit": worst["limit"],
        "presets": per,
    }

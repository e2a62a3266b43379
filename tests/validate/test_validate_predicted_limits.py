"""The families' corners (spine_mj.validate.predicted_limits)."""

from spine_mj.validate.plans import PLANS, FamilySpec, relative_starts
from spine_mj.validate.predicted_limits import families_limits, family_corner, family_corners, family_limits


def test_corners_on_two_workers_are_the_corners_one_by_one():
    """Every surface's limits predicted in worker processes give each family the corner
    (and each surface the limits) that one family at a time in this process gives, to the bit."""
    plan = PLANS["smoke"]
    fams = [
        plan.families[0],
        FamilySpec("random_gaussian", ("paper-random-convex",), (1,), relative_starts(3)),
    ]
    both = family_corners(plan, fams, workers=2)
    assert list(both) == [f.name for f in fams]
    for fam in fams:
        one = family_corner(plan, fam)
        assert both[fam.name] == one
        assert set(one["presets"]) == set(fam.presets) and one["presets"][fam.presets[0]]["ie"] > 0


def test_the_maps_limits_on_two_workers_are_those_one_by_one():
    plan = PLANS["smoke"]
    fam = FamilySpec(
        "single_peak_valley", ("paper-single-peak", "paper-single-valley"), None, plan.families[0].starts
    )
    both = families_limits(plan, [fam], n_starts=2, workers=2)[fam.name]
    assert both == family_limits(plan, fam, n_starts=2)
    assert list(both["presets"]) == list(fam.presets)
    assert both["ie_star"] == min(p["ie_star"] for p in both["presets"].values())

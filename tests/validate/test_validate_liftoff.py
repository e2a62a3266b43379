"""Lift-off over a crest, fast: a tip carried over a Gaussian ridge keeps contact well below
the predicted ``I_e* = 1 / (L_c c)`` and flies above it (the ground-truth study's scan, two
runs per width), in MuJoCo and in Bullet."""

import pytest

from spine_mj.choices import COMPARED_ENGINES
from spine_mj.validate.ground_truth import LIFTOFF_ABOVE, LIFTOFF_BELOW, LIFTOFF_GAP_RADII, crest_check


@pytest.mark.parametrize("engine", COMPARED_ENGINES)
@pytest.mark.parametrize("width", [0.35, 0.5])
def test_the_tip_keeps_the_crest_below_ie_star_and_leaves_it_above(width, engine):
    if engine == "bullet":
        pytest.importorskip("pybullet", reason="the Bullet engine needs the [bullet] extra (pybullet)")
    ie, gap, flight = crest_check(width, LIFTOFF_BELOW, engine)
    assert ie < 0.8 and gap < LIFTOFF_GAP_RADII and flight == 0.0, (ie, gap, flight)
    ie, gap, flight = crest_check(width, LIFTOFF_ABOVE, engine)
    assert ie > 1.0 and gap > 2 * LIFTOFF_GAP_RADII and flight > 0.25, (ie, gap, flight)

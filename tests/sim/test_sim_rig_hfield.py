"""The hfield a rig collides with (spine_mj.sim.rig_hfield) and its sides known before it is
sampled (spine_mj.sim.scales.planned_hfield_sides): the prediction an engine's limit is
checked on must be the hfield the slow sizing then makes."""

import numpy as np
import pytest

from spine_mj import sim
from spine_mj.sim.build import rig_sizing
from spine_mj.sim.rig_hfield import grid_keeps_samples, hfield_of, hfield_spacing, planned_spacing
from spine_mj.sim.scales import planned_hfield_sides
from spine_mj.surfaces import GridSurface, fractal_fbm, single_gaussian, to_hfield
from spine_mj.surfaces.hfield import hfield_half_extents

PERIODIC = fractal_fbm(nx=48, ny=32, rng=1)  # bounds one spacing past its last sample
OPEN = GridSurface(np.random.default_rng(0).random((17, 25)), np.linspace(0, 3, 25), np.linspace(-1, 1, 17))


@pytest.mark.parametrize("surface", [single_gaussian(), PERIODIC, OPEN], ids=["analytic", "periodic", "open"])
@pytest.mark.parametrize(("resolution", "refinement"), [(None, 1), (None, 3), (41, 1), (41, 2), (95, 1)])
def test_the_planned_spacing_is_the_sampled_hfield_s(surface, resolution, refinement):
    hf = hfield_of(surface, resolution, refinement)
    assert planned_spacing(surface, resolution, refinement, 0.01) == hfield_spacing(hf, 0.01)
    nrow, ncol = hf.nrow, hf.ncol
    given = resolution is not None or refinement != 1
    extents = hfield_half_extents(surface, nrow=nrow if given else None, ncol=ncol if given else None)
    assert extents == (hf.size[0], hf.size[1])


def test_half_extents_follow_to_hfield_on_a_periodic_grid_resampled_or_refined():
    assert PERIODIC.bounds[1] > PERIODIC.x[-1]  # the case where bounds and samples differ
    for nrow, ncol in ((None, None), (63, 95), (64, 64)):  # kept, refined x 2, resampled
        hf = to_hfield(PERIODIC, nrow=nrow, ncol=ncol)
        assert hfield_half_extents(PERIODIC, nrow=nrow, ncol=ncol) == hf.size[:2]


@pytest.mark.parametrize(
    ("surface", "sizing"),
    [
        (single_gaussian(), {}),
        (single_gaussian(), {"hfield_resolution": 61, "hfield_refinement": 2}),
        (PERIODIC, {}),
        (PERIODIC, {"hfield_refinement": 2}),
        # tips of over 4 spacings: the grid is coarsened to a quarter tip radius (then refined)
        (PERIODIC, {"tip": sim.TipParams(tip_radius_m=0.05), "hfield_refinement": 3}),
        (OPEN, {"tip": sim.TipParams(tip_radius_m=6e-4), "length_scale_m": 1e-3}),
    ],
)
def test_the_planned_sides_are_the_sides_the_rig_s_sizing_makes(surface, sizing):
    """The sizing rule's coarsening and refinement, predicted measuring only L_c."""
    tip = sizing.pop("tip", sim.TipParams())
    _, scales, hf = rig_sizing(surface, tip=tip, **sizing)
    keeps = grid_keeps_samples(surface, sizing.pop("hfield_resolution", None))
    assert planned_hfield_sides(surface, tip=tip, hfield_resolution=keeps, **sizing) == (hf.nrow, hf.ncol)
    if tip.tip_radius_m is not None:
        assert scales.hfield_resolution < max(surface.shape)  # coarsened

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


def test_a_coarsened_grid_is_refined_through_its_coarse_samples_not_its_own():
    """Refinement verifies the facets of one surface: a grid the rig resamples (a grit
    coarsened to a quarter tip radius) is refined through the interpolant of the samples it
    was resampled to. Closed form: a wave sin(pi x / d) on a fine grid, resampled at nodes d
    apart, samples 0 at every node; the rig's surface is then flat, and so must its x 2 and
    x 4 hfields be, where resampling the fine grid again drew a wave of amplitude 1."""
    d, n = 0.25, 17  # 17 nodes over [0, 4], d apart
    x = np.linspace(0.0, 4.0, 161)  # 10 samples a node spacing
    y = np.linspace(-1.0, 1.0, 81)
    wave = GridSurface(np.broadcast_to(np.sin(np.pi * x / d), (y.size, x.size)).copy(), x, y)
    base = hfield_of(wave, n)
    levels = (base, hfield_of(wave, n, 2), hfield_of(wave, n, 4))
    heights = [hf.data.astype(float) * hf.size[2] + hf.pos[2] for hf in levels]
    assert base.data.shape == (n, n)
    for h in heights:
        assert np.abs(h).max() < 1e-12  # flat: the nodes' samples, and their interpolant between them
    assert np.abs(wave.sample(2 * n - 1).heights).max() > 0.99  # what the old refinement resampled
    # every old sample kept, and each level the one below refined (the same surface throughout)
    hf4 = hfield_of(OPEN, 13, 4)
    h2, h4 = (hf.data.astype(float) * hf.size[2] + hf.pos[2] for hf in (hfield_of(OPEN, 13, 2), hf4))
    np.testing.assert_allclose(h4[::2, ::2], h2, atol=1e-6 * np.ptp(OPEN.heights))
    np.testing.assert_allclose(h4[::4, ::4], OPEN.sample(13).heights, atol=1e-6 * np.ptp(OPEN.heights))

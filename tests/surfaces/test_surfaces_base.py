"""surfaces.base: the length units, the grid-size limit and the generators' rng rule."""

import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import LENGTH_UNITS_M, MAX_GRID_POINTS, check_grid_size, length_unit, random_gaussians


def test_every_spelling_of_a_length_unit_maps_to_the_tables():
    assert {u: length_unit(u) for u in LENGTH_UNITS_M} == {u: u for u in LENGTH_UNITS_M}
    assert length_unit("\u00b5m") == length_unit("\u03bcm") == "um"  # micro sign and Greek mu
    assert [length_unit(u) for u in ("1", "A", "km", "", None, 3)] == [None] * 6


def test_the_unit_table_is_in_metres():
    assert LENGTH_UNITS_M["m"] == 1.0
    ratios = [LENGTH_UNITS_M[a] / LENGTH_UNITS_M[b] for a, b in (("mm", "um"), ("um", "nm"), ("nm", "pm"))]
    assert ratios == pytest.approx([1e3, 1e3, 1e3])


def test_a_grid_over_the_point_limit_is_refused_naming_where_and_its_size():
    side = int(np.sqrt(MAX_GRID_POINTS))
    check_grid_size(side, side, where="here")  # at the limit (memory aside: 4 arrays of 512 MiB)
    with pytest.raises(SpineInputError, match=r"^resampling: a 100000 x 100000 grid has 1e\+10 points.*GiB"):
        check_grid_size(100_000, 100_000, where="resampling")
    with pytest.raises(SpineInputError, match="inf"):
        check_grid_size(float("inf"), 10, where="x")


def test_a_grid_over_the_memory_budget_is_refused_before_allocating(monkeypatch):
    monkeypatch.setenv("SPINE_MJ_MEMORY_BUDGET", "1M")
    check_grid_size(100, 100, where="small")  # 4 arrays of 80 kB
    with pytest.raises(SpineInputError, match=r"^big: a 1000 x 1000 grid would need .* budget"):
        check_grid_size(1000, 1000, where="big")


def test_rng_an_int_seed_repeats_and_is_recorded_a_generator_is_taken_as_is():
    a, b = random_gaussians(n_peaks=5, rng=7), random_gaussians(n_peaks=5, rng=7)
    xs = np.linspace(-5.0, 5.0, 11)
    np.testing.assert_array_equal(a.height(xs, xs), b.height(xs, xs))
    assert not np.array_equal(a.height(xs, xs), random_gaussians(n_peaks=5, rng=8).height(xs, xs))
    assert a.metadata["seed"] == 7
    assert random_gaussians(n_peaks=5, rng=np.random.default_rng(7)).metadata["seed"] is None
    for bad in (-1, True, 1.5, "7"):
        with pytest.raises(SpineInputError, match="rng must be a non-negative int seed or a numpy Generator"):
            random_gaussians(n_peaks=5, rng=bad)

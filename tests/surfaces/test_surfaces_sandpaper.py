"""Sandpaper (surfaces/sandpaper.py): the grid resolves tip and grains, the covered
fraction follows the Boolean model, and the roughness scales with the grit."""

import math

import numpy as np
import pytest

from spine_mj.surfaces import GRIT_PARTICLE_DIAMETER_M, sandpaper


@pytest.mark.parametrize("grit", ["P36", "P60", "P600"])
def test_sandpaper_resolves_tip_and_particles(grit):
    d = GRIT_PARTICLE_DIAMETER_M[grit]
    size = 12 * d
    s = sandpaper(grit=grit, size_m=size, rng=2)
    assert s.unit == "m" and s.periodic
    dx = s.spacing[0]
    assert dx <= 25e-6 / 5 + 1e-12 and dx <= d / 10 + 1e-12
    assert s.heights.min() == 0.0
    assert s.heights.max() <= 0.7 * d * 1.8  # exposed part of the largest grains
    np.testing.assert_array_equal(s.heights, sandpaper(grit=grit, size_m=size, rng=2).heights)


def test_sandpaper_covered_fraction_follows_boolean_model():
    """Footprints of random discs cover 1 - exp(-sum of footprint areas / area)."""
    s = sandpaper(grit="P60", size_m=4e-3, coverage=0.6, rng=9)
    meta = s.metadata["params"]
    d = meta["particle_diameter_m"]
    e_lo, e_hi = meta["embed_range"]
    # footprint radius^2 = r^2 - zc^2 with zc = r(1 - 2e); E over e ~ U(e_lo, e_hi)
    e = np.linspace(e_lo, e_hi, 1001)
    mean_factor = np.mean(1 - (1 - 2 * e) ** 2)
    cv = meta["size_cv"]
    mean_r2 = (d / 2) ** 2 * (1 + cv**2)
    density = meta["n_particles"] / 4e-3**2
    expected = 1 - math.exp(-density * math.pi * mean_r2 * mean_factor)
    covered = np.mean(s.heights > 0)
    assert covered == pytest.approx(expected, abs=0.05)


def test_sandpaper_roughness_scales_with_grit():
    rms = {
        g: sandpaper(grit=g, size_m=10 * GRIT_PARTICLE_DIAMETER_M[g], rng=1).heights.std()
        for g in ("P36", "P600")
    }
    ratio = GRIT_PARTICLE_DIAMETER_M["P36"] / GRIT_PARTICLE_DIAMETER_M["P600"]
    assert rms["P36"] / rms["P600"] == pytest.approx(ratio, rel=0.3)

"""Path metrics of the validation."""

import numpy as np
import pytest

from spine_mj import validate


def test_prefix_frechet_cuts_the_streamline_at_the_mujoco_arc_length():
    q = np.column_stack([np.linspace(0, 10, 101), np.zeros(101)])
    # MuJoCo covered 1 unit of it, 0.05 to the side: the prefix deviation is the offset
    m = np.column_stack([np.linspace(0, 1, 11), np.full(11, 0.05)])
    assert validate.prefix_frechet(m, q, 1.0) == pytest.approx(0.05, abs=1e-3)
    # against the whole streamline it would be the 9 units MuJoCo did not cover
    assert validate.path_metrics(m, q, 1.0)[0] > 8.9

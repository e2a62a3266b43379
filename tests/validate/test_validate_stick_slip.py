"""Slip statistics of a drive-force trace."""

import numpy as np
import pytest

from spine_mj import validate
from spine_mj.errors import SpineInputError


def test_slip_statistics_on_a_constructed_stick_slip_trace():
    # stick (force rises 0 -> 1), slip 4 samples (x jumps by 0.1 each, force falls to 0.4),
    # stick again (rises to 0.9), slip 2 samples (y moves 0.3 + 0.4), and one-sample chatter
    t = np.arange(30, dtype=float)
    x = np.zeros(30)
    y = np.zeros(30)
    f = np.zeros(30)
    s = np.zeros(30, bool)
    f[:10] = np.linspace(0, 1, 10)
    s[10:14] = True
    x[10:14] = 0.1 * np.arange(1, 5)
    x[14:] = 0.4
    f[10:14] = [0.9, 0.7, 0.5, 0.4]
    f[14:20] = np.linspace(0.4, 0.9, 6)
    s[20:22] = True
    y[20], y[21:] = 0.3, 0.7
    f[20:22] = [0.8, 0.6]
    f[22:] = 0.6
    s[26] = True  # chatter: one sample, no motion
    st = validate.slip_statistics(t, x, y, f, s, min_samples=2)
    assert st.count == 2
    np.testing.assert_allclose(st.jump_lengths, [0.4, 0.7])
    # drop: the force at the last stuck sample minus the force after the slip ends
    np.testing.assert_allclose(st.force_drops, [1.0 - 0.4, 0.9 - 0.6])
    np.testing.assert_allclose(st.durations, [5.0, 3.0])
    assert validate.slip_statistics(t, x, y, f, s, min_samples=1).count == 3
    assert st.summary()["max_jump"] == pytest.approx(0.7)


def test_slip_statistics_rejects_mismatched_arrays():
    with pytest.raises(SpineInputError, match="one length"):
        validate.slip_statistics([0, 1], [0, 1], [0, 1], [0, 1], [True])

"""Slip statistics of a drive-force trace."""

import numpy as np
import pytest

from spine_mj import validate
from spine_mj.errors import SpineInputError
from spine_mj.theory.motion import SLIPPING, STUCK


def test_slip_statistics_on_a_constructed_stick_slip_trace():
    # stick (force rises 0 -> 1), slip 4 samples (x jumps by 0.1 each, force falls to 0.4),
    # stick again (rises to 0.9), slip 2 samples (y moves 0.3 + 0.4), one sample at rest
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
    s[26] = True  # one slipping sample with no motion and no drop
    st = validate.slip_statistics(t, x, y, f, np.where(s, SLIPPING, STUCK))
    assert st.count == 3
    np.testing.assert_allclose(st.jump_lengths, [0.4, 0.7, 0.0])
    # drop: the peak force (at the last loading sample) minus the lowest force after it
    np.testing.assert_allclose(st.force_drops, [1.0 - 0.4, 0.9 - 0.6, 0.0])
    np.testing.assert_allclose(st.durations, [4.0, 2.0, 1.0])
    assert st.summary()["max_jump"] == pytest.approx(0.7)


def test_slip_statistics_rejects_mismatched_arrays():
    with pytest.raises(SpineInputError, match="one length"):
        validate.slip_statistics([0, 1], [0, 1], [0, 1], [0, 1], [2])


def test_k_scan_transition_lies_between_the_last_slipping_and_the_first_sliding_k():
    from spine_mj.validate.stick_slip import transitions

    scan = [
        {"ie": 1e-4, "K": k, "events_per_wave": e}
        for k, e in ((0.1, 1.0), (0.2, 0.9), (0.4, 0.0), (0.8, 0.0))
    ]
    (t,) = transitions(scan, k_star=0.3)
    assert (t["k_low"], t["k_high"]) == (0.2, 0.4)
    assert t["over_k_star"] == pytest.approx(np.sqrt(0.08) / 0.3)

"""plotting: the house style's number and unit formatting."""

import pytest

from spine_mj import plotting


@pytest.mark.parametrize(
    "value, text",
    [
        (3.6068453317776017, "3.61"),
        (1e-4, "0.0001"),
        (0.031622776602047833, "0.0316"),
        (123456.0, "1.23e+05"),
        (7, "7"),
        (float("nan"), "nan"),
        (None, "-"),
        (True, "yes"),
    ],
)
def test_sig_rounds_to_three_significant_digits(value, text):
    assert plotting.sig(value) == text


def test_length_unit_picks_um_or_mm_for_scans():
    assert plotting.length_unit(4e-4) == (1e6, "um")
    assert plotting.length_unit(5e-3) == (1e3, "mm")
    assert plotting.length_unit(2.0) == (1.0, "m")

"""workers: the one rule for --workers, with the limit the message names."""

import os

import pytest

from spine_mj.errors import SpineInputError
from spine_mj.workers import MAX_WORKERS_PER_CORE, check_workers


def test_the_whole_allowed_range_is_accepted():
    limit = MAX_WORKERS_PER_CORE * (os.cpu_count() or 1)
    assert check_workers(1) == 1 and check_workers(limit) == limit


@pytest.mark.parametrize("bad", [0, -1, "over", True, 2.0, "2", None])
def test_anything_else_is_refused_naming_the_limit_and_the_value(bad):
    limit = MAX_WORKERS_PER_CORE * (os.cpu_count() or 1)
    value = limit + 1 if bad == "over" else bad
    with pytest.raises(
        SpineInputError, match=rf"--workers: must be an integer from 1 to {limit} .*got {value!r}"
    ):
        check_workers(value)

"""``spine-mj streamline``'s library side: both analyses from the same starts, one table,
both files or neither, and the one default step."""

import numpy as np
import pandas as pd
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import corrugation, single_gaussian
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory import streamline as sl
from spine_mj.theory.streamline_outputs import FIGURE_NAME, trace_starts, write_streamline_outputs
from spine_mj.theory.streamline_types import StreamlineParams

STARTS = [(-3.0, -1.0), (-3.0, -2.0)]


def test_the_default_step_is_a_thousandth_of_the_shorter_side():
    surf = corrugation()  # 8 x 1
    xmin, xmax, ymin, ymax = surf.bounds
    assert (xmax - xmin) / (ymax - ymin) == pytest.approx(8.0)
    assert sl.default_step(surf) == pytest.approx((ymax - ymin) / 1000)


def test_the_run_equals_the_two_analyses_run_apart():
    surf = single_gaussian()
    run = trace_starts(surf, STARTS, mu=1.2)
    params = StreamlineParams(mu=1.2, dl=sl.default_step(surf))
    direct = sl.streamlines(surf, STARTS, params)
    np.testing.assert_array_equal(run.stream.end_x, direct.end_x)
    np.testing.assert_array_equal(run.ideal.outcome, sl.ideal_trajectories(surf, STARTS, params).outcome)
    table = run.table()
    assert set(table.trajectory) == {"streamline", "ideal"}
    assert (table.mu == 1.2).all() and (table.tip_radius == 0.0).all()
    assert len(table) == run.stream.x.size + run.ideal.x.size
    assert [line.split(":")[0] for line in run.summary_lines()] == ["start (-3, -1)", "start (-3, -2)"]


def test_a_tip_rides_the_dilated_surface():
    surf = single_gaussian()
    run = trace_starts(surf, STARTS[:1], mu=1.2, tip_radius=0.3)
    np.testing.assert_array_equal(run.surface.heights, dilate(surf, 0.3).heights)
    assert run.tip_radius == 0.3 and (run.table().tip_radius == 0.3).all()


def test_both_files_are_written_and_read_back(tmp_path):
    run = trace_starts(single_gaussian(), STARTS, mu=1.2)
    table_path, figure_path = write_streamline_outputs(run, tmp_path, fmt="csv")
    assert table_path.name == "streamlines.csv" and figure_path.name == FIGURE_NAME
    pd.testing.assert_frame_equal(pd.read_csv(table_path), run.table(), check_dtype=False)
    assert figure_path.stat().st_size > 10_000


def test_an_unknown_format_writes_nothing(tmp_path):
    run = trace_starts(single_gaussian(), STARTS[:1], mu=1.2)
    with pytest.raises(SpineInputError, match="table format must be one of parquet, csv, got 'xlsx'"):
        write_streamline_outputs(run, tmp_path / "out", fmt="xlsx")
    assert not (tmp_path / "out").exists()

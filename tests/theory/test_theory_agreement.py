"""Comparison metrics on constructed cases whose answers are known by hand."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spine_mj import SpineInputError
from spine_mj.theory import agreement
from spine_mj.theory.agreement import (
    MAX_RESAMPLED_POINTS,
    capture_rate,
    frechet_distance,
    frechet_distance_reference,
    kappa_agreement,
    mean_lateral_deviation,
    miss_reason,
    outcome_agreement,
    peak_speed,
    resample_by_arclength,
    slide_fraction,
)


def line(y, n=50, x0=0.0, x1=5.0):
    x = np.linspace(x0, x1, n)
    return np.column_stack([x, np.full(n, y)])


def test_frechet_hand_examples():
    p = [(0, 0), (1, 0), (2, 0)]
    q = [(0, 1), (2, 1)]
    assert frechet_distance(p, q) == pytest.approx(math.sqrt(2))
    assert frechet_distance(line(0), line(0)) == 0.0
    assert frechet_distance(line(0), line(0.3), length_scale=0.1) == pytest.approx(3.0)
    # walking the same path backwards: the leash must span start to end at some moment
    assert frechet_distance(line(0), line(0)[::-1]) == pytest.approx(5.0)


def test_frechet_symmetric_and_bounded_by_hausdorff():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(30, 2)), rng.normal(size=(20, 2))
    assert frechet_distance(a, b) == pytest.approx(frechet_distance(b, a))
    d = np.linalg.norm(a[:, None] - b[None], axis=2)
    hausdorff = max(d.min(axis=1).max(), d.min(axis=0).max())
    # the bounds are equalities at worst (the leash at a pair of points), and the compiled
    # distance and numpy's norm round differently (a few ulps of O(1) distances, CPU-
    # dependent): allow 1e-12, far below any real violation
    fd = frechet_distance(a, b)
    assert fd >= hausdorff - 1e-12
    assert fd >= np.linalg.norm(a[0] - b[0]) - 1e-12
    assert fd >= np.linalg.norm(a[-1] - b[-1]) - 1e-12


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 12), st.integers(1, 12), st.integers(0, 10_000))
def test_compiled_frechet_equals_reference(n, m, seed):
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(n, 3)), rng.normal(size=(m, 3))
    assert frechet_distance(a, b) == pytest.approx(frechet_distance_reference(a, b), abs=1e-12)


def test_lateral_deviation_of_parallel_and_crossing_lines():
    assert mean_lateral_deviation(line(0.4), line(0.0)) == pytest.approx(0.4)
    assert mean_lateral_deviation(line(0.4), line(0.0), length_scale=2.0) == pytest.approx(0.2)
    # sparse reference vertices: distances to segments, not to vertices
    assert mean_lateral_deviation(line(0.4), line(0.0, n=2)) == pytest.approx(0.4)
    # a path crossing the reference at 45 degrees: mean |y| of y = x - 1 for x in 0..2
    diag = np.column_stack([np.linspace(0, 2, 3), np.linspace(-1, 1, 3)])
    ref = line(0.0, n=2, x0=-5, x1=5)
    assert mean_lateral_deviation(diag, ref, spacing=1e-3) == pytest.approx(0.5, rel=1e-3)


def test_lateral_deviation_weighs_by_length_not_samples():
    dense_then_sparse = np.vstack([line(1.0, n=500, x1=1.0), line(1.0, n=2, x0=1.0, x1=5.0)[1:]])
    assert mean_lateral_deviation(dense_then_sparse, line(0.0)) == pytest.approx(1.0)


def test_resample_by_arclength():
    p = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0]])
    r = resample_by_arclength(p, 1.0)
    assert len(r) == 8
    np.testing.assert_allclose(np.linalg.norm(np.diff(r, axis=0), axis=1), 1.0)
    np.testing.assert_allclose(r[-1], [3.0, 4.0])


def _segment_distance_by_point(points, ref):
    """Plain reference: each point against every segment of ``ref``, one point at a time."""
    out = []
    for p in points:
        best = math.inf
        for a, b in itertools.pairwise(ref):
            d = b - a
            t = 0.0 if d @ d == 0 else min(1.0, max(0.0, (p - a) @ d / (d @ d)))
            best = min(best, float(np.linalg.norm(p - (a + t * d))))
        out.append(best)
    return np.array(out)


@pytest.mark.parametrize("block_bytes", [64, 64 * 7, 2**25])
def test_point_segment_distance_in_blocks_equals_the_plain_loop(monkeypatch, block_bytes):
    """Whatever the byte budget cuts the points x segments into (one pair a block, a few,
    all), the distances are those of the plain loop; repeated vertices (zero-length
    segments) included."""
    monkeypatch.setattr(agreement, "BLOCK_BYTES", block_bytes)
    rng = np.random.default_rng(5)
    ref = np.cumsum(rng.normal(size=(23, 2)), axis=0)
    ref[7] = ref[6]
    points = rng.normal(scale=3.0, size=(31, 2))
    got = agreement._point_segment_distance(points, ref[:-1], ref[1:])
    np.testing.assert_allclose(got, _segment_distance_by_point(points, ref), rtol=1e-12)


def test_a_path_flown_to_a_million_lc_and_back_is_compared_in_bounded_samples():
    """A diverged run's path: 1e6 L_c out along x and back. Resampled at L_c / 50 it would
    take 1e8 points; it gets MAX_RESAMPLED_POINTS, ends kept, and its deviation from a
    reference along [0, 10] is the closed form mean(max(x - 10, 0)) over the out-and-back."""
    far = 1e6
    wild = np.array([[0.0, 0.0], [far, 0.0], [0.0, 0.0]])
    samples = resample_by_arclength(wild, 1 / 50)
    assert samples.shape == (MAX_RESAMPLED_POINTS, 2)
    np.testing.assert_array_equal(samples[[0, -1]], wild[[0, -1]])
    ref = line(0.0, n=11, x0=0.0, x1=10.0)
    expected = (far - 10) ** 2 / (2 * far)
    assert mean_lateral_deviation(wild, ref) == pytest.approx(expected, rel=1e-3)
    assert agreement.path_frechet(wild, ref, length_scale=1.0) == pytest.approx(far - 10, rel=1e-3)


def test_outcome_agreement_cases():
    locked_qs = [True, True, False, False, True]
    locked_mj = [True, True, False, True, False]
    end_qs = [[0, 0], [0, 0], [5, 1], [5, 1], [1, 1]]
    end_mj = [[0.1, 0], [2, 0], [5, -3], [5, 1], [1, 1]]
    out = outcome_agreement(locked_qs, end_qs, locked_mj, end_mj, length_scale=1.0, end_tolerance=0.25)
    np.testing.assert_array_equal(out["lock"], [True, True, True, False, False])
    np.testing.assert_array_equal(out["same_trap"], [True, False, False, False, False])
    np.testing.assert_array_equal(out["agree"], [True, False, True, False, False])
    np.testing.assert_array_equal(out["end"], [True, False, False, True, True])


def test_kappa_agreement_and_capture_rate():
    out = kappa_agreement([2.0, np.inf, 4.0], [1.8, 50.0, 50.0], kappa_cap=20.0)
    np.testing.assert_allclose(out["ratio"], [0.9, 1.0, 5.0])
    np.testing.assert_array_equal(out["both_capped"], [False, True, False])
    assert capture_rate([True, False, True, True]) == 0.75
    assert math.isnan(capture_rate([]))


def test_bad_input_is_named():
    with pytest.raises(SpineInputError, match=r"path_a must have shape \(n, 2\)"):
        frechet_distance(np.zeros(5), np.zeros((5, 2)))
    with pytest.raises(SpineInputError, match="same dimension"):
        frechet_distance(np.zeros((5, 2)), np.zeros((5, 3)))
    with pytest.raises(SpineInputError, match="NaN"):
        mean_lateral_deviation([[0, 0], [np.nan, 1]], [[0, 0], [1, 1]])
    with pytest.raises(SpineInputError, match="L_c"):
        frechet_distance([[0, 0]], [[1, 1]], length_scale=0)
    with pytest.raises(SpineInputError, match="same n runs"):
        outcome_agreement([True], [[0, 0]], [True, False], [[0, 0], [1, 1]])
    with pytest.raises(SpineInputError, match="kappa_cap"):
        kappa_agreement([1.0], [1.0], kappa_cap=np.inf)


def test_miss_reason_reads_where_the_restarted_reference_first_ends_as_the_run():
    """The reference is the line y = 0; the run leaves it towards y = 1. Its outcome is
    reached first from the checkpoint at y = 0.001 (within a facet of 0.01: a separatrix),
    or first from y = 0.5 (diverged by 0.5 L_c); never reached: the engine held or passed."""
    ref = line(0.0)
    run = np.column_stack([np.linspace(0.0, 5.0, 5), [0.0, 0.001, 0.2, 0.5, 1.0]])
    reaches = np.array([False, True, True, True, True])
    assert miss_reason(run, ref, reaches, True, length_scale=1.0, separatrix_offset=0.01) == (
        "separatrix",
        pytest.approx(0.001),
    )
    reaches[1:3] = False
    reason, offset = miss_reason(run, ref, reaches, True, length_scale=2.0, separatrix_offset=0.01)
    assert reason == "diverged" and offset == pytest.approx(0.25)  # 0.5 over L_c = 2
    for locked, expected in ((True, "engine_held"), (False, "engine_passed")):
        reason, offset = miss_reason(
            run, ref, np.zeros(5, bool), locked, length_scale=1.0, separatrix_offset=0.01
        )
        assert reason == expected and math.isnan(offset)
    with pytest.raises(SpineInputError, match="one flag per checkpoint"):
        miss_reason(run, ref, reaches[:3], True, length_scale=1.0, separatrix_offset=0.01)
    with pytest.raises(SpineInputError, match="separatrix_offset"):
        miss_reason(run, ref, reaches, True, length_scale=1.0, separatrix_offset=-1.0)


def test_slide_fraction_counts_the_arc_length_of_slip_segments():
    from spine_mj.theory.engagement import ENGAGED, SELF_LOCK, SLIP

    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0], [1.0, 4.0]])
    region = [ENGAGED, SLIP, SLIP, SELF_LOCK]  # the last point's region starts no segment
    assert slide_fraction(path, region) == pytest.approx(4.0 / 5.0)
    assert slide_fraction(path, [ENGAGED] * 4) == 0.0
    assert np.isnan(slide_fraction(path[:1], [SLIP]))
    with pytest.raises(SpineInputError, match="region must have one entry per path point"):
        slide_fraction(path, [SLIP])


def test_peak_speed_is_the_largest_row_norm():
    v = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, -6.0], [1.0, 1.0, 1.0]])
    assert peak_speed(v) == pytest.approx(6.0)
    assert np.isnan(peak_speed(np.zeros((0, 3))))

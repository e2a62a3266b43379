import itertools
import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spine_mj.errors import SpineInputError
from spine_mj.presets import load_preset, make_surface
from spine_mj.surfaces import GridSurface, fractal_fbm, random_gaussians, single_gaussian
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory.engagement import ENGAGED, SELF_LOCK
from spine_mj.theory.streamline import ideal_trajectories, streamlines
from spine_mj.theory.streamline_types import Outcome, StreamlineParams

FIVE_STARTS = [(-3.0, y) for y in (-4.0, -3.0, -2.0, -1.0, -0.5)]
MU = load_preset("paper-single-peak").extras["engagement"]["mu"]


def _plane(slope, n=41, half=2.0):
    x = np.linspace(-half, half, n)
    return GridSurface(heights=np.broadcast_to(slope * x, (n, n)), x=x, y=x.copy())


def _same(a, b, atol):
    np.testing.assert_array_equal(a.outcome, b.outcome)
    np.testing.assert_array_equal(a.n_steps, b.n_steps)
    for key in ("x", "y", "z"):
        np.testing.assert_allclose(getattr(a, key), getattr(b, key), atol=atol)
    np.testing.assert_array_equal(a.region, b.region)


@pytest.mark.parametrize("sign", [1, -1])
def test_kernel_matches_numpy_reference_single_gaussian(sign):
    surf = single_gaussian(sign=sign)
    p = StreamlineParams(mu=MU, dl=0.015)
    for fn in (streamlines, ideal_trajectories):
        _same(fn(surf, FIVE_STARTS, p, backend="numba"), fn(surf, FIVE_STARTS, p, backend="numpy"), 1e-9)


def test_kernel_matches_numpy_reference_random_and_grid():
    starts = np.c_[np.full(12, -9.5), np.linspace(-8, 8, 12)]
    p = StreamlineParams(mu=1.0, dl=0.03)
    surf = random_gaussians(sign=-1, rng=3)
    _same(streamlines(surf, starts, p, backend="numba"), streamlines(surf, starts, p, backend="numpy"), 1e-8)
    grid = fractal_fbm(nx=64, size=20.0, hurst=0.8, rms_slope=0.6, rng=2)
    _same(streamlines(grid, starts, p, backend="numba"), streamlines(grid, starts, p, backend="numpy"), 1e-8)
    nonperiodic = grid.resample(0.4)  # non-periodic copy
    assert not nonperiodic.periodic or grid.periodic
    r1 = streamlines(nonperiodic, starts, p, backend="numba")
    r2 = streamlines(nonperiodic, starts, p, backend="numpy")
    np.testing.assert_array_equal(r1.outcome, r2.outcome)


@pytest.mark.parametrize("sign", [1, -1])
def test_kernel_matches_reference_with_more_starts_than_lanes(sign):
    # the kernel steps starts in lanes and refills a lane when its trajectory ends; paths
    # come back in start order whatever the order in which trajectories finish
    surf = single_gaussian(sign=sign)
    starts = np.c_[np.linspace(-4.8, 0.0, 45), np.linspace(-4.8, 4.8, 45)]
    p = StreamlineParams(mu=MU, dl=0.05, max_steps=120)
    for fn in (streamlines, ideal_trajectories):
        ref = fn(surf, starts, p, backend="numpy")
        assert len(set(ref.outcome.tolist())) == 3  # lock, edge, cap: ragged lengths
        for store in (True, False):
            got = fn(surf, starts, p, backend="numba", store_paths=store)
            np.testing.assert_array_equal(got.outcome, ref.outcome)
            np.testing.assert_array_equal(got.n_steps, ref.n_steps)
            np.testing.assert_allclose(got.max_kappa, ref.max_kappa, rtol=1e-9)
            for key in ("end_x", "end_y", "end_z"):
                np.testing.assert_allclose(getattr(got, key), getattr(ref, key), atol=1e-9)
            if store:
                _same(got, ref, 1e-9)
                np.testing.assert_array_equal(got.offsets, ref.offsets)


def test_store_paths_false_gives_the_same_summary():
    surf = single_gaussian(sign=-1)
    p = StreamlineParams(mu=MU)
    a = streamlines(surf, FIVE_STARTS, p)
    b = streamlines(surf, FIVE_STARTS, p, store_paths=False)
    np.testing.assert_array_equal(a.outcome, b.outcome)
    # one compiled kernel, store_paths only switches the recording off: bitwise equal
    np.testing.assert_array_equal(a.max_kappa, b.max_kappa)
    assert b.x is None
    with pytest.raises(SpineInputError, match="store_paths"):
        b.path(0)


def test_flat_ground_goes_straight_with_kappa_mu():
    surf = _plane(0.0)
    p = StreamlineParams(mu=0.6, dl=0.01)
    r = streamlines(surf, [(-1.5, 0.3)], p)
    path = r.path(0)
    assert r.outcome[0] == Outcome.LEFT_DOMAIN
    np.testing.assert_allclose(path["y"], 0.3, atol=1e-12)
    np.testing.assert_allclose(path["kappa"], 0.6, rtol=1e-9)
    assert np.all(np.diff(path["x"]) == pytest.approx(0.01))
    assert r.n_steps[0] in (349, 350)  # 3.5 / dl, up to rounding of the running sum


def test_steep_ramp_self_locks_at_once_and_gentle_one_does_not():
    p = StreamlineParams(mu=0.5, dl=0.01)
    steep = streamlines(_plane(2.2), [(0.0, 0.0)], p)  # slope > 1/mu
    assert steep.outcome[0] == Outcome.SELF_LOCKED and steep.n_steps[0] == 0
    assert np.isposinf(steep.max_kappa[0])
    gentle = streamlines(_plane(1.5), [(0.0, 0.0)], p)
    assert gentle.outcome[0] == Outcome.LEFT_DOMAIN
    # kappa on a 2-D ramp is tan(theta + phi)
    path = gentle.path(0)
    inner = path["x"] < 1.5  # the spline's edge extension is exact only to O(h^3)
    np.testing.assert_allclose(path["kappa"][inner], math.tan(math.atan(1.5) + math.atan(0.5)), rtol=1e-6)


def test_y_mirror_symmetry_of_streamlines():
    surf = single_gaussian(sign=-1)
    p = StreamlineParams(mu=MU)
    r = streamlines(surf, [(-3.0, -1.3), (-3.0, 1.3)], p)
    a, b = r.path(0), r.path(1)
    assert r.outcome[0] == r.outcome[1]
    np.testing.assert_allclose(a["x"], b["x"], atol=1e-9)
    np.testing.assert_allclose(a["y"], -b["y"], atol=1e-9)


def test_ideal_keeps_y_and_step_cap():
    surf = single_gaussian(sign=1)
    p = StreamlineParams(mu=MU, dl=0.02)
    r = ideal_trajectories(surf, FIVE_STARTS, p)
    for i in range(5):
        assert np.all(r.path(i)["y"] == FIVE_STARTS[i][1])
    capped = streamlines(surf, FIVE_STARTS, StreamlineParams(mu=MU, max_steps=10))
    assert np.all(capped.outcome == Outcome.STEP_CAP)
    assert np.all(capped.n_steps == 10)


def _polyline_distance(a, b):
    pa, pb = np.c_[a["x"], a["y"]], np.c_[b["x"], b["y"]]
    return max(cKDTree(pb).query(pa)[0].max(), cKDTree(pa).query(pb)[0].max())


@pytest.mark.parametrize("preset", ["paper-single-peak", "paper-single-valley"])
def test_halving_dl_converges(preset):
    surf = make_surface(preset)
    sigma = 1.5
    starts = FIVE_STARTS + [(-3.0, y) for y in (-2.5, -1.5, 0.7, 2.2)]
    coarse = streamlines(surf, starts, StreamlineParams(mu=MU, dl=0.01 * sigma))
    fine = streamlines(surf, starts, StreamlineParams(mu=MU, dl=0.005 * sigma))
    np.testing.assert_array_equal(coarse.outcome, fine.outcome)
    for i in range(len(starts)):
        assert _polyline_distance(coarse.path(i), fine.path(i)) < 0.01 * sigma


def test_regions_along_path_are_consistent():
    surf = single_gaussian(sign=-1)
    r = streamlines(surf, FIVE_STARTS, StreamlineParams(mu=MU))
    for i in np.flatnonzero(r.self_locked):
        path = r.path(i)
        assert path["region"][-1] == SELF_LOCK
        assert np.all(path["region"][:-1] != SELF_LOCK)
    assert np.any(r.region == ENGAGED)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_edge_margin_ends_the_path_that_far_from_the_edge(backend):
    """Flat ground, +x: with a margin m the path ends LEFT_DOMAIN at its last step before
    x = xmax - m (within one step), the same path as without it up to there."""
    surf = _plane(0.0)
    p = StreamlineParams(mu=0.6, dl=0.01)
    full = streamlines(surf, [(-1.5, 0.3)], p, backend=backend)
    cut = streamlines(
        surf, [(-1.5, 0.3)], StreamlineParams(mu=0.6, dl=0.01, edge_margin=0.25), backend=backend
    )
    assert cut.outcome[0] == Outcome.LEFT_DOMAIN
    assert 2.0 - 0.25 - 0.01 < cut.end_x[0] <= 2.0 - 0.25
    n = cut.path(0)["x"].size
    np.testing.assert_array_equal(cut.path(0)["x"], full.path(0)["x"][:n])
    with pytest.raises(SpineInputError, match="edge_margin"):
        StreamlineParams(mu=0.6, edge_margin=-1.0)


def test_bad_input_names_the_argument():
    surf = single_gaussian()
    with pytest.raises(SpineInputError, match="starts must lie inside"):
        streamlines(surf, [(6.0, 0.0)], StreamlineParams(mu=1.0))
    with pytest.raises(SpineInputError, match=r"shape \(n, 2\)"):
        streamlines(surf, [[1.0, 2.0, 3.0]], StreamlineParams(mu=1.0))
    with pytest.raises(SpineInputError, match="dl"):
        StreamlineParams(mu=1.0, dl=-0.1)
    # steps no path can use: across the whole domain (10 wide), or lost in x + dl
    with pytest.raises(SpineInputError, match=r"dl must be smaller than the surface's domain \(10 across\)"):
        streamlines(surf, [(0.0, 0.0)], StreamlineParams(mu=1.0, dl=10.0))
    with pytest.raises(SpineInputError, match="dl must be at least 1e-09 of the surface's coordinates"):
        ideal_trajectories(surf, [(0.0, 0.0)], StreamlineParams(mu=1.0, dl=1e-12))
    with pytest.raises(SpineInputError, match="mu"):
        StreamlineParams(mu=0.0)
    with pytest.raises(SpineInputError, match="radius"):
        dilate(surf, -1.0)
    with pytest.raises(SpineInputError, match="max_halvings"):
        StreamlineParams(mu=1.0, max_halvings=-1)


# --------------------------------------------------------------------------- step control


def _groove(width=0.1, depth=0.25, descent=0.02):
    """A Gaussian groove along x whose floor descends gently in +x (slope ``descent``,
    engaged with mu = 0.5) between flanks steeper than the friction angle (up to 1.52)."""
    x = np.linspace(-2.0, 2.0, 401)
    heights = -descent * x[None, :] - depth * np.exp(-0.5 * (x[:, None] / width) ** 2)
    return GridSurface(heights=heights, x=x, y=x.copy())


def test_step_control_follows_a_groove_floor_that_fixed_steps_stall_in():
    """A step three groove widths long overshoots the floor from one flank to the other
    and back (gravity alone slides the tip down either flank, almost across the drive), so
    fixed steps stall where the path itself reaches the floor, is driven along it (engaged,
    kappa ~ mu) and leaves the domain. The controlled step follows the floor like a step
    shorter than the groove does."""
    surf, width = _groove(), 0.1
    start = [(-1.5, 0.25)]
    fixed = streamlines(surf, start, StreamlineParams(mu=0.5, dl=3 * width, max_halvings=0))
    assert fixed.outcome[0] == Outcome.STALLED and fixed.end_x[0] < 0
    resolved = streamlines(surf, start, StreamlineParams(mu=0.5, dl=0.2 * width, max_halvings=0))
    assert resolved.outcome[0] == Outcome.LEFT_DOMAIN
    p = StreamlineParams(mu=0.5, dl=3 * width)
    for backend in ("numba", "numpy"):
        res = streamlines(surf, start, p, backend=backend)
        assert res.outcome[0] == Outcome.LEFT_DOMAIN
        assert res.end_x[0] > 2.0 - 3 * width
        path = res.path(0)
        on_floor = path["x"] > -1.0  # past the slide down the first flank
        assert np.abs(path["y"][on_floor]).max() < 0.2 * width
    _same(streamlines(surf, start, p, backend="numba"), streamlines(surf, start, p, backend="numpy"), 1e-9)


def test_step_controlled_groove_path_converges_as_dl_shrinks():
    """Past the slide down the first flank the resolved path (steps a tenth of the groove
    width, none reversing) runs on the floor, y = 0; the controlled path's largest distance
    from it falls as dl shrinks, with the same outcome."""
    surf, width = _groove(), 0.1
    start = [(-1.5, 0.25)]

    def offset(res):
        path = res.path(0)
        return np.abs(path["y"][path["x"] > -1.0]).max()

    fine = streamlines(surf, start, StreamlineParams(mu=0.5, dl=0.1 * width))
    assert fine.outcome[0] == Outcome.LEFT_DOMAIN and offset(fine) < 1e-6 * width
    gaps = []
    for dl in (3 * width, 1.5 * width, 0.5 * width, 0.2 * width):
        res = streamlines(surf, start, StreamlineParams(mu=0.5, dl=dl))
        assert res.outcome[0] == Outcome.LEFT_DOMAIN
        gaps.append(offset(res))
    assert all(b <= a for a, b in itertools.pairwise(gaps)), gaps
    assert gaps[0] < 0.2 * width and gaps[-1] < 1e-6 * width


def test_step_controlled_kernel_matches_reference_with_more_starts_than_lanes():
    """Rejected steps, halvings and regrowth in the kernel's lanes (refilled as paths end)
    give the reference's paths point for point."""
    surf = _groove()
    starts = np.c_[np.full(40, -1.5), np.linspace(-0.6, 0.6, 40)]
    p = StreamlineParams(mu=0.5, dl=0.3, stall_window=16)
    _same(streamlines(surf, starts, p, backend="numba"), streamlines(surf, starts, p, backend="numpy"), 1e-9)


@pytest.mark.parametrize("sign", [1, -1])
def test_step_control_leaves_resolved_paths_alone(sign):
    """On the paper's single peak and valley at the paper's step no slip direction
    reverses: the controlled paths are the fixed-step ones, point for point."""
    surf = single_gaussian(sign=sign)
    controlled = streamlines(surf, FIVE_STARTS, StreamlineParams(mu=MU, dl=0.015))
    fixed = streamlines(surf, FIVE_STARTS, StreamlineParams(mu=MU, dl=0.015, max_halvings=0))
    _same(controlled, fixed, 0.0)


# --------------------------------------------------------------------------- finite tip


def _hemisphere(radius=1.0, half=2.6, h=0.02):
    x = np.arange(-half, half + h / 2, h)
    rho2 = x[None, :] ** 2 + x[:, None] ** 2
    heights = np.sqrt(np.clip(radius**2 - rho2, 0, None))
    return GridSurface(heights=heights, x=x, y=x.copy()), x, rho2


def test_dilation_of_a_hemisphere_matches_the_closed_form():
    big, r = 1.0, 0.5
    surf, _, rho2 = _hemisphere(big)
    g = dilate(surf, r)
    exact = np.maximum(r, np.sqrt(np.clip((big + r) ** 2 - rho2, 0, None))) - r
    assert np.abs(g.heights - exact).max() < 0.01
    # steepest slope met by the tip centre along the centre line: arccos(r / (R + r))
    xs = np.linspace(-2.5, 0.0, 2001)
    fx, _ = g.gradient(xs, 0.0)
    steepest = math.degrees(math.atan(np.max(fx)))
    assert steepest == pytest.approx(math.degrees(math.acos(r / (big + r))), abs=2.0)


@pytest.mark.parametrize(("ratio", "locks"), [(4.0, True), (2.0, True), (0.9, False)])
def test_hemisphere_self_lock_threshold(ratio, locks):
    # mu = 0.5: self-lock possible only for R / r >= 1 / sin(arctan mu) - 1 = 1.236
    surf, _, _ = _hemisphere(1.0, h=0.03)
    g = dilate(surf, 1.0 / ratio)
    r = streamlines(g, [(-2.55, 0.0)], StreamlineParams(mu=0.5, dl=0.005))
    assert bool(r.self_locked[0]) is locks


def test_zero_radius_recovers_point_contact():
    surf = make_surface("paper-single-valley")
    p = StreamlineParams(mu=MU, dl=0.015)
    point = streamlines(surf, FIVE_STARTS, p)
    tiny = dilate(surf, 1e-3, spacing=0.01)
    assert np.abs(tiny.heights - surf.height(tiny.x[None, :], tiny.y[:, None])).max() < 1e-5
    near = streamlines(tiny, FIVE_STARTS, p)
    np.testing.assert_array_equal(point.outcome, near.outcome)
    for i in range(5):
        assert _polyline_distance(point.path(i), near.path(i)) < 0.01 * 1.5
    zero = dilate(surf, 0.0, spacing=0.05)
    np.testing.assert_allclose(zero.heights, surf.height(zero.x[None, :], zero.y[:, None]))


def test_stalled_trajectories_end_on_an_evaluated_point():
    """A stall (too little progress over a window) ends like every other outcome: at a
    point that was evaluated, so the end point is on the surface and is the path's last
    point, identically in the kernel and the reference."""
    surf = single_gaussian(sign=-1)
    starts = np.column_stack([np.full(7, -3.0), np.linspace(-4.0, -0.5, 7)])
    params = StreamlineParams(mu=1.25, dl=0.02, stall_window=25, stall_distance=1.0)
    fast = streamlines(surf, starts, params, backend="numba")
    ref = streamlines(surf, starts, params, backend="numpy")
    assert np.all(fast.outcome == Outcome.STALLED)
    np.testing.assert_array_equal(fast.n_steps, ref.n_steps)
    np.testing.assert_array_equal(fast.n_steps, 25)
    for res in (fast, ref):
        np.testing.assert_allclose(res.end_z, surf.height(res.end_x, res.end_y), atol=1e-12)
        for i in range(len(starts)):
            path = res.path(i)
            assert len(path["x"]) == res.n_steps[i] + 1
            last = [path["x"][-1], path["y"][-1], path["z"][-1]]
            np.testing.assert_allclose(last, [res.end_x[i], res.end_y[i], res.end_z[i]], atol=1e-12)


# --------------------------------------------------------------------------- step cap


def _capped_starts():
    # 40 starts (more than the kernel's 32 lanes) on the valley, too short a cap for any to end
    return np.c_[np.full(40, -3.0), np.linspace(-4.0, 4.0, 40)]


@pytest.mark.parametrize(("max_steps", "stall_window"), [(128, 64), (192, 64), (64, 16), (100, 64)])
def test_capped_paths_match_the_reference_when_the_cap_falls_on_a_progress_check(max_steps, stall_window):
    # A cap that is a multiple of stall_window (the default 200_000 is one of 64) coincides
    # with a progress check; the kernel used to end the path there, one point short, and
    # with two or more capped starts wrote the last start's points past its arrays.
    surf = single_gaussian(sign=-1)
    starts = _capped_starts()
    p = StreamlineParams(mu=MU, dl=0.001, max_steps=max_steps, stall_window=stall_window)
    for fn in (streamlines, ideal_trajectories):
        ref = fn(surf, starts, p, backend="numpy")
        assert np.all(ref.outcome == Outcome.STEP_CAP)
        for store in (True, False):
            got = fn(surf, starts, p, backend="numba", store_paths=store)
            np.testing.assert_array_equal(got.outcome, ref.outcome)
            np.testing.assert_array_equal(got.n_steps, max_steps)
            for key in ("end_x", "end_y", "end_z"):
                np.testing.assert_allclose(getattr(got, key), getattr(ref, key), atol=1e-9)
            if store:
                np.testing.assert_array_equal(got.offsets, ref.offsets)
                _same(got, ref, 1e-9)
                last = got.offsets[1:] - 1
                np.testing.assert_allclose(got.x[last], got.end_x, atol=1e-12)
                np.testing.assert_allclose(got.y[last], got.end_y, atol=1e-12)
                assert len(got.to_frame()) == got.offsets[-1]


def test_kernel_has_no_out_of_bounds_access_on_capped_paths(monkeypatch):
    # numba does not bounds-check the kernel (boundscheck=False): compile its Python source
    # again with checks on, so any index past an array raises IndexError instead of
    # silently writing outside it, and run it on capped, ragged and locking starts.
    from numba import njit

    import spine_mj.theory.streamline as sl
    from spine_mj.theory import _kernels

    checked = njit(boundscheck=True, fastmath=_kernels._FM, error_model="numpy")(
        _kernels.run_trajectories.py_func
    )
    monkeypatch.setattr(sl, "_get_kernel", lambda: checked)
    surf = single_gaussian(sign=-1)
    ragged = np.c_[np.linspace(-4.8, 0.0, 45), np.linspace(-4.8, 4.8, 45)]
    for starts, dl in ((_capped_starts(), 0.001), (ragged, 0.05)):
        p = StreamlineParams(mu=MU, dl=dl, max_steps=128)
        for store in (True, False):
            got = streamlines(surf, starts, p, backend="numba", store_paths=store)
            ref = streamlines(surf, starts, p, backend="numpy", store_paths=store)
            np.testing.assert_array_equal(got.outcome, ref.outcome)
            np.testing.assert_array_equal(got.n_steps, ref.n_steps)
            if store:
                _same(got, ref, 1e-9)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_force_cap_ends_a_path_where_kappa_first_exceeds_it(backend):
    """The shared force cap: the capped path is the uncapped one cut at its first point of
    kappa > cap (held there, FORCE_CAP); a cap above the path's largest kappa changes nothing."""
    surf = single_gaussian(sign=1)
    free = streamlines(surf, FIVE_STARTS, StreamlineParams(mu=MU, dl=0.015), backend=backend)
    finite = np.where(np.isfinite(free.max_kappa), free.max_kappa, np.nan)
    cap = float(np.nanmin(finite[finite > 2.0])) * 0.9  # below one path's finite peak kappa
    capped = streamlines(surf, FIVE_STARTS, StreamlineParams(mu=MU, dl=0.015, kappa_cap=cap), backend=backend)
    hit = 0
    for i in range(len(free)):
        k = free.path(i)["kappa"]
        over = np.flatnonzero(np.isfinite(k) & (k > cap))
        if free.outcome[i] == Outcome.SELF_LOCKED and (over.size == 0 or over[0] == k.size - 1):
            assert capped.outcome[i] == Outcome.SELF_LOCKED
            continue
        if over.size == 0:
            assert capped.outcome[i] == free.outcome[i]
            assert capped.n_steps[i] == free.n_steps[i]
            continue
        hit += 1
        assert capped.outcome[i] == Outcome.FORCE_CAP and capped.self_locked[i]
        assert capped.n_steps[i] == over[0]
        np.testing.assert_array_equal(capped.path(i)["x"], free.path(i)["x"][: over[0] + 1])
    assert hit >= 1
    above = StreamlineParams(mu=MU, dl=0.015, kappa_cap=1e6)
    again = streamlines(surf, FIVE_STARTS, above, backend=backend)
    np.testing.assert_array_equal(again.outcome, free.outcome)
    np.testing.assert_array_equal(again.n_steps, free.n_steps)


def test_force_cap_kernel_matches_numpy_reference():
    grid = fractal_fbm(nx=64, size=20.0, hurst=0.8, rms_slope=0.6, rng=2)
    starts = np.c_[np.full(12, -9.5), np.linspace(-8, 8, 12)]
    p = StreamlineParams(mu=1.0, dl=0.03, kappa_cap=3.0)
    a, b = streamlines(grid, starts, p, backend="numba"), streamlines(grid, starts, p, backend="numpy")
    _same(a, b, 1e-8)
    assert (a.outcome == Outcome.FORCE_CAP).any()


def test_a_crease_descending_along_the_drive_is_followed_at_its_two_contact_kappa():
    """A V-groove whose floor descends gently along the drive: on either flank the slip
    direction points across the crease (a single-contact path would zig-zag there); the path
    follows the crease at the two-contact kappa of its flanks (crease_engagement)."""
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface
    from spine_mj.theory.engagement import crease_engagement

    x = np.linspace(0.0, 1.0, 21)
    y = np.linspace(-0.5, 0.5, 21)
    groove = TriangulatedSurface(heights=2.0 * np.abs(y)[:, None] - 0.1 * x[None, :], x=x, y=y)
    params = StreamlineParams(mu=0.5, dl=0.01, max_steps=100_000)
    res = streamlines(BallOnFacets(groove, 0.05), [(0.3, 0.12)], params)
    assert res.outcome[0] == Outcome.LEFT_DOMAIN and res.n_steps[0] < 1000
    k = float(crease_engagement(-0.1, 2.0, -0.1, -2.0, 0.5)[0])
    assert res.max_kappa[0] == pytest.approx(k, rel=1e-9)


def test_a_ball_slides_along_a_v_groove_at_the_wedge_kappa():
    """Flanks steeper than the friction angle and a flat floor along the drive: the path
    follows the crease on two contacts to the edge, at kappa = mu / cos(theta)."""
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface

    x = np.linspace(0.0, 1.0, 21)
    y = np.linspace(-0.5, 0.5, 21)
    groove = TriangulatedSurface(heights=np.broadcast_to(2.0 * np.abs(y)[:, None], (21, 21)), x=x, y=y)
    res = streamlines(BallOnFacets(groove, 0.05), [(0.3, 0.12)], StreamlineParams(mu=0.5, dl=0.01))
    assert res.outcome[0] == Outcome.LEFT_DOMAIN
    assert res.end_x[0] > 0.98 and abs(res.end_y[0]) < 1e-3
    assert res.max_kappa[0] == pytest.approx(0.5 * math.sqrt(5.0), rel=1e-9)


def _same_facets(a, b):
    """The compiled facet walk against the reference: the same outcomes, steps and regions,
    points within rounding (the same operations in the same order; compared with a
    tolerance, as floats from two code paths on any CPU)."""
    _same(a, b, 1e-9)
    for key in ("end_x", "end_y", "end_z", "max_kappa", "kappa"):
        np.testing.assert_allclose(getattr(a, key), getattr(b, key), rtol=1e-9, atol=1e-12, err_msg=key)


def test_facet_kernel_matches_the_reference_on_a_rough_ball_path(monkeypatch):
    """A ball on a steep fractal's facets: wedges in concave creases (held on two contacts,
    some only by the friction-cone bound, which the kernel asks its caller for), creases
    followed, self-locks, a stall and the edge; paths and summaries as the numpy reference's."""
    import spine_mj.theory.streamline as sl_module
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface

    grid = fractal_fbm(nx=48, size=6.0, hurst=0.7, rms_slope=1.0, rng=0)
    ball = BallOnFacets(TriangulatedSurface.from_grid(grid), 0.125)
    starts = np.c_[np.full(10, -2.0), np.linspace(-2.5, 2.5, 10)]
    params = StreamlineParams(mu=0.5, dl=0.125 / 8, kappa_cap=20.0)
    asked = []
    answer = sl_module._two_contact_kappa
    monkeypatch.setattr(sl_module, "_two_contact_kappa", lambda *a: asked.append(a[0].size) or answer(*a))
    fast = streamlines(ball, starts, params, backend="numba")
    assert sum(asked) > 10  # the kernel paused on the bound and resumed
    assert {Outcome.SELF_LOCKED, Outcome.LEFT_DOMAIN, Outcome.STALLED} <= set(fast.outcome.tolist())
    _same_facets(fast, streamlines(ball, starts, params, backend="numpy"))
    brief = streamlines(ball, starts, params, store_paths=False)
    np.testing.assert_array_equal(brief.n_steps, fast.n_steps)
    np.testing.assert_allclose(brief.end_x, fast.end_x, rtol=0, atol=1e-12)
    a, b = (ideal_trajectories(ball, starts, params, backend=k) for k in ("numba", "numpy"))
    _same_facets(a, b)


@pytest.mark.parametrize("descent", [0.0, 0.1])
def test_facet_kernel_follows_a_v_groove_as_the_reference(descent):
    """The crease state (a reversal at the shortest step, then the crease followed on two
    contacts) in the compiled facet walk, against the reference."""
    from spine_mj.surfaces import BallOnFacets, TriangulatedSurface

    x = np.linspace(0.0, 1.0, 21)
    y = np.linspace(-0.5, 0.5, 21)
    groove = TriangulatedSurface(heights=2.0 * np.abs(y)[:, None] - descent * x[None, :], x=x, y=y)
    ball = BallOnFacets(groove, 0.05)
    params = StreamlineParams(mu=0.5, dl=0.01, max_steps=100_000)
    starts = [(0.3, 0.12), (0.2, -0.3), (0.5, 0.05)]
    _same_facets(*(streamlines(ball, starts, params, backend=k) for k in ("numba", "numpy")))

"""Predicted drive limits against closed forms (docs/physics.md §8)."""

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
import pytest

from spine_mj import roughness
from spine_mj.errors import SpineInputError
from spine_mj.sim.holding import spring_swing
from spine_mj.surfaces import GaussianSurface, Surface, corrugation
from spine_mj.surfaces.dilation import dilate
from spine_mj.theory import streamline as sl
from spine_mj.theory.compliant import compliant_streamlines
from spine_mj.theory.drive_limits import (
    CORNER_MARGIN,
    SWING_BOUND_FP,
    ball_crest_bound,
    crest_curvature,
    drive_limits,
    quasistatic_corner,
    spring_ie_limits,
    trap_depths,
)
from spine_mj.theory.path_stiffness import (
    PATH_STIFFNESS_RESOLUTION,
    kappa_fall,
    path_criterion,
    path_stiffness,
    spring_run_travel,
    start_scores,
)
from spine_mj.theory.streamline_types import StreamlineParams

#: The path tolerance the corner's swing bound uses by default (the Frechet target, L_c).
FRECHET_TARGET_LC = 0.1


@dataclass(frozen=True, eq=False)
class Wall(Surface):
    """Flat, then a wall of slope ``t`` from x = 0 to x = w, then flat again."""

    t: float
    w: float
    bounds: tuple = (-1.0, 2.0, -0.5, 0.5)
    unit: str = "1"
    metadata: dict = field(default_factory=dict)

    def _evaluate(self, x, y, order):
        on = (x > 0) & (x < self.w)
        out = (self.t * np.clip(x, 0, self.w), np.where(on, self.t, 0.0), np.zeros_like(x))
        return out[:1] if order == 0 else out


@dataclass(frozen=True, eq=False)
class Tilted(Surface):
    """A corrugation of steepest slope ``s`` and unit wavelength whose crests run at ``phi``
    to the y axis: a fold's jump (along ``F u_x + W g``) leaves the slide's direction."""

    s: float = 0.4
    phi: float = 0.5
    bounds: tuple = (0.0, 4.0, -1.5, 1.5)
    unit: str = "1"
    metadata: dict = field(default_factory=dict)

    def _evaluate(self, x, y, order):
        c, sn = np.cos(self.phi), np.sin(self.phi)
        u = 2 * np.pi * (x * c + y * sn)
        out = (self.s / (2 * np.pi) * np.sin(u), self.s * np.cos(u) * c, self.s * np.cos(u) * sn)
        return out[:1] if order == 0 else out


def _left_starts(surf, n):
    xmin, xmax, ymin, ymax = surf.bounds
    return np.column_stack([np.full(n, xmin + 0.05 * (xmax - xmin)), np.linspace(ymin + 0.3, ymax - 0.3, n)])


@pytest.mark.parametrize("s, mu", [(0.3, 0.5), (0.5, 0.8)])
def test_corrugation_k_star_is_prandtl_tomlinson(s, mu):
    surf = corrugation(slope_amplitude=s, n_waves=4, points_per_wave=64)
    d = drive_limits(surf, mu, n_starts=3)
    u = np.linspace(0, 2 * np.pi, 100_001)
    t = s * np.cos(u)
    fall = ((1 + mu * mu) * s * 2 * np.pi * np.sin(u) / (1 - mu * t) ** 2).max()
    assert d.max_fall == pytest.approx(fall, rel=5e-3)
    assert d.slope_length == pytest.approx(0.190, rel=0.01)
    assert d.k_star == pytest.approx(d.slope_length * fall, rel=5e-3)
    if (s, mu) == (0.3, 0.5):
        assert d.k_star == pytest.approx(0.47, abs=0.01)
    # crests: -f'' = s 2 pi / lambda, lift-off at I_e = 1 / (L_c s 2 pi)
    assert d.max_crest_curvature == pytest.approx(2 * np.pi * s, rel=5e-3)
    assert d.ie_lift == pytest.approx(1 / (d.char_length * 2 * np.pi * s), rel=5e-3)
    assert d.n_traps == 0 and d.ie_trap == math.inf
    assert d.ie_lag == pytest.approx(2 * mu * 0.1)  # stopping distance I_e L_c / (2 mu) = 0.1 L_c
    assert d.ie_star == min(d.ie_lift, d.ie_lag) and d.limit == (
        "lag" if d.ie_lag < d.ie_lift else "lift-off"
    )
    assert "quasistatic needs K > " in d.sentence()


def test_progress_hears_a_big_dilation_row_by_row_and_changes_nothing(monkeypatch):
    """A tip 3 rows of samples wide: rows 1..3 of 3 once the dilation counts as big (a
    small one is silent), and the limits are those computed without a listener."""
    from spine_mj.surfaces import dilation

    surf = corrugation(slope_amplitude=0.3, n_waves=4, points_per_wave=64)
    tip = 2.5 * surf.spacing[1]
    heard = []
    quiet = drive_limits(surf, 0.5, n_starts=2, tip_radius=tip, progress=lambda *a: heard.append(a))
    assert heard == []
    monkeypatch.setattr(dilation, "PROGRESS_MIN_WORK", 0)
    d = drive_limits(surf, 0.5, n_starts=2, tip_radius=tip, progress=lambda *a: heard.append(a))
    assert heard == [(1, 3), (2, 3), (3, 3)]
    assert d == quiet


@pytest.mark.parametrize("amp, sigma", [(0.5, 1.0), (0.3, 0.6)])
def test_gaussian_ridge_lift_off(amp, sigma):
    ridge = GaussianSurface(
        amplitude=np.array([amp]),
        center_x=np.array([0.0]),
        center_y=np.array([0.0]),
        sigma_x=np.array([sigma]),
        sigma_y=np.array([1e6]),
        bounds=(-5.0, 5.0, -1.0, 1.0),
    )
    d = drive_limits(ridge, 1.0, n_starts=3, dl=0.01)
    assert d.max_crest_curvature == pytest.approx(amp / sigma**2, rel=1e-3)
    assert d.ie_lift == pytest.approx(1.0 / (d.char_length * amp / sigma**2), rel=1e-3)


def test_trap_depth_of_a_wall_is_the_work_to_its_top():
    mu, t, w = 0.5, 3.0, 0.4  # slope 3 > 1 / mu: self-locked
    wall = Wall(t, w)
    got = trap_depths(wall, [0.001], [0.0], [mu], mu, step=1e-4, kappa_cap=20.0)
    dz, dx = t * (w - 0.001), w - 0.001
    assert got[0] == pytest.approx(dz + mu * dx + mu * (mu * dz - dx), abs=2e-3)
    d = drive_limits(wall, mu, starts=[(-0.5, 0.0), (-0.5, 0.2)], dl=0.01, path_tolerance=10.0)
    assert d.n_traps == 2 and d.ie_star == d.ie_trap and d.limit == "trap"
    assert d.min_trap_depth == pytest.approx(t * w + mu * w + mu * (mu * t * w - w), rel=0.05)
    assert d.ie_trap == pytest.approx(2 * d.min_trap_depth / d.char_length)


def test_a_jump_along_a_corrugation_leaves_the_trace_and_the_outcome_as_they_were():
    # Prandtl-Tomlinson: below K* every wave folds, but on a profile uniform in y the jump
    # runs along the path: the criterion cannot see it (K_path is no boundary at all there)
    surf = corrugation(slope_amplitude=0.5, n_waves=3, points_per_wave=64)
    mu, starts = 0.8, _left_starts(surf, 2)
    params = StreamlineParams(mu=mu, dl=0.005)
    rigid = sl.streamlines(surf, starts, params, store_paths=True)
    k_star = drive_limits(surf, mu, n_starts=2, dl=0.005).k_star
    ls = roughness.slope_correlation_length(surf)
    soft = compliant_streamlines(surf, starts, params, stiffness=0.1 * k_star / ls)
    assert soft.folds.start.size >= 2 * 2  # every wave of both paths jumps
    agreement, frechet = path_criterion(rigid, soft, roughness.characteristic_length(surf))
    assert agreement == 1.0 and frechet < 0.01


def test_k_path_is_where_the_compliant_paths_stop_meeting_the_criterion_below_the_fold():
    surf, mu = Tilted(), 0.8
    starts = _left_starts(surf, 3)
    ls, lc = roughness.slope_correlation_length(surf), roughness.characteristic_length(surf)
    params = StreamlineParams(mu=mu, dl=ls / 40)
    k_path, k_fold, _ = path_stiffness(surf, starts, params, slope_length=ls, char_length=lc)
    rigid = sl.streamlines(surf, starts, params, store_paths=True)

    def criterion(k):
        return path_criterion(rigid, compliant_streamlines(surf, starts, params, stiffness=k / ls), lc)

    assert 0 < k_path < k_fold  # no fold above k_fold: the two paths are one
    assert criterion(k_fold) == (1.0, pytest.approx(0.0, abs=1e-9))
    agree, frechet = criterion(k_path)
    assert agree >= 0.95 and frechet <= 0.1
    agree, frechet = criterion(k_path / PATH_STIFFNESS_RESOLUTION)
    assert agree < 0.95 or frechet > 0.1
    # folds below the fold K* that the criterion does not see: the sub-threshold jumps
    between = compliant_streamlines(surf, starts, params, stiffness=np.sqrt(k_path * k_fold) / ls)
    assert between.folds.start.size > 0


WALL_MU, WALL_SLOPE, WALL_WIDTH, WALL_X0 = 0.5, 1.5, 0.4, -0.5


def _wall_case():
    """``(wall, starts, params, edge, l_s)``: two starts before a wall of slope 1.5 and width
    0.4 on flat ground, mu 0.5, l_s 0.7 (the K_path tests' case)."""
    wall = Wall(WALL_SLOPE, WALL_WIDTH)
    starts = np.array([(WALL_X0, 0.0), (WALL_X0, 0.2)])
    return wall, starts, StreamlineParams(mu=WALL_MU, dl=0.01), wall.bounds[1], 0.7


def test_k_path_with_the_runs_travel_is_where_their_carriage_stops_short_of_a_hold():
    # a wall of hold H = (t + mu) / (1 - mu t) = 8 > 1 + mu between flat ground: the tip
    # climbs it with the carriage at x + H l_s / K, and a run's carriage, stopped
    # 1.1 d + (1 + mu) l_s / K past the start (d: to the +x edge), leaves it at the wall's
    # top (x = w) below K = (H - 1 - mu) l_s / (1.1 d - (w - x0)), where the rigid path
    # goes on to the edge; the fold at the top (H falls to mu) jumps along the path
    mu, t, w, x0 = WALL_MU, WALL_SLOPE, WALL_WIDTH, WALL_X0
    wall, starts, params, edge, ls = _wall_case()
    hold = (t + mu) / (1 - mu * t)
    k_travel = (hold - 1 - mu) * ls / (1.1 * (edge - x0) - (w - x0))
    k_path, k_fold, _ = path_stiffness(
        wall, starts, params, slope_length=ls, char_length=1.0, carriage_edge=edge
    )
    assert k_travel <= k_path <= k_travel * PATH_STIFFNESS_RESOLUTION
    endless, _, _ = path_stiffness(wall, starts, params, slope_length=ls, char_length=1.0)
    assert endless < k_travel < k_fold
    # a softer spring stops the tip on the wall, where the stopped carriage holds it
    k = k_travel / 1.1
    end = x0 + spring_run_travel(edge - x0, ls / k, mu)
    stopped = compliant_streamlines(wall, starts, params, stiffness=k / ls, carriage_end=end)
    assert stopped.end_x == pytest.approx([end - hold * ls / k] * 2, abs=0.01)
    assert 0 < end - hold * ls / k < w
    # a hold beyond the force cap is a lock at its foot (x = 0), which the run decides at
    # kappa_cap F_p: the carriage need only reach kappa_cap l_s / K past it
    capped = dataclasses.replace(params, kappa_cap=5.0)
    k_cap = (5.0 - 1 - mu) * ls / (1.1 * (edge - x0) - (0.0 - x0))
    k_path, _, _ = path_stiffness(wall, starts, capped, slope_length=ls, char_length=1.0, carriage_edge=edge)
    assert k_cap <= k_path <= k_cap * PATH_STIFFNESS_RESOLUTION
    assert spring_run_travel(2.0, 0.5, 0.3) == pytest.approx(1.1 * 2.0 + 1.3 * 0.5)
    assert spring_run_travel(-1.0, 0.5, 0.3) == pytest.approx(1.3 * 0.5)  # none past the edge


def test_the_spring_swing_limits_invert_the_spring_block_amplitudes():
    k, ratio, t = 30.0, 0.8, 0.1
    lim = spring_ie_limits(k, ratio, path_tolerance=t, force_bound=1.0)
    # force: V sqrt(k m) = sqrt(I_e K L_c / l_s) F_p reaches F_p
    assert spring_swing(lim["swing-force"], k, ratio) == pytest.approx(1.0)
    # position: V / w = L_c sqrt(I_e / (K L_c / l_s)) reaches t L_c
    assert math.sqrt(lim["swing-path"] / (k * ratio)) == pytest.approx(t)
    assert lim["swing-path"] * lim["swing-force"] == pytest.approx(t**2)  # widest at K_c = 1 / t
    assert spring_ie_limits(float("nan"), ratio) == {"swing-path": math.inf, "swing-force": math.inf}


def test_the_corner_margin_puts_first_order_errors_at_the_frechet_resolution():
    from spine_mj.theory.targets import FRECHET_TARGET
    from spine_mj.validate.theory_orders import FRECHET_FLOOR_LC, PREDICTED_ORDERS

    # lag ~ I_e and compliant offset ~ 1 / K, both reaching the target at the limit
    assert PREDICTED_ORDERS == {"ie": 1.0, "inverse_k": 1.0}
    assert FRECHET_TARGET / CORNER_MARGIN == pytest.approx(FRECHET_FLOOR_LC)


@pytest.mark.parametrize("amp, sigma", [(0.5, 1.0), (0.3, 0.6)])
def test_corner_of_a_ridge_is_a_tenth_of_its_closed_form_lift_off(amp, sigma):
    ridge = GaussianSurface(
        amplitude=np.array([amp]),
        center_x=np.array([0.0]),
        center_y=np.array([0.0]),
        sigma_x=np.array([sigma]),
        sigma_y=np.array([1e6]),
        bounds=(-5.0, 5.0, -1.0, 1.0),
    )
    mu = 10.0  # lag at 2 mu 0.1 = 2: lift-off sets I_e*
    d = drive_limits(ridge, mu, n_starts=3, dl=0.01)
    lift = 1.0 / (d.char_length * amp / sigma**2)  # -z'' = amp / sigma^2 on the crest
    assert d.limit == "lift-off"
    # a soft enough K (the ridge's L_c is its length, so K_c = K L_c / l_s is large)
    ratio = d.char_length / d.slope_length
    c = quasistatic_corner(ie_star=d.ie_star, k_path=math.nan, k_star=0.1, lc_over_ls=ratio, ie_limit=d.limit)
    assert c.ie_bound == "I_e*" and c.k_bound == "K*" and c.k == 0.1 * CORNER_MARGIN
    assert lift / CORNER_MARGIN / 2 < c.ie <= lift / CORNER_MARGIN * (1 + 1e-3)
    assert f"{c.ie:.1g}" == f"{c.ie:.6g}"  # one digit
    assert c.swing_fp == pytest.approx(spring_swing(c.ie, c.k, ratio))
    assert c.swing_fp <= SWING_BOUND_FP and "lift-off" in c.reason


def test_corner_k_is_the_margin_over_the_prandtl_tomlinson_fold():
    s, mu = 0.3, 0.5
    surf = corrugation(slope_amplitude=s, n_waves=4, points_per_wave=64)
    d = drive_limits(surf, mu, n_starts=3)
    u = np.linspace(0, 2 * np.pi, 100_001)
    k_pt = d.slope_length * ((1 + mu * mu) * s * 2 * np.pi * np.sin(u) / (1 - mu * s * np.cos(u)) ** 2).max()
    c = quasistatic_corner(
        ie_star=d.ie_star, k_path=math.nan, k_star=d.k_star, lc_over_ls=d.char_length / d.slope_length
    )
    assert CORNER_MARGIN * k_pt <= c.k * (1 + 5e-3) and c.k <= CORNER_MARGIN * k_pt * 1.1  # two digits, up
    # K_path, where given, is what K is the margin over
    assert quasistatic_corner(ie_star=0.1, k_path=7.3, k_star=d.k_star, lc_over_ls=1.0).k == 73.0


def test_corner_swing_bounds():
    # a stiff K on a long L_c: the force swing sqrt(I_e K L_c / l_s) sets I_e at <= 1 F_p
    c = quasistatic_corner(ie_star=1.0, k_path=300.0, lc_over_ls=24.0)
    kc = c.k * 24.0
    assert c.k == 3000.0 and c.ie_bound == "swing-force"
    assert 0.5 / kc < c.ie <= 1.0 / kc and c.swing_fp <= SWING_BOUND_FP
    # a soft K: the position swing L_c sqrt(I_e / K_c) at a tenth of the path tolerance
    c = quasistatic_corner(ie_star=1.0, k_path=0.05, lc_over_ls=2.0)
    kc = c.k * 2.0
    assert c.ie_bound == "swing-path"
    assert math.sqrt(c.ie / kc) <= FRECHET_TARGET_LC / CORNER_MARGIN < 2 * math.sqrt(c.ie / kc)
    # every bound holds at once, whichever sets I_e
    for ie_star, k_path, ratio in [(3e-5, 29.0, 24.0), (0.25, 2.0, 1.0), (1e-3, 100.0, 0.5)]:
        c = quasistatic_corner(ie_star=ie_star, k_path=k_path, lc_over_ls=ratio)
        assert c.ie <= ie_star / CORNER_MARGIN and c.swing_fp <= SWING_BOUND_FP
        assert math.sqrt(c.ie / (c.k * ratio)) <= FRECHET_TARGET_LC / CORNER_MARGIN
        assert c.as_dict()["ie"] == c.ie and c.as_dict()["K"] == c.k


def test_corner_bad_input():
    with pytest.raises(SpineInputError, match="ie_star"):
        quasistatic_corner(ie_star=float("nan"), k_path=1.0, lc_over_ls=1.0)
    with pytest.raises(SpineInputError, match="lc_over_ls"):
        quasistatic_corner(ie_star=1e-3, k_path=1.0, lc_over_ls=-1.0)
    with pytest.raises(SpineInputError, match="K_path"):
        quasistatic_corner(ie_star=1e-3, k_path=float("nan"), k_star=0.0, lc_over_ls=1.0)
    with pytest.raises(SpineInputError, match="margin"):
        quasistatic_corner(ie_star=1e-3, k_path=1.0, lc_over_ls=1.0, margin=1.0)
    # a path criterion met at any K (K_path ~ 0) gives no scale: the floor sets K
    c = quasistatic_corner(ie_star=0.1, k_path=1e-5, lc_over_ls=16.9, k_floor=30.0)
    assert c.k == 30.0 and c.k_bound == "floor" and c.swing_fp <= SWING_BOUND_FP
    # no limit from the geometry (a plane): the swing alone sets I_e
    assert quasistatic_corner(ie_star=math.inf, k_path=1.0, lc_over_ls=1.0).ie_bound.startswith("swing")


def test_finite_differences_on_closed_forms():
    x = np.linspace(0, 1, 11)
    np.testing.assert_allclose(kappa_fall(x, 2 - 3 * x), 3.0)
    assert np.isnan(kappa_fall([0.0, 0.0], [1.0, 0.0])[0])
    xs = np.sort(np.random.default_rng(0).uniform(0, 1, 30))
    np.testing.assert_allclose(crest_curvature(xs, 0 * xs, -2.5 * xs**2), 5.0, rtol=1e-9)


def test_bad_input():
    with pytest.raises(SpineInputError, match="n_starts"):
        drive_limits(corrugation(), 0.5, n_starts=0)
    with pytest.raises(SpineInputError, match="surface"):
        drive_limits("corrugation", 0.5)


def test_the_ball_bound_is_the_section_of_the_tip_ball():
    # a path along +x over a ball-dilated crest (a circle of radius R): the bound is the
    # circle's own curvature -z'' = (1 + z'^2)^1.5 / R at every inner point
    r = 0.5
    x = np.linspace(-0.4, 0.4, 81)
    z = np.sqrt(r**2 - x**2)
    fx = -x / z
    bound = ball_crest_bound(x, 0 * x, z, fx, 0 * x, r)
    np.testing.assert_allclose(bound, (1 + fx[1:-1] ** 2) ** 1.5 / r, rtol=5e-3)
    np.testing.assert_allclose(crest_curvature(x, 0 * x, z), bound, rtol=5e-3)
    # across a slope the plane cuts the ball off its centre: a smaller circle, a higher bound
    tilted = ball_crest_bound(x, 0 * x, 0 * x, 0 * x, np.full_like(x, 1.0), r)
    np.testing.assert_allclose(tilted, 1 / (r * np.sqrt(0.5)), rtol=1e-12)
    assert np.all(np.isinf(ball_crest_bound(x, 0 * x, z, fx, 0 * x, 0.0)))


def test_lift_off_reads_no_crest_sharper_than_the_tip_ball():
    # a triangle wave (slopes +-0.5) has kinked crests; dilated by a ball of radius R each
    # crest is an arc of it, so the sharpest crest lies between 1 / R (its top) and
    # 1.25^1.5 / R (its steepest point), whatever the sampled dilation's interpolant reads
    from spine_mj.surfaces import GridSurface

    x = np.linspace(0.0, 8.0, 801)
    y = np.linspace(-0.5, 0.5, 21)
    profile = 0.5 * np.abs(np.mod(x, 2.0) - 1.0)
    surf = GridSurface(heights=np.tile(profile, (y.size, 1)), x=x, y=y)
    tip = 0.25
    start = np.array([[0.5, 0.0]])
    d = drive_limits(surf, 0.3, tip_radius=tip, starts=start)
    traced = dilate(surf, tip)
    path = sl.streamlines(traced, start, StreamlineParams(mu=0.3, dl=0.2 / 40), store_paths=True).path(0)
    rung = np.nanmax(crest_curvature(path["x"], path["y"], path["z"]))
    assert rung > 3 * 1.25**1.5 / tip  # the interpolant's ringing next to the valleys' creases
    # within 10 %: the interpolant's slope itself overshoots the flanks' 0.5 there
    assert 0.9 / tip <= d.max_crest_curvature <= 1.1 * 1.25**1.5 / tip
    assert d.ie_lift == pytest.approx(1.0 / (d.char_length * d.max_crest_curvature))


def test_k_path_leaves_out_the_starts_that_miss_at_every_stiffness_probed():
    # the wall above: both starts climb it at any K above the carriage's limit; against a
    # Frechet target no path meets, every start misses at 1, 10 and 100 times the fold, so
    # none is left to judge and K_path is the search's "none passes"
    wall, starts, params, edge, ls = _wall_case()
    k_path, k_fold, left_out = path_stiffness(
        wall, starts, params, slope_length=ls, char_length=1.0, carriage_edge=edge, frechet_target=-1.0
    )
    assert (k_path, left_out) == (np.inf, 2) and k_fold > 0
    # with the comparison's target none is left out
    assert path_stiffness(wall, starts, params, slope_length=ls, char_length=1.0, carriage_edge=edge)[2] == 0
    # the criterion over the starts kept is theirs alone
    rigid = sl.streamlines(wall, starts, params, store_paths=True)
    soft = compliant_streamlines(wall, starts, params, stiffness=0.5 / ls)
    agree, frechet = start_scores(rigid, soft, 1.0)
    assert path_criterion(rigid, soft, 1.0, keep=[False, True]) == (float(agree[1]), float(frechet[1]))

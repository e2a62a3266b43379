"""Spine arrays against closed forms: N mu W on a plane, N tan(theta + arctan mu) W on an
incline (both drives, at the default pace), the dynamic excess of a faster pace (the
spring-block swing, the force-rate lag), an array of one equals the single rig, and N
spines on a corrugation carry the sum of their Prandtl-Tomlinson curves."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_rigs import MU, R_TIP

from spine_mj import sim, surfaces
from spine_mj.errors import SpineInputError
from spine_mj.sim.array import ArrayRig
from spine_mj.sim.array_run import ForcePull
from spine_mj.sim.drives import DEFAULT_STIFFNESS_NUMBER, stiffness_n_m
from spine_mj.sim.holding import ONSET_SHARE, spring_swing
from spine_mj.sim.layout import Layout
from spine_mj.surfaces.generators import inclined_plane
from spine_mj.theory.array_reference import force_control_release, profile_spine_curve, summed_curve


def _plane_rig(slope_deg):
    surf = inclined_plane(slope_deg=slope_deg, half_width=0.05, n=101)
    return sim.Rig(surf, tip=sim.TipParams(tip_radius_m=R_TIP, mu_s=MU))


def _default_plane_rig(slope_deg, *, force_control, ie=None):
    """The rig ``spine-mj array`` builds on a plane (tip from the surface), at ``ie``
    (None: the arrays' default pace, :func:`spine_mj.sim.array_ie`), and that pace."""
    surf = inclined_plane(slope_deg=slope_deg, half_width=0.05, n=101)
    if ie is None:
        ie = sim.array_ie(sim.build_rig(surf, mu=MU).scales, mu=MU, force_control=force_control)
    return sim.build_rig(surf, mu=MU, ie=ie), ie


def _short_spring(rig, ie, kappa):
    """A spring drive at ``ie`` long enough to stretch the spring to 1.5 kappa F_p."""
    v = rig.scales.speed_for(ie)
    k = stiffness_n_m(sim.SpringDrive(speed_m_s=v), rig.scales)
    return sim.SpringDrive(speed_m_s=v, duration_s=1.5 * kappa * rig.scales.preload_n / k / v)


def _pull(rig, ie, kappa):
    """A force pull at ``ie`` (its rate per spine) from 0.05 F_p below breakaway: the rate
    sets the lag, the start only the run's length."""
    sc = rig.scales
    return ForcePull(
        rate_n_s=sc.force_rate_for(sc.speed_for(ie)), start_force_n=(kappa - 0.05) * sc.preload_n
    )


_GRID = Layout(rows=2, cols=2, spacing=0.01, spacing_unit="surface")


@pytest.mark.parametrize("slope_deg", [0.0, 15.0])
def test_displacement_controlled_array_holds_n_tan_theta_plus_phi_w_on_a_plane_at_its_default_pace(slope_deg):
    rig, ie = _default_plane_rig(slope_deg, force_control=False)
    kappa = math.tan(math.radians(slope_deg) + math.atan(MU))
    res = ArrayRig(rig, _GRID).run(_short_spring(rig, ie, kappa), centre=(0.0, 0.0))
    assert res.n_spines == 4 and res.locked_spines == 0
    assert res.holding_excess_predicted == pytest.approx(0.01 * MU)
    assert res.holding_force_n == pytest.approx(4 * kappa * rig.scales.preload_n, rel=0.01)
    assert res.holding_ratio == pytest.approx(kappa, rel=0.01)


@pytest.mark.parametrize("slope_deg", [0.0, 15.0])
def test_force_controlled_array_lets_go_at_n_tan_theta_plus_phi_w_at_its_default_pace(slope_deg):
    rig, ie = _default_plane_rig(slope_deg, force_control=True)
    kappa = math.tan(math.radians(slope_deg) + math.atan(MU))
    arr = ArrayRig(rig, _GRID, force_control=True)
    res = arr.run(_pull(rig, ie, kappa), centre=(0.0, 0.0))
    assert res.end_reason in ("let_go", "left_domain")
    assert res.holding_excess_predicted == pytest.approx(0.01 * MU)
    assert res.holding_ratio == pytest.approx(kappa, rel=0.01)


def test_a_fast_spring_drive_swings_by_the_spring_block_closed_form_and_the_holding_reading_drops_it():
    # at I_e = 1e-3 the spring force swings sqrt(I_e K L_c / l_s) F_p = 0.17 F_p per spine
    # past breakaway (the curve's peak); the holding, read before let-go, keeps at most
    # ONSET_SHARE of it
    rig, ie = _default_plane_rig(0.0, force_control=False, ie=1e-3)
    sc = rig.scales
    res = ArrayRig(rig, _GRID).run(_short_spring(rig, ie, 2 * MU), centre=(0.0, 0.0))
    swing = spring_swing(ie, DEFAULT_STIFFNESS_NUMBER, sc.char_length_m / sc.slope_length_m)
    assert res.peak_ratio - MU == pytest.approx(swing, rel=0.1)
    assert res.holding_excess_predicted == pytest.approx(ONSET_SHARE * swing)
    assert 0 <= res.holding_ratio - MU <= res.holding_excess_predicted


def test_a_fast_pull_lags_within_the_force_rate_bounds():
    # past breakaway the excess pull accelerates the carriage (and the tips) to the release
    # speed: the pull read as held lies between sqrt(2 I_e) and 2 sqrt(I_e) F_p above it
    rig, ie = _default_plane_rig(0.0, force_control=True, ie=1e-3)
    res = ArrayRig(rig, _GRID, force_control=True).run(_pull(rig, ie, MU), centre=(0.0, 0.0))
    assert res.holding_excess_predicted == pytest.approx(2 * math.sqrt(ie))
    assert math.sqrt(2 * ie) <= res.holding_ratio - MU <= res.holding_excess_predicted


def test_the_default_pace_follows_the_closed_forms():
    sc = _plane_rig(0.0).scales
    lc_ls = sc.char_length_m / sc.slope_length_m
    for force in (False, True):
        ie = sim.array_ie(sc, mu=MU, force_control=force)
        excess = sim.holding_excess(ie, force_control=force, stiffness_number=30.0, lc_over_ls=lc_ls)
        assert excess == pytest.approx(sim.HOLDING_TOLERANCE * MU)
    stiff = sim.array_ie(sc, mu=MU, force_control=False, stiffness_n_m=sc.stiffness_for(120.0))
    assert stiff == pytest.approx(sim.array_ie(sc, mu=MU, force_control=False) / 4)


def test_force_control_pull_locks_every_spine_on_a_plane_steeper_than_lock():
    rig = _plane_rig(70.0)  # theta + arctan(mu) > 90 deg: self-locking
    fp, tau = rig.scales.preload_n, rig.scales.time_s
    arr = ArrayRig(rig, Layout(rows=1, cols=2, spacing=0.01, spacing_unit="surface"), force_control=True)
    det = sim.Detection(kappa_cap=3.0)
    # a start force above tan(theta - phi) F_p = 0.95 F_p keeps the tips from sliding back
    res = arr.run(ForcePull(rate_n_s=0.5 * fp / tau, start_force_n=fp), centre=(0.0, 0.0), detection=det)
    assert res.end_reason == "held" and res.locked_spines == 2
    assert res.holding_force_n == pytest.approx(2 * 3.0 * fp, rel=1e-6)


def _corrugation_rig():
    return sim.Rig(surfaces.corrugation(n_waves=4, width=0.5), tip=sim.TipParams(mu_s=MU))


def test_array_of_one_follows_the_single_rig():
    rig = _corrugation_rig()
    lc = rig.scales.char_length_m
    v = rig.scales.speed_for(1e-3)
    drive = sim.SpringDrive(speed_m_s=v, duration_s=1.5 * lc / v)
    start = (0.3, 0.0)
    single = rig.run(drive, start=start)
    arr = ArrayRig(rig, Layout(rows=1, cols=1, spacing=1.0))
    res = arr.run(drive, centre=start)
    assert res.end_reason == "completed" and single.end_reason is sim.EndReason.COMPLETED
    assert res.simulated_steps == len(single.time_s)
    # the single rig's columns come from sensors, read before each step's integration:
    # its row i + 1 holds the position of the array's (state) row i
    rows = res.step_index
    ok = rows + 1 < len(single.time_s)
    gap = np.abs(res.position_m[ok, 0] - single.position_m[rows[ok] + 1]).max()
    assert gap < 1e-4 * lc
    assert res.max_force_n[0] == pytest.approx(single.drive_force_n.max(), rel=0.05)


def _corrugation_curves(rig, res, drive):
    """Prandtl-Tomlinson curves F / W of each spine of ``res`` at its carriage positions."""
    s = rig.length_scale_m
    kk = stiffness_n_m(drive, rig.scales) * s / rig.scales.preload_n
    x = res.carriage_x_m / s
    slope = lambda u: 0.3 * np.cos(2 * math.pi * u)  # noqa: E731 (the preset: lambda 1, slope 0.3)
    return [
        profile_spine_curve(
            x, x0=x0, slope=slope, mu=MU, spring_per_preload=kk, tip_radius=rig.tip.tip_radius_m / s
        )
        for x0 in res.start_xy[:, 0]
    ]


def test_spines_along_a_corrugation_carry_the_sum_of_their_shifted_curves():
    # K = 30 > K* = 0.47: every spine slides smoothly on its Prandtl-Tomlinson branch; the
    # dynamic excess past breakaway scales as sqrt(I_e) (spring-block overshoot)
    rig = _corrugation_rig()
    arr = ArrayRig(rig, Layout(rows=1, cols=3, spacing=0.3, spacing_unit="surface"))
    errors = {}
    for ie in (1e-4, 1e-5):
        v = rig.scales.speed_for(ie)
        drive = sim.SpringDrive(speed_m_s=v, duration_s=1.1 * rig.length_scale_m / v)
        res = arr.run(drive, centre=(1.0, 0.0))
        curves = _corrugation_curves(rig, res, drive)
        total = summed_curve(curves)
        mj = res.total_force_n / rig.scales.preload_n
        assert np.allclose(mj, res.spine_force_n.sum(axis=1) / rig.scales.preload_n)
        errors[ie] = (np.median(np.abs(mj - total)) / 3, res.peak_ratio - total.max() / 3)
    median, excess = errors[1e-5]
    assert median < 0.015
    assert 0 <= excess < math.sqrt(1e-5 * 100) + 0.005
    assert errors[1e-5][1] < 0.5 * errors[1e-4][1]


def test_spines_outside_the_surface_are_refused():
    rig = _corrugation_rig()
    arr = ArrayRig(rig, Layout(rows=8, cols=8, spacing=1.0))
    with pytest.raises(SpineInputError, match="spacing 1 L_c puts spine"):
        arr.run(sim.SpringDrive(speed_m_s=1.0), centre=(2.0, 0.0))


def test_a_drive_of_the_other_kind_is_refused():
    arr = ArrayRig(_corrugation_rig(), Layout(rows=1, cols=2, spacing=0.1))
    with pytest.raises(SpineInputError, match="built for a SpringDrive, got ForcePull"):
        arr.run(ForcePull())


def test_python_reference_equals_the_native_rollout():
    rig = _corrugation_rig()
    arr = ArrayRig(rig, Layout(kind="staggered", rows=2, cols=2, spacing=0.2, spacing_unit="surface"))
    v = rig.scales.speed_for(1e-3)
    drive = sim.SpringDrive(speed_m_s=v, duration_s=0.3 * rig.length_scale_m / v)
    native, python = (arr.run(drive, centre=(1.0, 0.0), backend=b) for b in ("rollout", "python"))
    assert native.simulated_steps == python.simulated_steps
    assert np.allclose(native.position_m, python.position_m, rtol=0, atol=1e-9 * rig.scales.char_length_m)


def test_batched_runs_equal_runs_one_at_a_time():
    rig = _corrugation_rig()
    arr = ArrayRig(rig, Layout(rows=1, cols=2, spacing=0.25, spacing_unit="surface"))
    v = rig.scales.speed_for(1e-3)
    drive = sim.SpringDrive(speed_m_s=v, duration_s=0.2 * rig.length_scale_m / v)
    centres = [(1.0, 0.0), (1.37, 0.05)]
    batch = arr.run_batch(drive, centres, nthread=2)
    for c, b in zip(centres, batch):
        one = arr.run(drive, centre=c, nthread=1)
        assert np.array_equal(one.position_m, b.position_m)


def test_force_controlled_spines_on_a_corrugation_let_go_where_the_summed_curve_peaks():
    # three spines at 0.3 wavelength offsets: the summed forward curve peaks once per
    # wavelength at one height, so a catch after the first let-go holds no more
    rig = _corrugation_rig()
    fp, tau, s = rig.scales.preload_n, rig.scales.time_s, rig.length_scale_m
    arr = ArrayRig(rig, Layout(rows=1, cols=3, spacing=0.3, spacing_unit="surface"), force_control=True)
    res = arr.run(ForcePull(rate_n_s=3e-3 * fp / tau), centre=(1.0, 0.0))
    assert res.end_reason == "let_go"
    kk = stiffness_n_m(ForcePull(), rig.scales) * s / fp
    x = np.linspace(0.0, 3.0, 6001)
    slope = lambda u: 0.3 * np.cos(2 * math.pi * u)  # noqa: E731
    r = rig.tip.tip_radius_m / s
    curves = [
        profile_spine_curve(x, x0=x0, slope=slope, mu=MU, spring_per_preload=kk, tip_radius=r)
        for x0 in res.start_xy[:, 0]
    ]
    rel = force_control_release(x, summed_curve(curves))
    assert rel.holding == pytest.approx(rel.first_let_go, rel=1e-3)
    assert res.holding_ratio == pytest.approx(rel.holding / 3, rel=0.03)

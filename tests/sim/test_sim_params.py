"""Parameters: bad values rejected clearly, engine settings recorded, the scaling rule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_rigs import R_TIP, START, flat_rig

from spine_mj.errors import SpineInputError
from spine_mj.sim import EngineSettings, RampDrive, Rig, SpringDrive, StaticProbe, TipParams
from spine_mj.surfaces import GridSurface, single_gaussian


def _coarse_grid() -> GridSurface:
    x = np.linspace(-5.0, 5.0, 41)  # 0.25 apart
    return GridSurface(heights=0.5 * np.sin(x)[None, :] * np.cos(x)[:, None], x=x, y=x)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: TipParams(mass_kg=-0.01), r"mass_kg must be a finite number > 0, got -0\.01"),
        (lambda: TipParams(mu_s=-0.1), r"mu_s must be a finite number >= 0, got -0\.1"),
        (lambda: EngineSettings(timestep_s=0.0), r"timestep_s must be a finite number > 0, got 0\.0"),
        (lambda: EngineSettings(timestep_s=1e-3, solref=(1e-3, 1.0)), r"solref timeconst_s must be >= 2"),
        (lambda: EngineSettings(timestep_s=1e-3, cone="pyramidal"), r"pyramidal.*noslip"),
        (lambda: EngineSettings(timestep_s=1e-3, cone="conical"), r"cone must be one of"),
        (lambda: SpringDrive(speed_m_s=0.0), r"speed_m_s must be a finite number > 0"),
        (lambda: TipParams(gravity_m_s2=0.0), r"no normal preload"),
        (
            lambda: Rig(single_gaussian(), tip=TipParams(tip_radius_m=1e-5)),
            r"surface too coarse for the tip: hfield spacing 0\.0005 m \(0\.05 surface units\) "
            r"> 2 x tip_radius_m 1e-05 m \(0\.001 surface units\).*; raise hfield_resolution or the tip",
        ),
        (  # a gridded surface keeps its own samples: no hfield_resolution refines it
            lambda: Rig(_coarse_grid(), tip=TipParams(tip_radius_m=1e-3)),
            r"surface too coarse for the tip: hfield spacing 0\.0025 m \(0\.25 surface units\) > 2 x "
            r"tip_radius_m 0\.001 m .*; a gridded surface \(a file, a scan\) keeps its own samples, so "
            r"hfield_resolution does not apply: use a tip radius of at least 0\.00125 m \(0\.125 surface "
            r"units\), or the surface on a finer grid$",
        ),
        (lambda: flat_rig().run(StaticProbe(), start=(1.0, 0.0)), r"start \(1, 0\) lies outside"),
        (  # a batch's starts are checked at once; the first bad one is named
            lambda: flat_rig().run_batch(StaticProbe(), [(0.0, 0.0), (0.0, math.nan), (1.0, 0.0)]),
            r"start \(0, nan\) lies outside",
        ),
        (
            lambda: flat_rig().run_batch(StaticProbe(), [(0.0, 0.0), (0.0, 0.0, 1.0)]),
            r"each start must be a pair \(x0, y0\) of numbers, got \(0\.0, 0\.0, 1\.0\)",
        ),
        (
            lambda: flat_rig().run(RampDrive(), start=(0.0, 0.0, 1.0)),
            r"each start must be a pair \(x0, y0\) of numbers",
        ),
        (
            lambda: flat_rig().run_batch(StaticProbe(), [("a", 0.0)]),
            r"each start must be a pair \(x0, y0\) of numbers, got \('a', 0\.0\)",
        ),
    ],
)
def test_bad_parameters_are_rejected_clearly(make, match):
    with pytest.raises(SpineInputError, match=match):
        make()


def test_engine_settings_are_recorded_with_every_run():
    rig = flat_rig()
    res = rig.run(SpringDrive(speed_m_s=0.02, duration_s=0.05), start=(0.0, 0.0))
    summary = res.summary()
    eng = summary["engine"]
    assert eng["timestep_s"] == rig.engine.timestep_s and eng["cone"] == "elliptic"
    assert {"integrator", "impratio", "noslip_iterations", "solref", "solimp"} <= set(eng)
    assert summary["scales"]["hfield_resolution"] == rig.scales.hfield_resolution
    # the default rule: resting penetration a_p dt^2 <= 0.5 % of the tip radius
    assert rig.scales.preload_n / rig.tip.mass_kg * rig.engine.timestep_s**2 <= 0.005 * R_TIP
    assert res.penetration_m.max() < 0.01 * rig.scales.char_length_m


def test_scales_for_surface_are_the_rigs_scales_without_building_a_model():
    """Scales.for_surface is the one sizing rule: a rig's scales equal it, and the default
    tip radius is max(one hfield spacing, L_c / 100) in metres for a dimensionless surface."""
    from spine_mj.roughness import characteristic_length
    from spine_mj.sim import DEFAULT_LENGTH_SCALE_M, Scales

    surf = single_gaussian()
    tip = TipParams(mass_kg=0.02)
    scales = Scales.for_surface(surf, tip=tip, hfield_resolution=101)
    rig = Rig(
        surf, tip=tip, engine=EngineSettings(timestep_s=1e-3, solref=(2e-3, 1.0)), hfield_resolution=101
    )
    assert scales == rig.scales
    hfield = Scales.with_hfield(surf, tip=tip, hfield_resolution=101)[1]
    assert hfield.size == rig.hfield.size and (hfield.data == rig.hfield.data).all()
    lc_m = characteristic_length(surf) * DEFAULT_LENGTH_SCALE_M
    spacing_m = 10 / 100 * DEFAULT_LENGTH_SCALE_M
    assert scales.char_length_m == pytest.approx(lc_m, rel=1e-12)
    assert scales.hfield_spacing_m == pytest.approx(spacing_m, rel=1e-12)
    assert scales.tip_radius_m == pytest.approx(max(spacing_m, lc_m / 100), rel=1e-3)
    assert scales.inertia_number(scales.speed_for(3e-4)) == pytest.approx(3e-4, rel=1e-12)


def test_a_surface_in_any_spelling_of_a_length_unit_is_scaled_by_that_unit():
    """um is um however it is spelled (the micro sign SurfaceTopography writes, Greek mu);
    a unit the rig does not know is refused with the list it knows."""
    from spine_mj.sim import Scales
    from spine_mj.surfaces import length_unit

    assert [length_unit(u) for u in ("\u00b5m", "\u03bcm", "um", "nm", "1", "A", None)] == [
        "um",
        "um",
        "um",
        "nm",
        None,
        None,
        None,
    ]
    grid = single_gaussian().sample(64)
    for unit in ("\u00b5m", "\u03bcm", "um"):
        surf = GridSurface(heights=grid.heights, x=grid.x, y=grid.y, unit=unit)
        assert Scales.for_surface(surf).length_scale_m == 1e-6
    bad = GridSurface(heights=grid.heights, x=grid.x, y=grid.y, unit="A")
    with pytest.raises(
        SpineInputError, match=r"surface unit must be .*\['m', 'mm', 'nm', 'pm', 'um'\], got 'A'"
    ):
        Scales.for_surface(bad)


def test_a_fast_drive_shortens_the_step_so_impacts_stay_shallow():
    """dt <= 0.05 e r / (2 v): an arrival at the drive's speed sinks at most ~5 % of r."""
    from spine_mj.sim import Scales, default_engine

    scales = Scales.for_surface(single_gaussian(), tip=TipParams(mass_kg=0.01))
    rest = default_engine(scales)
    assert default_engine(scales, speed_m_s=scales.speed_for(1e-6)).timestep_s == rest.timestep_s
    fast = scales.speed_for(1.0)
    dt = default_engine(scales, speed_m_s=fast).timestep_s
    bound = 0.05 * math.e * scales.tip_radius_m / (2 * fast)
    assert dt < rest.timestep_s and dt <= bound * 1.05  # 2-digit rounding in engine units
    assert default_engine(scales, speed_m_s=fast).solref[0] == pytest.approx(2 * dt)


def test_fall_height_is_the_landing_a_slip_can_make():
    """Closed forms of :func:`fall_height`: a plane has none (no turn) whatever its slope;
    a ramp steeper than friction (slope s > mu, run L) ending on a floor lands from
    ``(s - mu) L sin^2(arctan s)``; one gentler than friction never gains speed; a cliff
    of height H over one cell dx lands from ``(H - mu dx) sin^2`` of its turn."""
    from spine_mj.sim.scales import fall_height

    x = np.arange(200.0)  # spacing 1
    for slope in (0.0, 0.3, 2.0, -5.0):
        plane = np.tile(slope * x, (8, 1))
        assert fall_height(plane, (1.0, 1.0), mu=0.5, radius=1.0) < 1e-9
    s, mu, run = 2.0, 0.5, 60.0
    ramp = np.tile(np.clip(s * (100.0 - x), 0.0, s * run), (8, 1))  # descends from x = 40 to 100
    expected = (s - mu) * run * s**2 / (1 + s**2)
    assert fall_height(ramp, (1.0, 1.0), mu=mu, radius=1.0) == pytest.approx(expected, rel=1e-12)
    gentle = np.tile(np.clip(0.4 * (100.0 - x), 0.0, 24.0), (8, 1))
    assert fall_height(gentle, (1.0, 1.0), mu=0.5, radius=1.0) == 0.0
    cliff_h = 50.0
    cliff = np.tile(np.where(x < 100, cliff_h, 0.0), (8, 1)).T  # along y this time
    expected = (cliff_h - mu) * cliff_h**2 / (cliff_h**2 + 1)
    assert fall_height(cliff, (1.0, 1.0), mu=mu, radius=1.0) == pytest.approx(expected, rel=1e-12)
    # the turn is what the tip feels over one radius: a wider tip on the same cliff
    wide = (cliff_h - mu) * cliff_h**2 / (cliff_h**2 + 4**2)
    assert fall_height(cliff, (1.0, 1.0), mu=mu, radius=4.0) == pytest.approx(wide, rel=1e-12)


def test_a_time_step_whose_contact_rests_the_tip_too_deep_is_refused_with_the_largest_that_fits():
    """rest_depth_m is MuJoCo's for one contact: a flat rig at 0.8 of the largest time step
    the refusal names rests the tip 0.64 of the penetration tolerance deep, divided among
    the contacts that carry it; 1.1 of it is refused, and so is a step below
    MIN_TIMESTEP_TAU."""
    import re

    import mujoco

    from spine_mj.sim.step_rule import MIN_TIMESTEP_TAU, penetration_tolerance_m, rest_depth_m

    base = flat_rig()
    surface, tip = base.surface, base.tip
    with pytest.raises(SpineInputError, match=r"rests the tip .* deep in the surface") as refused:
        Rig(surface, tip=tip, engine=EngineSettings(timestep_s=1.0, solref=(2.0, 1.0)))
    most = float(re.search(r"at most ([0-9.e+-]+) s", str(refused.value)).group(1))
    near = Rig(surface, tip=tip, engine=EngineSettings(timestep_s=0.8 * most, solref=(1.6 * most, 1.0)))
    tol = penetration_tolerance_m(near.scales)
    assert rest_depth_m(near.engine, near.scales) == pytest.approx(0.64 * tol, rel=0.01)
    data = mujoco.MjData(near.model)
    data.qpos[:] = near.place(*START)
    mujoco.mj_step(near.model, data, 400)
    depths = np.array([-c.dist for c in data.contact[: data.ncon]]) * near.units.length_m
    # the contacts of the hfield's triangles under the tip share the preload, each pushing
    # in proportion to its depth
    assert data.ncon >= 1 and depths.sum() == pytest.approx(0.64 * tol, rel=0.02)
    with pytest.raises(SpineInputError, match="rests the tip"):
        Rig(surface, tip=tip, engine=EngineSettings(timestep_s=1.1 * most, solref=(2.2 * most, 1.0)))
    tiny = 0.5 * MIN_TIMESTEP_TAU * base.scales.time_s
    with pytest.raises(SpineInputError, match=r"timestep_s must be at least 1e-09 of the time scale"):
        Rig(surface, tip=tip, engine=EngineSettings(timestep_s=tiny, solref=(2 * tiny, 1.0)))


@pytest.mark.parametrize(
    "kwargs", [dict(preload_n=1e30), dict(gravity_m_s2=1e9), dict(mass_kg=1e-24, preload_n=1.0)]
)
def test_a_load_per_unit_mass_beyond_physics_is_refused(kwargs):
    with pytest.raises(SpineInputError, match=r"preload_n and gravity_m_s2: the load per unit mass"):
        TipParams(**kwargs)
    TipParams(preload_n=1e3)  # 1e5 m/s^2 on the default 10 g: allowed


@pytest.mark.parametrize("k_number", [3.0, 30.0, 300.0, 3000.0, 30000.0])
def test_the_step_rule_resolves_the_drive_spring_and_the_contact_follows_the_step(k_number):
    """omega dt <= SPRING_OMEGA_DT for any K (MuJoCo integrates the spring explicitly), the
    contact's time constant twice the step (stiffer than the spring: omega_c ~ 1 / (2 dt)
    against omega <= 0.3 / dt), and build_rig gives the rule with or without a contact
    damping ratio given (a sweep always passes one)."""
    from spine_mj import presets, sim

    surface = presets.make_surface("paper-fractal", seed=1)
    mu = presets.resolve_mu(surface, None)
    tip = sim.TipParams(mu_s=mu)
    scales = sim.Scales.for_surface(surface, tip=tip)
    k = scales.stiffness_for(k_number)
    eng = sim.default_engine(scales, speed_m_s=scales.speed_for(1e-4), stiffness_n_m=k)
    wdt = sim.spring_omega_dt(k, scales.mass_kg, eng.timestep_s)
    contact = sim.default_engine(scales, speed_m_s=scales.speed_for(1e-4), stiffness_n_m=1e-30).timestep_s
    assert wdt <= sim.SPRING_OMEGA_DT * (1 + 1e-9)
    # the spring sets the step where the contact's would not resolve it (cut to 2 digits)
    assert eng.timestep_s == pytest.approx(contact) if k_number <= 30 else wdt > 0.9 * sim.SPRING_OMEGA_DT
    assert eng.solref == pytest.approx((2 * eng.timestep_s, 1.0))
    for damp in (None, 1.0):
        rig = sim.build_rig(surface, mu=mu, ie=1e-4, stiffness_number=k_number, solref_dampratio=damp)
        assert rig.engine.timestep_s == pytest.approx(eng.timestep_s)
        assert rig.engine.solref == pytest.approx(eng.solref)


def test_engine_overrides_replace_only_what_they_name():
    """No override gives the rule; a timestep carries the contact along (2 dt); each half of
    solref replaces its own half of the rule's, the other half stays the rule's."""
    from spine_mj import sim

    scales = sim.Scales.for_surface(single_gaussian(), tip=TipParams(mu_s=0.5))
    rule = sim.default_engine(scales, speed_m_s=scales.speed_for(1e-3))
    engine = sim.EngineOverrides().engine
    assert engine(scales, speed_m_s=scales.speed_for(1e-3)) == rule
    dt = rule.timestep_s / 4
    assert sim.EngineOverrides(timestep_s=dt).engine(scales).solref == pytest.approx((2 * dt, 1.0))
    damped = sim.EngineOverrides(solref_dampratio=0.5).engine(scales, speed_m_s=scales.speed_for(1e-3))
    assert damped.solref == pytest.approx((rule.solref[0], 0.5))
    slow = sim.EngineOverrides(solref_timeconst_s=3 * rule.solref[0]).engine(
        scales, speed_m_s=scales.speed_for(1e-3)
    )
    assert slow.solref == pytest.approx((3 * rule.solref[0], 1.0))
    assert slow.timestep_s == rule.timestep_s


def test_a_step_factor_refines_only_the_step_and_tolerances_reach_the_model():
    """``timestep_factor`` scales the rule's step at this pace and spring, the contact's time
    constant kept; the solver tolerances are MuJoCo's unless given, and the model reads them."""
    from spine_mj import sim

    surface = single_gaussian()
    scales = sim.Scales.for_surface(surface, tip=TipParams(mu_s=0.5))
    for ie, k_number in ((1e-3, 30.0), (1e-1, 300.0)):
        speed, spring = scales.speed_for(ie), scales.stiffness_for(k_number)
        rule = sim.default_engine(scales, speed_m_s=speed, stiffness_n_m=spring)
        half = sim.EngineOverrides(timestep_factor=0.5).engine(scales, speed_m_s=speed, stiffness_n_m=spring)
        assert half.timestep_s == pytest.approx(rule.timestep_s / 2)
        assert half.solref == rule.solref and half.solimp == rule.solimp
    with pytest.raises(SpineInputError, match="timestep_s and timestep_factor: give one of them"):
        sim.EngineOverrides(timestep_s=1e-4, timestep_factor=0.5).engine(scales)
    assert (rule.tolerance, rule.noslip_tolerance) == (1e-8, 1e-6)
    rig = sim.build_rig(surface, mu=0.5, ie=1e-3, tolerance=1e-10, noslip_tolerance=1e-8, timestep_factor=0.5)
    assert (rig.model.opt.tolerance, rig.model.opt.noslip_tolerance) == (1e-10, 1e-8)
    plain = sim.build_rig(surface, mu=0.5, ie=1e-3)
    assert (plain.model.opt.tolerance, plain.model.opt.noslip_tolerance) == (1e-8, 1e-6)
    assert rig.engine.timestep_s == pytest.approx(plain.engine.timestep_s / 2)
    with pytest.raises(SpineInputError, match="tolerance must be"):
        sim.EngineSettings(timestep_s=1e-4, solref=(2e-4, 1.0), tolerance=0.0)


def test_a_narrow_strip_gets_a_tip_that_fits_across_it_and_a_tip_too_wide_is_refused_by_its_own_name():
    """A strip 1 wide of waves 300 long: the usual default (L_c / 100 = 3) would be wider
    than the strip; the default is at most the width over DEFAULT_TIP_RADII_ACROSS. A tip
    the user gives too wide is refused with the user's number."""
    from spine_mj.sim import Scales
    from spine_mj.sim.scales import DEFAULT_TIP_RADII_ACROSS
    from spine_mj.surfaces import GridSurface

    x, y = np.arange(4001) * 0.125, np.arange(9) * 0.125
    strip = GridSurface(heights=3 * np.sin(2 * np.pi * x / 300)[None, :] * np.ones((9, 1)), x=x, y=y)
    scales = Scales.for_surface(strip)
    assert scales.tip_radius_m <= 1.0 * scales.length_scale_m / DEFAULT_TIP_RADII_ACROSS
    with pytest.raises(
        SpineInputError, match=r"tip_radius_m 0\.006 m \(0\.6 surface units\) is larger than the surface"
    ):
        Scales.for_surface(strip, tip=TipParams(tip_radius_m=0.006))


def test_a_size_refusal_names_its_lengths_in_the_surfaces_own_unit_too():
    """The CLI takes the tip radius in the surface's unit: a refusal in metres alone named
    numbers its user never gave (--tip-radius 0.6 on a dimensionless strip read 0.006 m)."""
    from spine_mj.sim import Scales

    x = np.linspace(0.0, 10.0, 41)
    surf = GridSurface(heights=0.5 * np.sin(x)[None, :] * np.ones((41, 1)), x=x, y=x, unit="mm")
    with pytest.raises(
        SpineInputError,
        match=r"^tip_radius_m 0\.02 m \(20 mm\) is larger than the surface: its diameter must be "
        r"smaller than the domain's width 0\.01 m \(10 mm\)$",
    ):
        Scales.for_surface(surf, tip=TipParams(tip_radius_m=0.02))

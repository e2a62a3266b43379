"""MuJoCo rig: hfield geometry, placement, the three drives, events, batches, validation."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.sim import (
    Detection,
    EndReason,
    EngineSettings,
    RampDrive,
    Rig,
    SpringDrive,
    StaticProbe,
    TipParams,
    inclined_plane,
)
from spine_mj.surfaces import GridSurface, TriangulatedSurface, from_hfield, single_gaussian

MU = 0.5
PHI = math.atan(MU)
R_TIP = 5e-4
START = (3.1e-4, 2.7e-4)


def plane_rig(slope_deg, **tip):
    return Rig(inclined_plane(slope_deg=slope_deg), tip=TipParams(tip_radius_m=R_TIP, mu_s=MU, **tip))


def asymmetric_surface(n=121):
    """Tilted plane plus an off-centre bump, dimensionless, on -3..3."""
    x = np.linspace(-3, 3, n)
    xx, yy = np.meshgrid(x, x)
    h = 0.25 * xx - 0.1 * yy + 0.8 * np.exp(-((xx - 1.2) ** 2 + (yy + 0.7) ** 2) / (2 * 0.6**2))
    return GridSurface(heights=h, x=x, y=x.copy(), unit="1")


def deepest_contacts(rig, q):
    d = mujoco.MjData(rig.model)
    d.qpos[:] = q
    mujoco.mj_forward(rig.model, d)
    out = []
    for c in d.contact[: d.ncon]:
        n = c.frame[:3] * (1 if c.frame[2] > 0 else -1)
        out.append((c.pos - 0.5 * c.dist * n, n))
    return out


# --------------------------------------------------------------------------- geometry


def test_hfield_orientation_extent_and_scale_match_the_surface():
    surf = asymmetric_surface()
    rig = Rig(surf, tip=TipParams(tip_radius_m=1e-3))
    s = rig.length_scale_m
    tri = TriangulatedSurface.from_grid(from_hfield(rig.hfield))
    chord = 0.05**2 / 8 * 2.3 * s  # spacing^2 max|f''| / 8, in metres
    rng = np.random.default_rng(0)
    for x0, y0 in rng.uniform(-2.5, 2.5, (12, 2)):
        q = rig.place(x0, y0)
        contacts = deepest_contacts(rig, q)
        assert contacts, (x0, y0)
        for p, n in contacts:
            # the contact lies on the surface (in metres) and faces the smooth normal
            assert p[2] == pytest.approx(s * surf.height(p[0] / s, p[1] / s), abs=chord)
            assert p[2] == pytest.approx(s * tri.height(p[0] / s, p[1] / s), abs=1e-9)
            fx, fy = surf.gradient(p[0] / s, p[1] / s)
            ns = np.array([-fx, -fy, 1.0]) / math.hypot(1, math.hypot(fx, fy))
            assert math.degrees(math.acos(min(1.0, float(n @ ns)))) < 4.0
        # the sphere centre sits one radius from its contact
        assert np.linalg.norm(q - contacts[0][0]) == pytest.approx(rig.tip.tip_radius_m, rel=1e-3)


def _alt_normal(grid, x, y):
    """Facet normal with the *other* diagonal (x_max, y_min)-(x_min, y_max): must not match."""
    dx, dy = grid.spacing
    i = int((x - grid.x[0]) // dx)
    j = int((y - grid.y[0]) // dy)
    s, t = (x - grid.x[i]) / dx, (y - grid.y[j]) / dy
    h = grid.heights
    if s + t <= 1:
        fx, fy = (h[j, i + 1] - h[j, i]) / dx, (h[j + 1, i] - h[j, i]) / dy
    else:
        fx, fy = (h[j + 1, i + 1] - h[j + 1, i]) / dx, (h[j + 1, i + 1] - h[j, i + 1]) / dy
    n = np.array([-fx, -fy, 1.0])
    return n / np.linalg.norm(n)


def test_triangulated_surface_matches_mujoco_facets():
    rng = np.random.default_rng(1)
    x = np.linspace(-0.02, 0.02, 9)
    grid = GridSurface(heights=rng.uniform(0, 0.004, (9, 9)), x=x, y=x.copy(), unit="m")
    rig = Rig(grid, tip=TipParams(tip_radius_m=3e-3))
    tri = TriangulatedSurface.from_grid(from_hfield(rig.hfield, unit="m"))
    n_facet, n_alt_mismatch = 0, 0
    for x0, y0 in rng.uniform(-0.015, 0.015, (30, 2)):
        contacts = deepest_contacts(rig, rig.place(x0, y0))
        for p, _n in contacts:
            assert p[2] == pytest.approx(float(tri.height(p[0], p[1])), abs=1e-9)
        if len(contacts) == 1:  # inside a facet: the engine's normal is the facet normal
            p, n = contacts[0]
            fx, fy = tri.gradient(p[0], p[1])
            nt = np.array([-fx, -fy, 1.0]) / math.hypot(1, math.hypot(fx, fy))
            np.testing.assert_allclose(n, nt, atol=1e-6)
            n_facet += 1
            n_alt_mismatch += not np.allclose(n, _alt_normal(grid, p[0], p[1]), atol=1e-3)
    assert n_facet >= 10
    assert n_alt_mismatch >= 3


def test_triangulated_surface_interpolates_nodes_and_is_linear_per_facet():
    x = np.array([0.0, 1.0, 2.0, 3.0])
    h = np.arange(16.0).reshape(4, 4) ** 1.5
    tri = TriangulatedSurface(heights=h, x=x, y=x.copy())
    np.testing.assert_allclose(tri.height(x[None, :], x[:, None]), h)
    # lower triangle of cell (0, 0): vertices (0,0), (1,0), (1,1)
    fx, fy = tri.gradient(0.7, 0.2)
    assert fx == pytest.approx(h[0, 1] - h[0, 0]) and fy == pytest.approx(h[1, 1] - h[0, 1])
    fx, fy = tri.gradient(0.2, 0.7)
    assert fx == pytest.approx(h[1, 1] - h[1, 0]) and fy == pytest.approx(h[1, 0] - h[0, 0])
    assert np.all(np.asarray(tri.hessian(0.3, 0.6)) == 0)
    assert np.isnan(tri.height(5.0, 0.0))


def test_placement_starts_at_rest_without_impact():
    rig = plane_rig(20.0)
    res = rig.run(StaticProbe(start_force_n=0.5 * rig.scales.preload_n), start=START)
    settle = slice(0, res.drive_start_index)
    # a start one step above the surface would fall to g dt = 5 mm/s
    assert np.abs(res.velocity_m_s[settle]).max() < 2e-5
    assert res.penetration_m[settle].max() < 0.01 * R_TIP


def test_export_xml_is_self_contained(tmp_path):
    rig = Rig(single_gaussian(), engine=None)
    path = rig.export_xml(tmp_path / "rig.xml")
    m = mujoco.MjModel.from_xml_path(str(path))
    assert m.nhfield == 1 and m.hfield_nrow[0] == rig.hfield.nrow
    np.testing.assert_allclose(m.hfield_data, rig.model.hfield_data, atol=2e-6)
    assert m.opt.timestep == rig.engine.timestep_s
    assert m.opt.noslip_iterations == rig.engine.noslip_iterations


def test_set_surface_recompiles_in_place():
    rig = Rig(single_gaussian(sign=1), tip=TipParams(tip_radius_m=5e-4))
    z_peak = rig.place(0.0, 0.0)[2]
    rig.set_surface(single_gaussian(sign=-1))
    assert rig.place(0.0, 0.0)[2] < z_peak - 0.03


# --------------------------------------------------------------------------- static probe


@pytest.mark.parametrize("slope_deg", [-15.0, 0.0, 20.0, 45.0, 60.0])
def test_static_probe_matches_closed_form(slope_deg):
    rig = plane_rig(slope_deg)
    theta = math.radians(slope_deg)
    low = max(0.0, math.tan(theta - PHI))  # smallest force that holds the tip
    hold = 0.5 * (low + math.tan(theta + PHI)) if low > 0 else 0.0
    res = rig.run(StaticProbe(start_force_n=hold * rig.scales.preload_n), start=START)
    assert res.end_reason is EndReason.BREAKAWAY, res.end_detail
    assert res.kappa_mj == pytest.approx(math.tan(theta + PHI), rel=0.05)
    assert res.events[-1].kind == "breakaway"


def test_static_probe_self_locks_beyond_90_degrees():
    rig = plane_rig(70.0)  # theta + arctan(mu) = 96.6 deg
    res = rig.run(
        StaticProbe(
            start_force_n=1.5 * math.tan(math.radians(70) - PHI) * rig.scales.preload_n,
            rate_n_s=20 * rig.scales.preload_n,
        ),
        start=START,
    )
    assert res.end_reason is EndReason.SELF_LOCK
    assert res.drive_force_n[-1] >= res.detection.kappa_cap * rig.scales.preload_n * (1 - 1e-9)
    assert math.isnan(res.kappa_mj)


def test_tip_on_slope_steeper_than_friction_angle_slides():
    rig = plane_rig(40.0)
    res = rig.run(StaticProbe(), start=START)
    assert res.end_reason is EndReason.SLID
    assert res.position_m[-1, 0] < res.position_m[0, 0]  # downhill, against the drive
    # and at 20 deg (< arctan 0.5) the same tip stays put until pushed
    assert plane_rig(20.0).run(StaticProbe(), start=START).end_reason is EndReason.BREAKAWAY


# --------------------------------------------------------------------------- spring and ramp


def flat_rig():
    return Rig(
        inclined_plane(slope_deg=0.0, half_width=0.05, n=101), tip=TipParams(tip_radius_m=R_TIP, mu_s=MU)
    )


def test_flat_ground_spring_drive_pulls_with_mu_w():
    rig = flat_rig()
    res = rig.run(SpringDrive(speed_m_s=0.005, duration_s=2.0), start=(-0.04, 2.3e-4))
    assert res.end_reason is EndReason.COMPLETED
    half = res.n // 2
    force = res.drive_force_n[half:].mean()
    assert force == pytest.approx(MU * rig.scales.preload_n, rel=0.02)
    assert res.slipping[half:].mean() > 0.5
    assert res.inertia_number == pytest.approx(
        rig.tip.mass_kg * 0.005**2 / (rig.scales.preload_n * rig.scales.char_length_m)
    )
    # cell edges give two contacts: a few um of drift over 80 mm, no more
    assert abs(res.position_m[-1, 1] - res.position_m[0, 1]) < 1e-5
    table = res.table()
    assert len(table) == res.n and {"position_x_m", "drive_force_n", "slipping"} <= set(table)


def test_ramp_with_reset_slips_at_mu_and_ramps_again():
    rig = flat_rig()
    res = rig.run(RampDrive(rate_n_s=2 * rig.scales.preload_n, duration_s=1.2), start=(-0.04, 0.0))
    assert res.end_reason is EndReason.COMPLETED
    assert len(res.slip_kappas) >= 2
    np.testing.assert_allclose(res.slip_kappas, MU, rtol=0.05)
    kinds = [e.kind for e in res.events]
    assert "reset" in kinds and kinds.index("reset") > kinds.index("slip_onset")
    assert res.speed_m_s == pytest.approx(rig.scales.char_length_m * 2)


def test_ramp_slides_the_set_distance_per_cycle():
    """The paper's algorithm: break away at kappa W, step dl, reset. Each cycle moves the
    tip at least slide_distance_m (and not runaway far), breaking away at mu W each time."""
    rig = flat_rig()
    slide = 0.05 * rig.scales.char_length_m
    res = rig.run(
        RampDrive(rate_n_s=2 * rig.scales.preload_n, duration_s=1.2, slide_distance_m=slide),
        start=(-0.04, 0.0),
    )
    resets = [e.index for e in res.events if e.kind == "reset"]
    assert len(resets) >= 2
    steps = np.diff(res.position_m[resets, 0])
    assert np.all(steps >= slide) and np.all(steps < 3 * slide)
    np.testing.assert_allclose(res.slip_kappas, MU, rtol=0.05)
    short = rig.run(
        RampDrive(rate_n_s=2 * rig.scales.preload_n, duration_s=1.2, slide_distance_m=0.0), start=(-0.04, 0.0)
    )
    short_resets = [e.index for e in short.events if e.kind == "reset"]
    assert np.diff(short.position_m[short_resets, 0]).max() < slide


# --------------------------------------------------------------------------- end reasons


def test_every_end_reason_is_reachable_and_recorded():
    rig = flat_rig()
    reasons = {}
    res = rig.run(SpringDrive(speed_m_s=0.02, duration_s=0.3), start=(0.0, 0.0))
    reasons[res.end_reason] = res
    res = rig.run(SpringDrive(speed_m_s=0.05), start=(0.044, 0.0))
    assert res.end_reason is EndReason.LEFT_DOMAIN
    reasons[res.end_reason] = res
    res = rig.run(
        SpringDrive(speed_m_s=0.02, duration_s=0.3),
        start=(0.0, 0.0),
        detection=Detection(penetration_tol_m=1e-7),
    )
    assert "penetration" in res.end_detail
    reasons[res.end_reason] = res
    res = rig.run(
        SpringDrive(speed_m_s=0.01, stiffness_n_m=1e9, duration_s=0.05),
        start=(0.0, 0.0),
        detection=Detection(kappa_cap=1e12),
    )
    assert res.end_reason is EndReason.ENGINE_TROUBLE and "reset" in res.end_detail
    for slope, probe in ((0.0, StaticProbe()), (40.0, StaticProbe())):
        res = plane_rig(slope).run(probe, start=START)
        reasons[res.end_reason] = res
    lock = plane_rig(70.0)
    res = lock.run(
        StaticProbe(start_force_n=1.5 * lock.scales.preload_n, rate_n_s=20 * lock.scales.preload_n),
        start=START,
    )
    reasons[res.end_reason] = res
    assert set(reasons) == set(EndReason)
    for reason, res in reasons.items():
        assert res.events[-1].kind == reason.value
        assert res.summary()["end_reason"] == reason.value and res.end_detail


# --------------------------------------------------------------------------- batches


def test_batch_equals_one_at_a_time_and_python_reference():
    rig = flat_rig()
    drives = [
        SpringDrive(speed_m_s=0.01, duration_s=0.15),
        SpringDrive(speed_m_s=0.03, duration_s=0.15, stiffness_n_m=50.0),
        StaticProbe(rate_n_s=5 * rig.scales.preload_n),
    ]
    starts = [(-0.02, 0.0), (0.01, 0.013), (0.0, -0.01)]
    batch = rig.run_batch(drives, starts, nthread=2)
    for drive, start, b in zip(drives, starts, batch):
        one = rig.run(drive, start=start)
        ref = rig.run(drive, start=start, backend="python")
        for other in (one, ref):
            assert other.end_reason is b.end_reason and other.n == b.n
            np.testing.assert_allclose(other.position_m, b.position_m, rtol=0, atol=1e-12)
            np.testing.assert_allclose(other.drive_force_n, b.drive_force_n, rtol=1e-9, atol=1e-12)


# --------------------------------------------------------------------------- validation


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
            r"surface too coarse for the tip: hfield spacing 0\.0005 m > 2 x tip_radius_m",
        ),
        (lambda: flat_rig().run(StaticProbe(), start=(1.0, 0.0)), r"start \(1, 0\) lies outside"),
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
    assert {"integrator", "impratio", "noslip_iterations", "solref", "solimp", "hfield_resolution"} <= set(
        eng
    )
    # the default rule: resting penetration a_p dt^2 <= 0.5 % of the tip radius
    assert rig.scales.preload_n / rig.tip.mass_kg * rig.engine.timestep_s**2 <= 0.005 * R_TIP
    assert res.penetration_m.max() < 0.01 * rig.scales.char_length_m


# --------------------------------------------------------------------------- CLI


def test_cli_simulate_export_and_view(tmp_path, monkeypatch):
    import pandas as pd
    from click.testing import CliRunner

    from spine_mj.cli import main

    runner = CliRunner()
    res = runner.invoke(
        main,
        [
            "simulate",
            "paper-single-peak",
            "--start",
            "-3,-1",
            "--drive",
            "spring",
            "--speed",
            "0.05",
            "--duration",
            "0.05",
            "-o",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    table = pd.read_parquet(tmp_path / "trajectory.parquet")
    assert len(table) > 100 and (tmp_path / "run.png").stat().st_size > 0
    res = runner.invoke(main, ["sim", "export", "paper-single-peak", "-o", str(tmp_path / "rig.xml")])
    assert res.exit_code == 0 and mujoco.MjModel.from_xml_path(str(tmp_path / "rig.xml")).nhfield == 1
    res = runner.invoke(main, ["simulate", "paper-single-peak", "--start", "-3", "-o", str(tmp_path)])
    assert res.exit_code == 2 and "--start must look like X,Y" in res.output
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    res = runner.invoke(main, ["view", "paper-single-peak"])
    assert res.exit_code != 0 and "no display" in res.output and "Traceback" not in res.output


def test_fine_grid_is_coarsened_to_respect_the_contact_cap():
    """MuJoCo keeps <= 50 contacts per geom pair: the P600 grid (2.6 um) under a 25 um tip
    would lose the deepest ones, so the rig resamples the hfield to ~R/4 and records it."""
    from spine_mj.surfaces import sandpaper

    surf = sandpaper(grit="P600", size_m=0.3e-3, rng=1)
    rig = Rig(surf, tip=TipParams(tip_radius_m=25e-6))
    assert rig.scales.hfield_spacing_m >= 0.25 * 25e-6 * (1 - 1e-9)
    assert rig.engine.hfield_resolution == rig.hfield.ncol
    for start in [(0.0, 0.0), (-1e-4, 5e-5), (1e-4, -1e-4)]:
        z = rig.place(*start)[2]
        assert surf.height(*start) < z < surf.heights.max() + 2 * 25e-6


def test_scales_for_surface_are_the_rigs_scales_without_building_a_model():
    """Scales.for_surface is the one sizing rule: a rig's scales equal it, and the default
    tip radius is max(one hfield spacing, L_c / 100) in metres for a dimensionless surface."""
    from spine_mj.sim import DEFAULT_LENGTH_SCALE_M, Scales, characteristic_length

    surf = single_gaussian()
    tip = TipParams(mass_kg=0.02)
    scales = Scales.for_surface(surf, tip=tip, hfield_resolution=101)
    rig = Rig(
        surf, tip=tip, engine=EngineSettings(timestep_s=1e-3, solref=(2e-3, 1.0), hfield_resolution=101)
    )
    assert scales == rig.scales
    lc_m = characteristic_length(surf) * DEFAULT_LENGTH_SCALE_M
    spacing_m = 10 / 100 * DEFAULT_LENGTH_SCALE_M
    assert scales.char_length_m == pytest.approx(lc_m, rel=1e-12)
    assert scales.hfield_spacing_m == pytest.approx(spacing_m, rel=1e-12)
    assert scales.tip_radius_m == pytest.approx(max(spacing_m, lc_m / 100), rel=1e-3)
    assert scales.inertia_number(scales.speed_for(3e-4)) == pytest.approx(3e-4, rel=1e-12)

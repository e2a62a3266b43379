"""Scale invariance: the engine works in the problem's own units (L_c, F_p, m), so the same
dimensionless problem at 1 um, 1 mm and 1 m is the same model and the same trajectory."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from spine_mj.errors import SpineInputError
from spine_mj.roughness import characteristic_length
from spine_mj.sim import EndReason, Rig, Scales, SpringDrive, TipParams, default_engine
from spine_mj.surface_io import import_topography, load_surface, save_surface
from spine_mj.surfaces import GridSurface, fractal_fbm, single_gaussian

SCALES_M = (1e-6, 1e-3, 1.0)


def _dimensionless_run(surface, length_scale_m, *, ie, k_number, tip_over_l, mass_kg, start):
    """A spring run of one dimensionless problem at ``length_scale_m`` metres per unit; its
    path in L_c, time in tau and drive force in F_p."""
    lc = characteristic_length(surface) * length_scale_m
    tip = TipParams(tip_radius_m=tip_over_l * lc, mass_kg=mass_kg, mu_s=0.5)
    sc = Scales.for_surface(surface, tip=tip, length_scale_m=length_scale_m)
    engine = default_engine(sc, stiffness_n_m=sc.stiffness_for(k_number))  # the spring bounds the step
    rig = Rig(surface, tip=tip, length_scale_m=length_scale_m, engine=engine)
    drive = SpringDrive(
        speed_m_s=sc.speed_for(ie), stiffness_n_m=sc.stiffness_for(k_number), duration_s=40 * sc.time_s
    )
    res = rig.run(drive, start=start)
    assert res.inertia_number == pytest.approx(ie, rel=1e-12)
    assert res.stiffness_number == pytest.approx(k_number, rel=1e-12)
    return (
        rig,
        res,
        {
            "x": res.position_m / sc.char_length_m,
            "t": res.time_s / sc.time_s,
            "f": res.drive_force_n / sc.preload_n,
            "k_lc": res.stiffness_n_m * sc.char_length_m / sc.preload_n,
        },
    )


@pytest.mark.parametrize(
    ("surface", "start", "tip_over_l", "k_number"),
    [
        (single_gaussian(), (-3.0, -2.0), 0.05, 300.0),
        (fractal_fbm(nx=48, size=6.0, hurst=0.8, rms_slope=0.5, rng=3), (-1.5, 0.2), 0.1, 30.0),
    ],
    ids=["single_peak", "fractal"],
)
def test_same_dimensionless_problem_gives_the_same_trajectory_at_every_scale(
    surface, start, tip_over_l, k_number
):
    """Masses differ too (1 g .. 1 kg): only the ratios I_e, K, mu, r / L_c matter.

    Tolerance: the scaled models are equal up to the rounding of ``x * s / s`` (a few ulp);
    switches of the contact set at facet edges amplify that (measured: 3e-11 L_c on the
    fractal, 5e-8 L_c over 70 stick-slip events on the peak), so 1e-6 L_c in position and
    the spring force that stretch makes, 1e-6 k L_c, in force; the times agree to
    round-off. (With a soft drive, K = 30, the tip sliding over the peak's facet kinks
    amplifies the same round-off to 1e-2 L_c: the dynamics' own sensitivity, not a
    difference of the models. On this fractal the opposite: K = 30 agrees to 4e-12 L_c,
    while at K = 300, with the step and the contact's time constant refined for the spring,
    one scale's run splits from the others near a facet edge by 0.1 L_c, two steps apart
    at the domain's edge.)
    """
    runs = [
        _dimensionless_run(
            surface, s, ie=1e-2, k_number=k_number, tip_over_l=tip_over_l, mass_kg=m, start=start
        )
        for s, m in zip(SCALES_M, (1e-3, 1e-2, 1.0))
    ]
    (rig0, res0, ref), others = runs[0], runs[1:]
    assert res0.end_reason in (EndReason.COMPLETED, EndReason.LEFT_DOMAIN, EndReason.SELF_LOCK)
    assert np.ptp(ref["x"][:, 0]) > 0.1  # the tip moved a tenth of L_c or more
    for rig, res, dimless in others:
        assert rig.model.opt.timestep == pytest.approx(rig0.model.opt.timestep, rel=1e-14)
        np.testing.assert_allclose(rig.model.hfield_size, rig0.model.hfield_size, rtol=1e-14)
        assert res.end_reason is res0.end_reason and res.n == res0.n
        np.testing.assert_allclose(dimless["t"], ref["t"], rtol=1e-12)
        np.testing.assert_allclose(dimless["x"], ref["x"], rtol=0, atol=1e-6)
        np.testing.assert_allclose(dimless["f"], ref["f"], rtol=0, atol=1e-6 * ref["k_lc"])


def test_micrometre_and_nanometre_tips_compile_with_order_one_engine_numbers():
    """The SI model of a 1 nm tip had an inertia below MuJoCo's floor (mjMINVAL = 1e-15);
    in engine units the mass is 1 and the tip radius r / L_c."""
    for length_scale_m in (1e-9, 1e-6):
        rig = Rig(single_gaussian(), length_scale_m=length_scale_m)
        body = mujoco.mj_name2id(rig.model, mujoco.mjtObj.mjOBJ_BODY, "tip")
        assert rig.model.body_mass[body] == pytest.approx(1.0, rel=1e-12)
        assert rig.model.geom_size[rig.geom_tip, 0] == pytest.approx(
            rig.tip.tip_radius_m / rig.scales.char_length_m, rel=1e-12
        )
        assert rig.tip.tip_radius_m < 1e-7 * length_scale_m / 1e-9


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (
            {"tip": TipParams(tip_radius_m=0.2)},
            r"tip_radius_m 0\.2 m \(20 surface units\) is larger than the surface",
        ),
        ({"length_scale_m": 1e-30}, r"length_scale_m must lie in \[1e-12, 1000\] m .*got 1e-30"),
        ({"tip": TipParams(tip_radius_m=1e-13)}, r"finer than the engine resolves"),
    ],
)
def test_unphysical_sizes_are_rejected_clearly(kwargs, match):
    with pytest.raises(SpineInputError, match=match):
        Rig(single_gaussian(), **kwargs)
    with pytest.raises(SpineInputError, match=r"mass_kg must lie in \[1e-24, 1e\+06\] kg, got 1e-30"):
        TipParams(mass_kg=1e-30)


def test_a_scan_kept_in_its_instrument_unit_runs_as_the_scan_in_metres(tmp_path, topography_dir):
    """The profilometer scan imported in its own um (through a saved .npz) and the same
    heights converted to metres, as old .npz files hold them, are one dimensionless model:
    the same engine numbers and the same SI trajectory. Both differ only by the rounding of
    ``x * 1e-6`` (measured 2e-12 L_c over 5.6 L_c of travel), hence 1e-9 L_c."""
    scan = import_topography(topography_dir / "plu-1.plu")
    assert scan.unit == "um"
    window = (slice(0, 64), slice(0, 64))  # 106 um a side: a fast run, still 5 L_c of path
    um = load_surface(
        save_surface(
            GridSurface(heights=scan.heights[window], x=scan.x[:64], y=scan.y[:64], unit="um"),
            tmp_path / "um.npz",
        )
    )
    metres = GridSurface(heights=um.heights * 1e-6, x=um.x * 1e-6, y=um.y * 1e-6, unit="m")
    runs = []
    for surface, unit_m in ((um, 1e-6), (metres, 1.0)):
        rig = Rig(surface)
        assert rig.length_scale_m == unit_m
        speed = rig.scales.speed_for(1e-2)
        start = (surface.x[6], surface.y[32])  # surface units: the same point
        runs.append((rig, rig.run(SpringDrive(speed_m_s=speed), start=start)))
    (rig_um, res_um), (rig_m, res_m) = runs
    lc = rig_um.scales.char_length_m
    assert rig_m.scales.char_length_m == pytest.approx(lc, rel=1e-12)
    assert rig_m.tip.tip_radius_m == rig_um.tip.tip_radius_m
    assert rig_m.model.opt.timestep == pytest.approx(rig_um.model.opt.timestep, rel=1e-14)
    assert res_um.end_reason is res_m.end_reason and res_um.n == res_m.n
    assert np.ptp(res_um.position_m[:, 0]) > lc  # it went somewhere
    table_um, table_m = res_um.table(), res_m.table()  # SI columns both
    np.testing.assert_allclose(table_um["time_s"], table_m["time_s"], rtol=1e-12)
    for col in ("position_x_m", "position_y_m", "position_z_m"):
        np.testing.assert_allclose(table_um[col], table_m[col], rtol=0, atol=1e-9 * lc)

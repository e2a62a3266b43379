"""The static map's solution verification: its hfield x 2 refines the plane's hfield and
keeps the tip (a plane of twice the samples would halve the default tip with it)."""

import dataclasses
import time

import pytest

from spine_mj import sweep
from spine_mj.validate.plan_sections import StaticPlan
from spine_mj.validate.plans import HFIELD_DOUBLED, PLANS, RECOMMENDED
from spine_mj.validate.static_map import static_map
from spine_mj.validate.study_runner import StudyRunner


def test_the_hfield_doubled_probe_runs_on_the_same_plane_and_tip_with_its_hfield_refined(tmp_path):
    static = StaticPlan(slopes_deg=(20.0,), azimuths_deg=(0.0,), engines=(RECOMMENDED, HFIELD_DOUBLED))
    plan = dataclasses.replace(PLANS["smoke"], static=static)
    res = static_map(plan, StudyRunner(tmp_path, 1, None, time.perf_counter()))
    stores = sorted((tmp_path / "sweeps" / "static").iterdir())
    assert len(stores) == 2
    runs = {s.name: sweep.load_runs(s).iloc[0] for s in stores}
    base = next(r for n, r in runs.items() if n.endswith("default"))
    fine = next(r for n, r in runs.items() if "hfield_factor" in n)
    assert (base["hfield_refinement"], fine["hfield_refinement"]) == (1, 2)
    assert fine["tip_radius_m"] == base["tip_radius_m"]  # the tip kept
    # a plane's refined facets are the same plane: the breakaway does not move
    by = {r["engine"]: r for r in res.rows}
    assert by[HFIELD_DOUBLED[0]]["kappa_mj"] == pytest.approx(by[RECOMMENDED[0]]["kappa_mj"], rel=1e-3)
    assert set(res.convergence) == {"hfield_doubled"}
    # per plane: a block on the incline, kappa = tan(theta + arctan mu) in the drive's section.
    # MuJoCo holds it no less (within a ramp step), and no more than the contacts it finds
    # there hold together (their multi-contact lock); what it holds beyond kappa is the tilt
    # of those contacts' normals (a prism's beside the plane's own), read as a tilt of the plane
    import math

    (plane,) = res.planes
    base = by[RECOMMENDED[0]]
    kappa = math.tan(math.radians(20.0) + math.atan(0.5))
    step = plane["force_step_fp"]
    assert plane["kappa"] == pytest.approx(kappa, rel=1e-9)
    assert plane["kappa_mj"] >= kappa - step
    assert plane["first_slip_kappa"] >= kappa - step  # nothing slips before the plane lets it
    assert plane["breakaway_contacts"] >= 1
    assert plane["kappa_mj"] <= plane["contacts_lock_kappa"] * (1 + 0.0015) + step  # the LP's inscribed cone
    tilt_of_a_step = step / kappa / base["kappa_gain_per_deg"]
    assert abs(base["equivalent_tilt_deg"]) <= plane["contact_tilt_deg"] + tilt_of_a_step
    assert plane["converged"] is True and plane["cause"] == "-"
    assert res.validation_keys()["static_plane_summary"]["converged_planes"] == 1


@pytest.mark.parametrize("slope", [0.0, 20.0, 45.0, 60.0])
def test_the_tilt_gain_is_the_closed_form_pole_of_tan_theta_plus_phi(slope):
    """In the drive's section kappa = tan(theta + phi): d ln(kappa) / d theta =
    2 / sin(2 (theta + phi)), which grows without bound toward the self-lock pole."""
    import math

    from spine_mj.validate.static_map import equivalent_tilt_deg, kappa_tilt_gain

    mu = 0.5
    total = math.radians(slope) + math.atan(mu)
    gain = kappa_tilt_gain(slope, 0.0, mu)
    assert gain == pytest.approx(2 / math.sin(2 * total) * math.pi / 180, rel=1e-4)  # central difference
    # a breakaway from a plane tilted 0.05 deg more reads as that tilt on every plane
    ratio = math.tan(total + math.radians(0.05)) / math.tan(total)
    assert equivalent_tilt_deg(ratio, gain) == pytest.approx(0.05, rel=0.02)
    assert math.isnan(kappa_tilt_gain(70.0, 0.0, mu))  # self-locked: no kappa to perturb


def test_the_error_rule_turns_absolute_where_the_relative_gain_of_a_tilt_doubles():
    """kappa = tan(psi): d ln kappa / d psi = (1 + kappa^2) / kappa, least (2) at kappa = 1;
    the floor is where it is twice that, below it the error is absolute over the floor,
    continuous at the floor."""
    import math

    from spine_mj.validate.static_map import KAPPA_FLOOR, kappa_error

    k = KAPPA_FLOOR
    assert (1 + k * k) / k == pytest.approx(2 * 2.0)
    assert k == pytest.approx(math.tan(math.radians(15.0)))
    assert kappa_error(1.05, 1.0) == pytest.approx(0.05)  # relative above
    assert kappa_error(5.0 * 1.02, 5.0) == pytest.approx(0.02)
    assert kappa_error(0.05 + 0.01, 0.05) == pytest.approx(0.01 / k)  # absolute below: 0.01 F_p
    assert kappa_error(k * 1.03, k) == pytest.approx(kappa_error(k * 1.03 - 1e-12, k - 1e-12), rel=1e-6)
    # the same absolute error near kappa = 0 is not magnified as kappa shrinks
    assert kappa_error(0.017 + 0.02, 0.02) == pytest.approx(kappa_error(0.017 + 0.002, 0.002))


def _setting(engine, kappa, kmj, **kw):
    from spine_mj.validate.static_map import kappa_error

    row = {
        "engine": engine,
        "slope_deg": 52.5,
        "azimuth_deg": 0.0,
        "region": "engaged",
        "kappa": kappa,
        "kappa_mj": kmj,
        "error": kappa_error(kmj, kappa),
        "abs_error_fp": kmj - kappa,
        "force_step_fp": 0.0016,
        "breakaway_contacts": 1,
        "held_contacts": 1,
        "contact_tilt_deg": 0.0,
        "contacts_lock_kappa": kappa,
        "first_slip_kappa": kmj,
        "slid_before_r_tip": 0.0,
    }
    return {**row, **kw}


def test_a_plane_converges_when_each_ladders_last_change_lies_within_slack_plus_the_ramp_steps():
    from spine_mj.validate.plans import DT_HALVED, HFIELD_DOUBLED, HFIELD_QUADRUPLED
    from spine_mj.validate.static_map import plane_table

    engines = (RECOMMENDED, DT_HALVED, HFIELD_DOUBLED, HFIELD_QUADRUPLED)
    k = 1.0
    # tolerance 0.0025 + 2 x 0.0016 = 0.0057 on a relative error at kappa = 1
    rows = [
        _setting(RECOMMENDED[0], k, 1.004),
        _setting(DT_HALVED[0], k, 1.004 + 0.005),
        _setting(HFIELD_DOUBLED[0], k, 1.06),  # an unconverged middle level: only the last change counts
        _setting(HFIELD_QUADRUPLED[0], k, 1.06 - 0.005),
        {**_setting(RECOMMENDED[0], 0.0, 0.0), "slope_deg": 75.0, "region": "self_lock"},
    ]
    (plane,) = plane_table(rows, engines)
    assert plane["change_hfield"] == pytest.approx(-0.005)
    assert plane["tolerance_hfield"] == pytest.approx(0.0025 + 0.0032)
    assert plane["converged"] is True
    assert plane["cause"].startswith(HFIELD_DOUBLED[0] + ": one contact")  # its error misses 5 %
    rows[3] = _setting(HFIELD_QUADRUPLED[0], k, 1.06 - 0.007)
    assert plane_table(rows, engines)[0]["converged"] is False


def test_a_tip_that_slipped_and_was_held_again_by_tilted_contacts_is_an_edge_catch():
    from spine_mj.validate.static_map import setting_cause

    caught = _setting(
        RECOMMENDED[0],
        5.176,
        5.464,
        breakaway_contacts=2,
        held_contacts=2,
        contact_tilt_deg=1.8,
        contacts_lock_kappa=6.23,
        first_slip_kappa=5.179,
        slid_before_r_tip=0.053,
    )
    cause = setting_cause(caught)
    assert cause.startswith("edge catch: slipped at kappa 5.179 (+0.06%)")
    assert "up to 2 contacts tilted up to 1.8 deg, whose lock is kappa 6.23" in cause
    assert setting_cause({**caught, "slid_before_r_tip": 0.0}).startswith("tilted contacts")
    # held again by the plane's own normal: caught, not an edge
    assert setting_cause({**caught, "contact_tilt_deg": 0.0}).startswith("caught: slipped")
    # a first slip within the readings' tolerance of the breakaway is the breakaway itself
    assert setting_cause({**caught, "first_slip_kappa": 5.464 - 0.01}).startswith("tilted contacts")
    assert setting_cause(_setting(RECOMMENDED[0], 1.0, 1.06)).startswith("one contact")
    assert setting_cause(_setting(RECOMMENDED[0], 1.0, float("nan"))) == "no breakaway"


def test_the_52_5_deg_plane_slips_at_the_closed_form_and_is_held_again_by_a_tilted_prism_contact(tmp_path):
    """The full plan's largest error, measured: on the 52.5 deg plane (azimuth 0) the tip
    slips within its ramp step of tan(theta + arctan mu), and what holds it beyond kappa is
    a contact whose normal is tilted from the plane's: the breakaway lies between the plane's
    kappa and the multi-contact lock of the contacts found, and the plane tilt that would
    explain the error is no larger than the largest tilt of those contacts."""
    import math

    static = StaticPlan(slopes_deg=(52.5,), azimuths_deg=(0.0,), engines=(RECOMMENDED,))
    plan = dataclasses.replace(PLANS["smoke"], static=static)
    res = static_map(plan, StudyRunner(tmp_path, 1, None, time.perf_counter()))
    (plane,) = res.planes
    (row,) = res.rows
    kappa = math.tan(math.radians(52.5) + math.atan(0.5))
    step = plane["force_step_fp"]
    assert plane["first_slip_kappa"] == pytest.approx(kappa, abs=3 * step)
    assert plane["held_contacts"] >= 2 and plane["contact_tilt_deg"] > 1.0
    assert kappa < plane["kappa_mj"] <= plane["contacts_lock_kappa"] * 1.0015 + step
    assert 0 < row["equivalent_tilt_deg"] <= plane["contact_tilt_deg"]
    assert plane["slid_before_r_tip"] > 0 and "edge catch" in plane["cause"]

"""Validation harness: I_e* estimator, slip statistics, a smoke-size end-to-end run, CLI."""

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj import validate
from spine_mj.cli import main
from spine_mj.errors import SpineInputError

IE = np.array([1e-4, 1e-3, 1e-2, 1e-1, 1.0])


# --------------------------------------------------------------------------- I_e*


def test_ie_star_interpolates_the_agreement_crossing_in_log_ie():
    # agreement 1.0 at 1e-2, 0.9 at 1e-1: 0.95 is crossed half-way in log10, at 10**-1.5
    est = validate.estimate_ie_star(IE, [1.0, 1.0, 1.0, 0.9, 0.5])
    assert est.kind == "bracketed"
    assert (est.low, est.high) == (1e-2, 1e-1)
    assert est.value == pytest.approx(10**-1.5, rel=1e-9)


def test_ie_star_takes_the_earlier_of_agreement_and_frechet_crossings():
    # Frechet 0.04 -> 0.19 crosses 0.1 at 40 % of the decade; agreement 1 -> 0.85 at 1/3
    est = validate.estimate_ie_star(IE, [1, 1, 1, 0.85, 0.5], [0.01, 0.02, 0.04, 0.19, 1.0])
    assert est.value == pytest.approx(10 ** (-2 + 1 / 3), rel=1e-9)
    est = validate.estimate_ie_star(IE, [1, 1, 1, 1, 0.5], [0.01, 0.02, 0.04, 0.19, 1.0])
    assert est.value == pytest.approx(10 ** (-2 + 0.4), rel=1e-9)
    assert (est.low, est.high) == (1e-2, 1e-1)


def test_ie_star_reports_when_the_grid_does_not_bracket_it():
    above = validate.estimate_ie_star(IE, np.ones(5), np.full(5, 0.01))
    assert above.kind == "above" and above.low == 1.0 and math.isnan(above.value)
    below = validate.estimate_ie_star(IE, [0.5, 1, 1, 1, 1])
    assert below.kind == "below" and below.high == 1e-4 and math.isnan(below.value)


@pytest.mark.parametrize(
    "ie, ag, match",
    [
        ([1e-3, 1e-4], [1, 1], "strictly increasing"),
        ([1e-3], [1], "same length >= 2"),
        ([1e-3, 1e-2], [1, 1, 1], "same length >= 2"),
    ],
)
def test_ie_star_rejects_bad_grids(ie, ag, match):
    with pytest.raises(SpineInputError, match=match):
        validate.estimate_ie_star(ie, ag)


def test_bootstrap_of_identical_starts_collapses_on_the_estimate():
    ag = np.repeat(np.array([1.0, 1.0, 1.0, 0.0, 0.0])[:, None], 6, axis=1)
    fr = np.full_like(ag, 0.01)
    lo, hi = validate.bootstrap_ie_star(IE, ag, fr, n_boot=50, rng=0)
    # every resample sees agreement 1 -> 0 between 1e-2 and 1e-1: crossing at 5 % of the decade
    assert lo == pytest.approx(hi) == pytest.approx(10 ** (-2 + 0.05))
    # starts that disagree at 1e-1 for some resamples widen the interval
    ag[3, :3] = 1.0
    lo, hi = validate.bootstrap_ie_star(IE, ag, fr, n_boot=200, rng=0)
    assert 1e-2 < lo < hi <= 1e-1


# --------------------------------------------------------------------------- slip statistics


def test_slip_statistics_on_a_constructed_stick_slip_trace():
    # stick (force rises 0 -> 1), slip 4 samples (x jumps by 0.1 each, force falls to 0.4),
    # stick again (rises to 0.9), slip 2 samples (y moves 0.3 + 0.4), and one-sample chatter
    t = np.arange(30, dtype=float)
    x = np.zeros(30)
    y = np.zeros(30)
    f = np.zeros(30)
    s = np.zeros(30, bool)
    f[:10] = np.linspace(0, 1, 10)
    s[10:14] = True
    x[10:14] = 0.1 * np.arange(1, 5)
    x[14:] = 0.4
    f[10:14] = [0.9, 0.7, 0.5, 0.4]
    f[14:20] = np.linspace(0.4, 0.9, 6)
    s[20:22] = True
    y[20], y[21:] = 0.3, 0.7
    f[20:22] = [0.8, 0.6]
    f[22:] = 0.6
    s[26] = True  # chatter: one sample, no motion
    st = validate.slip_statistics(t, x, y, f, s, min_samples=2)
    assert st.count == 2
    np.testing.assert_allclose(st.jump_lengths, [0.4, 0.7])
    # drop: the force at the last stuck sample minus the force after the slip ends
    np.testing.assert_allclose(st.force_drops, [1.0 - 0.4, 0.9 - 0.6])
    np.testing.assert_allclose(st.durations, [5.0, 3.0])
    assert validate.slip_statistics(t, x, y, f, s, min_samples=1).count == 3
    assert st.summary()["max_jump"] == pytest.approx(0.7)


def test_slip_statistics_rejects_mismatched_arrays():
    with pytest.raises(SpineInputError, match="one length"):
        validate.slip_statistics([0, 1], [0, 1], [0, 1], [0, 1], [True])


# --------------------------------------------------------------------------- end to end


def test_smoke_validation_writes_report_and_json(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a relative --out, as `make demo` passes it
    out = tmp_path / "val"
    res = CliRunner().invoke(main, ["validate", "--plan", "smoke", "--out", "val", "--workers", "1"])
    assert res.exit_code == 0, res.output
    doc = json.loads((out / "validation.json").read_text())
    for key in (
        "static_kappa_max_rel_error",
        "lowest_ie",
        "outcome_agreement_at_lowest_ie",
        "mean_frechet_at_lowest_ie",
        "ie_star",
        "engine_settings",
    ):
        assert key in doc
    assert doc["lowest_ie"] == validate.PLANS["smoke"].lowest_ie
    assert set(doc["outcome_agreement_at_lowest_ie"]) == {"single_peak_valley"}
    assert 0.0 <= doc["outcome_agreement_at_lowest_ie"]["single_peak_valley"] <= 1.0
    assert {"value", "low", "high", "kind"} <= set(doc["ie_star"]["spring"])
    # the static probe on a 20 deg plane (engaged) matches tan(theta + arctan mu) closely
    assert doc["static_kappa_max_rel_error"] < 0.05
    report = (out / "report.md").read_text()
    assert "Quasistatic limit" in report and "figures/boundary.png" in report
    assert (out / "figures" / "boundary.png").stat().st_size > 1000
    assert (out / "sweeps" / "boundary" / "spring-paper-single-peak" / "runs.parquet").is_file()
    assert "outcome agreement" in res.output


def test_unknown_plan_is_rejected():
    with pytest.raises(SpineInputError, match="plan must be one of"):
        validate.run_validation("unused", plan="huge")


@pytest.mark.parametrize(
    "args, match",
    [
        (["--quick", "--plan", "smoke"], "give one of them"),
        (["--plan", "smoke", "--out-is-file"], "is not a folder"),
    ],
)
def test_cli_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, args, match):
    target = tmp_path / "out"
    if "--out-is-file" in args:
        args = [a for a in args if a != "--out-is-file"]
        target.write_text("not a folder")
    before = sorted(p.name for p in tmp_path.iterdir())
    res = CliRunner().invoke(main, ["validate", *args, "--out", str(target)])
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error:") and match in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before


# --------------------------------------------------------------------------- robust I_e*


def test_one_outlying_start_moves_the_mean_criterion_but_not_the_median():
    # 10 starts, all agree in outcome; one start deviates by 5 L_c at every I_e (a marginal
    # start), the others by 0.02 L_c until 1e-1
    ag = np.ones((5, 10))
    ag[3:, :] = 0.0
    fr = np.full((5, 10), 0.02)
    fr[:, 0] = 5.0
    by = validate.ie_star_by_criterion(IE, ag, fr, n_boot=100, rng=1)
    assert set(by) == set(validate.IE_STAR_CRITERIA) | {"departure"}
    assert by["mean_frechet"]["kind"] == "below"  # mean 0.52 L_c at every I_e
    for key in ("median_frechet", "outcome"):
        assert by[key]["kind"] == "bracketed"
        assert (by[key]["low"], by[key]["high"]) == (1e-2, 1e-1)
        assert 1e-2 <= by[key]["ci_low"] <= by[key]["ci_high"] <= 1e-1
    assert "median" in by["median_frechet"]["criterion"]


def test_bootstrap_rejects_an_unknown_statistic():
    with pytest.raises(SpineInputError, match="stat must be"):
        validate.bootstrap_ie_star(IE, np.ones((5, 2)), np.ones((5, 2)), n_boot=2, rng=0, stat="max")


def test_prefix_frechet_cuts_the_streamline_at_the_mujoco_arc_length():
    q = np.column_stack([np.linspace(0, 10, 101), np.zeros(101)])
    # MuJoCo covered 1 unit of it, 0.05 to the side: the prefix deviation is the offset
    m = np.column_stack([np.linspace(0, 1, 11), np.full(11, 0.05)])
    assert validate.prefix_frechet(m, q, 1.0) == pytest.approx(0.05, abs=1e-3)
    # against the whole streamline it would be the 9 units MuJoCo did not cover
    assert validate.path_metrics(m, q, 1.0)[0] > 8.9


def test_ramp_duration_covers_the_target_from_the_measured_slip_per_cycle():
    from spine_mj import sim

    rig = sim.Rig(sim.inclined_plane(slope_deg=0.0, azimuth_deg=0.0), tip=sim.TipParams(mu_s=0.5))
    rp = validate.ramp_duration(rig, validate.PLANE_START, 1.0, target_lc=0.5, max_steps=4000)
    assert rp.ie_equivalent == pytest.approx(1.0, rel=1e-9)
    assert rp.slip_per_cycle_lc > 0 and rp.cycle_s > 0
    # three times the pilot's cycles over the target, plus one ramp to the self-lock cap
    lock_s = sim.Detection().kappa_cap * rig.scales.preload_n / rp.rate_n_s
    assert rp.required_s == pytest.approx(3 * rp.cycle_s * 0.5 / rp.slip_per_cycle_lc + lock_s, rel=1e-9)
    assert rp.duration_s == pytest.approx(min(rp.required_s, 4000 * rp.timestep_s), rel=1e-3)
    assert rp.capped == (rp.required_s > 4000 * rp.timestep_s)
    assert 0 < rp.coverage_expected <= 1


def test_departure_ie_star_finds_the_break_below_an_imperfect_plateau():
    """Agreement stuck at 90 % (one start always disagrees) fails the absolute 95 % rule at
    every I_e; the departure criterion still brackets the drop between 1e-2 and 1e-1."""
    ie = np.logspace(-4, 0, 5)
    runs = np.ones((5, 10))
    runs[:, 0] = 0  # an I_e-independent disagreement
    runs[3:, 1:6] = 0  # inertia breaks agreement from I_e = 0.1 on
    absolute = validate.estimate_ie_star(ie, runs.mean(axis=1))
    assert absolute.kind == "below"
    dep = validate.departure_ie_star(ie, runs, n_boot=50)
    assert dep.kind == "bracketed" and (dep.low, dep.high) == pytest.approx((1e-2, 1e-1))
    assert 1e-2 <= dep.value <= 1e-1
    flat = validate.departure_ie_star(ie, np.ones((5, 10)), n_boot=0)
    assert flat.kind == "above"

"""Solution verification of the corner: observed order, Richardson, the converged verdict,
the paired change, and the refined sweeps' engine keys."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from spine_mj import presets, sim
from spine_mj.errors import SpineInputError
from spine_mj.validate.convergence import (
    GRID_ONLY,
    REFINEMENTS,
    family_convergence,
    headline_convergence,
    is_converged,
    observed_order,
    paired_change,
    refinement_note,
    richardson,
    thin_starts,
    unconverged_mark,
)
from spine_mj.validate.paths import tip_radius
from spine_mj.validate.plans import MASS_KG, PLANS, FamilySpec, paper_starts, relative_starts
from spine_mj.validate.quasistatic_limit import limit_doc
from spine_mj.validate.sweep_configs import engine_grid, refined_resolution, rig_engine


@pytest.mark.parametrize("order", [1.0, 2.0, 0.5])
@pytest.mark.parametrize("ratio", [2.0, 3.0])
def test_observed_order_and_richardson_recover_a_power_law_sequence(order, ratio):
    # f(h) = f0 + C h^p at h, h / r, h / r^2: the order is p and Richardson gives f0 exactly
    f0, c, h = 0.87, -0.3, 0.1
    coarse, medium, fine = (f0 + c * (h / ratio**i) ** order for i in range(3))
    p = observed_order(fine, medium, coarse, ratio=ratio)
    assert p == pytest.approx(order, rel=1e-9)
    assert richardson(fine, medium, p, ratio=ratio) == pytest.approx(f0, abs=1e-12)


def test_observed_order_is_undefined_without_a_monotone_change():
    assert math.isnan(observed_order(1.0, 1.0, 0.9))  # no change between the finer two
    assert math.isnan(observed_order(1.0, 0.9, 1.0))  # oscillatory
    assert math.isnan(observed_order(float("nan"), 0.9, 1.0))
    assert math.isnan(richardson(1.0, 0.9, float("nan")))
    assert math.isnan(richardson(1.0, 0.9, -1.0))
    with pytest.raises(ValueError, match="ratio must be > 1"):
        observed_order(1.0, 0.9, 0.8, ratio=1.0)


def test_converged_means_the_refined_value_stays_inside_the_interval():
    assert is_converged(0.9, 0.05, (0.8, 0.96)) is True
    assert is_converged(0.9, 0.07, (0.8, 0.96)) is False
    assert is_converged(0.9, -0.1, (0.8, 0.96)) is True  # the low end is inside
    assert is_converged(0.9, -0.11, (0.8, 0.96)) is False
    assert is_converged(0.9, float("nan"), (0.8, 0.96)) is None
    assert is_converged(0.9, 0.0, (float("nan"), float("nan"))) is None
    # a median at the metric's resolution: a narrower interval than the metric resolves
    assert is_converged(0.0100, -0.002, (0.0100, 0.0101)) is False
    assert is_converged(0.0100, -0.002, (0.0100, 0.0101), resolution=0.01) is True
    assert is_converged(0.0100, 0.02, (0.0100, 0.0101), resolution=0.01) is False


def _rows(surface, ys, agree, frechet, lc=1.0):
    return pd.DataFrame(
        {
            "surface": surface,
            "surface_lc": lc,
            "start_x": -3.0,
            "start_y": np.asarray(ys, float),
            "agree": agree,
            "frechet": np.asarray(frechet, float),
        }
    )


def test_the_change_is_paired_on_the_starts_both_sides_ran():
    base = _rows("peak", [-1.0, -2.0, -3.0, -4.0], [True, True, False, np.nan], [0.01, 0.02, 0.5, np.nan])
    # the refined runs: two of the base's starts (one flips to agreeing) and one it never ran
    refined = _rows("peak", [-2.0, -3.0, -9.0], [True, True, False], [0.03, 0.04, 9.0])
    pc = paired_change(base, refined)
    assert pc["runs"] == 2
    assert pc["outcome_agreement"] == {"base": 0.5, "refined": 1.0, "change": 0.5}
    assert pc["median_frechet"]["base"] == pytest.approx(0.26)
    assert pc["median_frechet"]["refined"] == pytest.approx(0.035)
    # another surface's start at the same point is another start, a generator variant
    # (same label, another L_c) too
    assert paired_change(base, _rows("valley", [-2.0], [True], [0.1]))["runs"] == 0
    assert paired_change(base, _rows("peak", [-2.0], [True], [0.1], lc=2.0))["runs"] == 0


def test_a_family_is_converged_only_where_every_refinement_keeps_its_numbers_inside():
    ys = np.linspace(-1, -4, 10)
    agree = [True] * 9 + [False]
    base = _rows("peak", ys, agree, np.full(10, 0.010))
    summary = {
        "outcome_agreement": 0.9,
        "outcome_agreement_ci": [0.6, 1.0],
        "agreement_well_conditioned": 0.9,
        "agreement_ci": [0.6, 1.0],
        "median_frechet": 0.010,
        "median_frechet_ci": [0.009, 0.012],
    }
    halved = _rows("peak", ys, agree, np.full(10, 0.011))  # a change inside both intervals
    quartered = _rows("peak", ys, agree, np.full(10, 0.0115))
    finer_hfield = _rows("peak", ys, [True] * 10, np.full(10, 0.03))  # the Frechet leaves its interval
    out = family_convergence(
        summary, base, {"dt_halved": halved, "dt_quartered": quartered, "hfield_doubled": finer_hfield}
    )
    assert out["dt_halved"]["converged"] is True
    assert out["dt_halved"]["runs"] == 10
    assert out["dt_halved"]["agreement_change"] == 0.0
    assert out["dt_halved"]["median_frechet_change"] == pytest.approx(0.001)
    assert out["hfield_doubled"]["agreement_change"] == pytest.approx(0.1)
    assert out["hfield_doubled"]["outcome_agreement_converged"] is True
    assert out["hfield_doubled"]["median_frechet_converged"] is False  # by 0.02, twice what it resolves
    assert out["hfield_doubled"]["converged"] is False
    assert out["converged"] is False
    # three step levels, changes 0.001 then 0.0005: first order, converged value 0.012
    order = out["dt_order"]["median_frechet"]
    assert order["order"] == pytest.approx(1.0)
    assert order["richardson"] == pytest.approx(0.012)
    assert math.isnan(out["dt_order"]["outcome_agreement"]["order"])  # no run flipped


def test_the_judged_agreement_changes_on_the_well_conditioned_starts_only():
    # 10 paired starts, 2 ill-conditioned (coin tosses: both flip under the refinement), 1
    # well-conditioned one flips; the headline is over the well-conditioned ones, 7 / 8
    ys = np.linspace(-1, -4, 10)
    well = np.array([True] * 8 + [False] * 2)
    agree = np.array([True] * 7 + [False] * 3)
    base = _rows("peak", ys, agree, np.full(10, 0.01)).assign(well_conditioned=well)
    refined = _rows("peak", ys, [True] * 10, np.full(10, 0.01))
    pc = paired_change(base, refined)
    assert pc["runs"] == 10 and pc["well_conditioned_runs"] == 8
    assert pc["agreement_well_conditioned"] == {"base": 7 / 8, "refined": 1.0, "change": pytest.approx(1 / 8)}
    assert pc["outcome_agreement"]["change"] == pytest.approx(0.3)
    summary = {
        "agreement_well_conditioned": 0.875,
        "agreement_ci": [0.7, 1.0],
        "outcome_agreement": 0.7,
        "outcome_agreement_ci": [0.6, 0.8],
        "median_frechet": 0.01,
        "median_frechet_ci": [0.009, 0.012],
    }
    out = family_convergence(summary, base, {"dt_halved": refined})["dt_halved"]
    assert out["agreement_change"] == pytest.approx(1 / 8)  # the judged headline's change
    assert out["agreement_change_all_starts"] == pytest.approx(0.3)
    assert out["agreement_well_conditioned_converged"] is True  # 1.0 inside [0.7, 1.0]
    assert out["outcome_agreement_converged"] is False  # the coin tosses move it out
    assert out["converged"] is True  # judged on what the targets judge
    # without the column every start counts
    assert paired_change(base.drop(columns="well_conditioned"), refined)["well_conditioned_runs"] == 10


def test_a_start_whose_reference_stalls_at_either_level_leaves_the_pairs_and_is_counted():
    # 10 well-conditioned starts, all agreeing at the corner; the refined facets resolve a
    # pit on 3 of them, where the reference stalls (no answer: agree False, a long Frechet
    # to the stopped path), and 1 start stalled already at the corner. The judged headlines pair
    # the 6 starts answered at both levels; the 4 are counted, not read as MuJoCo's misses.
    ys = np.linspace(-1, -4, 10)
    stalled_base = np.array([False] * 9 + [True])
    stalled_refined = np.array([True] * 3 + [False] * 7)
    base = _rows("P600", ys, ~stalled_base, np.where(stalled_base, 5.0, 0.02)).assign(
        well_conditioned=True, reference_outcome=np.where(stalled_base, "stalled", "left_domain")
    )
    refined = _rows("P600", ys, ~stalled_refined, np.where(stalled_refined, 5.0, 0.03)).assign(
        reference_outcome=np.where(stalled_refined, "stalled", "left_domain")
    )
    pc = paired_change(base, refined)
    assert pc["runs"] == 10 and pc["well_conditioned_runs"] == 6 and pc["reference_stalled"] == 4
    assert pc["agreement_well_conditioned"] == {"base": 1.0, "refined": 1.0, "change": 0.0}
    assert pc["median_frechet"]["change"] == pytest.approx(0.01)
    # the all-starts agreement keeps them: a stall is its miss (9 / 10 to 7 / 10)
    assert pc["outcome_agreement"]["change"] == pytest.approx(-0.2)
    # without the column every reference answered
    assert (
        paired_change(base.drop(columns="reference_outcome"), refined.drop(columns="reference_outcome"))[
            "reference_stalled"
        ]
        == 0
    )


def test_a_refinement_not_run_says_so():
    base = _rows("fractal", [0.2, 0.8], [True, True], [0.01, 0.01])
    summary = {
        "outcome_agreement": 1.0,
        "outcome_agreement_ci": [0.3, 1.0],
        "agreement_well_conditioned": 1.0,
        "agreement_ci": [0.3, 1.0],
        "median_frechet": 0.01,
        "median_frechet_ci": [0.01, 0.01],
    }
    out = family_convergence(summary, base, {"dt_halved": base, "hfield_doubled": None})
    hf = out["hfield_doubled"]
    assert hf["refined"] is False and hf["converged"] is None and hf["note"] == "not run"
    assert math.isnan(hf["agreement_change"]) and math.isnan(hf["median_frechet_change"])
    assert out["converged"] is True  # decided by what was refined


def test_thin_starts_keeps_the_same_points_on_every_surface():
    fam = FamilySpec(
        "f", ("a",), (1, 2, 3), relative_starts(6), variants=((("hurst", 0.7),), (("hurst", 0.9),))
    )
    thin = thin_starts(fam, 2)
    ys = dict(fam.starts)["y"]
    assert dict(thin.starts)["y"] == (ys[0], ys[-1])
    assert thin.seeds == fam.seeds and thin.variants == fam.variants
    assert thin_starts(fam, 10) == fam


def test_the_rigs_engine_is_the_sweeps_and_a_halved_step_keeps_the_contacts_time_constant():
    preset, res, ie, mu = "paper-single-peak", 101, 1e-3, presets.calibrated_mu("paper-single-peak")
    tip = tip_radius(preset, None, res)
    surface = presets.make_surface(preset)
    engine = rig_engine(surface, tip=tip, mu=mu, ie=ie, hfield_resolution=res, stiffness_number=300.0)
    rig_args = dict(
        mu=mu,
        tip_radius_m=tip * sim.DEFAULT_LENGTH_SCALE_M,
        mass_kg=MASS_KG,
        hfield_resolution=res,
        ie=ie,
        stiffness_number=300.0,
    )
    assert engine == sim.build_rig(surface, **rig_args).engine
    plan = PLANS["smoke"]
    grid = engine_grid(
        plan, (("timestep_factor", 0.5),), preset, None, tip, mu=mu, ie=ie, stiffness_number=300.0
    )
    # the sweep halves each case's own step, the contact's time constant kept
    assert grid["timestep_factor"] == 0.5 and "timestep" not in grid and "solref_timeconst" not in grid
    halved = sim.build_rig(surface, **rig_args, timestep_factor=grid["timestep_factor"])
    assert halved.engine.timestep_s == pytest.approx(engine.timestep_s / 2)
    assert halved.engine.solref == engine.solref  # only the step changes
    soft = engine_grid(plan, (("solref_timeconst_factor", 10.0),), preset, None, tip, mu=mu, ie=ie)
    # the contact's time constant is the contact rule's, whatever the spring
    assert soft["solref_timeconst"] == pytest.approx(10 * engine.solref[0])


def test_a_doubled_hfield_nests_the_old_samples_and_keeps_the_tip():
    assert refined_resolution(151, 2) == 301 and refined_resolution(101, 4) == 401
    plan = PLANS["smoke"]
    fam = plan.families[0]
    base = limit_doc(plan, fam, "paper-single-peak", "base")
    finer = limit_doc(plan, fam, "paper-single-peak", "finer", (("hfield_factor", 2),))
    assert finer["grid"]["hfield_refinement"] == 2
    assert finer["grid"]["hfield_resolution"] == base["grid"]["hfield_resolution"]
    assert finer["grid"]["tip_radius"] == base["grid"]["tip_radius"]
    # a level is judged on the rigid reference: the compliant one runs at the corner alone
    assert finer["grid"]["compliant_reference"] is False and "compliant_reference" not in base["grid"]
    # the quick and full plans leave it out at the corner too (its cost); the smoke plan keeps it
    for name in ("quick", "full"):
        doc = limit_doc(PLANS[name], fam, "paper-single-peak", name)
        assert doc["grid"]["compliant_reference"] is False
    assert (
        finer["starts"]
        == base["starts"]
        == FamilySpec("x", (), None, paper_starts([-2.0, -4.0])).starts_table()
    )


def test_the_static_error_is_converged_when_a_halved_step_moves_it_less_than_the_slack():
    from spine_mj.validate.plans import DT_HALVED, HFIELD_DOUBLED, RECOMMENDED
    from spine_mj.validate.static_map import static_convergence

    plan = PLANS["smoke"]
    assert plan.static.engines == (RECOMMENDED, DT_HALVED, HFIELD_DOUBLED)

    def per_engine(err_halved, regions_halved=1.0):
        return {
            RECOMMENDED[0]: {"max_rel_error": 0.006, "region_agreement": 1.0},
            DT_HALVED[0]: {"max_rel_error": err_halved, "region_agreement": regions_halved},
            HFIELD_DOUBLED[0]: {"max_rel_error": 0.006, "region_agreement": 1.0},
        }

    out = static_convergence(plan, per_engine(0.0045))
    assert out["dt_halved"]["max_rel_error_change"] == pytest.approx(-0.0015)
    assert out["dt_halved"]["converged"] is True
    assert out["hfield_doubled"]["max_rel_error_change"] == 0.0 and out["hfield_doubled"]["converged"]
    assert static_convergence(plan, per_engine(0.0100))["dt_halved"]["converged"] is False  # > 0.0025
    assert static_convergence(plan, per_engine(0.006, 0.5))["dt_halved"]["converged"] is False


@pytest.mark.parametrize("plan_name", ["quick", "full"])
def test_every_refined_sweep_of_the_plans_is_a_valid_config_that_changes_only_its_refinement(plan_name):
    from spine_mj import sweep
    from spine_mj.validate.quasistatic_limit import _refinement_docs

    plan = PLANS[plan_name]
    # the analytic families (the quick plan: all; each fractal seed costs a surface)
    corner = [
        plan.limit.corner_family(f) for f in plan.families if plan_name == "quick" or f.name != "fractal"
    ]
    docs = _refinement_docs(plan, corner)
    keys = {(fam, key) for fam, key, _, _ in docs}
    from spine_mj.validate.sweep_configs import gridded

    for fam in corner:
        # every family's hfield is refined, a gridded one's through its spline (and four times)
        grid_only = set() if gridded(fam.presets[0], fam) else set(GRID_ONLY)
        assert {(fam.name, k) for k in plan.limit.convergence_refinements if k not in grid_only} <= keys
        assert not {(fam.name, k) for k in grid_only} & keys
        # at least convergence_starts paired starts a family, spread over its surfaces
        one = next(doc for f, k, _, doc in docs if f == fam.name)
        per_surface = len(one["starts"]["y"])
        assert per_surface * len(fam.seeds or (None,)) * len(fam.variants) * len(fam.presets) >= min(
            plan.limit.convergence_starts, len(fam.starts_table()["y"]) * len(fam.presets)
        )
        # ... and every start of the corner where the plan asks for all of them
        if fam.name in plan.limit.convergence_all_starts:
            assert one["starts"]["y"] == list(fam.starts_table()["y"])
    own_step = {fam.name: fam.timestep_factor for fam in corner}
    for fam_name, key, _, doc in docs:
        sweep.parse_config(doc)
        grid = doc["grid"]
        assert grid["hfield_resolution"] == plan.hfield_resolution
        # a refinement of the step is relative to the family's own (the rule's, or a fraction)
        step = own_step[fam_name] * dict(REFINEMENTS[key]).get("timestep_factor", 1.0)
        assert grid.get("timestep_factor", 1.0) == step
        if key.startswith("dt_"):
            assert step < own_step[fam_name]
        elif key.startswith("hfield_"):
            assert grid["hfield_refinement"] == dict(REFINEMENTS[key])["hfield_factor"] in (2, 4)
            assert "timestep" not in grid
        else:  # the solver's tolerances, a hundredth of MuJoCo's
            assert (grid["tolerance"], grid["noslip_tolerance"]) == (1e-10, 1e-8)
            assert grid["hfield_resolution"] == plan.hfield_resolution


def test_a_single_headline_is_judged_on_log10_where_it_lives_on_a_log_grid():
    # I_e* 0.1 with its 95 % interval [0.05, 0.3]: x 1.5 stays inside, x 4 leaves it
    refined = {
        "dt_halved": {"base": 0.1, "refined": 0.15, "runs": 20},
        "hfield_doubled": {"base": 0.1, "refined": 0.4, "runs": 20},
        "dt_quartered": {"base": 0.1, "refined": 0.15 * 1.5**0.5, "runs": 20},
    }
    out = headline_convergence(0.1, (0.05, 0.3), refined, log=True)
    assert out["dt_halved"]["change"] == pytest.approx(math.log10(1.5))
    assert out["dt_halved"]["converged"] is True
    assert out["hfield_doubled"]["converged"] is False and out["converged"] is False
    # log10 I_e* moves by log10 1.5, then by half that: order 1, Richardson 0.1 * 1.5**2
    assert out["dt_order"]["order"] == pytest.approx(1.0)
    assert out["dt_order"]["richardson"] == pytest.approx(0.1 * 1.5**2)
    assert unconverged_mark(out) == " (unconverged: hfield x 2)"
    assert refinement_note(out) == " (unconverged: hfield x 2)"
    del out["hfield_doubled"]
    assert refinement_note(out) == " (converged: dt / 2, dt / 4)"


def test_a_rate_is_judged_on_its_paired_change_and_a_refinement_that_changes_nothing_says_why():
    # a rate of 0.5 [0.3, 0.7] over 30 surfaces; on 10 of them 4 -> 5 locked
    out = headline_convergence(
        0.5,
        (0.3, 0.7),
        {"dt_halved": {"base": 0.4, "refined": 0.5, "runs": 10}, "hfield_doubled": None},
        note="gridded",
    )
    assert out["dt_halved"]["change"] == pytest.approx(0.1) and out["dt_halved"]["converged"] is True
    assert out["hfield_doubled"] == {
        "refined": False,
        "runs": 0,
        "note": "gridded",
        "change": out["hfield_doubled"]["change"],
        "converged": None,
    }
    assert math.isnan(out["hfield_doubled"]["change"])
    assert out["converged"] is True and "dt_order" not in out
    assert headline_convergence(0.5, (0.3, 0.7), {"hfield_doubled": None})["converged"] is None
    assert refinement_note(None) == "" and refinement_note({"hfield_doubled": out["hfield_doubled"]}) == ""


def test_gci_is_roaches_band_with_its_safety_factors():
    from spine_mj.validate.convergence import gci

    # f = f* + c h^p at h = 4, 2, 1 with p = 2: the observed order is 2, GCI 1.25 |e| / 3
    f = [1.0 + 0.01 * h**2 for h in (4.0, 2.0, 1.0)]
    p = observed_order(f[2], f[1], f[0])
    assert p == pytest.approx(2.0)
    assert gci(f[2], f[1], p) == pytest.approx(1.25 * abs((f[2] - f[1]) / f[2]) / 3.0)
    # the band covers the exact value's relative distance from the finest level
    assert gci(f[2], f[1], p) * f[2] >= abs(f[2] - richardson(f[2], f[1], p))
    # two levels: Fs 3 and the formal first order
    assert gci(f[2], f[1], math.nan) == pytest.approx(3.0 * abs((f[2] - f[1]) / f[2]))
    assert math.isnan(gci(0.0, 0.1, 1.0))


def test_a_three_level_verdict_needs_its_last_change_inside_the_interval():
    summary = {
        "agreement_well_conditioned": 1.0,
        "agreement_ci": [0.9, 1.0],
        "outcome_agreement": 1.0,
        "outcome_agreement_ci": [0.9, 1.0],
        "median_frechet": 0.05,
        "median_frechet_ci": [0.04, 0.06],
    }

    def rows(frechets):
        return pd.DataFrame(
            {
                "surface": ["s"] * len(frechets),
                "surface_lc": [1.0] * len(frechets),
                "start_x": [0.0] * len(frechets),
                "start_y": np.arange(len(frechets), dtype=float),
                "agree": [True] * len(frechets),
                "frechet": frechets,
            }
        )

    base = rows([0.05] * 5)
    # dt / 2 moves the median by +0.009 and dt / 4 by +0.018 from the base: each inside the
    # interval [0.04, 0.06] alone; the last change, +0.009, too
    out = family_convergence(
        summary, base, {"dt_halved": rows([0.059] * 5), "dt_quartered": rows([0.068] * 5)}
    )
    assert out["dt_halved"]["converged"] is True
    # dt / 4 against the base leaves it (0.068), so does not converge whatever its last change
    assert out["dt_quartered"]["median_frechet_converged"] is False
    assert out["dt_quartered"]["last_change"]["median_frechet"] == pytest.approx(0.009)
    assert out["dt_quartered"]["converged"] is False and out["converged"] is False
    # a series that settles: +0.008, then +0.001 (last change inside)
    out = family_convergence(
        summary, base, {"dt_halved": rows([0.058] * 5), "dt_quartered": rows([0.059] * 5)}
    )
    assert out["dt_quartered"]["median_frechet_last_converged"] is True and out["converged"] is True
    o = out["dt_order"]["median_frechet"]
    assert o["order"] == pytest.approx(math.log2(8.0)) and math.isfinite(o["gci"])
    # a last change larger than the interval's width fails even where each level alone is in
    wide = {**summary, "median_frechet_ci": [0.03, 0.07]}
    out = family_convergence(wide, base, {"dt_halved": rows([0.035] * 5), "dt_quartered": rows([0.065] * 5)})
    assert out["dt_halved"]["converged"] is True and out["dt_quartered"]["median_frechet_converged"] is True
    assert out["dt_quartered"]["median_frechet_last_converged"] is False
    assert out["dt_quartered"]["converged"] is False


def test_a_family_at_its_own_step_runs_its_corner_and_refinements_relative_to_it():
    """A family whose rule's step did not converge (FamilySpec.timestep_factor) runs its
    corner at that fraction of the rule's step and halves and quarters from there; a family
    at the rule's step adds no key (its stores keep their configs)."""
    from spine_mj.validate.plans import PEAK_VALLEY
    from spine_mj.validate.quasistatic_limit import _refinement_docs, limit_family_docs

    plan = PLANS["smoke"]
    own = dataclasses.replace(PEAK_VALLEY, presets=("paper-single-peak",), timestep_factor=0.5)
    corner = {"paper-single-peak": {"ie": 0.01, "K": 30.0}}
    ((_, doc),) = limit_family_docs(plan, own, corner)
    assert doc["grid"]["timestep_factor"] == 0.5
    steps = {
        key: d["grid"].get("timestep_factor", 1.0)
        for _, key, _, d in _refinement_docs(plan, [own], {own.name: corner})
    }
    assert steps == {key: 0.5 * dict(REFINEMENTS[key]).get("timestep_factor", 1.0) for key in steps}
    rule = dataclasses.replace(own, timestep_factor=1.0)
    ((_, doc),) = limit_family_docs(plan, rule, corner)
    assert "timestep_factor" not in doc["grid"]
    for bad in (0.0, 1.5, math.nan):
        with pytest.raises(SpineInputError, match="timestep_factor must be in"):
            FamilySpec("x", ("paper-single-peak",), None, PEAK_VALLEY.starts, timestep_factor=bad)

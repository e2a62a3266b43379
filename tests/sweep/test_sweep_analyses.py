"""The built-in analyses: the engine and compare rows are the rig's own runs."""

import numpy as np
import pytest
import tomllib
from sweep_support import write_config

from spine_mj import sweep

MJ = """
[sweep]
name = "mujoco"
analyses = ["quasistatic", "engine", "compare"]
[[surfaces]]
preset = "paper-single-peak"
[starts]
frame = "absolute"
points = [[-4.0, 0.0], [-4.0, 1.0]]
[drive]
protocol = "spring"
ie = [0.01, 0.1]
[grid]
mu = 1.25
dl = 0.02
dynamic_drive = true
"""


def test_mujoco_and_compare_runs_match_the_rig_run_directly(tmp_path):
    from spine_mj import presets, sim

    cfg = write_config(tmp_path, MJ)
    out = tmp_path / "out"
    summary = sweep.run_sweep(cfg, out, workers=1)
    assert summary.total_runs == 12
    runs = sweep.load_runs(out)
    mj = runs[runs.analysis == "engine"]
    assert mj.status.isin(["ok", "nan", "engine_warning", "penetration", "diverged"]).all()
    np.testing.assert_allclose(mj.inertia_number, mj.ie, rtol=1e-9)
    # the start on the peak's ridge self-locks quasistatically; compare's outcome agreement
    # is that of MuJoCo and its facet-traced reference, and of the smooth row beside it
    qs = runs[runs.analysis == "quasistatic"].set_index(["case_id", "start"])
    assert qs.self_locked.xs(0, level="start").astype(bool).all()
    mjs = mj.set_index(["case_id", "start"])
    cmp_ = runs[runs.analysis == "compare"].set_index(["case_id", "start"])
    ref_held = cmp_.reference_outcome.isin(["self_locked", "force_cap"])
    expected = ref_held == mjs.self_locked.astype(bool).loc[cmp_.index]
    assert (cmp_.agree_lock.astype(bool) == expected).all()
    smooth_lock_differs = qs.self_locked.astype(bool) != mjs.self_locked.astype(bool)
    assert not cmp_.agree_smooth.astype(bool)[smooth_lock_differs.loc[cmp_.index]].any()
    assert (cmp_.geometry_frechet >= 0).all()
    # the peak's flanks are gentler than mu_s's friction angle: no gravity slides; the tip
    # moves on average with the carriage, so its peak speed is at least the drive's
    assert (cmp_.reference_slide_fraction == 0).all()
    ran = mjs.status.loc[cmp_.index] == "ok"
    assert (cmp_.tip_peak_ie[ran] >= 0.5 * mjs.ie.loc[cmp_.index][ran]).all()
    assert mjs.end_detail[mjs.self_locked.astype(bool)].str.match("lock rule|force cap").all()
    assert (cmp_.status == np.where(mjs.status.loc[cmp_.index] == "ok", "ok", "dependency_failed")).all()
    # the spring-block swing sqrt(I_e K L_c / l_s) of each run's drive, in F_p
    swing = np.sqrt(mj.ie * mj.stiffness_number * mj.char_length / mj.slope_length)
    np.testing.assert_allclose(mj.spring_swing_fp, swing, rtol=1e-9)
    assert cmp_.frechet[ran].notna().all() and (cmp_.frechet[ran] >= 0).all()
    # the spring drive is also set against the compliant streamline of its own spring
    assert (cmp_.compliant_frechet[ran] >= 0).all() and (cmp_.stiffness_frechet >= 0).all()
    assert cmp_.agree_compliant.isin([0.0, 1.0]).all() and (cmp_.compliant_jumps >= 0).all()
    # a run that agrees has no miss reason; one the engine finished and that disagrees has one
    agree = cmp_.agree.astype(bool)
    assert (cmp_.miss_reason[agree] == "").all()
    assert (
        cmp_.miss_reason[~agree & ran]
        .isin(["separatrix", "diverged", "engine_held", "engine_passed", "reference_stalled"])
        .all()
    )
    # both sides end at the engine's domain margin: at the lower I_e, runs that leave the
    # domain end together
    left = (
        (cmp_.reference_outcome == "left_domain")
        & (mjs.end_reason.loc[cmp_.index] == "left_domain")
        & (mjs.ie.loc[cmp_.index] == 0.01)
    )
    assert left.any() and (cmp_.end_distance[left] < 0.05).all(), cmp_.end_distance[left]
    # the stored run is the rig's own run at that speed
    case_id = mj.case_id[mj.ie == 0.01].iloc[0]
    # the engine's step follows the drive speed (impacts): the rule of sim.default_engine
    surface, tip = presets.make_surface("paper-single-peak"), sim.TipParams(mu_s=1.25)
    scales = sim.Scales.for_surface(surface, tip=tip)
    speed = scales.speed_for(0.01)
    rig = sim.Rig(surface, tip=tip, engine=sim.default_engine(scales, speed_m_s=speed))
    direct = rig.run_batch(sim.SpringDrive(speed_m_s=speed), [(-4.0, 1.0)], nthread=1)[0]
    row = mj[(mj.case_id == case_id) & (mj.start == 1)].iloc[0]
    assert row.end_x == pytest.approx(direct.position_m[-1, 0] / rig.length_scale_m, abs=1e-12)
    traj = sweep.load_trajectories(out, case_id, analysis="engine", start=1, columns=["x"])
    assert len(traj) == direct.n
    np.testing.assert_allclose(traj.x, direct.position_m[:, 0] / rig.length_scale_m)
    # the reference ends where the run does: the tip radius (the domain margin) from the edge
    edge = surface.bounds[1] - rig.tip.tip_radius_m / rig.length_scale_m
    ref = sweep.load_trajectories(out, case_id, analysis="compare", start=1, columns=["x"])
    assert direct.end_reason.value == "left_domain" and row.end_x > edge
    assert edge - 2 * 0.02 < ref.x.max() <= edge  # within a step (dl 0.02) of it


def test_a_scan_in_um_takes_its_tip_radius_in_um(tmp_path, topography_dir):
    """A sweep's ``tip_radius`` is in the surface's length unit: 5 on a surface kept in
    the instrument's um is a 5 um tip (the rule of ``sim.scales.surface_unit_m``)."""
    from spine_mj.surface_io import import_topography, save_surface
    from spine_mj.sweep.analyses.engine import case_rig

    save_surface(import_topography(topography_dir / "plu-1.plu"), tmp_path / "scan.npz")
    doc = {
        "sweep": {"analyses": ["engine"]},
        "surfaces": [{"file": "scan.npz"}],
        "starts": {"points": [[0.1, 0.5]]},
        "drive": {"protocol": "spring", "ie": 1e-3},
        "grid": {"tip_radius": 5.0, "mu": 0.5},
    }
    (case,) = sweep.expand_cases(sweep.parse_config(doc, base_dir=tmp_path))
    rig = case_rig(case)
    assert rig.surface.unit == "um" and rig.length_scale_m == 1e-6
    assert rig.tip.tip_radius_m == pytest.approx(5e-6, rel=1e-12)


@pytest.mark.parametrize("tip_radius", [None, 0.1])
def test_one_config_gives_both_analyses_the_same_tip(tmp_path, tip_radius):
    """``tip_radius`` has one meaning in both analyses: absent, the rig's default tip (the
    quasistatic streamline traces the surface dilated by the ball MuJoCo runs), else that
    radius in the surface's length unit, at any length scale."""
    from spine_mj import presets
    from spine_mj.sim.scales import resolve_tip_radius
    from spine_mj.sweep.analyses.engine import case_rig
    from spine_mj.sweep.analyses.quasistatic import case_tip_radius

    grid = {"mu": 1.25, "length_scale": 0.02, "hfield_resolution": 61}
    doc = {
        "sweep": {"analyses": ["quasistatic", "engine"]},
        "surfaces": [{"preset": "paper-single-peak"}],
        "starts": {"points": [[0.1, 0.5]]},
        "drive": {"protocol": "spring", "ie": 1e-3},
        "grid": grid if tip_radius is None else {**grid, "tip_radius": tip_radius},
    }
    (case,) = sweep.expand_cases(sweep.parse_config(doc, base_dir=tmp_path))
    surface = presets.make_surface("paper-single-peak")
    rig = case_rig(case, surface)
    traced = case_tip_radius(case, surface)
    assert traced > 0
    assert traced == pytest.approx(rig.tip.tip_radius_m / rig.length_scale_m, rel=1e-12)
    if tip_radius is None:  # the rig's rule: one of its 61 samples' spacing, not 201's
        given = {"length_scale_m": 0.02, "hfield_resolution": 61}
        assert traced == pytest.approx(resolve_tip_radius(surface, None, **given), rel=1e-12)
        assert traced > resolve_tip_radius(surface, None) * 1.5
    else:
        assert traced == tip_radius


def test_a_point_tip_is_traced_by_the_streamline_and_refused_by_the_engine(tmp_path):
    """``tip_radius = 0`` is a point: the quasistatic analysis traces the surface itself;
    the engine's tip is a ball, so a config running it is refused in one line naming the key."""
    from spine_mj.errors import SpineInputError
    from spine_mj.sweep.analyses.quasistatic import traced_surface

    doc = {
        "sweep": {"analyses": ["quasistatic"]},
        "surfaces": [{"preset": "paper-single-peak"}],
        "starts": {"points": [[0.1, 0.5]]},
        "grid": {"mu": 1.25, "tip_radius": 0.0},
    }
    (case,) = sweep.expand_cases(sweep.parse_config(doc, base_dir=tmp_path))
    surface = case.surface.make()
    assert traced_surface(case, surface) is surface
    doc["sweep"]["analyses"] = ["quasistatic", "engine"]
    with pytest.raises(SpineInputError, match=r"config key grid.tip_radius 0 is a point tip.*leave"):
        sweep.parse_config(doc, base_dir=tmp_path)


ENSEMBLE = """
[sweep]
name = "ensemble"
analyses = ["quasistatic", "engine", "compare"]
[[surfaces]]
preset = "paper-single-peak"
[starts]
frame = "absolute"
points = [[-4.0, 1.0], [-4.001, 1.0], [-4.0, 1.001], [-4.0, 0.0], [-4.001, 0.0], [-4.0, 0.001]]
[drive]
protocol = "spring"
ie = 0.01
[grid]
mu = 1.25
dl = 0.02
ensemble_members = {members}
compliant_reference = {compliant}
"""


def test_an_ensembles_copies_get_their_outcome_and_its_first_member_everything(tmp_path):
    """With ``ensemble_members`` = 3 the first start of each three gets the whole comparison,
    the same as without ensembles; the copies get their outcome on both sides only. With
    ``compliant_reference`` off, every start gets all but the compliant comparison."""
    rows = {}
    for members, compliant in ((1, "true"), (3, "true"), (1, "false")):
        doc = ENSEMBLE.format(members=members, compliant=compliant)
        cfg = write_config(tmp_path, doc, name=f"e{members}{compliant}.toml")
        out = tmp_path / f"out{members}{compliant}"
        sweep.run_sweep(cfg, out, workers=1)
        runs = sweep.load_runs(out)
        rows[members, compliant] = runs[runs.analysis == "compare"].set_index("start").sort_index()
    full, ens = rows[1, "true"], rows[3, "true"]
    # without the compliant reference (a refinement level): its columns empty, the rest alike
    rigid = rows[1, "false"]
    for col in ("compliant_frechet", "agree_compliant", "compliant_jumps", "stiffness_frechet"):
        assert full[col].notna().all() and rigid[col].isna().all(), col
    for col in ("frechet", "lateral_deviation", "frechet_smooth", "geometry_frechet"):
        np.testing.assert_allclose(rigid[col], full[col], rtol=1e-12, err_msg=col)
    assert (rigid.agree == full.agree).all()
    lead = ens.index % 3 == 0
    for col in ("frechet", "lateral_deviation", "frechet_smooth", "geometry_frechet", "compliant_frechet"):
        np.testing.assert_allclose(ens[col][lead], full[col][lead], rtol=1e-9, err_msg=col)
        assert ens[col][~lead].isna().all(), col
    for col in ("agree", "agree_lock", "reference_outcome"):
        assert (ens[col] == full[col]).all(), col
    assert ens.agree_smooth[lead].astype(bool).tolist() == full.agree_smooth[lead].astype(bool).tolist()
    assert ens.agree_smooth[~lead].isna().all()


def test_compare_leaves_out_a_run_the_engine_failed(tmp_path):
    """A run the engine failed (here marked diverged, its path replaced by a pathological
    one 1e6 L_c out and back) is not compared as physics: no distances, status
    ``dependency_failed``; the healthy run beside it gets the same numbers as before, and
    the memory stays bounded by the recorded size (no resampling of the long path)."""
    import dataclasses
    import tracemalloc

    from spine_mj.sweep.registry import ANALYSES, AnalysisResult

    (case,) = sweep.expand_cases(
        sweep.parse_config(tomllib.loads(MJ.replace("ie = [0.01, 0.1]", "ie = 0.01")), base_dir=tmp_path)
    )
    surface = case.surface.make()
    starts = case.starts.resolve(surface.bounds, case.seed)
    up = {"quasistatic": ANALYSES["quasistatic"].func(case, surface, starts, {})}
    up["engine"] = ANALYSES["engine"].func(case, surface, starts, up)
    before = ANALYSES["compare"].func(case, surface, starts, up)
    rig, runs = up["engine"].data
    lc = rig.scales.char_length_m
    n = runs[1].position_m.shape[0]
    wild = runs[1].position_m.copy()
    wild[runs[1].drive_start_index :, 0] += (
        1e6 * lc * np.sin(np.linspace(0, np.pi, n - runs[1].drive_start_index))
    )
    runs = [runs[0], dataclasses.replace(runs[1], position_m=wild)]
    status = np.array(["ok", "diverged"], dtype=object)
    up["engine"] = AnalysisResult(
        up["engine"].metrics, status=status, reason=np.array(["", "diverged"]), data=(rig, runs)
    )
    tracemalloc.start()
    after = ANALYSES["compare"].func(case, surface, starts, up)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert list(after.status) == ["ok", "dependency_failed"]
    assert np.isnan(after.metrics["frechet"][1]) and np.isnan(after.metrics["lateral_deviation"][1])
    assert after.metrics["frechet"][0] == pytest.approx(before.metrics["frechet"][0], rel=1e-12)
    assert peak < 200 * 2**20


def test_quasistatic_without_dl_steps_as_the_streamline_command(tmp_path):
    """One default step (theory.streamline.default_step): a thousandth of the shorter side
    of the domain, here the corrugation's width (8 x 1), as ``spine-mj streamline`` takes."""
    from spine_mj import presets
    from spine_mj.theory import streamline as sl

    doc = """
[sweep]
name = "step"
analyses = ["quasistatic"]
[[surfaces]]
preset = "corrugation"
[starts]
frame = "absolute"
points = [[0.5, 0.0], [0.5, 0.2]]
[grid]
mu = 0.6
"""
    out = tmp_path / "out"
    sweep.run_sweep(write_config(tmp_path, doc), out, workers=1)
    runs = sweep.load_runs(out)
    assert (runs.n_steps > 0).all()
    step = sl.default_step(presets.make_surface("corrugation"))
    assert step == pytest.approx(1e-3)
    np.testing.assert_allclose(runs.path_length / runs.n_steps, step, rtol=1e-12)


def test_cases_differing_only_in_their_drive_share_their_streamlines(tmp_path):
    """The boundary's I_e ladder and the (I_e, K) map trace the same references for every
    drive: the second case's quasistatic and facet streamlines come from the process's
    memo, equal to a fresh trace, and a changed start is traced anew."""
    from spine_mj.sweep.analyses import quasistatic as qs_analysis
    from spine_mj.sweep.registry import ANALYSES
    from spine_mj.theory import streamline as sl

    doc = tomllib.loads(MJ)
    qs_analysis.clear_cache()
    first, second = sweep.expand_cases(sweep.parse_config(doc, base_dir=tmp_path))
    assert first.params["ie"] != second.params["ie"]
    surface = first.surface.make()
    starts = first.starts.resolve(surface.bounds, first.seed)
    res = [ANALYSES["quasistatic"].func(c, surface, starts, {}).data for c in (first, second)]
    assert res[1] is res[0]
    fresh = sl.streamlines(
        qs_analysis.traced_surface(first, surface),
        starts,
        qs_analysis.streamline_params(first, surface),
        store_paths=True,
    )
    np.testing.assert_array_equal(res[0].x, fresh.x)
    moved = ANALYSES["quasistatic"].func(first, surface, starts + np.array([0.0, 0.25]), {}).data
    assert moved is not res[0] and not np.array_equal(moved.end_y, res[0].end_y)
    key = qs_analysis.hfield_key
    rigs = [ANALYSES["engine"].func(c, surface, starts, {}).data[0] for c in (first, second)]
    assert rigs[0] is not rigs[1]
    assert key(rigs[0].hfield, 0.1) == key(rigs[1].hfield, 0.1) != key(rigs[0].hfield, 0.2)


def test_miss_reasons_restart_a_run_that_left_the_domain_from_its_edge(tmp_path):
    """A dynamic run ends past the domain's edge (the fractal at I_e = 0.1-1 did, and the
    whole comparison failed: "starts must lie inside the surface bounds"); its checkpoints
    out there restart the reference on the edge."""
    from spine_mj.sweep.analyses.compare import MISS_CHECKPOINTS, _miss_reasons
    from spine_mj.sweep.registry import ANALYSES
    from spine_mj.theory import streamline as sl

    doc = tomllib.loads(MJ.replace("ie = [0.01, 0.1]", "ie = 0.01"))
    (case,) = sweep.expand_cases(sweep.parse_config(doc, base_dir=tmp_path))
    surface = case.surface.make()
    starts = case.starts.resolve(surface.bounds, case.seed)
    up = {"quasistatic": ANALYSES["quasistatic"].func(case, surface, starts, {})}
    rig, _ = ANALYSES["engine"].func(case, surface, starts, up).data
    contact = rig.contact_surface()
    params = up["quasistatic"].data.params
    facets = sl.streamlines(contact, starts, params, store_paths=True)
    xmax = contact.bounds[1]
    past = np.column_stack([np.linspace(starts[0, 0], xmax + 0.5, 50), np.full(50, starts[0, 1])])
    mpaths = [past, np.empty((0, 2))]
    reason, _ = _miss_reasons(
        contact,
        params,
        sl.streamlines,
        mpaths,
        facets,
        np.array([False, False]),
        np.array([past[-1], starts[1]]),
        1.0,
        np.array([True, False]),
    )
    assert reason[0] != "" and reason[1] == "" and MISS_CHECKPOINTS > 1


FRACTAL_SPRING = """
[sweep]
name = "stiff"
analyses = {analyses}
[[surfaces]]
preset = "paper-fractal"
seeds = [1]
set = {{ hurst = 0.7 }}
[starts]
frame = "relative"
x = [0.05]
y = [0.5]
[drive]
protocol = "spring"
ie = {ie!r}
K = {K!r}
{extra}
"""


def _fractal_cases(tmp_path, *, ie, K, analyses=("quasistatic", "engine", "compare"), extra=""):
    text = FRACTAL_SPRING.format(analyses=list(analyses), ie=ie, K=K, extra=extra)
    return sweep.expand_cases(sweep.parse_config(tomllib.loads(text), base_dir=tmp_path))


def test_a_spring_drive_too_fast_for_its_stiffness_is_refused_before_the_comparison(tmp_path):
    """The compare analysis refuses a spring whose spring-block swing sqrt(I_e K L_c / l_s)
    exceeds SWING_BOUND_FP preloads, and accepts it where the swing is within the bound, as
    a dynamic study on purpose, and without the comparison."""
    from spine_mj.errors import SpineInputError
    from spine_mj.sweep.analyses.engine import case_scales
    from spine_mj.sweep.preflight import check_cases
    from spine_mj.theory.drive_limits import SWING_BOUND_FP

    cases = _fractal_cases(tmp_path, ie=1e-4, K=3000.0)
    sc = case_scales(cases[0])
    kc = 3000.0 * sc.char_length_m / sc.slope_length_m
    swing, ie_max = (1e-4 * kc) ** 0.5, SWING_BOUND_FP**2 / kc
    assert swing > SWING_BOUND_FP
    with pytest.raises(SpineInputError, match="K = 3000: compared") as info:
        check_cases(cases)
    message = str(info.value)
    assert f"got {swing:.3g} F_p" in message and f"use I_e <= {ie_max:.3g}" in message
    check_cases(_fractal_cases(tmp_path, ie=0.99 * ie_max, K=3000.0))
    check_cases(_fractal_cases(tmp_path, ie=1e-4, K=3000.0, extra="[grid]\ndynamic_drive = true"))
    check_cases(_fractal_cases(tmp_path, ie=1e-4, K=3000.0, analyses=("engine",)))


def test_landing_verdicts_judge_a_run_against_where_its_fall_lands():
    """A ramp steeper than friction onto a floor: the landing reference falls once, lands on
    the floor and moves on to the domain's edge; a run that ended there agrees, one held on
    the ramp does not."""
    import math

    from spine_mj.surfaces import BallOnFacets, GridSurface, TriangulatedSurface
    from spine_mj.sweep.analyses.compare import fall_params, landing_verdicts
    from spine_mj.theory import streamline as sl
    from spine_mj.theory.streamline_types import StreamlineParams

    x = np.linspace(-1.0, 1.0, 101)
    row = np.where(x < 0, -math.tan(math.radians(40.0)) * x, 0.0)
    grid = GridSurface(heights=np.tile(row, (5, 1)), x=x, y=np.linspace(-0.2, 0.2, 5), unit="m")
    contact = BallOnFacets(TriangulatedSurface.from_grid(grid), 0.01)
    scales = type("S", (), {"mass_kg": 1e-3, "preload_n": 1.0})()  # only these two are read
    fall = fall_params(
        scales, stiffness_n_m=1e-9, speed_m_s=0.0, timestep_s=1e-3, length_scale_m=1.0, duration_s=5.0
    )
    assert (fall.max_fall_s, fall.load_n, fall.mass_kg, fall.timestep_s) == (5.0, 1.0, 1e-3, 1e-3)
    params = StreamlineParams(mu=0.5, dl=0.02, edge_margin=0.05)
    end = np.array([[0.95, 0.0], [-0.5, 0.0]])
    mpaths = [np.array([[-0.5, 0.0], [0.95, 0.0]]), np.array([[-0.5, 0.0], [-0.5, 0.0]])]
    got = landing_verdicts(
        contact, params, sl.streamlines, [(-0.5, 0.0)] * 2, fall, np.array([False, True]), end, mpaths, 1.0
    )
    assert list(got["landing_falls"]) == [1.0, 1.0]
    assert list(got["agree_landing"]) == [1.0, 0.0]
    assert got["frechet_landing"][0] < 0.05 < got["frechet_landing"][1]

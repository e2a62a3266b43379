"""The pre-run check covers every combination of the grid: a sweep with one bad case is
refused in one line naming it before any case runs (issue 44), and stays fast."""

import pytest
from sweep_support import write_config

from spine_mj import sweep
from spine_mj.errors import SpineInputError
from spine_mj.sweep import preflight


def _refused_before_any_run(tmp_path, text, *fragments):
    out = tmp_path / "out"
    with pytest.raises(SpineInputError) as err:
        sweep.run_sweep(write_config(tmp_path, text), out, workers=1)
    message = str(err.value)
    assert "\n" not in message and message.startswith("sweep case ("), message
    for fragment in fragments:
        assert fragment in message, message
    assert not list(out.glob("runs/*.parquet"))
    return message


FRACTAL = """
[sweep]
analyses = {analyses}
[[surfaces]]
preset = "paper-fractal"
[starts]
x = [0.05]
y = [0.5]
[drive]
ie = [1e-4, 1e-3]
K = [10, 100]
"""


def test_a_spring_swing_only_one_combination_makes_is_refused_before_any_run(tmp_path):
    """On the paper fractal (L_c / l_s = 24) sqrt(I_e K L_c / l_s) is 0.15 to 0.49 F_p for
    three of the four cases, 1.55 F_p at I_e = 1e-3 and K = 100: each value alone passes,
    the combination is refused (it used to run and be compared)."""
    text = FRACTAL.format(analyses='["quasistatic", "engine", "compare"]')
    _refused_before_any_run(tmp_path, text, "ie = 0.001, K = 100", "spring drive at I_e = 0.001, K = 100")
    # without the comparison every case is a legitimate dynamic run
    cases = sweep.expand_cases(
        sweep.load_config(write_config(tmp_path, FRACTAL.format(analyses='["engine"]')))
    )
    preflight.check_cases(cases)


PEAK_ENGINE = """
[sweep]
analyses = ["engine"]
[[surfaces]]
preset = "paper-single-peak"
[starts]
x = [0.05]
y = [0.5]
"""

STEPS = (
    PEAK_ENGINE
    + """
[drive]
ie = [1.0, 1e-3]
[grid]
timestep_factor = [1.0, 1e-3]
"""
)


def test_a_run_beyond_the_step_limit_only_one_combination_makes_is_refused(tmp_path):
    _refused_before_any_run(tmp_path, STEPS, "ie = 1.0, timestep_factor = 0.001", "more than the limit")


SIZES = """
[sweep]
analyses = ["engine"]
[[surfaces]]
preset = "paper-single-peak"
[starts]
x = [0.05]
y = [0.5]
[grid]
hfield_resolution = [61, 1500]
hfield_refinement = [1, 6]
"""


def test_an_hfield_only_one_combination_makes_too_large_is_refused(tmp_path):
    _refused_before_any_run(
        tmp_path, SIZES, "hfield_resolution = 1500, hfield_refinement = 6", "samples a side, more than"
    )


def test_a_limit_one_engine_breaks_is_refused_before_any_case_is_sized(tmp_path):
    """MuJoCo takes a 1500-a-side hfield, pybullet at most 1448: the Bullet case is refused
    before the MuJoCo case's sizing (an 8000-a-side grid over both engines sized MuJoCo's
    hfield, 29 CPU-s and 2.3 GB, before refusing Bullet's)."""
    pytest.importorskip("pybullet")
    from spine_mj.sweep.analyses import engine

    text = PEAK_ENGINE + '[grid]\nengine = ["mujoco", "bullet"]\nhfield_resolution = 1500\n'
    cases = sweep.expand_cases(sweep.load_config(write_config(tmp_path, text)))
    engine.case_rig.cache_clear()
    with pytest.raises(SpineInputError, match=r"^sweep case \(paper-single-peak, engine = 'bullet'\): "):
        preflight.check_cases(cases, swept=["engine"])
    assert not engine._SIZINGS  # nothing sized


ARRAY = """
[sweep]
analyses = ["array"]
[[surfaces]]
preset = "corrugation"
[starts]
frame = "absolute"
points = {points}
[drive]
ie = 1e-2
duration = 0.02
[array]
{layout}
spacing_unit = "surface"
"""


@pytest.mark.parametrize(
    ("points", "layout", "fragment"),
    [
        ("[[1.0, 0.0]]", 'layout = "grid"\nrows = 2\ncols = 2\nspacing = 2.0', "outside the surface"),
        ("[[1.0, 0.0]]", 'layout = "staggered"\nrows = 3\ncols = 40\nspacing = 0.2', "outside the surface"),
        (
            "[[1.0, 0.0], [7.99, 0.0]]",
            'layout = "grid"\nrows = 1\ncols = 2\nspacing = 0.15',
            "centre (7.99, 0)",
        ),
        (
            "[[2.0, 0.0]]",
            'layout = "random"\nrows = 8\ncols = 8\nspacing = 0.001',
            "spacing 0.001 is too small for 64 random spines",
        ),
    ],
)
def test_array_layouts_off_the_surface_are_refused_before_any_run(tmp_path, points, layout, fragment):
    _refused_before_any_run(tmp_path, ARRAY.format(points=points, layout=layout), fragment)


def test_every_combination_is_checked_without_building_a_rig_or_repeating_a_check(tmp_path, monkeypatch):
    """4000 MuJoCo cases (I_e x K x step factor) checked on the rig's plan, no rig built;
    2000 quasistatic cases over mu x dl checked once per dl (the only key its check reads).
    The time this takes is a benchmark's (benchmarks/), not a test's."""
    text = STEPS.replace(
        "ie = [1.0, 1e-3]", "ie = {logspace = [1e-4, 1e-2], num = 20}\nK = {logspace = [1, 100], num = 20}"
    )
    text = text.replace(
        "timestep_factor = [1.0, 1e-3]", "timestep_factor = {linspace = [0.5, 1.0], num = 10}"
    )
    cases = sweep.expand_cases(sweep.load_config(write_config(tmp_path, text)))
    from spine_mj.sweep.analyses import engine, quasistatic

    engine.case_rig.cache_clear()
    preflight.check_cases(cases)
    assert len(cases) == 4000 and engine._rig.cache_info().misses == 0

    steps = []
    real = quasistatic.sl.check_step
    monkeypatch.setattr(
        quasistatic.sl, "check_step", lambda surface, dl: steps.append(dl) or real(surface, dl)
    )
    qs = """
    [sweep]
    analyses = ["quasistatic"]
    [[surfaces]]
    preset = "paper-single-peak"
    [starts]
    points = [[0.1, 0.5]]
    [grid]
    mu = {linspace = [0.1, 2.0], num = 1000}
    dl = [0.01, 0.02]
    """
    cases = sweep.expand_cases(sweep.load_config(write_config(tmp_path, qs)))
    preflight.check_cases(cases)
    assert len(cases) == 2000 and sorted(steps) == [0.01, 0.02]


def test_a_large_sweep_says_what_it_prepares_before_its_first_case(tmp_path, monkeypatch):
    """Listing, checking and recording 999,999 cases takes minutes: a sweep of at
    least PREPARE_NOTICE_CASES says each step (the threshold lowered here to 4 cases)."""
    from sweep_support import peak_config

    from spine_mj.sweep import session

    monkeypatch.setattr(session, "PREPARE_NOTICE_CASES", 4)
    said = []
    sweep.run_sweep(peak_config(tmp_path, nmu=4, ny=1), tmp_path / "out", workers=1, notice=said.append)
    assert said[:3] == [
        "preparing 4 cases: listing them",
        "preparing 4 cases: checking every one before the first runs",
        "preparing 4 cases: writing the store's manifest",
    ]
    said.clear()
    sweep.run_sweep(
        peak_config(tmp_path, nmu=3, ny=1, name="small"), tmp_path / "small", workers=1, notice=said.append
    )
    assert not any("preparing" in s for s in said)


def test_engines_of_one_sizing_measure_the_surface_once_before_any_run(tmp_path, monkeypatch):
    """A grid over both engines checks each engine's case on one measurement of the surface
    (its hfield sampled, its fall height traced: a minute at 8000 a side), as MuJoCo's
    cases alone did; Bullet's rig was built afresh, measuring it again. The Bullet case is
    still checked as its rig (its heightfield's memory: refused here under a 1 MiB budget)."""
    pytest.importorskip("pybullet")
    from spine_mj.sim.scales import Scales

    calls = []
    measure = Scales.with_hfield.__func__

    def counted(cls, surface, **kw):
        calls.append(kw.get("hfield_resolution"))
        return measure(cls, surface, **kw)

    monkeypatch.setattr(Scales, "with_hfield", classmethod(counted))
    sweep.session.clear_caches()
    text = PEAK_ENGINE + '[grid]\nengine = ["mujoco", "bullet"]\nhfield_resolution = 101\n'
    cases = sweep.expand_cases(sweep.load_config(write_config(tmp_path, text)))
    preflight.check_cases(cases, ("engine",))
    assert calls == [101]
    monkeypatch.setenv("SPINE_MJ_MEMORY_BUDGET", "1M")
    with pytest.raises(SpineInputError, match=r"engine = 'bullet'.*Bullet's heightfield of 101 x 101"):
        preflight.check_cases(cases, ("engine",))


def test_a_start_on_the_domain_s_edge_is_refused_before_any_run(tmp_path):
    """It ran, every run ending left_domain at once (a run ends a tip radius from an edge)."""
    text = PEAK_ENGINE.replace(
        "[starts]\nx = [0.05]\ny = [0.5]", '[starts]\nframe = "absolute"\npoints = [[-5.0, -1.0]]'
    )
    _refused_before_any_run(tmp_path, text, "start (-5, -1) lies on the edge", "x in [-5, 5], y in [-5, 5]")


def test_an_hfield_past_the_budget_is_refused_on_its_predicted_sides_before_any_sizing(tmp_path, monkeypatch):
    """4000 a side refined twice, both engines (MuJoCo alone without the [bullet] extra): the
    7999-a-side hfield is refused by its predicted size (the sizing would have sampled and
    named the 4000-a-side one first)."""
    from spine_mj import extras

    monkeypatch.setenv("SPINE_MJ_MEMORY_BUDGET", "300M")
    engines = '"mujoco"' if extras.missing("bullet") else '["mujoco", "bullet"]'
    text = PEAK_ENGINE + f"[grid]\nengine = {engines}\nhfield_resolution = 4000\nhfield_refinement = 2\n"
    _refused_before_any_run(tmp_path, text, "an hfield of 7999 x 7999 samples would need")


def test_one_bad_combination_buried_in_a_large_grid_is_refused_naming_it(tmp_path):
    """2480 cases over I_e x K on the paper fractal (L_c / l_s about 29): the spring-block
    swing sqrt(I_e K L_c / l_s) is below 1 F_p in every case but I_e = 1e-3 with K = 100
    (1.7 F_p), both in the middle of their lists: the memoized check still finds it."""
    ie = [round(1e-5 * (1 + 0.3 * i), 9) for i in range(30)]
    ie.insert(15, 1e-3)
    stiff = [round(10 + 0.25 * i, 4) for i in range(79)]
    stiff.insert(40, 100.0)
    text = FRACTAL.format(analyses='["quasistatic", "engine", "compare"]')
    text = text.replace("ie = [1e-4, 1e-3]\nK = [10, 100]", f"ie = {ie}\nK = {stiff}")
    _refused_before_any_run(tmp_path, text, "ie = 0.001, K = 100.0", "spring drive at I_e = 0.001, K = 100")


MIXED = """
[sweep]
analyses = ["quasistatic", "engine", "compare"]
[[surfaces]]
preset = "paper-single-peak"
[[surfaces]]
preset = "paper-single-valley"
starts = {random = 2}
[starts]
x = [0.05, 0.9]
y = [0.5]
[drive]
ie = [1.0, 1e-3, 1e-5]
K = [3, 3000]
[grid]
timestep_factor = [1.0, 1e-3]
tip_radius = [0.05, 0.1]
"""


def _plain_check(case) -> str | None:
    """The slow, obvious reference: every analysis's checks on ``case`` alone, every cache
    and memo of the checks emptied first; the refusal's text, or None."""
    from spine_mj.sim import step_rule
    from spine_mj.sweep.registry import ANALYSES

    sweep.session.clear_caches()
    step_rule._AT_STEP.clear()
    step_rule._cached_settings.cache_clear()
    surface = case.surface.make()
    starts = case.starts.resolve(surface.bounds, case.seed)
    try:
        for name in case.analyses:
            analysis = ANALYSES[name]
            if analysis.precheck_case is not None:
                analysis.precheck_case(case, surface)
            if analysis.check_case is not None:
                analysis.check_case(case, surface, starts)
    except SpineInputError as exc:
        return str(exc)
    return None


def test_the_memoized_check_refuses_exactly_the_cases_the_plain_check_refuses(tmp_path):
    """48 cases over two surfaces (one with random starts, its own per case), I_e, K, the
    step factor and the tip, refused for three reasons (a swing too large to compare, a run
    past the step limit, a random start on the domain's edge) or not. The grid's check,
    its memos kept from one pass to the next, refuses the first bad case in order, and with
    that case removed the next, exactly the cases and messages of the plain check."""
    config = sweep.load_config(write_config(tmp_path, MIXED))
    cases = sweep.expand_cases(config)
    reference = [(c.case_id, why) for c in cases if (why := _plain_check(c)) is not None]
    kinds = {
        kind for _, why in reference for kind in ("must swing", "more than the limit", "edge") if kind in why
    }
    assert len(cases) == 48 and 3 < len(reference) < 45 and len(kinds) == 3

    sweep.session.clear_caches()
    left, refused = list(cases), []
    while True:
        try:
            preflight.check_cases(left, config.swept)
            break
        except SpineInputError as exc:
            bad = next(c for c in left if f"sweep case ({preflight._where(c, config.swept)}): " in str(exc))
            refused.append((bad.case_id, str(exc).split("): ", 1)[1]))
            left.remove(bad)
    assert refused == reference


def test_a_case_s_plan_is_the_plan_of_its_inputs(tmp_path):
    """case_plan (the inputs without the drive checked once, the engine settings per case,
    made once per rounded step) against plan_rig of the case's own RigInputs, case by case."""
    from spine_mj.sim.build import plan_rig, rig_sizing
    from spine_mj.sweep.analyses import engine

    cases = sweep.expand_cases(sweep.load_config(write_config(tmp_path, MIXED)))
    sweep.session.clear_caches()
    sized = {}
    for case in cases:
        surface = case.surface.make()
        inputs = engine.case_inputs(case, surface)
        key = (case.surface.label, inputs.tip)
        sized.setdefault(key, rig_sizing(surface, tip=inputs.tip, **inputs.sizing))
        plain, fast = plan_rig(surface, inputs, sized=sized[key]), engine.case_plan(case, surface)
        assert (fast.engine, fast.scales, fast.tip) == (plain.engine, plain.scales, plain.tip)


def test_sweeps_run_together_size_each_surface_once_and_their_rigs_are_build_rigs(tmp_path, monkeypatch):
    """The checks of sweeps run together and the cases' rigs share one sizing per surface and
    tip (the validation's studies sized each surface once per sweep and again per case); the
    rig built on it is the one :func:`spine_mj.sim.build_rig` builds from the case's inputs."""
    from spine_mj import sim
    from spine_mj.sweep.analyses import engine

    sized = []
    measure = engine.rig_sizing
    monkeypatch.setattr(engine, "rig_sizing", lambda *a, **k: sized.append(k) or measure(*a, **k))
    text = PEAK_ENGINE + "[drive]\nduration = 0.002\n"
    configs = [sweep.load_config(write_config(tmp_path, text, name=f"{n}.toml")) for n in ("a", "b")]
    sweep.run_sweeps([(c, tmp_path / f"out-{i}") for i, c in enumerate(configs)], workers=1)
    assert len(sized) == 1
    case = sweep.expand_cases(configs[0])[0]
    rig = engine.case_rig(case)
    built = sim.build_rig(case.surface.make(), engine.case_inputs(case))
    assert rig.scales == built.scales and rig.tip == built.tip and rig.engine == built.engine
    assert (rig.hfield.data == built.hfield.data).all()

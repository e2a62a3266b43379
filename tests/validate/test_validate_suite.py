"""The validation suite end to end: a smoke-size run, bad plans, the CLI."""

import json

import pytest
from click.testing import CliRunner

from spine_mj import extras, validate
from spine_mj.choices import COMPARED_ENGINES
from spine_mj.cli import main
from spine_mj.errors import SpineInputError


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
        "median_frechet_at_lowest_ie",
        "failed_runs",
        "ie_star",
        "engine_settings",
    ):
        assert key in doc
    # the corner study runs each family at its own corner, from its predicted limits
    corners = doc["corner"]["single_peak_valley"]
    limits = doc["corner_limits"]["single_peak_valley"]
    assert doc["lowest_ie"] == min(c["ie"] for c in corners.values())
    assert doc["limit_families"]["single_peak_valley"]["corner"] == corners
    for preset, corner in corners.items():  # each preset at its own limits
        own = limits["surfaces"][preset]
        assert corner["ie"] <= own["ie_star"] / 10 and limits["presets"][preset]["swing_fp"] <= 1.0
        assert corner["K"] >= 10 * own["k_path"]
    assert set(doc["outcome_agreement_at_lowest_ie"]) == {"single_peak_valley"}
    assert 0.0 <= doc["outcome_agreement_at_lowest_ie"]["single_peak_valley"] <= 1.0
    # runs the engine stopped, by status, per family (none expected on the smoke plan's peak)
    assert doc["failed_runs"] == {"single_peak_valley": {}}
    # every headline number with its 95 % interval, and the machine that made them
    fam = doc["limit_families"]["single_peak_valley"]
    lo, hi = fam["agreement_ci"]
    assert lo <= fam["outcome_agreement"] <= hi
    assert len(fam["median_frechet_ci"]) == 2
    assert {"cpu", "vector_instruction_sets", "python", "numpy", "mujoco", "os"} <= set(doc["platform"])
    assert "interval" in doc["targets"]["rule"]
    assert {"value", "low", "high", "kind"} <= set(doc["ie_star"]["spring"])
    # the static probe on a 20 deg plane (engaged) matches tan(theta + arctan mu) closely
    assert doc["static_kappa_max_rel_error"] < 0.05
    # and again with the step halved (the contact's time constant kept)
    halved = doc["static_convergence"]["dt_halved"]
    assert abs(halved["max_rel_error_change"]) < 0.05 and halved["region_agreement_change"] == 0
    # and on the plane's grid at twice the samples (its facets are the same plane)
    finer = doc["static_convergence"]["hfield_doubled"]
    assert abs(finer["max_rel_error_change"]) < 0.05 and finer["region_agreement_change"] == 0
    report = (out / "report.md").read_text()
    assert "Quasistatic limit" in report and "figures/boundary.png" in report
    assert "Verdicts with their intervals" in report and doc["platform"]["cpu"] in report
    assert (out / "figures" / "boundary.png").stat().st_size > 1000
    assert (out / "sweeps" / "boundary" / "spring-paper-single-peak" / "runs.parquet").is_file()
    assert "outcome agreement" in res.output
    # the engines study: its section with the [bullet] extra, one line saying so without it
    assert "## Engines side by side: the closed forms" in report
    engines = doc["engines"]
    if extras.missing("bullet"):
        assert engines["missing"] == ["bullet"] and "Bullet is not installed" in report
    else:
        assert engines["engines"] == list(COMPARED_ENGINES)
        checks = {"static kappa", "spring-block period", "spring-block peak speed"}
        assert {r["check"] for r in engines["rows"]} == checks
        assert all(f"{e}_measured" in r for r in engines["rows"] for e in COMPARED_ENGINES)
    assert "engines side by side" in res.output
    # the fractal self-lock study: one row per H of the plan, every rate with its count
    fractal = doc["fractal_lock_rate"]
    plan = validate.PLANS["smoke"]
    assert [r["hurst"] for r in fractal["rows"]] == list(plan.fractal.hursts)
    for row in fractal["rows"]:
        for series in ("streamline", "mujoco_corner", "mujoco_dynamic"):
            assert row[f"n_{series}"] == plan.fractal.surfaces
            assert row[f"n_ok_{series}"] + row[f"failed_runs_{series}"] == plan.fractal.surfaces
    assert fractal["corner_ie"] == plan.lowest_ie and fractal["dynamic_ie"] == plan.fractal.dynamic_ie
    assert "fractal_lock" in doc["timings_s"]
    # CPU seconds per study, the workers' included: the studies and the report add up to the total
    cpu = doc["cpu_s"]
    assert set(cpu) == set(doc["timings_s"]) | {"report"} and cpu["limit"] > 0
    assert sum(v for k, v in cpu.items() if k != "total") == pytest.approx(cpu["total"], abs=0.1)
    assert "Self-lock rate against the Hurst exponent" in report and "figures/fractal_lock_rate.png" in report
    assert (out / "figures" / "fractal_lock_rate.png").stat().st_size > 1000
    # the (I_e, K) map: I_e* per family and K, its heat map, no CCDF without rough families
    star = doc["ie_star_by_stiffness"]["single_peak_valley"]["30"]
    assert {"value", "low", "high", "ci_low", "ci_high", "kind"} <= set(star)
    cell = doc["stiffness_map"]["agreement"]["single_peak_valley"]["30"]
    assert cell["ie"] == list(validate.PLANS["smoke"].stiffness_map.ie) and cell["n"] == [1, 1]
    assert doc["stiffness_map"]["energy"][0]["K"] == 30.0
    assert "stiffness_map" in doc["timings_s"]
    assert "over (I_e, K)" in report and "figures/ie_k_map.png" in report
    assert (out / "figures" / "ie_k_map.png").stat().st_size > 1000
    assert "slip_ccdf.png" not in report and not (out / "figures" / "slip_ccdf.png").exists()
    # solution verification of the corner, per family and refinement, shown in the report
    conv = doc["convergence"]["single_peak_valley"]
    for key in ("dt_halved", "hfield_doubled"):
        assert {"agreement_change", "median_frechet_change", "converged"} <= set(conv[key])
        assert conv[key]["refined"] and conv[key]["runs"] == plan.limit.convergence_starts
    assert "Solution verification" in report
    # and of I_e*: the smoke grid's two I_e values rerun with the step halved
    star_conv = doc["ie_star"]["spring"]["convergence"]
    assert star_conv["dt_halved"]["runs"] == len(plan.boundary.ie_values) * 2
    assert star_conv["ie_refined"] == list(plan.boundary.ie_values)
    assert "Solution verification of I_e*" in report
    # and of the fractal lock rates: both MuJoCo series, each surface's own step halved
    for row in fractal["rows"]:
        for series in ("mujoco_corner", "mujoco_dynamic"):
            entry = row[f"convergence_{series}"]["dt_halved"]
            assert entry["runs"] == plan.fractal.refined_surfaces and entry["converged"] is not None
    assert "Solution verification of the MuJoCo rates" in report
    # the map's convergence to the theory and the predicted limits against the measured
    assert {r["axis"] for r in doc["convergence_to_theory"]} == {"ie", "inverse_k"}
    assert doc["predicted_vs_measured"][0]["family"] == "single_peak_valley"


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


def test_too_many_workers_are_refused_before_anything_is_written(tmp_path):
    out = tmp_path / "v"
    result = CliRunner().invoke(main, ["validate", "--quick", "--workers", "100000", "--out", str(out)])
    assert result.exit_code == 2 and "--workers: must be an integer from 1 to" in result.output, result.output
    assert not out.exists()


def test_a_phase_without_a_sweep_ends_its_progress_at_100_percent(tmp_path):
    from spine_mj.validate.study_runner import StudyRunner

    seen = []
    runner = StudyRunner(tmp_path, 1, seen.append, 0.0)
    runner.study = "report"
    with runner.phase("figures and report"):
        pass
    with runner.phase("ramp pilots", 3) as tick:
        for _ in range(3):
            tick()
    steps = [(p.step, p.finished_cases, p.total_cases) for p in seen]
    assert steps[:2] == [("figures and report", 0, 1), ("figures and report", 1, 1)]
    assert steps[2:] == [("ramp pilots", n, 3) for n in (0, 1, 2, 3, 3)]

"""The one rig builder: ``spine-mj simulate`` and a sweep case given the same inputs build
the same model and drive, and the drive-rate rule inverts the equivalent speed."""

import dataclasses
import enum
import json

import pytest
from click.testing import CliRunner

from spine_mj import sim, sweep
from spine_mj.cli import main
from spine_mj.errors import SpineInputError
from spine_mj.surface_io import save_surface
from spine_mj.surfaces import fractal_fbm, inclined_plane, single_gaussian
from spine_mj.sweep.analyses.engine import case_drive, case_rig


def _enc(obj) -> dict:
    d = dataclasses.asdict(obj)
    return {k: (v.value if isinstance(v, enum.Enum) else v) for k, v in d.items()}


def _cli_summary(tmp_path, surface: str, start, args) -> dict:
    out = tmp_path / "cli-run"
    cmd = ["simulate", surface, "--start", f"{start[0]},{start[1]}", "--duration", "0.002", "--out", str(out)]
    res = CliRunner().invoke(main, [*cmd, *map(str, args)])
    assert res.exit_code == 0, res.output
    return json.loads((out / "summary.json").read_text())


def _sweep_case(tmp_path, surface: dict, start, drive: dict, grid: dict):
    doc = {
        "sweep": {"analyses": ["engine"]},
        "surfaces": [surface],
        "starts": {"frame": "absolute", "points": [list(start)]},
        "drive": {"protocol": "spring", **drive},
        "grid": grid,
    }
    (case,) = sweep.expand_cases(sweep.parse_config(doc, base_dir=tmp_path))
    rig = case_rig(case)
    return rig, case_drive(rig, case.params)


def _flat(d: dict) -> dict:
    """``d`` with list values spread into ``key[i]`` entries (for pytest.approx)."""
    out = {}
    for k, v in d.items():
        for i, x in enumerate(v) if isinstance(v, (list, tuple)) else [(None, v)]:
            out[k if i is None else f"{k}[{i}]"] = x
    return out


def _assert_same_model(summary: dict, rig, drive) -> None:
    """Equal settings; floats to 1e-12 (a tip radius in surface units times 0.01 m)."""
    for got, want in [
        (summary["engine"], json.loads(json.dumps(rig.engine.to_dict()))),
        (summary["tip"], _enc(rig.tip)),
        (summary["scales"], _enc(rig.scales)),
        (summary["drive_params"], _enc(drive)),
    ]:
        got, want = _flat(got), _flat(want)
        assert set(got) == set(want)
        for k, v in want.items():
            same = (
                got[k] == v
                if isinstance(v, (str, bool)) or v is None
                else got[k] == pytest.approx(v, rel=1e-12)
            )
            assert same, (k, got[k], v)
    assert summary["drive"] == type(drive).__name__


def test_cli_and_sweep_build_the_same_model_on_an_analytic_surface(tmp_path):
    start = (-3.0, -1.0)
    summary = _cli_summary(
        tmp_path,
        "paper-single-peak",
        start,
        ["--ie", 1e-3, "--K", 10, "--mu", 1.2, "--tip-radius", 0.2, "--resolution", 41],
    )
    rig, drive = _sweep_case(
        tmp_path,
        {"preset": "paper-single-peak"},
        start,
        {"ie": 1e-3, "K": 10.0, "duration": 0.002},
        {"mu": 1.2, "tip_radius": 0.2, "hfield_resolution": 41},
    )
    _assert_same_model(summary, rig, drive)
    assert rig.hfield.ncol == 41 and summary["scales"]["hfield_resolution"] == 41


def test_cli_and_sweep_keep_a_grids_own_samples(tmp_path):
    """A gridded surface is not resampled by --resolution / hfield_resolution: MuJoCo
    collides with the heights the streamline reads."""
    surface = fractal_fbm(nx=48, size=10.0, hurst=0.8, rms_height=0.3, rng=3)
    save_surface(surface, tmp_path / "f.npz")
    start = (-2.0, 0.0)
    summary = _cli_summary(tmp_path, str(tmp_path / "f.npz"), start, ["--mu", 0.8, "--resolution", 41])
    rig, drive = _sweep_case(
        tmp_path, {"file": "f.npz"}, start, {"duration": 0.002}, {"mu": 0.8, "hfield_resolution": 41}
    )
    _assert_same_model(summary, rig, drive)
    assert (rig.hfield.nrow, rig.hfield.ncol) == surface.heights.shape


def test_force_rate_is_the_inverse_of_the_equivalent_speed():
    rig = sim.Rig(single_gaussian(), tip=sim.TipParams(mu_s=1.0))
    sc = rig.scales
    v = sc.speed_for(1e-3)
    assert sc.force_rate_for(v) == pytest.approx(v * sc.preload_n / sc.char_length_m, rel=1e-15)
    assert sc.equivalent_speed(sc.force_rate_for(v)) == pytest.approx(v, rel=1e-12)
    ramp = sim.build_drive(sc, "ramp", ie=1e-3)
    assert sc.inertia_number(sc.equivalent_speed(ramp.rate_n_s)) == pytest.approx(1e-3, rel=1e-12)


def test_a_refined_hfield_keeps_every_sample_and_the_tip_on_a_grid_and_an_analytic_surface(tmp_path):
    """Solution verification's hfield x 2: a grid through its own spline, an analytic surface
    sampled twice as densely; the old samples and the default tip's radius kept, in the
    sweep's rig (``hfield_refinement``) as in build_rig."""
    grid = fractal_fbm(nx=48, size=10.0, hurst=0.8, rms_height=0.3, rng=3)
    save_surface(grid, tmp_path / "f.npz")
    for surface, entry, res in (
        (grid, {"file": "f.npz"}, None),
        (single_gaussian(), {"preset": "paper-single-peak"}, 41),
    ):
        base = sim.build_rig(surface, mu=0.8, hfield_resolution=res)
        fine = sim.build_rig(surface, mu=0.8, hfield_resolution=res, hfield_refinement=2)
        n0, n1 = base.hfield.ncol, fine.hfield.ncol
        assert n1 == 2 * n0 - 1 and fine.hfield.nrow == 2 * base.hfield.nrow - 1
        assert fine.scales.tip_radius_m == base.scales.tip_radius_m
        assert fine.scales.hfield_spacing_m == pytest.approx(base.scales.hfield_spacing_m / 2)
        assert fine.scales.hfield_refinement == 2 and base.scales.hfield_refinement == 1
        old = base.hfield.data * base.hfield.size[2] + base.hfield.pos[2]
        new = fine.hfield.data[::2, ::2] * fine.hfield.size[2] + fine.hfield.pos[2]
        assert new == pytest.approx(old, abs=1e-6 * base.hfield.size[2])
        rig, _ = _sweep_case(
            tmp_path,
            entry,
            (0.0, 0.0),
            {"duration": 0.002},
            {"mu": 0.8, "hfield_resolution": res or 41, "hfield_refinement": 2},
        )
        assert rig.hfield.ncol == n1 and rig.scales.tip_radius_m == base.scales.tip_radius_m


@pytest.mark.parametrize(
    ("given", "named"),
    [
        ({"ie": 1e-3, "speed_m_s": 0.01}, "ie, speed_m_s, rate_n_s"),
        ({"ie": 1e-3, "rate_n_s": 1.0}, "ie, speed_m_s, rate_n_s"),
        ({"stiffness_number": 10.0, "stiffness_n_m": 100.0}, "stiffness_number, stiffness_n_m"),
    ],
)
def test_build_drive_refuses_a_pace_or_a_stiffness_given_twice(given, named):
    # "at most one of speed and I_e": neither wins silently, in build_drive and build_rig alike
    scales = sim.build_rig(inclined_plane(slope_deg=0.0), mu=0.5, tip_radius_m=1e-3).scales
    for protocol in ("spring", "ramp"):
        with pytest.raises(SpineInputError, match=f"give at most one of {named}, got"):
            sim.build_drive(scales, protocol, **given)
    if "ie" in given:
        with pytest.raises(SpineInputError, match=f"give at most one of {named}"):
            sim.drive_speed_m_s(scales, **given)


def test_a_rig_s_preparation_reports_each_stage_through_its_callback(monkeypatch):
    """Long preparations show progress (8192 a side took 43 s before the run): every stage
    reaches the callback, the fall height line by line to its total, and the model's stage
    ends done; the library prints nothing. Only hfields of PROGRESS_MIN_SAMPLES report (a
    small case's refusal stays one line): lowered here to this small one."""
    from spine_mj.sim import build, scales

    surf, quiet, heard = fractal_fbm(nx=64, rng=0), [], []
    sim.build_rig(surf, mu=0.5, hfield_refinement=2, progress=lambda *a: quiet.append(a))
    assert quiet == []
    monkeypatch.setattr(scales, "PROGRESS_MIN_SAMPLES", 0)
    monkeypatch.setattr(build, "PROGRESS_MIN_SAMPLES", 0)
    rig = sim.build_rig(surf, mu=0.5, hfield_refinement=2, progress=lambda *a: heard.append(a))
    stages = list(dict.fromkeys(stage for _, _, stage in heard))
    assert stages == ["sampling the hfield", "fall height", "refining the hfield", "building mujoco's model"]
    lines = [(done, total) for done, total, stage in heard if stage == "fall height"]
    assert lines[-1] == (2 * rig.hfield.nrow, 2 * rig.hfield.nrow)  # both axes of the refined hfield
    assert heard[-1] == (1, 1, "building mujoco's model")


def test_the_tips_defaults_have_one_home_for_every_command(tmp_path, monkeypatch):
    """``simulate`` without --mass/--preload, a sweep without mass/preload/gravity and
    ``build_rig`` without them all take sim.TipParams' defaults (the sweep's schema reads
    them from its fields): a changed default there (here a patched TipParams whose mass
    defaults to 0.02 kg) is the one RigInputs, and so build_rig and simulate, build with."""
    import dataclasses

    from spine_mj.sim import rig_inputs
    from spine_mj.sweep.analyses import engine

    summary = _cli_summary(tmp_path, "paper-single-peak", (-3.0, -1.0), ["--mu", 1.2, "--resolution", 41])
    rig, _ = _sweep_case(tmp_path, {"preset": "paper-single-peak"}, (-3.0, -1.0), {"ie": 1e-3}, {"mu": 1.2})
    default = sim.TipParams(mu_s=1.2)
    assert summary["tip"]["mass_kg"] == rig.tip.mass_kg == default.mass_kg
    assert summary["tip"]["preload_n"] == rig.tip.preload_n == default.preload_n
    assert rig.tip.gravity_m_s2 == default.gravity_m_s2
    heavier = dataclasses.make_dataclass(
        "TipParams",
        [("mass_kg", float, dataclasses.field(default=0.02))],
        bases=(sim.TipParams,),
        frozen=True,
    )
    monkeypatch.setattr(rig_inputs, "TipParams", heavier)
    assert sim.build_rig(inclined_plane(slope_deg=0.0), mu=0.5).tip.mass_kg == 0.02
    assert engine._TIP["mass_kg"] == sim.TipParams.__dataclass_fields__["mass_kg"].default
    assert rig_inputs.RigInputs(mu=0.5).tip.mass_kg == 0.02

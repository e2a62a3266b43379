"""The slip catalog: MuJoCo's Prandtl-Tomlinson jumps on a corrugation land where the
inertial reference says, not where the overdamped one does; every source fills the same
columns in the same units."""

import numpy as np
import pandas as pd
import pytest

from spine_mj import surfaces
from spine_mj.errors import SpineInputError
from spine_mj.validate.slip_catalog import COLUMNS
from spine_mj.validate.stickslip_outputs import OUTPUT_FILES, stickslip_to


@pytest.fixture(scope="module")
def corrugation_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("pt")
    surf = surfaces.corrugation(n_waves=4, points_per_wave=128, width=0.5)
    # K 0.2 < K* 0.47: one jump a wavelength; I_e 1e-4, a tip of lambda / 100 (the ground truth's)
    res = stickslip_to(
        out, surf, mu=0.5, stiffness_numbers=[0.2], ie=1e-4, engine="mujoco", tip_radius_m=1e-4
    )
    return res, pd.read_parquet(out / "events.parquet")


def test_mujoco_jumps_as_the_inertial_reference_not_the_overdamped(corrugation_study):
    _, events = corrugation_study
    assert tuple(events.columns) == COLUMNS
    # past the first, partly loaded fold, and landing a wavelength (2 L_c) short of the grid's end
    steady = events[(events["start_x_lc"] > 1.5) & (events["start_x_lc"] + events["size_lc"] < 6.0)]
    size = {
        s: steady.loc[steady["source"] == s, "size_lc"].to_numpy()
        for s in ("overdamped", "inertial", "mujoco")
    }
    drop = {s: steady.loc[steady["source"] == s, "force_drop_fp"].to_numpy() for s in size}
    assert size["mujoco"].size >= 2 and np.ptp(size["inertial"]) < 1e-2
    assert np.abs(size["mujoco"] / size["inertial"].mean() - 1).max() < 0.1
    assert np.abs(drop["mujoco"] / drop["inertial"].mean() - 1).max() < 0.1
    assert size["inertial"].mean() > 1.3 * size["overdamped"].mean()  # inertia overshoots
    for s in size:  # every slip is faster than the carriage, and dissipates
        rows = steady[steady["source"] == s]
        assert (rows["peak_speed_v"] > 5).all() and (rows["dissipated_fp_lc"] > 0).all()


def test_study_writes_every_file_and_a_summary_per_source(corrugation_study):
    res, _ = corrugation_study
    assert [p.name for p in res.files] == list(OUTPUT_FILES)
    assert all(p.is_file() for p in res.files)
    assert set(res.summary["sources"]) == {"overdamped", "inertial", "mujoco"}
    assert res.summary["sources"]["mujoco"]["0.2"]["n_events"] >= 3
    assert "mujoco_vs_inertial" in res.summary["two_sample"]["0.2"]
    drops = pd.read_parquet(res.files[1])
    assert tuple(drops.columns) == COLUMNS
    assert set(drops["source"]) == {
        "overdamped",
        "inertial",
        "mujoco",
        "overdamped_facets",
        "inertial_facets",
    }
    counts = res.summary["drops"]["n_events"]
    assert all(counts[s]["0.2"] == (drops["source"] == s).sum() for s in counts)
    assert set(res.summary["drops"]["two_sample"]["0.2"]) == {
        f"mujoco_vs_{s}" for s in ("overdamped", "inertial", "overdamped_facets", "inertial_facets")
    }
    # by one rule on both sides MuJoCo's slips over a crest (past the first, partly loaded
    # fold) are the faceted inertial reference's
    crest = (drops["force_drop_fp"] > 0.1) & (drops["start_x_lc"] > 1.5)
    big = {s: drops.loc[crest & (drops["source"] == s), "size_lc"] for s in counts}
    assert big["mujoco"].size >= 2
    assert np.abs(big["mujoco"] / big["inertial_facets"].mean() - 1).max() < 0.1
    assert big["inertial_facets"].mean() > 1.2 * big["overdamped_facets"].mean()
    regime = res.summary["regime"]  # the corrugation's Prandtl-Tomlinson fold, K* 0.47
    assert regime["K_star"] == pytest.approx(0.47, rel=0.05)
    # the swing reaches the median drop far above this study's I_e 1e-4, below the 1 F_p bound
    assert 1e-4 < regime["swing_ie"]["0.2"] < regime["quasistatic_ie"]["0.2"]


SWEEP = """
[sweep]
name = "pt"
analyses = ["engine"]
[[surfaces]]
preset = "corrugation"
set = { points_per_wave = 128, n_waves = 4, width = 0.5 }
[starts]
frame = "absolute"
x = [0.25]
y = [0.0]
[drive]
protocol = "spring"
ie = 1e-4
K = [0.2]
[grid]
mu = 0.5
tip_radius = 0.01
"""


def test_a_sweep_stores_the_catalog_and_a_resume_keeps_it(tmp_path, corrugation_study):
    from spine_mj import sweep
    from spine_mj.validate.slip_catalog import store_catalog

    config = tmp_path / "sweep.toml"
    config.write_text(SWEEP)
    out = tmp_path / "out"
    sweep.run_sweep(config, out, workers=1)
    first = store_catalog(out)
    assert tuple(first.columns) == COLUMNS
    assert len(first) == int(sweep.load_runs(out)["slip_events"].sum()) >= 3
    sweep.run_sweep(config, out, workers=1)  # a resume: nothing left to run, the table stays
    pd.testing.assert_frame_equal(store_catalog(out), first)
    # the stored jumps land as the inertial reference's on the same corrugation
    _, events = corrugation_study
    inertial = events[(events["source"] == "inertial") & (events["start_x_lc"] > 1.5)]["size_lc"].mean()
    stored = first[(first["start_x_lc"] > 1.5) & (first["start_x_lc"] + first["size_lc"] < 6.0)]
    assert len(stored) >= 2
    assert np.abs(stored["size_lc"] / inertial - 1).max() < 0.1


def test_force_drop_rule_gives_mujoco_the_inertial_references_drops_on_a_corrugation():
    """One rule for both sides: MuJoCo's force drops (peak of the spring's force to its
    trough) on a corrugation are the inertial reference's, from the crest's force peak to
    the slip's stop, within a tenth; the overdamped reference's are smaller. A floor of
    0.01 F_p: MuJoCo's load passes the crest in a 1e-3 F_p wobble on the hfield's facets."""
    from spine_mj.sim.build import build_rig
    from spine_mj.validate.slip_catalog import (
        TrackUnits,
        engine_drop_rows,
        reference_drop_rows,
        track_landscape,
    )
    from spine_mj.validate.stickslip_outputs import _engine_run

    surf = surfaces.corrugation(n_waves=4, points_per_wave=128, width=0.5)
    rig = build_rig(surf, engine="mujoco", mu=0.5, ie=1e-4, stiffness_number=0.2, tip_radius_m=1e-4)
    units = TrackUnits.of(rig.scales, 1e-4)
    land = track_landscape(surf, 0.5, units.tip_radius, (0.25, 3.75))
    refs = reference_drop_rows(land, units, 0.2, 0.01)
    run = _engine_run(rig, units, land, 0.2, 1e-4, 0.25, 3.5)
    eng = engine_drop_rows(run, units, "mujoco", 0.2, 0.01)
    assert list(eng) == list(COLUMNS)
    steady = {
        s: np.asarray(r["force_drop_fp"])[np.asarray(r["start_x_lc"]) > 1.0]
        for s, r in (refs | {"mujoco": eng}).items()
    }
    assert steady["mujoco"].size >= 2 and np.ptp(steady["inertial"]) < 1e-2
    assert np.abs(steady["mujoco"] / steady["inertial"].mean() - 1).max() < 0.1
    assert steady["inertial"].mean() > 1.2 * steady["overdamped"].mean()


def test_drop_summary_puts_the_carriages_advance_back_at_a_fixed_carriage():
    """An engine's drop is the reference's less ``k V T`` (its carriage moves during the
    drop, the reference's does not): the raw drops differ, the drops at a fixed carriage are
    the same sample (KS distance 0)."""
    from spine_mj.validate.slip_catalog import TrackUnits
    from spine_mj.validate.stickslip_outputs import drop_summary

    rng = np.random.default_rng(0)
    units = TrackUnits(1e-3, 4.0, 2.0, 0.01, 1.0, 1e-3, speed=0.02)
    k_number, n = 1.0, 400
    ref = 0.01 + rng.exponential(0.05, n)  # every drop deeper than k V T (under 0.01)
    duration = rng.uniform(0.5, 1.0, n)
    engine = ref - units.stiffness(k_number) * units.speed * duration
    frame = pd.DataFrame(
        {
            "source": ["inertial"] * n + ["mujoco"] * n,
            "K": k_number,
            "size_lc": np.concatenate([ref, ref]),
            "duration_s": np.concatenate([np.full(n, np.nan), duration]),
            "force_drop_fp": np.concatenate([ref, engine]),
        }
    )
    out = drop_summary(frame, "mujoco", [k_number], {k_number: units}, 1e-3)
    test = out["two_sample"]["1"]["mujoco_vs_inertial"]
    assert out["n_events"] == {"inertial": {"1": n}, "mujoco": {"1": n}}
    assert test["size_lc"]["ks"] == 0.0
    assert test["force_drop_fp"]["ks"] > 0.1 and not test["force_drop_fp"]["agree"]
    assert test["force_drop_fixed_carriage_fp"]["ks"] < 2 / n  # equal up to rounding


def test_the_faceted_landscape_is_the_height_fields_straight_pieces():
    """With ``facets``, the line is straight between the nodes: a point tip's threshold is
    ``tan(theta + arctan mu)`` of each piece's slope, constant along it."""
    from spine_mj.validate.slip_catalog import track_landscape

    surf = surfaces.corrugation(n_waves=2, points_per_wave=16, width=0.5)
    xmin, xmax, _, _ = surf.bounds
    nodes = np.linspace(xmin, xmax, 33)
    land = track_landscape(surf, 0.5, 0.0, (xmin, xmax), facets=33)
    z = surf.height(nodes, np.zeros_like(nodes))
    slope = np.diff(z) / np.diff(nodes)
    u = land.positions
    piece = np.clip(np.searchsorted(nodes, u) - 1, 0, 31)
    inner = np.abs(u - nodes[piece] - 0.5 * (nodes[1] - nodes[0])) < 0.3 * (nodes[1] - nodes[0])
    expected = (slope[piece] + 0.5) / (1 - 0.5 * slope[piece])
    np.testing.assert_allclose(land.force[inner], expected[inner], rtol=1e-9, atol=1e-9)


def test_a_ball_wider_than_a_valley_rides_the_lines_dilation():
    """A rough line where the offset path would loop (from_profile refuses it): the centre
    rides the disk's dilation, never below the line plus the radius straight under it, and
    resting on it somewhere."""
    from spine_mj.theory.avalanches import Landscape
    from spine_mj.validate.slip_catalog import track_landscape

    surf = surfaces.corrugation(n_waves=8, points_per_wave=64, width=0.5, wavelength=0.1)
    xmin, xmax, _, _ = surf.bounds
    x = np.linspace(xmin, xmax, 2000)
    z, (gx, _) = surf.height(x, 0 * x), surf.gradient(x, 0 * x)
    with pytest.raises(SpineInputError, match="radius of curvature"):
        Landscape.from_profile(x, gx, z, 0.5, 0.08)
    land = track_landscape(surf, 0.5, 0.08, (xmin, xmax))
    base = surf.height(land.positions, 0 * land.positions) + 0.08
    assert np.all(land.height >= base - 1e-9)
    assert np.min(land.height - base) < 1e-6


def test_a_refined_landscape_keeps_the_references_jumps_and_refuses_a_fraction():
    """``refinement`` samples the same line finer (the references' grid convergence): on a
    coarse corrugation each reference's jumps, one a wavelength, move by less than a tenth of the
    coarse grid's step under refinement x 2; a refinement that is no whole number >= 1 is
    refused."""
    from spine_mj.validate.slip_catalog import REFINEMENT, TrackUnits, reference_rows, track_landscape

    surf = surfaces.corrugation(n_waves=4, points_per_wave=16, width=0.5)
    units = TrackUnits(1.0, 1.0, 1 / (2 * np.pi), 0.0, 1.0, 1e-3, speed=0.01)
    coarse, fine = (track_landscape(surf, 0.5, 0.0, (0.25, 3.75), refinement=f) for f in (1, 2))
    assert fine.positions.size - 1 == 2 * (coarse.positions.size - 1)
    step = surf.spacing[0] / REFINEMENT
    a, b = (reference_rows(land, units, 0.2) for land in (coarse, fine))
    for source in a:
        sa, sb = (np.asarray(r[source]["size_lc"]) for r in (a, b))
        assert sa.size == sb.size >= 3
        np.testing.assert_allclose(sb, sa, atol=0.1 * step)
    for bad in (0, 1.5, True):
        with pytest.raises(SpineInputError, match="refinement"):
            track_landscape(surf, 0.5, 0.0, (0.25, 3.75), refinement=bad)


def test_engine_run_starts_a_soft_spring_stretched_near_the_threshold():
    """A run shorter than the spring's stretch at the start's threshold starts with all but
    START_MARGIN of it (the carriage would otherwise spend the run climbing); a longer run
    climbs from zero."""
    from spine_mj.sim.build import build_rig
    from spine_mj.validate.slip_catalog import TrackUnits, track_landscape
    from spine_mj.validate.stickslip_outputs import START_MARGIN, _engine_run

    surf = surfaces.corrugation(n_waves=4, points_per_wave=128, width=0.5)
    land = track_landscape(surf, 0.5, 1e-4, (0.25, 3.75))
    k = 0.2
    rig = build_rig(surf, engine="mujoco", mu=0.5, ie=1e-4, stiffness_number=k, tip_radius_m=1e-4)
    units = TrackUnits.of(rig.scales, 1e-4)
    for stretched in (True, False):
        lead = land.force[0] / units.stiffness(k)
        run = _engine_run(rig, units, land, k, 1e-4, 0.25, lead / 2 if stretched else 1.2 * lead)
        start = run.drive_force_n[run.drive_start_index] / units.preload_n
        expected = (1 - START_MARGIN) * land.force[0] if stretched else 0.0
        assert start == pytest.approx(expected, abs=2e-3)

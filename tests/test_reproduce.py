import json

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj.cli import main
from spine_mj.reproduce import kappa_map, raw_rms_height, single_peak


def test_single_peak_qualitative_facts_reduced_run():
    numbers, _ = single_peak(quick=True)
    convex = {s["y0"]: s for s in numbers["convex_starts"]}
    concave = {s["y0"]: s for s in numbers["concave_starts"]}
    # bypass: no convex streamline from the five starts self-locks; the ideal at -0.5 does
    assert all(s["streamline"] != "self_locked" for s in convex.values())
    assert convex[-0.5]["ideal"] == "self_locked"
    # trap: concave streamlines near the centre self-lock, the farthest does not
    for y in (-0.5, -1.0, -2.0):
        assert concave[y]["streamline"] == "self_locked"
    assert concave[-4.0]["streamline"] != "self_locked"
    for y in (-1.0, -2.0, -3.0):
        assert concave[y]["ideal"] != "self_locked"
    assert numbers["convex_ratio"] < 1 < numbers["concave_ratio"]
    # mirror symmetry of the kappa field: the same ideal self-lock ranges. The two walks
    # sample mirrored slopes at different x, so a start right at the threshold could
    # count on one side only: allow one scan step
    assert numbers["convex_ideal_range"] == pytest.approx(
        numbers["concave_ideal_range"], abs=numbers["y0_step"]
    )


def test_kappa_map_peak_and_valley_have_equal_self_lock_area():
    numbers, _ = kappa_map(quick=True)
    # mirror images, but linspace(-5, 5) is not bitwise symmetric about 0: a grid point
    # within rounding of the self-lock boundary may fall on either side, so allow one
    # point per side (the fraction of one point is 1 / n^2)
    convex, concave = numbers["convex_self_lock_fraction"], numbers["concave_self_lock_fraction"]
    assert convex > 0
    assert convex == pytest.approx(concave, abs=2.0 / numbers["n"] ** 2)


def test_raw_rms_height_matches_a_synthesis():
    from spine_mj.surfaces import fractal_fbm

    h = [fractal_fbm(nx=64, size=20.0, hurst=0.8, rng=s).heights for s in range(1)]
    assert raw_rms_height(0.8, 64, 20.0) > 0
    assert np.isfinite(h[0]).all()


def test_cli_reproduce_and_errors(tmp_path):
    runner = CliRunner()
    res = runner.invoke(main, ["reproduce", "kappa-map", "--out", str(tmp_path), "--quick"])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "kappa-map.json").read_text())
    assert data["mu"] > 0 and (tmp_path / "kappa-map.png").stat().st_size > 0
    res = runner.invoke(
        main, ["streamline", "paper-single-valley", "--start", "9,9", "--out", str(tmp_path / "bad")]
    )
    assert res.exit_code == 2 and "starts must lie inside" in res.output
    assert not (tmp_path / "bad").exists()
    res = runner.invoke(
        main, ["streamline", "paper-single-valley", "--start", "x", "--out", str(tmp_path / "bad")]
    )
    assert res.exit_code == 2 and "--start" in res.output


def test_cli_streamline_writes_a_table(tmp_path):
    import pandas as pd

    res = CliRunner().invoke(
        main,
        [
            "streamline",
            "paper-single-valley",
            "--mu",
            "1.2",
            "--start",
            "-3,-1",
            "--start",
            "-3,-2",
            "--out",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    table = pd.read_parquet(tmp_path / "streamlines.parquet")
    assert set(table["trajectory"]) == {"streamline", "ideal"}
    assert (tmp_path / "streamlines.png").exists()


def test_random_surface_single_peak_normalization_and_finite_max_kappa():
    from spine_mj.reproduce.random_gaussian import _max_kappa, _random_surface
    from spine_mj.theory.streamline import streamlines
    from spine_mj.theory.streamline_types import StreamlineParams

    gen = {"n_peaks": 20, "sign": -1, "sigma_range": (0.5, 1.5), "overlap": True, "k_range": (1.0, 2.0)}
    surf = _random_surface(gen, 3)
    k = -surf.amplitude * 2 * np.pi * surf.sigma_x * surf.sigma_y
    assert np.all((k >= 1.0) & (k <= 2.0))
    res = streamlines(surf, [(-9.99, y) for y in np.linspace(-5, 5, 11)], StreamlineParams(mu=1.25, dl=0.02))
    fin, inf = _max_kappa(res, "finite"), _max_kappa(res, "inf")
    # the finite convention never exceeds the kernel's max and is finite wherever engaged
    ok = np.isfinite(fin)
    assert np.all(fin[ok] <= inf[ok]) and not np.isposinf(fin).any()
    assert np.array_equal(np.isposinf(inf), res.self_locked)


def test_options_are_used_or_refused_never_ignored(tmp_path):
    """--surfaces given with --quick is what runs (quick only sets the default); --workers
    and --surfaces of a figure that takes neither are refused."""
    from spine_mj.reproduce import fractal_hurst

    numbers, _ = fractal_hurst(quick=True, surfaces=36, hursts=[0.8], workers=1)
    assert numbers["surfaces_per_hurst"] == 36 and numbers["by_hurst"][0]["surfaces"] == 36
    for option in (["--workers", "4"], ["--surfaces", "10"]):
        res = CliRunner().invoke(main, ["reproduce", "kappa-map", "--out", str(tmp_path), *option])
        assert res.exit_code == 2 and f"reproduce kappa-map does not use {option[0]}" in res.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--surfaces", "100000000", "--workers", "1"], "--surfaces: at most 20000 per H"),
        (["--workers", "100000"], "--workers: must be an integer from 1 to"),
    ],
)
def test_fractal_hurst_counts_are_checked_before_any_work(tmp_path, args, fragment):
    out = tmp_path / "r"
    result = CliRunner().invoke(main, ["reproduce", "fractal-hurst", "--quick", "--out", str(out), *args])
    assert result.exit_code == 2 and fragment in result.output, result.output
    assert not out.exists()


def test_kappa_map_to_draws_one_surface_with_the_region_shares_of_the_paper_map(tmp_path):
    from spine_mj.reproduce import kappa_map_to
    from spine_mj.surfaces import single_gaussian
    from spine_mj.theory.engagement import REGION_NAMES

    numbers, _ = kappa_map(n=41)
    shares = kappa_map_to(tmp_path / "k.png", single_gaussian(sign=1), mu=numbers["mu"], resolution=41)
    assert list(shares) == list(REGION_NAMES.values())
    assert shares == {label: numbers[f"convex_{label}_fraction"] for label in shares}
    assert sum(shares.values()) == pytest.approx(1.0)
    assert (tmp_path / "k.png").read_bytes()[:4] == b"\x89PNG"


def test_run_to_writes_the_numbers_and_figure_of_run(tmp_path):
    import json

    from spine_mj.reproduce import run_to

    json_path, png_path = run_to(tmp_path / "r", "kappa-map", quick=True, n=21)
    assert (json_path, png_path) == (tmp_path / "r" / "kappa-map.json", tmp_path / "r" / "kappa-map.png")
    assert json.loads(json_path.read_text()) == pytest.approx(kappa_map(n=21)[0])
    assert png_path.stat().st_size > 1000

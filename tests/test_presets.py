"""Surface recipes in surfaces/: every preset builds, seeds reproduce, overrides validate."""

import numpy as np
import pytest

from spine_mj import SpineInputError
from spine_mj.presets import list_presets, load_preset, make_surface, parse_override

PAPER = [
    "paper-single-peak",
    "paper-single-valley",
    "paper-random-convex",
    "paper-random-concave",
    "paper-fractal",
    "sandpaper-P36",
    "sandpaper-P60",
    "sandpaper-P600",
]


def test_all_paper_presets_exist():
    assert set(PAPER) <= set(list_presets())


@pytest.mark.parametrize("name", PAPER)
def test_preset_builds_and_records_its_name(name):
    surf = make_surface(name)
    assert surf.metadata["preset"] == name
    x0, x1, y0, y1 = surf.bounds
    assert np.isfinite(surf.height(0.5 * (x0 + x1), 0.5 * (y0 + y1)))


def test_single_peak_preset_is_the_paper_surface():
    surf = make_surface("paper-single-peak")
    assert surf.height(0, 0) == pytest.approx(2.2222, abs=1e-4)
    assert surf.bounds == (-5, 5, -5, 5)
    assert make_surface("paper-single-valley").height(0, 0) == pytest.approx(-2.2222, abs=1e-4)


def test_overrides_and_seed():
    a = make_surface("paper-fractal", seed=3, hurst=0.65)
    b = make_surface("paper-fractal", seed=3, hurst=0.65)
    c = make_surface("paper-fractal", seed=4, hurst=0.65)
    np.testing.assert_array_equal(a.heights, b.heights)
    assert not np.array_equal(a.heights, c.heights)
    assert a.metadata["params"]["hurst"] == 0.65 and a.metadata["seed"] == 3


def test_bad_presets_and_overrides(tmp_path):
    with pytest.raises(SpineInputError, match=r"unknown preset 'nope'; known presets: .*paper-single-peak"):
        load_preset("nope")
    with pytest.raises(SpineInputError, match=r"unknown parameter\(s\) \['colour'\]"):
        make_surface("paper-fractal", colour="red")
    with pytest.raises(SpineInputError, match="takes no seed"):
        make_surface("paper-single-peak", seed=1)
    bad = tmp_path / "bad.toml"
    bad.write_text("generator = 'fractal_fbm'\n[params\n")
    with pytest.raises(SpineInputError, match="not valid TOML"):
        load_preset(str(bad))
    bad.write_text("generator = 'teapot'\n")
    with pytest.raises(SpineInputError, match="generator must be one of"):
        load_preset(str(bad))


def test_parse_override():
    assert parse_override("hurst=0.7") == ("hurst", 0.7)
    assert parse_override("size=[10, 12]") == ("size", [10, 12])
    assert parse_override("grit=P36") == ("grit", "P36")
    with pytest.raises(SpineInputError, match="key=value"):
        parse_override("hurst")


def test_corrugation_preset_is_the_prandtl_tomlinson_profile():
    # z = h sin(2 pi x / lambda), slope amplitude s: f_x = s cos(2 pi x / lambda), f_y = 0;
    # L_c = lambda and l_s = 0.190 lambda (docs/physics.md), the numbers K* is quoted with
    from spine_mj import roughness

    surf = make_surface("corrugation")
    lam, s = surf.metadata["params"]["wavelength"], surf.metadata["params"]["slope_amplitude"]
    x = np.linspace(0.1, 7.3, 41)
    y = np.full_like(x, 0.2)
    fx, fy = surf.gradient(x, y)
    np.testing.assert_allclose(fx, s * np.cos(2 * np.pi * x / lam), atol=1e-4)
    np.testing.assert_allclose(fy, 0.0, atol=1e-12)
    np.testing.assert_allclose(
        surf.height(x, y), s * lam / (2 * np.pi) * np.sin(2 * np.pi * x / lam), atol=1e-5
    )
    assert roughness.characteristic_length(surf) == pytest.approx(lam, rel=1e-3)
    assert roughness.slope_correlation_length(surf) == pytest.approx(0.190 * lam, rel=0.01)


@pytest.mark.parametrize(
    "bad", [{"n_waves": 0}, {"n_waves": 2.5}, {"points_per_wave": 4}, {"slope_amplitude": float("nan")}]
)
def test_corrugation_refuses_nonsense(bad):
    with pytest.raises(SpineInputError, match=next(iter(bad))):
        make_surface("corrugation", **bad)


def test_open_surface_reads_every_kind_of_spec(tmp_path):
    from spine_mj.presets import open_surface
    from spine_mj.surface_io import save_surface

    peak = open_surface("paper-single-peak")
    assert peak.metadata["preset"] == "paper-single-peak"
    assert (
        open_surface("paper-fractal", seed=4).heights.tolist()
        == make_surface("paper-fractal", seed=4).heights.tolist()
    )
    save_surface(peak.sample(16), tmp_path / "p.npz")
    np.testing.assert_array_equal(open_surface(str(tmp_path / "p.npz")).heights, peak.sample(16).heights)
    scan = open_surface("example:plu-1.plu")  # a shipped instrument file
    assert scan.unit != "1" and scan.heights.ndim == 2


def test_open_surface_names_what_it_cannot_open(tmp_path):
    from spine_mj.presets import open_surface

    with pytest.raises(SpineInputError, match=r"SURFACE must be a \.npz file, a preset .* got 'no-such'"):
        open_surface("no-such")
    with pytest.raises(SpineInputError, match=r"is a surface file: overrides \(seed\) are for presets"):
        open_surface("example:plu-1.plu", seed=3)


def test_preset_descriptions_are_each_presets_own():
    from spine_mj.presets import preset_descriptions

    described = preset_descriptions()
    assert list(described) == list_presets()
    assert all(described[n] == load_preset(n).description for n in described)


def test_surface_info_has_drive_limits_only_with_a_mu(tmp_path):
    from spine_mj import roughness
    from spine_mj.presets import SurfaceInfo, surface_info
    from spine_mj.surfaces import single_gaussian

    surf = single_gaussian(sign=1).sample(64)  # no preset, so no calibrated mu_s
    plain = surface_info(surf)
    assert isinstance(plain, SurfaceInfo) and plain.unit == surf.unit and plain.drive_limits is None
    assert plain.roughness.rms_slope == roughness.summarize(surf).rms_slope
    assert plain.as_dict()["drive_limits"] is None
    with pytest.raises(SpineInputError, match="--tip-radius must be a finite number >= 0"):
        surface_info(surf, mu=0.5, tip_radius=-1.0)
    given = surface_info(surf, mu=0.5, psd_png=tmp_path / "psd.png")
    assert given.drive_limits.mu == 0.5 and given.as_dict()["drive_limits"]["mu"] == 0.5
    assert (tmp_path / "psd.png").read_bytes()[:4] == b"\x89PNG"


def test_make_surface_file_needs_exactly_one_source(tmp_path):
    from spine_mj.presets import make_surface_file

    with pytest.raises(SpineInputError, match="exactly one of PRESET or --from-file"):
        make_surface_file(tmp_path / "s.npz")
    surf = make_surface_file(tmp_path / "s.npz", preset="paper-single-peak", png=tmp_path / "s.png")
    assert surf.metadata["preset"] == "paper-single-peak"
    assert (tmp_path / "s.npz").is_file() and (tmp_path / "s.png").is_file()

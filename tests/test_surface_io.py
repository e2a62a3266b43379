"""Saving, loading, importing measured topographies, and the STL solid."""

import numpy as np
import pytest
from click.testing import CliRunner

from spine_mj import SpineInputError
from spine_mj.cli import main
from spine_mj.surface_io import (
    import_topography,
    load_surface,
    save_surface,
    surface_mesh,
    write_stl,
)
from spine_mj.surfaces import MAX_PEAKS, GridSurface, fractal_fbm, random_gaussians, single_gaussian


def test_npz_round_trip_grid_and_gaussian(tmp_path):
    grid = fractal_fbm(nx=32, ny=20, hurst=0.6, rng=4, unit="m")
    back = load_surface(save_surface(grid, tmp_path / "g.npz"))
    np.testing.assert_array_equal(back.heights, grid.heights)
    np.testing.assert_array_equal(back.x, grid.x)
    assert back.periodic and back.unit == "m"
    assert back.metadata["params"]["hurst"] == 0.6 and back.metadata["seed"] == 4

    gauss = random_gaussians(n_peaks=5, rng=2)
    back = load_surface(save_surface(gauss, tmp_path / "r.npz"))
    x, y = np.random.default_rng(0).uniform(-9, 9, (2, 50))
    np.testing.assert_array_equal(back.height(x, y), gauss.height(x, y))
    assert back.bounds == gauss.bounds
    with np.load(tmp_path / "r.npz", allow_pickle=False) as npz:
        assert "metadata_json" in npz.files


def test_load_rejects_corrupt_and_foreign_files(tmp_path):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip at all")
    with pytest.raises(SpineInputError, match="not a readable"):
        load_surface(bad)
    foreign = tmp_path / "foreign.npz"
    np.savez(foreign, a=np.zeros(3))
    with pytest.raises(SpineInputError, match="not a spine_mj surface"):
        load_surface(foreign)
    with pytest.raises(SpineInputError, match="not found"):
        load_surface(tmp_path / "missing.npz")
    nan = tmp_path / "nan.npz"
    save_surface(single_gaussian().sample(8), nan)
    with np.load(nan) as npz:
        data = dict(npz)
    data["heights"] = data["heights"].copy()
    data["heights"][2, 3] = np.nan
    np.savez(nan, **data)
    with pytest.raises(SpineInputError, match="NaN"):
        load_surface(nan)


def test_a_file_over_the_gaussian_limit_is_refused_when_read(tmp_path):
    """At most MAX_PEAKS Gaussians, whether generated or read: a file holding 200 000
    (written by hand) is refused on reading, before any evaluation (``surface info`` used to
    work 352 s on one, ``surface show`` drew it), with one line and nothing written."""
    small = tmp_path / "small.npz"
    save_surface(random_gaussians(n_peaks=5, rng=2), small)
    with np.load(small) as npz:
        data = dict(npz)
    n = 2 * MAX_PEAKS
    for key in ("amplitude", "center_x", "center_y"):
        data[key] = np.zeros(n)
    data["sigma_x"] = data["sigma_y"] = np.ones(n)
    big = tmp_path / "big.npz"
    np.savez(big, **data)
    with pytest.raises(
        SpineInputError, match=rf"big.npz: a Gaussian surface holds at most {MAX_PEAKS} Gaussians, got {n}"
    ):
        load_surface(big)
    for args in (
        ["surface", "info", str(big)],
        ["surface", "show", str(big), "-o", str(tmp_path / "big.png")],
    ):
        result = CliRunner().invoke(main, args)
        lines = result.output.strip().splitlines()
        assert result.exit_code == 2 and len(lines) == 1 and lines[0].startswith("Error: "), result.output
        assert f"at most {MAX_PEAKS} Gaussians" in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.npz", "small.npz"]


def test_failed_save_leaves_nothing(tmp_path):
    class Weird:
        unit, bounds, metadata = "1", (0, 1, 0, 1), {}

    with pytest.raises(SpineInputError, match="cannot save"):
        save_surface(Weird(), tmp_path / "w.npz")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "name, n_expected, unit", [("plu-1.plu", (576, 768), "um"), ("di-1.di", (512, 512), "nm")]
)
def test_import_instrument_files(topography_dir, name, n_expected, unit):
    surf = import_topography(topography_dir / name)
    assert surf.unit == unit
    assert surf.shape == n_expected
    h = surf.heights
    assert np.isfinite(h).all()
    # levelled: the least-squares plane of the result is flat
    yy, xx = np.meshgrid(surf.y, surf.x, indexing="ij")
    design = np.column_stack([np.ones(h.size), xx.ravel(), yy.ravel()])
    coef = np.linalg.lstsq(design, h.ravel(), rcond=None)[0]
    assert np.abs(coef[1:]).max() < 1e-9 * h.std() and abs(coef[0]) < 1e-3 * h.std()
    # the instrument's units: nanometre-to-micrometre heights on fields of 0.5 um (AFM)
    # and 1.3 mm (profilometer)
    assert 1e-2 < h.std() < 1e2
    assert 1e2 < surf.bounds[1] - surf.bounds[0] < 2e3
    raw = import_topography(topography_dir / name, level=False)
    assert np.abs(raw.heights - h).max() > 0.01 * h.std()


@pytest.mark.parametrize("name, st_unit", [("plu-1.plu", "\u00b5m"), ("di-1.di", "nm")])
def test_import_keeps_the_numbers_surfacetopography_reads(tmp_path, topography_dir, name, st_unit):
    """Heights and grid in the file's unit ("µm" spelled "um"), as SurfaceTopography reads
    them, and through a saved .npz. Unlevelled they are the reader's float64 numbers
    themselves (nothing is converted: tolerance 0); levelled, SurfaceTopography's own plane removal
    (``detrend("height")``) agrees to round-off: the plu scan's tilt is 150 times its
    roughness, so subtracting it costs ~150 ulp of the heights (measured 5e-12 of the rms
    height), hence 1e-9."""
    import SurfaceTopography as st

    topo = st.open_topography(str(topography_dir / name)).topography()
    assert topo.unit == st_unit
    raw = import_topography(topography_dir / name, level=False)
    np.testing.assert_array_equal(raw.heights, topo.heights().T)
    spacing = np.asarray(topo.physical_sizes) / np.asarray(topo.nb_grid_pts)
    np.testing.assert_allclose(raw.spacing, spacing, rtol=1e-12)
    levelled = import_topography(topography_dir / name)
    reference = topo.detrend("height").heights().T
    np.testing.assert_allclose(levelled.heights, reference, rtol=0, atol=1e-9 * reference.std())
    back = load_surface(save_surface(levelled, tmp_path / "scan.npz"))
    assert back.unit == levelled.unit
    np.testing.assert_array_equal(back.heights, levelled.heights)


def test_import_resamples_to_spacing(topography_dir):
    surf = import_topography(topography_dir / "di-1.di")
    dx = surf.spacing[0]  # nm; spacing_m is in metres whatever the file's unit
    coarse = import_topography(topography_dir / "di-1.di", spacing_m=4 * dx * 1e-9)
    assert coarse.unit == "nm" and coarse.spacing[0] == pytest.approx(4 * dx)
    assert coarse.shape[1] == pytest.approx(surf.shape[1] / 4, abs=1)
    np.testing.assert_allclose(coarse.heights[::1, ::1][5, 5], surf.heights[20, 20], rtol=1e-6)


@pytest.fixture
def holey_x3p(tmp_path):
    import SurfaceTopography as st

    rng = np.random.default_rng(0)
    h = np.add.outer(np.linspace(0, 1, 40), np.linspace(0, 2, 30)) + 0.01 * rng.normal(size=(40, 30))
    masked = np.ma.masked_array(h, mask=np.zeros_like(h, dtype=bool))
    masked.mask[10:13, 5:9] = True
    path = tmp_path / "holey.x3p"
    st.Topography(masked, (40.0, 30.0), unit="um").to_x3p(str(path))
    return path


def test_missing_points_refused_or_filled(holey_x3p):
    with pytest.raises(SpineInputError, match="12 missing points"):
        import_topography(holey_x3p)
    for method in ("harmonic", "nearest", "mean"):
        surf = import_topography(holey_x3p, fill=method, level=False)
        assert np.isfinite(surf.heights).all()
        assert surf.metadata["missing_points"] == 12
    # a harmonic fill of a smooth ramp stays on the ramp (x3p stores metres: the file's unit)
    harm = import_topography(holey_x3p, fill="harmonic", level=False)
    near = import_topography(holey_x3p, fill="nearest", level=False)
    assert harm.unit == near.unit == "m"
    ramp_value = harm.heights[6, 11]
    assert abs(ramp_value - near.heights[6, 11]) < 0.2e-6


def test_import_rejects_bad_files(tmp_path):
    corrupt = tmp_path / "scan.plu"
    corrupt.write_bytes(b"\x00\x01garbage" * 10)
    with pytest.raises(SpineInputError, match="cannot read topography"):
        import_topography(corrupt)
    with pytest.raises(SpineInputError, match="not found"):
        import_topography(tmp_path / "none.x3p")
    with pytest.raises(SpineInputError, match="fill must be one of"):
        import_topography(corrupt, fill="zero")


def test_stl_is_watertight_solid(tmp_path):
    surf = fractal_fbm(nx=24, ny=17, hurst=0.8, rng=1)
    mesh = surface_mesh(surf, base_thickness=0.5)
    assert mesh.is_watertight and mesh.is_volume
    assert mesh.bounds[0][2] == pytest.approx(surf.heights.min() - 0.5)
    # exact volume of the two-triangles-per-cell solid: A/6 (2 h_a + h_b + h_c + 2 h_d)
    h = surf.heights - mesh.bounds[0][2]
    cell = surf.spacing[0] * surf.spacing[1]
    exact = cell / 6 * np.sum(2 * h[:-1, :-1] + h[:-1, 1:] + h[1:, :-1] + 2 * h[1:, 1:])
    assert mesh.volume == pytest.approx(exact, rel=1e-9)
    path = write_stl(single_gaussian(), tmp_path / "peak.stl", resolution=40)
    import trimesh

    loaded = trimesh.load(path)
    assert loaded.is_watertight


def test_stl_refuses_wrong_suffix(tmp_path):
    with pytest.raises(SpineInputError, match=r"\.stl"):
        write_stl(single_gaussian(), tmp_path / "peak.obj")
    assert not any(tmp_path.iterdir())


def test_grid_surface_metadata_survives(tmp_path):
    surf = GridSurface(
        heights=np.zeros((4, 4)), x=np.arange(4.0), y=np.arange(4.0), metadata={"note": "flat", "n": 3}
    )
    assert load_surface(save_surface(surf, tmp_path / "f.npz")).metadata == {"note": "flat", "n": 3}


@pytest.mark.parametrize("unit", ["banana", ""])
def test_load_refuses_a_surface_whose_unit_is_no_length_unit(tmp_path, unit):
    from spine_mj.presets import make_surface

    path = save_surface(make_surface("paper-single-peak").sample(16), tmp_path / "s.npz")
    data = dict(np.load(path))
    data["unit"] = np.array(unit)
    np.savez(path, **data)
    with pytest.raises(SpineInputError, match=rf"s\.npz: unit must be '1' .* got '{unit}'"):
        load_surface(path)


def test_load_refuses_a_zip_that_is_not_an_npz_of_arrays(tmp_path):
    import zipfile

    path = tmp_path / "z.npz"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("hello.txt", "hello")
    with pytest.raises(SpineInputError, match=r"z\.npz is not a spine_mj \.npz surface: member 'hello\.txt'"):
        load_surface(path)


@pytest.mark.parametrize("rows", [3, 64])
def test_the_streamed_stl_is_the_meshs_solid(tmp_path, monkeypatch, rows):
    """write_stl streams the triangles a few rows at a time: the file holds the faces of
    surface_mesh (the reference, built whole by trimesh), outward, watertight, with its
    volume, whether the rows come in several pieces or one."""
    import trimesh

    from spine_mj import surface_io

    monkeypatch.setattr(surface_io, "_STL_ROWS", rows)
    surf = fractal_fbm(nx=24, ny=17, hurst=0.8, rng=1)
    reference = surface_mesh(surf, base_thickness=0.5, scale=2.0)
    loaded = trimesh.load(write_stl(surf, tmp_path / "f.stl", base_thickness=0.5, scale=2.0))
    assert loaded.is_watertight and loaded.is_volume and len(loaded.faces) == len(reference.faces)
    assert loaded.volume == pytest.approx(reference.volume, rel=1e-5)  # float32 coordinates

    # the same triangles, each with its vertices in the same (outward) order
    def rows_of(tris):
        return np.unique(np.round(np.asarray(tris).reshape(len(tris), -1), 3), axis=0)

    np.testing.assert_allclose(rows_of(loaded.triangles), rows_of(reference.triangles), atol=2e-3)

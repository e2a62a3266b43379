"""Reading and writing surfaces: spine_mj's .npz format, measured instrument files, STL.

* ``.npz``: every array plus a JSON metadata string; loads with ``allow_pickle=False``.
* measured topographies (x3p, opd, datx, plu, di, sur, ...) through SurfaceTopography, in
  the instrument's length unit, levelled, with missing points filled by a stated method or
  refused;
* a watertight STL solid (top surface, side walls, flat bottom) for 3-D printing.

Writers go through :func:`spine_mj.errors.atomic_output`: a failure leaves no file behind.
"""

from __future__ import annotations

import json
import math
import os
import re
import zipfile
from pathlib import Path

import numpy as np

from spine_mj.atomic import atomic_output
from spine_mj.choices import FILL_METHODS
from spine_mj.errors import SpineInputError, check_positive
from spine_mj.jsonio import to_jsonable
from spine_mj.surfaces import (
    LENGTH_UNITS_M,
    MAX_GRID_POINTS,
    GaussianSurface,
    GridSurface,
    HField,
    Surface,
    check_grid_size,
    check_unit,
    length_unit,
    to_hfield,
)

__all__ = [
    "export_surface",
    "import_topography",
    "load_surface",
    "save_surface",
    "surface_mesh",
    "write_hfield",
    "write_preview",
    "write_stl",
]

FORMAT = "spine_mj.surface/1"
_GAUSS_KEYS = ("amplitude", "center_x", "center_y", "sigma_x", "sigma_y")


def save_surface(surface: Surface, path: str | os.PathLike) -> Path:
    """Write ``surface`` to ``path`` (.npz), atomically.

    Every array and the metadata (generator, parameters, seed, version, unit) as JSON; the
    file loads with ``numpy.load(..., allow_pickle=False)`` and :func:`load_surface`.

    Parameters
    ----------
    surface : Surface
        A Gaussian or grid surface.
    path : str or os.PathLike
        The output file.

    Returns
    -------
    Path
        The path written.
    """
    path = Path(path)
    if path.suffix != ".npz":
        raise SpineInputError(f"surface files must end in .npz, got {path.name!r}")
    common = {
        "format": np.array(FORMAT),
        "unit": np.array(surface.unit),
        "bounds": np.asarray(surface.bounds, dtype=float),
        "metadata_json": np.array(json.dumps(to_jsonable(surface.metadata))),
    }
    if isinstance(surface, GridSurface):
        arrays = dict(
            kind=np.array("grid"),
            heights=surface.heights,
            x=surface.x,
            y=surface.y,
            periodic=np.array(surface.periodic),
        )
    elif isinstance(surface, GaussianSurface):
        arrays = {"kind": np.array("gaussian")}
        arrays.update({k: getattr(surface, k) for k in _GAUSS_KEYS})
    else:
        raise SpineInputError(f"cannot save a surface of type {type(surface).__name__}")
    with atomic_output(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **common, **arrays)
    return path


_NUMERIC_KEYS = {"heights", "x", "y", "bounds", *_GAUSS_KEYS}


def _npz_member_shape(npz, name: str) -> tuple[int, ...]:
    """The shape of array ``name`` of an open .npz, read from its .npy header."""
    with npz.zip.open(f"{name}.npy") as f:
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            return np.lib.format.read_array_header_1_0(f)[0]
        return np.lib.format.read_array_header_2_0(f)[0]


def load_surface(path: str | os.PathLike) -> Surface:
    """Read a surface written by :func:`save_surface`.

    Parameters
    ----------
    path : str or os.PathLike
        An ``.npz`` file (or ``example:NAME`` resolved by the caller).

    Returns
    -------
    Surface

    Raises
    ------
    SpineInputError
        If the file is missing, not an .npz, corrupt, from another program, or holds
        invalid data (NaN heights, bad coordinates, ...).
    """
    path = Path(path)
    if not path.is_file():
        raise SpineInputError(f"surface file not found: {path}")
    data = _read_npz(path)
    if str(data.get("format", "")) != FORMAT:
        raise SpineInputError(f"{path} is not a spine_mj surface file (no format tag {FORMAT!r})")
    try:
        metadata = json.loads(str(data["metadata_json"]))
        if not isinstance(metadata, dict):
            raise SpineInputError(f"metadata_json must be a JSON object, got {type(metadata).__name__}")
        for name, arr in data.items():
            if name in _NUMERIC_KEYS and not np.issubdtype(arr.dtype, np.number):
                raise SpineInputError(f"array {name!r} must be numeric, got dtype {arr.dtype}")
        kind = str(data["kind"])
        unit = str(data["unit"])
        check_unit(unit)
        if kind == "grid":
            periodic = data["periodic"]
            if periodic.shape != () or periodic.dtype.kind not in "bi" or periodic not in (0, 1):
                raise SpineInputError(
                    f"array 'periodic' must be one boolean, got {periodic.dtype} of shape {periodic.shape}"
                )
            return GridSurface(
                heights=data["heights"],
                x=data["x"],
                y=data["y"],
                periodic=bool(periodic),
                unit=unit,
                metadata=metadata,
            )
        if kind == "gaussian":
            return GaussianSurface(
                **{k: data[k] for k in _GAUSS_KEYS},
                bounds=tuple(data["bounds"]),
                unit=unit,
                metadata=metadata,
            )
    except KeyError as exc:
        raise SpineInputError(f"{path} is missing the array {exc.args[0]!r}") from None
    except json.JSONDecodeError as exc:
        raise SpineInputError(f"{path} has corrupt metadata ({exc})") from None
    except RecursionError:
        raise SpineInputError(f"{path} has metadata nested too deep to read") from None
    except SpineInputError as exc:
        raise SpineInputError(f"{path}: {exc}") from None
    raise SpineInputError(f"{path} has unknown surface kind {kind!r}; expected 'grid' or 'gaussian'")


# --------------------------------------------------------------------------- measured data


def _read_npz(path: Path) -> dict[str, np.ndarray]:
    """The arrays of the .npz file at ``path``, each checked for size from its header before
    a compressed array is inflated, and a grid's heights against the memory budget as the
    grid they make (:func:`~spine_mj.surfaces.check_grid_size`: a 4096 x 4096 grid loaded
    took 514 MiB, four arrays of its size); SpineInputError for a file that is no readable
    .npz of .npy arrays."""
    try:
        with np.load(path, allow_pickle=False) as npz:
            for name in npz.files:  # sizes from the headers, before a compressed array is inflated
                if f"{name}.npy" not in npz.zip.namelist():
                    raise SpineInputError(
                        f"{path} is not a spine_mj .npz surface: member {name!r} is not a .npy array"
                    )
                shape = _npz_member_shape(npz, name)
                if math.prod(shape) > MAX_GRID_POINTS:
                    raise SpineInputError(
                        f"{path}: array {name!r} has shape {shape}, more than {MAX_GRID_POINTS} values"
                    )
                if name == "heights" and len(shape) == 2:
                    check_grid_size(shape[1], shape[0], where=str(path))
            return {k: npz[k] for k in npz.files}
    except SpineInputError:
        raise
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as exc:
        raise SpineInputError(f"{path} is not a readable spine_mj .npz surface ({exc})") from None


def _unreadable(path: Path, exc: Exception) -> SpineInputError:
    """One line for a file SurfaceTopography cannot read: the readers it tried (or the
    first line of its message); the full text rides along as ``details``."""
    text = str(exc)
    tried = re.findall(r"tried (\w+?)(?:Reader)?:", text)
    if tried:
        reason = f"no reader recognises it (tried {', '.join(tried)})"
    else:
        first = text.strip().splitlines()[0] if text.strip() else ""
        reason = f"{type(exc).__name__}: {first[:200]}"
    error = SpineInputError(f"cannot read topography {path.name}: {reason}")
    error.details = f"{type(exc).__name__}: {text}"
    return error


def import_topography(
    path: str | os.PathLike,
    *,
    channel: int = 0,
    fill: str = "refuse",
    level: bool = True,
    spacing_m: float | None = None,
) -> GridSurface:
    """Read a measured topography through SurfaceTopography, in the instrument's unit.

    Heights and coordinates keep the length unit the file states, spelled as in
    :data:`~spine_mj.surfaces.LENGTH_UNITS_M` ("µm" becomes "um"): an AFM scan stays in
    nm, a profilometer's in um, and its numbers are the instrument's own (the rig and the
    roughness analysis convert through the unit). A unit outside that table ("A", "km")
    is converted to metres.

    Parameters
    ----------
    path
        Any format SurfaceTopography reads (x3p, opd, datx, plu, di, sur, ...).
    channel
        Index of the data channel to read (height channels come first in most formats).
    fill
        What to do with missing points: ``"refuse"`` (raise, naming their count),
        ``"harmonic"`` (SurfaceTopography's harmonic interpolation: the solution of
        Laplace's equation with the measured points as boundary values), ``"nearest"``
        (value of the nearest measured point), or ``"mean"`` (the mean height).
    level
        Remove the best-fit plane (tilt and offset) by least squares.
    spacing_m
        Resample to this spacing, given in metres, with the C2 interpolant; None keeps the
        instrument's grid.

    Raises
    ------
    SpineInputError
        A missing or unreadable file, a channel out of range or without a length unit
        (phase, amplitude), a non-uniform or 1-D scan, missing points with ``fill="refuse"``.
    """
    if fill not in FILL_METHODS:
        raise SpineInputError(f"fill must be one of {FILL_METHODS}, got {fill!r}")
    path = Path(path)
    if not path.is_file():
        raise SpineInputError(f"topography file not found: {path}")

    topo, unit = _read_channel(path, channel)
    heights = np.ma.filled(np.ma.masked_invalid(topo.heights()).astype(float), np.nan)
    missing = ~np.isfinite(heights)
    n_missing = int(missing.sum())
    if n_missing:
        heights = _filled(heights, missing, fill, topo, path)
    if level:
        heights = _remove_plane(heights)

    nx_, ny_ = topo.nb_grid_pts
    sx, sy = topo.physical_sizes
    x = np.arange(nx_) * (sx / nx_)
    y = np.arange(ny_) * (sy / ny_)
    meta = {
        "generator": "measured",
        "source": path.name,
        "channel": channel,
        "fill": fill,
        "missing_points": n_missing,
        "levelled": bool(level),
        "instrument": str(topo.info.get("instrument", {}).get("name", "")),
    }
    surface = GridSurface(
        heights=heights.T, x=x - x.mean(), y=y - y.mean(), periodic=False, unit=unit, metadata=meta
    )
    if spacing_m is None:
        return surface
    spacing = check_positive("spacing_m", spacing_m) / LENGTH_UNITS_M[unit]
    try:
        return surface.resample(spacing)
    except SpineInputError as exc:
        raise SpineInputError(
            f"spacing_m {spacing_m:g} m ({spacing:g} {unit}) on {path.name}: {exc}"
        ) from None


def _read_channel(path: Path, channel: int):
    """SurfaceTopography's topography of ``channel`` in ``path`` and its length unit (a unit
    outside :data:`LENGTH_UNITS_M` converted to metres); one-line errors for bad files."""
    import SurfaceTopography as st  # lazy like mujoco: 1.7 s to import, needed only for instrument files

    try:
        reader = st.open_topography(str(path))
        n_channels = len(reader.channels)
        if not (0 <= channel < n_channels):
            raise SpineInputError(f"channel must be in 0..{n_channels - 1} for {path.name}, got {channel}")
        topo = reader.topography(channel_index=channel)
        unit = length_unit(topo.unit)
        if unit is None:
            if not _is_st_length_unit(topo.unit):
                raise SpineInputError(
                    f"channel {channel} of {path.name} must be heights in a length unit, "
                    f"got unit {topo.unit!r}"
                )
            topo, unit = topo.to_unit("m"), "m"
    except SpineInputError:
        raise
    except Exception as exc:  # SurfaceTopography raises many types for bad files
        raise _unreadable(path, exc) from None
    if topo.dim != 2 or not topo.is_uniform:
        raise SpineInputError(f"{path.name} is not a uniform 2-D area scan")
    return topo, unit


def _filled(heights: np.ndarray, missing: np.ndarray, fill: str, topo, path: Path) -> np.ndarray:
    """``heights`` with its ``missing`` points filled by ``fill``, or refused."""
    n_missing = int(missing.sum())
    if fill == "refuse":
        raise SpineInputError(
            f"{path.name} has {n_missing} missing points ({100 * n_missing / heights.size:.2f} %);"
            " choose a fill method (harmonic, nearest, mean)"
        )
    if n_missing == heights.size:
        raise SpineInputError(f"{path.name} has no valid height at all")
    return _fill_missing(heights, missing, fill, topo)


def _is_st_length_unit(unit) -> bool:
    """Whether SurfaceTopography knows ``unit`` as a length (it can convert it to metres)."""
    from SurfaceTopography.Support.UnitConversion import is_length_unit

    return isinstance(unit, str) and is_length_unit(unit)


def _fill_missing(heights, missing, method, topo):
    if method == "harmonic":
        filled = topo.interpolate_undefined_data("harmonic").heights()
        return np.asarray(np.ma.filled(filled, np.nan), dtype=float)
    if method == "mean":
        out = heights.copy()
        out[missing] = heights[~missing].mean()
        return out

    from scipy import ndimage

    _, (ii, jj) = ndimage.distance_transform_edt(missing, return_indices=True)
    return heights[ii, jj]


def _remove_plane(heights: np.ndarray) -> np.ndarray:
    n0, n1 = heights.shape
    a, b = np.meshgrid(np.arange(n0, dtype=float), np.arange(n1, dtype=float), indexing="ij")
    design = np.column_stack([np.ones(heights.size), a.ravel(), b.ravel()])
    coef, *_ = np.linalg.lstsq(design, heights.ravel(), rcond=None)
    return heights - (design @ coef).reshape(heights.shape)


# --------------------------------------------------------------------------- STL


def _mesh_grid(surface, resolution: int, base_thickness, scale: float):
    """``(grid, z_bottom, scale)`` of a mesh of ``surface``: a grid meshed at its own
    samples, an analytic surface sampled ``resolution`` a side; the flat bottom
    ``base_thickness`` below the lowest point (default 5 % of the larger side)."""
    grid = surface if isinstance(surface, GridSurface) else surface.sample(resolution)
    span = max(grid.x[-1] - grid.x[0], grid.y[-1] - grid.y[0])
    base_thickness = (
        0.05 * span if base_thickness is None else check_positive("base_thickness", base_thickness)
    )
    return grid, float(grid.heights.min() - base_thickness), check_positive("scale", scale)


def surface_mesh(
    surface: Surface, *, resolution: int = 201, base_thickness: float | None = None, scale: float = 1.0
):
    """A closed, watertight triangle mesh: the surface on top, walls, a flat bottom.

    A :class:`GridSurface` is meshed at its own samples, an analytic surface on a
    ``resolution x resolution`` grid. ``base_thickness`` (below the lowest point) defaults
    to 5 % of the larger side. Coordinates are multiplied by ``scale``.

    Returns
    -------
    trimesh.Trimesh
    """

    grid, z_bottom, scale = _mesh_grid(surface, resolution, base_thickness, scale)
    h = grid.heights
    ny, nx = h.shape
    xx, yy = np.meshgrid(grid.x, grid.y)
    top = np.column_stack([xx.ravel(), yy.ravel(), h.ravel()])
    bottom = np.column_stack([xx.ravel(), yy.ravel(), np.full(h.size, z_bottom)])
    vertices = np.vstack([top, bottom]) * scale
    idx = np.arange(ny * nx).reshape(ny, nx)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    top_faces = np.concatenate([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    off = ny * nx
    bottom_faces = top_faces[:, ::-1] + off
    ring = np.concatenate([idx[0, :], idx[1:, -1], idx[-1, -2::-1], idx[-2:0:-1, 0]])
    nxt = np.roll(ring, -1)
    walls = np.concatenate(
        [np.column_stack([ring, ring + off, nxt + off]), np.column_stack([ring, nxt + off, nxt])]
    )
    import trimesh  # on demand, like SurfaceTopography: the meshes are an export

    mesh = trimesh.Trimesh(
        vertices=vertices, faces=np.concatenate([top_faces, bottom_faces, walls]), process=False
    )
    mesh.fix_normals()
    return mesh


#: Rows of the grid whose triangles are made and written at once (memory O(rows x nx)).
_STL_ROWS = 64
_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])


def write_stl(
    surface: Surface,
    path: str | os.PathLike,
    *,
    resolution: int = 201,
    base_thickness: float | None = None,
    scale: float = 1.0,
) -> Path:
    """Write the solid of :func:`surface_mesh` as binary STL, atomically, streamed: the
    triangles are made and written a few rows of the grid at a time, so memory stays that
    of the heights (a 2048 x 2048 fractal took 9.2 GB through a whole mesh, 839 MB on disk).
    The same vertices and faces as :func:`surface_mesh`, in the same winding (outward
    normals): watertight by construction (tested against it).

    Parameters
    ----------
    surface : Surface
        The surface to print: a solid under its heights (mm for physical surfaces).
    path : str or os.PathLike
        The output ``.stl`` file.
    resolution, base_thickness, scale
        As for :func:`surface_mesh`.

    Returns
    -------
    Path
        The path written.
    """
    path = Path(path)
    if path.suffix.lower() != ".stl":
        raise SpineInputError(f"STL output must end in .stl, got {path.name!r}")
    grid, z_bottom, scale = _mesh_grid(surface, resolution, base_thickness, scale)
    h = grid.heights
    ny, nx = h.shape
    n_faces = 4 * (ny - 1) * (nx - 1) + 4 * (nx - 1 + ny - 1)
    with atomic_output(path) as tmp, open(tmp, "wb") as fh:
        fh.write(b"spine_mj surface solid".ljust(80, b" ") + np.uint32(n_faces).tobytes())
        for i0 in range(0, ny - 1, _STL_ROWS):
            rows = slice(i0, min(i0 + _STL_ROWS, ny - 1) + 1)
            xx, yy = np.meshgrid(grid.x, grid.y[rows])
            top = np.stack([xx, yy, h[rows]], axis=-1)
            a, b, c, d = top[:-1, :-1], top[:-1, 1:], top[1:, :-1], top[1:, 1:]
            tris = np.concatenate([np.stack([a, b, d], -2), np.stack([a, d, c], -2)]).reshape(-1, 3, 3)
            _write_triangles(fh, tris, scale)
            bottom = tris[:, ::-1].copy()
            bottom[..., 2] = z_bottom
            _write_triangles(fh, bottom, scale)
        ring = np.concatenate(
            [
                np.column_stack([grid.x, np.full(nx, grid.y[0]), h[0]]),
                np.column_stack([np.full(ny - 1, grid.x[-1]), grid.y[1:], h[1:, -1]]),
                np.column_stack([grid.x[-2::-1], np.full(nx - 1, grid.y[-1]), h[-1, -2::-1]]),
                np.column_stack([np.full(ny - 2, grid.x[0]), grid.y[-2:0:-1], h[-2:0:-1, 0]]),
            ]
        )
        nxt = np.roll(ring, -1, axis=0)
        low, nxt_low = ring.copy(), nxt.copy()
        low[:, 2] = nxt_low[:, 2] = z_bottom
        _write_triangles(
            fh,
            np.concatenate([np.stack([ring, low, nxt_low], -2), np.stack([ring, nxt_low, nxt], -2)]),
            scale,
        )
    return path


def _write_triangles(fh, tris: np.ndarray, scale: float) -> None:
    """Triangles ``(n, 3, 3)`` as binary STL records (float32, unit normals by their
    winding), refusing coordinates the STL's 32-bit floats cannot hold."""
    v = tris * scale
    v32 = v.astype(np.float32)
    if not np.isfinite(v32).all():
        raise SpineInputError(
            "the mesh's coordinates overflow the STL's 32-bit floats: use a smaller --stl-scale or --base"
        )
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    rec = np.zeros(len(v), _STL_RECORD)
    rec["normal"] = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    rec["vertices"] = v32
    fh.write(rec.tobytes())


def write_hfield(surface: Surface, path: str | os.PathLike, *, resolution: int | None = None) -> HField:
    """Write the surface as MuJoCo hfield data (:func:`~spine_mj.surfaces.to_hfield`;
    ``resolution`` samples a side, else a grid's own or 201) to an ``.npz`` with ``data``,
    ``size``, ``pos`` and ``unit``, atomically. Returns the hfield."""
    hf = to_hfield(surface, ncol=resolution, nrow=resolution) if resolution else to_hfield(surface)
    with atomic_output(path) as tmp, open(tmp, "wb") as fh:
        np.savez(
            fh, data=hf.data, size=np.asarray(hf.size), pos=np.asarray(hf.pos), unit=np.array(surface.unit)
        )
    return hf


def write_preview(surface: Surface, path: str | os.PathLike) -> Path:
    """Write the PNG preview of ``surface`` (height map and 3-D view,
    :func:`~spine_mj.plotting.surface_preview`) to ``path`` atomically; returns it."""
    from spine_mj.plotting import save_figure, surface_preview

    return save_figure(surface_preview(surface), path)


def export_surface(
    surface: Surface,
    *,
    stl: str | os.PathLike | None = None,
    hfield: str | os.PathLike | None = None,
    stl_scale: float | None = None,
    base_thickness: float | None = None,
    resolution: int | None = None,
) -> tuple[float | None, HField | None]:
    """Write ``surface`` as the STL solid ``stl`` (:func:`write_stl`) and/or as MuJoCo hfield
    data ``hfield`` (:func:`write_hfield`), all or none (``spine-mj surface export``).

    ``stl_scale`` multiplies the STL's coordinates (None: the surface's length unit to mm,
    1 for a dimensionless surface); ``base_thickness`` and ``resolution`` as in
    :func:`surface_mesh`. Returns the STL's scale and the hfield written (None for an
    output not asked for).
    """
    from spine_mj.atomic import all_or_none

    unit = length_unit(surface.unit)
    mm_scale = 1.0 if unit is None else LENGTH_UNITS_M[unit] / LENGTH_UNITS_M["mm"]
    scale = check_positive("--stl-scale", stl_scale if stl_scale is not None else mm_scale)
    if base_thickness is not None:
        base_thickness = check_positive("--base", base_thickness)
    hf = None
    with all_or_none(stl, hfield):
        if stl:
            mesh_opts = {"scale": scale, "base_thickness": base_thickness}
            if resolution:
                mesh_opts["resolution"] = resolution
            write_stl(surface, stl, **mesh_opts)
        if hfield:
            hf = write_hfield(surface, hfield, resolution=resolution)
    return (scale if stl else None), hf

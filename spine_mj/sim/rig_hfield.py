"""The hfield a rig collides with: its resolution and refinement (checked), its sides
(known before it is sampled, for budgets and engine limits), its sampling and its spacing.

:class:`~spine_mj.sim.scales.Scales` sizes a rig on this hfield (the sizing rule, the tip
and the coarsening, lives there); nothing here needs MuJoCo.
"""

from __future__ import annotations

from spine_mj.errors import SpineInputError, check_count
from spine_mj.memory import check_memory
from spine_mj.surfaces import GridSurface, HField, Surface, to_hfield
from spine_mj.surfaces.hfield import DEFAULT_HFIELD_SIDE, hfield_half_extents

__all__ = [
    "HFIELD_BYTES_PER_SAMPLE",
    "MAX_HFIELD_SIDE",
    "check_hfield_refinement",
    "check_hfield_resolution",
    "check_hfield_size",
    "grid_keeps_samples",
    "hfield_of",
    "hfield_sides",
    "hfield_spacing",
    "planned_spacing",
]

MAX_HFIELD_SIDE = 8192  # samples a side of an hfield (memory; MuJoCo's collision stays local)
#: Bytes per hfield sample a rig holds at its peak: the float64 evaluation of the surface on
#: the samples (the points' x and y, the values and their join: 32; a grid's refinement the
#: same through its interpolant) and the float32 hfield kept (4). The later stages take less:
#: MjSpec's copy and the compiled model's (8), the run's model copy (4), the fall height's
#: float64 copy and its scaled one (16). Measured 33-35 B a sample at 2048 a side, analytic
#: or a refined fractal (tests/test_memory.py); a Python list of the samples for MjSpec took
#: 32 B more (``simulate --resolution 8192`` peaked at 3.9 GB).
HFIELD_BYTES_PER_SAMPLE = 36


def check_hfield_resolution(resolution) -> int | None:
    """A user's hfield resolution: None (the rule's) or a whole count of samples a side in
    [4, MAX_HFIELD_SIDE], else SpineInputError naming ``hfield_resolution``."""
    if resolution is None:
        return None
    return check_count("hfield_resolution (samples a side)", resolution, least=4, most=MAX_HFIELD_SIDE)


def check_hfield_refinement(refinement) -> int:
    """A user's hfield refinement: a whole factor in [1, MAX_HFIELD_SIDE] (the hfield at that
    many times its samples a side), else SpineInputError naming ``hfield_refinement``."""
    return check_count("hfield_refinement (a factor on the samples a side)", refinement, most=MAX_HFIELD_SIDE)


def check_hfield_size(nrow: int, ncol: int, refinement: int = 1) -> None:
    """Refuse an hfield of ``nrow x ncol`` samples past MAX_HFIELD_SIDE a side (naming the
    refinement that made it) or past the memory budget (HFIELD_BYTES_PER_SAMPLE a sample),
    before it is sampled."""
    side = max(nrow, ncol)
    if refinement != 1 and side > MAX_HFIELD_SIDE:
        raise SpineInputError(
            f"hfield_refinement {refinement} gives {side} samples a side, more than {MAX_HFIELD_SIDE}"
        )
    check_memory(HFIELD_BYTES_PER_SAMPLE * float(nrow) * ncol, where=f"an hfield of {nrow} x {ncol} samples")


def hfield_sides(surface: Surface, resolution: int | None, refinement) -> tuple[int, int]:
    """``(nrow, ncol)`` of :func:`hfield_of`'s hfield, before it is made."""
    if resolution or not isinstance(surface, GridSurface):
        ny = nx = resolution or DEFAULT_HFIELD_SIDE
    else:
        ny, nx = surface.shape
    f = int(refinement)
    return (ny - 1) * f + 1, (nx - 1) * f + 1


def grid_keeps_samples(surface: Surface, resolution: int | None) -> int | None:
    """The hfield resolution a rig of ``surface`` asks for: ``resolution`` for an analytic
    surface, None for a gridded one (fractal, sandpaper, measured scan, a saved grid), which
    keeps its own samples as the hfield. MuJoCo then collides with the heights the
    streamline reads, and a resampling cannot leave facets coarser than a small tip (a
    sandpaper resampled to an analytic surface's 151 a side left 33 um facets under a 25 um
    tip). The rig still coarsens a grid finer than a quarter tip radius
    (:meth:`Scales.with_hfield`). The one home of this rule: the rig, the sweep's configs and
    the validation's measurements all ask here."""
    return None if isinstance(surface, GridSurface) else resolution


def hfield_of(surface: Surface, resolution: int | None = None, refinement: int = 1) -> HField:
    """The surface as MuJoCo hfield data, resampled to ``resolution`` a side when given,
    then refined ``refinement`` times.

    Parameters
    ----------
    surface : Surface
        Any surface.
    resolution : int, optional
        Samples a side (None: a grid surface's own, 201 for an analytic one).
    refinement : int
        That hfield's ``n`` samples a side become ``(n - 1) refinement + 1``, every one
        kept: an analytic surface sampled that densely over the same bounds, a grid
        refined through the interpolant of the samples the first hfield has
        (:func:`spine_mj.surfaces.refine_grid`): its own, or those it was resampled to (a
        grid coarsened to a quarter tip radius). Only the facets change, never the surface:
        refinement is solution verification of the surface the rig collides with.

    Returns
    -------
    HField
    """
    ny, nx = hfield_sides(surface, resolution, refinement)
    f = int(refinement)
    check_hfield_size(ny, nx, f)
    hf = to_hfield(surface, nrow=resolution, ncol=resolution) if resolution else to_hfield(surface)
    if refinement == 1:
        return hf
    if resolution and isinstance(surface, GridSurface):
        # through the resampled grid's interpolant, not its own: resampling its own finer
        # draws features the first hfield never had (sandpaper-P600, 2.56 um samples
        # coarsened to 6.25 um: x 4 moved its heights by 1.2 um RMS, 18 % of its RMS
        # height), a new surface at each level instead of finer facets of one
        surface = surface.sample(hf.ncol, hf.nrow)
    return to_hfield(surface, nrow=(hf.nrow - 1) * f + 1, ncol=(hf.ncol - 1) * f + 1)


def hfield_spacing(hfield: HField, length_scale_m: float = 1.0) -> float:
    """The larger of an hfield's two sample spacings, in metres.

    Parameters
    ----------
    hfield : HField
        MuJoCo height field data.
    length_scale_m : float
        Metres per surface unit.

    Returns
    -------
    float
    """
    return _spacing(hfield.size[0], hfield.size[1], hfield.nrow, hfield.ncol, length_scale_m)


def planned_spacing(surface: Surface, resolution: int | None, refinement: int, length_scale_m: float):
    """:func:`hfield_spacing` [m] of :func:`hfield_of`'s hfield, before it is made (no sampling)."""
    nrow, ncol = hfield_sides(surface, resolution, refinement)
    given = resolution is not None or refinement != 1
    rx, ry = hfield_half_extents(surface, nrow=nrow if given else None, ncol=ncol if given else None)
    return _spacing(rx, ry, nrow, ncol, length_scale_m)


def _spacing(rx: float, ry: float, nrow: int, ncol: int, length_scale_m: float) -> float:
    return length_scale_m * 2 * max(rx / (ncol - 1), ry / (nrow - 1))

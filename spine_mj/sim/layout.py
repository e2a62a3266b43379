"""Where the spines of an array sit: grid, staggered grid or random pattern at one footprint.

A :class:`Layout` gives the spines' offsets from the array's centre in surface units. The
drive pulls in +x; ``cols`` spines stand along the drive and ``rows`` across it. All three
kinds share one footprint, ``cols`` by ``rows`` cells of ``spacing``: the grid puts one
spine at each cell's centre, the staggered grid shifts every other row by half a spacing
along the drive (so that neighbouring rows meet the surface's features at other phases),
and the random pattern draws ``rows * cols`` points uniformly in the footprint, no two
closer than :data:`MIN_GAP_TIP_DIAMETERS` tip diameters. Nothing here needs MuJoCo.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from spine_mj.errors import SpineInputError, check_positive

#: Most spines in one array (the rig is tested up to this size).
MAX_SPINES = 256
#: Closest two spines of a random pattern may stand, in tip diameters (tips never collide
#: in the model, but two tips in one place would be one spine counted twice).
MIN_GAP_TIP_DIAMETERS = 1.0
_RANDOM_TRIES = 200


class LayoutKind(enum.Enum):
    """How the spines are laid out in the footprint."""

    GRID = "grid"
    STAGGERED = "staggered"
    RANDOM = "random"


class SpacingUnit(enum.Enum):
    """What ``spacing`` is measured in: surface units, or multiples of the surface's
    slope correlation length ``l_s`` or characteristic length ``L_c``."""

    SURFACE = "surface"
    L_S = "l_s"
    L_C = "L_c"


@dataclass(frozen=True)
class Layout:
    """An array's layout (validated on construction).

    Attributes
    ----------
    kind : LayoutKind or str
        ``grid``, ``staggered`` or ``random``.
    rows, cols : int
        Spines across and along the drive (``rows * cols`` spines, at most :data:`MAX_SPINES`).
    spacing : float
        Distance between neighbouring spines, > 0, in ``spacing_unit``.
    spacing_unit : SpacingUnit or str
        ``surface`` (surface units), ``l_s`` or ``L_c``.
    seed : int
        Seed of the random pattern, >= 0 (ignored by the grids).
    """

    kind: LayoutKind | str = LayoutKind.GRID
    rows: int = 1
    cols: int = 1
    spacing: float = 1.0
    spacing_unit: SpacingUnit | str = SpacingUnit.L_C
    seed: int = 0

    def __post_init__(self):
        for name, cls in (("kind", LayoutKind), ("spacing_unit", SpacingUnit)):
            value = getattr(self, name)
            if not isinstance(value, cls):
                try:
                    value = cls(str(value))
                except ValueError:
                    raise SpineInputError(
                        f"layout {name} must be one of {[e.value for e in cls]}, got {value!r}"
                    ) from None
                object.__setattr__(self, name, value)
        for name in ("rows", "cols"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise SpineInputError(f"layout {name} must be an integer >= 1, got {v!r}")
            object.__setattr__(self, name, int(v))
        if self.n_spines > MAX_SPINES:
            raise SpineInputError(
                f"an array has at most {MAX_SPINES} spines, got rows x cols = {self.rows} x {self.cols} "
                f"= {self.n_spines}"
            )
        object.__setattr__(self, "spacing", check_positive("spacing", self.spacing))
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise SpineInputError(f"layout seed must be an integer >= 0, got {self.seed!r}")

    @property
    def n_spines(self) -> int:
        return self.rows * self.cols

    def spacing_in_surface_units(self, *, l_s: float, l_c: float) -> float:
        """``spacing`` in surface units, given the surface's ``l_s`` and ``L_c`` (surface units)."""
        factor = {SpacingUnit.SURFACE: 1.0, SpacingUnit.L_S: l_s, SpacingUnit.L_C: l_c}[self.spacing_unit]
        return self.spacing * factor

    def offsets(self, spacing: float, *, tip_radius: float = 0.0) -> np.ndarray:
        """The spines' offsets ``(N, 2)`` from the array's centre (the footprint's centre),
        in the units of ``spacing`` (surface units); ``tip_radius`` in the same units
        bounds how close two random spines may stand. Rows of the result run along x
        first (spine ``i`` is in row ``i // cols``, column ``i % cols``)."""
        s = check_positive("spacing", spacing)
        r, c = np.divmod(np.arange(self.n_spines), self.cols)
        if self.kind is LayoutKind.RANDOM:
            return self._random(s, 2 * MIN_GAP_TIP_DIAMETERS * tip_radius)
        x = (c - (self.cols - 1) / 2) * s
        if self.kind is LayoutKind.STAGGERED:
            x = x + np.where(r % 2 == 1, 0.5 * s, 0.0) - (0.25 * s if self.rows > 1 else 0.0)
        y = (r - (self.rows - 1) / 2) * s
        return np.column_stack([x, y]).astype(float)

    def footprint(self, spacing: float) -> tuple[float, float]:
        """The footprint's length along x and width along y (``cols`` and ``rows`` cells)."""
        return self.cols * spacing, self.rows * spacing

    def _random(self, s: float, gap: float) -> np.ndarray:
        rng = np.random.default_rng(self.seed)
        lx, ly = self.footprint(s)
        n = self.n_spines
        if gap > 0 and n > 1 and n * math.pi * (gap / 2) ** 2 > 0.5 * lx * ly:
            raise SpineInputError(
                f"spacing {s:g} is too small for {n} random spines {gap:g} apart: raise the spacing"
            )
        pts = np.empty((0, 2))
        for _ in range(_RANDOM_TRIES):
            cand = (rng.random((n, 2)) - 0.5) * [lx, ly]
            for p in cand:
                if len(pts) == n:
                    break
                if len(pts) == 0 or np.min(np.hypot(*(pts - p).T)) >= gap:
                    pts = np.vstack([pts, p])
            if len(pts) == n:
                return pts
        raise SpineInputError(f"could not place {n} random spines {gap:g} apart at spacing {s:g}")

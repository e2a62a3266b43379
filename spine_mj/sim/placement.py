"""Placing the tip at rest on the hfield: a safeguarded Newton search on MuJoCo's own distance.

A start is placed once per model and kept (the search is deterministic), so a batch or a
sweep pays for each start once.
"""

from __future__ import annotations

import copy

import numpy as np

from spine_mj.errors import SpineInputError
from spine_mj.surfaces import HField, Surface

PLACE_CACHE_SIZE = 4096  # placements kept per rig (by start)
#: MuJoCo keeps at most this many contacts of one geom pair (``mjMAXCONPAIR``): a probe that
#: finds as many may have lost its deepest one.
MAX_PAIR_CONTACTS = 50
_MARGIN_RADII = 0.2  # the probe's contact margin [tip radii]: a gap reads as a positive distance


class Placer:
    """Places the tip on one compiled model; build a new one when the model changes.

    Parameters
    ----------
    model : mujoco.MjModel
        The rig's model (copied; the copy gets a contact margin on the tip).
    geom_tip : int
        The tip geom's id.
    surface, hfield : Surface, HField
        The surface (its heights bracket the search) and its hfield.
    length_scale, tip_radius : float
        Engine lengths per surface unit; the tip radius (engine units).
    rest_depth : float
        Depth of the soft contact at rest (engine units), subtracted from the touching height.
    """

    def __init__(
        self,
        model,
        *,
        geom_tip: int,
        surface: Surface,
        hfield: HField,
        length_scale: float,
        tip_radius: float,
        rest_depth: float,
    ):
        import mujoco

        self.model = model
        pm = copy.copy(model)
        self._m, self._d, self._tip = pm, mujoco.MjData(pm), geom_tip
        self._surface, self._hfield = surface, hfield
        self._s, self._r = length_scale, tip_radius
        self._rest_depth = rest_depth
        self._placed: dict[tuple[float, float], np.ndarray] = {}

    def place(self, x0: float, y0: float) -> np.ndarray:
        """qpos ``(3,)`` (engine units) with the tip resting on the hfield at ``(x0, y0)`` (surface units)."""
        return self.place_many([(x0, y0)])[0]

    def place_many(self, points) -> np.ndarray:
        """qpos ``(k, 3)`` of :meth:`place` for ``k`` points; the surface heights that start
        the searches are evaluated in one call."""
        placed, s = self._placed, self._s
        got = {p: placed[p] for p in points if p in placed}  # the search is deterministic: reuse
        new = [p for p in dict.fromkeys(points) if p not in got]
        if new:
            lo = self._surface.height(np.array([p[0] for p in new]), np.array([p[1] for p in new]))
            for (x0, y0), z_lo in zip(new, np.atleast_1d(lo)):
                z = self._touching_z(x0, y0, float(z_lo) * s) - self._rest_depth
                got[(x0, y0)] = np.array([x0 * s, y0 * s, z])
                if len(placed) >= PLACE_CACHE_SIZE:
                    placed.pop(next(iter(placed)))
                placed[(x0, y0)] = got[(x0, y0)]
        return np.array([got[p] for p in points])

    def _probe(self, x0: float, y0: float, z: float) -> tuple[float | None, float]:
        """Signed distance of the deepest contact at height ``z`` (None: none) and |n_z|.

        The tip gets a contact margin of :data:`_MARGIN_RADII` tip radii (a gap above the
        surface reads as a positive distance), cut by 4 each time the probe fills MuJoCo's
        :data:`MAX_PAIR_CONTACTS` (on an hfield much finer than the tip, more facets lie
        within the margin than MuJoCo keeps, and the one it drops may be the deepest: the
        tip would then be placed sunk into the surface), down to none.
        """
        import mujoco

        m, d, s = self._m, self._d, self._s
        d.qpos[:] = (x0 * s, y0 * s, z)
        margin = _MARGIN_RADII * self._r
        while True:
            m.geom_margin[self._tip] = margin
            mujoco.mj_kinematics(m, d)  # positions and contacts only: no dynamics needed
            mujoco.mj_collision(m, d)
            n = d.ncon
            if n < MAX_PAIR_CONTACTS or margin == 0:
                break
            margin = margin / 4 if margin > 1e-6 * self._r else 0.0
        if not n:
            return None, 1.0
        contacts = d.contact
        dist = contacts.dist
        k = int(dist[:n].argmin())
        return float(dist[k]), abs(float(contacts.frame[k, 2]))

    def _touching_z(self, x0: float, y0: float, lo: float) -> float:
        """Height (engine units) of the sphere centre touching the hfield (distance within 1e-7
        radii), searched from ``lo``, the surface's height there (engine units)."""
        s, r = self._s, self._r
        _, _, elev, _ = self._hfield.size
        # 2 r above the hfield's top the sphere (contact margin 0.2 r) touches nothing
        hi = (self._hfield.pos[2] + elev) * s + 2 * r
        z = lo + r
        # Newton on the engine's distance, safeguarded by [lo, hi]: the sphere centred at the
        # surface's height cuts the hfield; where it would not, the search fails to converge
        for _ in range(100):
            g, nz = self._probe(x0, y0, z)
            if g is None:
                hi, z = z, 0.5 * (z + lo)
                continue
            if abs(g) < 1e-7 * r:
                break
            if g > 0:
                hi = z
            else:
                lo = z
            z_new = z - g / max(nz, 0.05)
            z = z_new if lo < z_new < hi else 0.5 * (lo + hi)
        else:
            raise SpineInputError(f"could not place the tip on the surface at ({x0:g}, {y0:g})")
        return z - g

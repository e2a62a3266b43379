"""Rigs and constants shared by the tests of :mod:`spine_mj.sim` (not a test module)."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from spine_mj.sim import Rig, TipParams
from spine_mj.surfaces import GridSurface, inclined_plane

MU = 0.5
PHI = math.atan(MU)
R_TIP = 5e-4
START = (3.1e-4, 2.7e-4)


def plane_rig(slope_deg, **tip):
    return Rig(inclined_plane(slope_deg=slope_deg), tip=TipParams(tip_radius_m=R_TIP, mu_s=MU, **tip))


def asymmetric_surface(n=121):
    """Tilted plane plus an off-centre bump, dimensionless, on -3..3."""
    x = np.linspace(-3, 3, n)
    xx, yy = np.meshgrid(x, x)
    h = 0.25 * xx - 0.1 * yy + 0.8 * np.exp(-((xx - 1.2) ** 2 + (yy + 0.7) ** 2) / (2 * 0.6**2))
    return GridSurface(heights=h, x=x, y=x.copy(), unit="1")


def deepest_contacts(rig, q):
    """Contact points [m] and normals of the tip at qpos ``q`` (engine units)."""
    d = mujoco.MjData(rig.model)
    d.qpos[:] = q
    mujoco.mj_forward(rig.model, d)
    out = []
    for c in d.contact[: d.ncon]:
        n = c.frame[:3] * (1 if c.frame[2] > 0 else -1)
        out.append(((c.pos - 0.5 * c.dist * n) * rig.units.length_m, n))
    return out


def flat_rig():
    return Rig(
        inclined_plane(slope_deg=0.0, half_width=0.05, n=101), tip=TipParams(tip_radius_m=R_TIP, mu_s=MU)
    )

"""
A MuJoCo run against its streamline
===================================

The same start, twice: the quasistatic streamline (paper Eq. 4) and a MuJoCo run of a
spherical tip pulled through a spring at a small inertia number. Like for like, the
streamline is traced on the surface the tip's centre rides on (the surface dilated by the
tip radius, :func:`spine_mj.dilate`), and the two paths are compared by their Frechet
distance in units of L_c.
"""

import matplotlib.pyplot as plt
import numpy as np

import spine_mj as sm
from spine_mj import sim

surface = sm.make_surface("paper-single-valley")
rig = sim.build_rig(surface, mu=1.23)
unit = rig.scales.length_scale_m  # metres per surface unit
start = (-3.0, -1.0)
run = rig.run(sim.build_drive(rig.scales, "spring", ie=1e-3), start=start)

tip = rig.scales.tip_radius_m / unit
ref = sm.streamlines(sm.dilate(surface, tip), [start], sm.StreamlineParams(mu=1.23))
mj = np.asarray(run.position_m)[:, :2] / unit
sl = np.column_stack([ref.x, ref.y])
lc = rig.scales.char_length_m / unit
print(f"MuJoCo ended: {run.end_reason.name}; streamline: {sm.Outcome(ref.outcome[0]).name}")
print(f"Frechet distance: {sm.frechet_distance(mj, sl, length_scale=lc):.4f} L_c")

# %%
x0, x1, y0, y1 = surface.bounds
x, y = np.meshgrid(np.linspace(x0, x1, 200), np.linspace(y0, y1, 200))
fig, ax = plt.subplots(figsize=(5.5, 5), constrained_layout=True)
ax.contourf(x, y, surface.height(x, y), levels=20, cmap="terrain")
ax.plot(sl[:, 0], sl[:, 1], "c-", lw=3, label="streamline (dilated surface)")
ax.plot(mj[:, 0], mj[:, 1], "k--", lw=1.5, label=f"MuJoCo, I_e = 1e-3 ({run.end_reason.name})")
ax.plot(*start, "ko")
ax.set_aspect("equal")
ax.set_xlabel("x (drive)")
ax.set_ylabel("y")
ax.legend(loc="lower left")

"""
Streamlines on a peak and a valley
==================================

A streamline (paper Eq. 4) is the quasistatic path of a spine tip pulled in +x by the
largest force that still holds it: at each point it moves along the tangential load and
ends where it self-locks or leaves the domain. On a convex **peak** the tips are deflected
around it (the *bypass* effect); in a concave **valley** they are funnelled into the
bottom and lock there (the *trap* effect): the paper's Figs. 3-4.
"""

import matplotlib.pyplot as plt
import numpy as np

import spine_mj as sm

starts = np.column_stack([np.full(9, -4.0), np.linspace(-3.0, 3.0, 9)])
params = sm.StreamlineParams(mu=1.23)

fig, axes = plt.subplots(1, 2, figsize=(9, 4.2), constrained_layout=True)
for ax, name in zip(axes, ("paper-single-peak", "paper-single-valley")):
    surface = sm.make_surface(name)
    res = sm.streamlines(surface, starts, params)
    x0, x1, y0, y1 = surface.bounds
    x, y = np.meshgrid(np.linspace(x0, x1, 200), np.linspace(y0, y1, 200))
    ax.contourf(x, y, surface.height(x, y), levels=20, cmap="terrain")
    for i in range(len(starts)):
        s = slice(res.offsets[i], res.offsets[i + 1])
        locked = res.outcome[i] == sm.Outcome.SELF_LOCKED
        ax.plot(res.x[s], res.y[s], color="tab:red" if locked else "k", lw=1.2)
        if locked:
            ax.plot(res.end_x[i], res.end_y[i], "o", color="tab:red", ms=5)
    n_locked = int(np.sum(res.outcome == sm.Outcome.SELF_LOCKED))
    ax.set_title(f"{name}: {n_locked} of {len(starts)} self-lock")
    ax.set_aspect("equal")
    ax.set_xlabel("x (drive)")
axes[0].set_ylabel("y")

# %%
# The outcome of each start, by name (:class:`spine_mj.Outcome`):
print([sm.Outcome(o).name for o in res.outcome])

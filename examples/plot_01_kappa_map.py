"""
A surface and its kappa map
===========================

The engagement ratio ``kappa = F / W`` (paper Eqs. 1-3) is the drive force, per unit
preload, at which a spine resting at a point lets go. It depends only on the local slopes
and the friction coefficient: where the surface rises steeply enough in the drive
direction the tip **self-locks** (no force breaks the hold), where it falls steeper than
the friction angle it **slips** under its own weight.

Here: the paper's single Gaussian peak (Fig. 3) and its kappa map at mu_s = 1.2 (Fig. 2B).
"""

import matplotlib.pyplot as plt
import numpy as np

import spine_mj as sm

surface = sm.make_surface("paper-single-peak")
x0, x1, y0, y1 = surface.bounds
x, y = np.meshgrid(np.linspace(x0, x1, 301), np.linspace(y0, y1, 301))
fx, fy = surface.gradient(x, y)
kappa, region = sm.kappa(fx, fy, mu=1.2)

# %%
# Height, then kappa with the self-lock (red) and slip (grey) regions. Self-lock needs a
# slope rising in the drive direction steeper than 1 / mu_s; slip a fall steeper than
# mu_s. The peak's steepest slope is 0.90: at mu_s = 1.2 a small patch of its near flank
# self-locks and nothing slips, and kappa climbs toward the patch.
fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(9, 3.8), constrained_layout=True)
im = ax0.pcolormesh(x, y, surface.height(x, y), cmap="terrain", shading="auto")
fig.colorbar(im, ax=ax0, label="height")
ax0.set_title("paper-single-peak")
shown = np.where(region == sm.ENGAGED, kappa, np.nan)
im = ax1.pcolormesh(x, y, shown, cmap="viridis", vmin=0, vmax=5, shading="auto")
ax1.contourf(x, y, region == sm.SELF_LOCK, levels=[0.5, 1], colors=["tab:red"])
ax1.contourf(x, y, region == sm.SLIP, levels=[0.5, 1], colors=["0.6"])
fig.colorbar(im, ax=ax1, label="kappa = F / W (engaged)")
ax1.set_title("kappa at mu_s = 1.2: red self-lock, grey slip")
for ax in (ax0, ax1):
    ax.set_aspect("equal")
    ax.set_xlabel("x (drive direction)")
ax0.set_ylabel("y")

# %%
# Shares of the three regions over the domain:
for name, code in (("slip", sm.SLIP), ("engaged", sm.ENGAGED), ("self-lock", sm.SELF_LOCK)):
    print(f"{name:9s} {np.mean(region == code):.3f}")

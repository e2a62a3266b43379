"""
A spine array's load sharing
============================

Grippers carry many spines on one carriage. Here four spines in a row along the drive, on
one of the paper's random Gaussian surfaces, each on its own spring to one carriage moving at constant
speed (:class:`spine_mj.sim.ArrayRig`): the array's force is the sum of its spines', and
where one spine slips off an asperity the others carry on. The spines peak at different
places, so the array holds less than N times one spine's peak.
"""

import matplotlib.pyplot as plt
import numpy as np

import spine_mj as sm
from spine_mj import sim

surface = sm.make_surface("paper-random-convex", seed=1)
rig = sim.build_rig(surface, mu=1.23)
layout = sim.Layout(kind="grid", rows=1, cols=4, spacing=2.0, spacing_unit="l_s")
array = sim.ArrayRig(rig, layout)
drive = sim.build_drive(rig.scales, "spring", ie=1e-3, duration_s=0.5)
x0, x1, y0, y1 = surface.bounds
(result,) = array.run_batch(drive, [(x0 + 0.4 * (x1 - x0), 0.5 * (y0 + y1))])

fp = rig.scales.preload_n
lc = rig.scales.char_length_m
carriage = result.carriage_x_m / lc
fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
for i in range(result.n_spines):
    ax.plot(carriage, result.spine_force_n[:, i] / fp, lw=1, label=f"spine {i + 1}")
ax.plot(carriage, result.total_force_n / fp, "k", lw=2, label="array (sum)")
ax.set_xlabel("carriage displacement / L_c")
ax.set_ylabel("force / F_p")
ax.legend(ncol=3, fontsize="small")
ax.set_title(f"{result.n_spines} spines, end: {result.end_reason}")

# %%
# The array's holding force against the sum of its spines' own peaks:
print(f"holding force / (N F_p): {result.holding_ratio:.2f}")
print(f"sum of the spines' peaks / (N F_p): {np.sum(result.max_force_n) / (result.n_spines * fp):.2f}")
print(f"self-locked spines: {result.locked_spines} of {result.n_spines}")

"""
From a measured scan to a verdict
=================================

Will a spine hold on this surface? A measured topography is read (any format
SurfaceTopography reads; here the two AFM and profilometer scans that ship with the
package as ``example:di-1.di`` and ``example:plu-1.plu``), levelled, and the quasistatic
streamline is traced from many random starts. The verdict is the share of starts that
self-lock, with its 95 % Wilson interval, at each friction coefficient: an estimate from
a finite sample of starts, never a yes or no from one path.
"""

import matplotlib.pyplot as plt
import numpy as np

import spine_mj as sm
from spine_mj import examples, roughness
from spine_mj.validate.intervals import wilson

rng = np.random.default_rng(1)
mus = [0.5, 0.75, 1.0, 1.25, 1.5]
fig, axes = plt.subplots(1, 2, figsize=(9, 3.8), constrained_layout=True)
for name in ("example:di-1.di", "example:plu-1.plu"):
    scan = sm.import_topography(examples.resolve(name), fill="harmonic")
    x0, x1, y0, y1 = scan.bounds
    starts = np.column_stack([rng.uniform(x0, x1, 200), rng.uniform(y0, y1, 200)])
    rates, lows, highs = [], [], []
    for mu in mus:
        res = sm.streamlines(scan, starts, sm.StreamlineParams(mu=mu), store_paths=False)
        locked = int(np.sum(res.outcome == sm.Outcome.SELF_LOCKED))
        lo, hi = wilson(locked, len(starts))
        rates.append(locked / len(starts))
        lows.append(lo)
        highs.append(hi)
    r = np.array(rates)
    axes[1].errorbar(mus, r, yerr=[r - lows, np.array(highs) - r], marker="o", capsize=3, label=name)
    print(
        f"{name}: L_c = {roughness.characteristic_length(scan):.3g} {scan.unit}, "
        f"self-lock share at mu_s = 1.0: {rates[2]:.3f} [{lows[2]:.3f}, {highs[2]:.3f}]"
    )
    if name.endswith(".di"):
        x = np.asarray(scan.x)
        y = np.asarray(scan.y)
        im = axes[0].pcolormesh(x, y, scan.heights, cmap="copper", shading="auto")
        fig.colorbar(im, ax=axes[0], label=f"height [{scan.unit}]")
        axes[0].set_title(f"{name} (AFM, levelled)")
        axes[0].set_aspect("equal")
axes[1].set_xlabel("mu_s")
axes[1].set_ylabel("share of starts that self-lock")
axes[1].set_title("verdict with its 95 % Wilson interval")
axes[1].legend()

# %%
# The profilometer scan is smooth (rms slope far below 1 / mu_s): no start locks at any
# mu_s, and the interval bounds how rare a lock can be. The AFM scan's steep steps between
# scan lines lock some starts from mu_s = 1 on.

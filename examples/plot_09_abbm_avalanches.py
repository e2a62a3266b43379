"""
Avalanches on an ABBM track: the overdamped and inertial references
===================================================================

A track whose slope along x is a random walk makes the landscape force
``W tan(theta + arctan mu)`` a random walk too: the ABBM model, whose overdamped slips
follow ``P(S) ~ S^-3/2 exp(-S / (4 S_m))`` with ``S_m = sigma / k^2`` (the physics notes,
§12). The overdamped reference (each slip stops at the first stable point) against the
inertial one (a tip with mass stops where its kinetic energy is spent), at three spring
stiffnesses: the sizes collapse onto one curve once scaled by ``S_m``, with the fitted
exponent ``tau`` and its 95 % interval.
"""

import matplotlib.pyplot as plt
import numpy as np

from spine_mj.surfaces import abbm_force_intensity, abbm_slope_walk
from spine_mj.theory.avalanches import Landscape, abbm_cutoff, inertial_slips, overdamped_slips
from spine_mj.validate.avalanche_stats import collapse, cutoff_size, truncated_fit_by_ks

mu, dx, d, xi, n = 0.5, 0.02, 1e-6, 1e4, 1_000_000
slope = abbm_slope_walk(n, dx, d, xi, np.random.default_rng(0))
x = dx * np.arange(n)
land = Landscape.from_profile(x, slope, np.cumsum(slope) * dx, mu)
sigma = abbm_force_intensity(d, mu)

fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.6), constrained_layout=True)
series = {}
for k in (2e-4, 6e-4, 2e-3):
    sizes = overdamped_slips(land, k).size
    inert = inertial_slips(land, k).size
    series[k] = sizes
    fit = truncated_fit_by_ks(sizes)
    cut = cutoff_size(sizes)
    print(
        f"k {k:g}: {sizes.size} slips, tau {fit['tau']:.3f} [{fit['low']:.3f}, {fit['high']:.3f}], "
        f"S_m {cut['value']:.3g} (sigma / k^2 = {abbm_cutoff(sigma, k):.3g}); inertial mean size "
        f"{inert.mean():.3g} against {sizes.mean():.3g}"
    )
    for s, style in ((np.sort(sizes), "-"), (np.sort(inert), ":")):
        left.loglog(s, 1 - np.arange(s.size) / s.size, style, label=f"k {k:g}" if style == "-" else None)
left.set_xlabel("slip size S")
left.set_ylabel("P(size >= S)  (dotted: inertial)")
left.legend()
for k, (xs, ys) in collapse(series, 1.5).items():
    right.loglog(xs, ys, "o-", ms=3, label=f"k {k:g}")
right.set_xlabel("S / S_m")
right.set_ylabel("S^3/2 P(S)")
right.set_title("overdamped: one curve")
right.legend()
plt.show()

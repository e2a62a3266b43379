"""
The (I_e, K) map read from a sweep
==================================

Where does MuJoCo stop following the quasistatic streamline? The validation's stiffness
map ran 30 starts at every point of a grid of inertia numbers ``I_e`` and spring stiffness
numbers ``K = k l_s / F_p`` on three families of surfaces, and recorded the share of runs
whose outcome agrees with the streamline's. This script reads the committed
``validation.json`` of the full plan (no run: the map took minutes of sweeps) and draws the
map, with the boundary ``I_e*(K)`` where the targets stop being met and the boundary
predicted from the geometry alone (:mod:`spine_mj.theory.drive_limits`). Each family has its own K
axis, set around its predicted K_path with its fold K* and 10 K*.

Run from the repository's ``examples/`` folder, or point ``path`` at any
``validation.json`` that ``spine-mj validate`` wrote.
"""

import json
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

path = next(
    p / "analysis" / "reports" / "validation-full" / "validation.json"
    for p in (Path.cwd(), *Path.cwd().parents)
    if (p / "analysis" / "reports" / "validation-full" / "validation.json").is_file()
)
smap = json.loads(path.read_text())["stiffness_map"]
ie = np.array(smap["ie"])  # every I_e of the map (the deep ones ran at the stiffest K only)

fig, axes = plt.subplots(1, len(smap["families"]), figsize=(11, 3.6), constrained_layout=True)
for ax, family in zip(axes, smap["families"]):
    by_k = smap["agreement"][family]
    ks = smap["k_by_family"].get(family) or smap["K"]  # each family's own K axis
    grid = np.full((len(ks), len(ie)), np.nan)  # (K, I_e); blank where a K did not run
    for i, k in enumerate(ks):
        cell = by_k[f"{k:g}"]
        for v, a in zip(cell["ie"], cell["agreement"]):
            grid[i, np.searchsorted(ie, v)] = a
        star = cell["ie_star"]
        if star.get("value"):
            pos = np.interp(np.log10(star["value"]), np.log10(ie), np.arange(len(ie))) + 0.5
            ax.plot(pos, i + 0.5, "kv", ms=8)
    im = ax.pcolormesh(np.arange(len(ie) + 1), np.arange(len(ks) + 1), grid, vmin=0, vmax=1, cmap="RdYlGn")
    pred = smap.get("predicted", {}).get(family, {})
    title = family.replace("_", " ")
    if pred:
        title += f"\npredicted K_path = {pred.get('k_path', np.nan):.2g}, fold K* = {pred['k_star']:.3g}"
    ax.set_title(title, fontsize="small")
    ax.set_xticks(np.arange(len(ie)) + 0.5, [f"{v:g}" for v in ie], rotation=45)
    ax.set_yticks(np.arange(len(ks)) + 0.5, [f"{k:g}" for k in ks])
    ax.set_xlabel("I_e")
axes[0].set_ylabel("K = k l_s / F_p")
fig.colorbar(im, ax=axes, label="outcome agreement (30 starts a point)")

# %%
# Triangles mark the measured ``I_e*`` at each K (agreement >= 95 % and median Frechet
# <= 0.1 L_c below it); a row without one meets the targets nowhere on the grid.
for family in smap["families"]:
    ks = smap["k_by_family"].get(family) or smap["K"]
    stars = {k: smap["agreement"][family][f"{k:g}"]["ie_star"] for k in ks}
    print(
        family, {f"K={k:g}": f"{s['value']:.3g}" if s.get("value") else s["kind"] for k, s in stars.items()}
    )

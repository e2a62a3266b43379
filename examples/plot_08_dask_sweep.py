"""
A sweep on a Dask cluster
=========================

A sweep is a TOML config (surfaces, starts, drive, a grid of parameters, the analyses per
case) expanded into cases, each run once into a resumable store
(:func:`spine_mj.sweep.run_sweep`). On a cluster the cases run on a Dask scheduler's
workers and come back to this process, which writes the store. Here a
``distributed.LocalCluster`` (two workers in this process) stands in for a real one (on
SLURM, ``dask_jobqueue``'s ``SLURMCluster`` gives the scheduler address the same way);
the numbers do not depend on where a case ran, because each case's seed comes from the
master seed and its own id.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
from distributed import LocalCluster

from spine_mj import sweep

config = sweep.parse_config(
    {
        "sweep": {"name": "fractal-lock", "seed": 7, "analyses": ["quasistatic"]},
        "surfaces": [{"preset": "paper-fractal", "seeds": [1, 2, 3]}],
        "starts": {"frame": "relative", "x": [0.02], "y": {"linspace": [0.1, 0.9], "num": 20}},
        "grid": {"mu": [0.6, 0.8, 1.0, 1.25, 1.5]},
    }
)
out = Path(tempfile.mkdtemp()) / "fractal-lock"
with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
    summary = sweep.run_sweep(config, out, scheduler=cluster.scheduler_address)
print(summary)

# %%
# The store's table, one row per run: the self-lock share per mu_s and surface.
runs = sweep.load_runs(out)
share = runs.groupby(["mu", "surface_seed"])["self_locked"].mean().unstack()
print(share)
fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
for seed in share.columns:
    ax.plot(share.index, share[seed], "o-", label=f"fractal seed {seed:g}")
ax.set_xlabel("mu_s")
ax.set_ylabel("share of starts that self-lock")
ax.legend()

# %%
# Running the same call again skips every finished case: a killed sweep resumes.
print(sweep.run_sweep(config, out, workers=1))

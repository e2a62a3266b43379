"""Headless batch sweeps: a TOML config, cases, a resumable result store, local or Dask workers.

A sweep config names surfaces (presets or files, with seeds), start points, a parameter
grid and the analyses to run on every case::

    [sweep]
    name = "quasistatic-mu"
    seed = 0                          # master seed; each case derives its own
    analyses = ["quasistatic"]        # any of: quasistatic, engine, compare, array

    [[surfaces]]
    preset = "paper-random-convex"
    seeds = [1, 2, 3]                 # or seed = 1, or n_seeds = 3 (derived from the master seed)
    set = { n_peaks = 40 }            # generator overrides

    [[surfaces]]
    file = "scan.npz"                 # relative to the config file

    [starts]
    frame = "relative"                # or "absolute" (the surface's length unit)
    x = [0.05]                        # starts: product of x and y, or points = [[x, y], ...],
    y = { linspace = [0.1, 0.9], num = 9 }   # or random = N (uniform, from the case seed)

    [grid]
    mu = [0.3, 0.5, 0.8]              # a value, a list, or { linspace | logspace = [a, b], num = n }
    tip_radius = 0.05                 # surface units (absent: the rig's default tip; 0: a point)

A *case* is one surface instance and one point of the grid, with all its starts; its id is
a hash of those parameters, and its seed is derived from the master seed and that id, so a
case gives the same numbers whatever the order or the machine it runs on. A *run* is one
start of one case under one analysis: a row of the result table.

The store in the output folder::

    manifest.json              config, its hash, input hashes, seeds, versions, git commit
    runs.parquet               one row per run (parameters, metrics, status, reason, timing)
    runs/<case_id>.parquet     the rows of one case, written atomically when the case ends
    trajectories/<case_id>.parquet   long table of the case's paths (analysis, start, step, ...)

A case counts as finished when its ``runs/`` file exists, so a sweep killed at any moment
resumes without losing or repeating a run; ``runs.parquet`` is rebuilt from those files at
the end of every sweep.

Modules, each importing only those above it: :mod:`~spine_mj.sweep.registry` (analyses and
their parameters), :mod:`~spine_mj.sweep.tables` (the schema's table base, value types
and one-line errors), :mod:`~spine_mj.sweep.digests` (config hashes, input digests),
:mod:`~spine_mj.sweep.config` (the TOML schema),
:mod:`~spine_mj.sweep.cases` (expansion, ids, seeds), :mod:`~spine_mj.sweep.case_runs` (one
case), :mod:`~spine_mj.sweep.store` (the result store and its readers),
:mod:`~spine_mj.sweep.pool` (local worker processes that die with their parent),
:mod:`~spine_mj.sweep.executors` (in-process, local processes, Dask),
:mod:`~spine_mj.sweep.session` (:func:`run_sweep`, :func:`run_sweeps`), :mod:`~spine_mj.sweep.report` (HTML),
and :mod:`~spine_mj.sweep.analyses` (the built-in analyses, registered on import).
"""

import lazy_loader as _lazy

# the built-in analyses register themselves on import; every reader of the registry (the
# config check, preflight, a case run in a worker process) relies on them being there
from spine_mj.sweep import analyses as _analyses  # noqa: F401

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)

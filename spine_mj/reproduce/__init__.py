"""Reproductions of the paper's figures: numbers (a JSON-ready dict) plus a figure.

``REPRODUCTIONS`` maps a name to a function ``f(*, quick=False, progress=None, **over)``
returning ``(numbers, figure)``. Parameters the paper leaves open (mu_s, random-field
widths and heights, fractal size and normalization) come from the ``[engagement]`` and
``[reproduce]`` tables of the ``paper-*`` presets (calibrated in
``analysis/calibration.py``); keyword overrides replace them. ``progress(done, total)`` is
called as work completes.

One module per figure family: :mod:`~spine_mj.reproduce.single_peak` (Figs. 2B, 3-4),
:mod:`~spine_mj.reproduce.random_gaussian` (Fig. 5), :mod:`~spine_mj.reproduce.fractal`
(Figs. 7E, 9); what they share in ``_common``; the reproductions by name and running one
in :mod:`~spine_mj.reproduce.registry`.
"""

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)

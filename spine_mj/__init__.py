"""spine_mj: will a spine hold on this surface, and can the simulation saying so be trusted?

The analytic side (surfaces, engagement ratio, streamlines, convexity, comparison metrics)
imports without MuJoCo; the MuJoCo rig (:mod:`spine_mj.sim`) and the sweep runner
(:mod:`spine_mj.sweep`) load on first use of their names.

Modules: :mod:`~spine_mj.surfaces`, :mod:`~spine_mj.surface_io`,
:mod:`~spine_mj.presets`, :mod:`~spine_mj.theory` (engagement, streamlines, compliant drive,
convexity, drive limits, agreement metrics), :mod:`~spine_mj.sim`,
:mod:`~spine_mj.sweep`, :mod:`~spine_mj.reproduce`, :mod:`~spine_mj.cli`.

``import spine_mj`` itself is light (no numba, pandas, SciPy or MuJoCo): every public name
and subpackage is imported from its home on first use, so the command line starts at once
and a user pays only for what they touch. The names are listed once, in the type stub
``__init__.pyi`` beside this file, which type checkers and the docs read and which
``lazy_loader.attach_stub`` turns into this module's ``__getattr__``, ``__dir__`` and
``__all__``.
"""

import lazy_loader as _lazy

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)

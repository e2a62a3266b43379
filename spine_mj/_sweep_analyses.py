"""Old home of the built-in sweep analyses, now :mod:`spine_mj.sweep.analyses`.

Kept only because :func:`spine_mj.validate._engine_default` imports ``MUJOCO_PARAMS`` from
here; delete this module once it imports ``spine_mj.sweep.MUJOCO_PARAMS`` instead.
"""

from spine_mj.sweep.analyses.mujoco import MUJOCO_PARAMS
from spine_mj.sweep.analyses.quasistatic import QUASISTATIC_PARAMS

__all__ = ["MUJOCO_PARAMS", "QUASISTATIC_PARAMS"]

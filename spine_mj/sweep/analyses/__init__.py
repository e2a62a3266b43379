"""The built-in sweep analyses: ``quasistatic``, ``engine``, ``compare`` and ``array``.

Each analysis touches the API of its module in one place (``quasistatic`` ->
:mod:`spine_mj.theory.streamline`, ``engine`` -> :mod:`spine_mj.sim`, ``compare`` ->
:mod:`spine_mj.theory.agreement`), so that a change there is a change here in one place. Importing
this package registers them, in this order (the run order: dependencies first).
"""

from spine_mj.sweep.analyses import quasistatic  # noqa: I001  (registration order is run order)
from spine_mj.sweep.analyses import engine
from spine_mj.sweep.analyses import compare
from spine_mj.sweep.analyses import array

__all__ = ["array", "compare", "engine", "quasistatic"]

"""Package data. ``spine_mj._data.models`` and ``spine_mj._data.surfaces`` are the
repository's top-level ``models/`` and ``surfaces/`` folders, mapped here by ``setup.py``
so that they ship inside the installed package; :mod:`spine_mj.resources` finds them."""

"""Sweep configs, installed as the package ``spine_mj._data.sweeps`` and named
``example:NAME`` (see spine_mj/examples.py)."""

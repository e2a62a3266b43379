"""Example measured scans (see README.md here), installed as the package
``spine_mj._data.scans`` and named ``example:NAME`` (see spine_mj/examples.py)."""

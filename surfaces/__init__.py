"""Surface presets (TOML), installed as the package ``spine_mj._data.surfaces``.

See spine_mj/resources.py.
"""

"""MJCF models, installed as the package ``spine_mj._data.models`` (see spine_mj/resources.py)."""

"""Where the files that ship with the package live: the MuJoCo rig and the surface presets.

The repository keeps them at its top level (``models/spine_rig.xml``, ``surfaces/*.toml``);
``setup.py`` maps those folders onto the packages ``spine_mj._data.models`` and
``spine_mj._data.surfaces``, so they are found through :mod:`importlib.resources` in an
editable install, a wheel, or any working directory. Nothing else in spine_mj should build
a path to these files.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["MODEL_NAME", "model_path", "presets_dir"]

MODELS_PACKAGE = "spine_mj._data.models"
SURFACES_PACKAGE = "spine_mj._data.surfaces"
MODEL_NAME = "spine_rig.xml"


def _folder(package: str) -> Path:
    # Installed packages (wheel or editable) are plain folders on disk; a zip import would
    # need importlib.resources.as_file, which nothing here supports.
    return Path(str(resources.files(package)))


def model_path(name: str = MODEL_NAME) -> Path:
    """Path of an MJCF model shipped with spine_mj (default: the spine rig)."""
    return _folder(MODELS_PACKAGE) / name


def presets_dir() -> Path:
    """Folder holding the surface presets (``*.toml``) shipped with spine_mj."""
    return _folder(SURFACES_PACKAGE)

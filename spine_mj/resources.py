"""Where the files that ship with the package live: the MuJoCo rig, the surface presets and
the README's examples (two measured scans, the sweep configs).

The repository keeps them at its top level (``models/spine_rig.xml``, ``surfaces/*.toml``);
``setup.py`` maps those folders onto the packages ``spine_mj._data.models`` and
``spine_mj._data.surfaces``, so they are found through :mod:`importlib.resources` in an
editable install, a wheel, or any working directory. Nothing else in spine_mj should build
a path to these files.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["MODEL_NAME", "examples_dirs", "model_path", "presets_dir"]

MODELS_PACKAGE = "spine_mj._data.models"
SURFACES_PACKAGE = "spine_mj._data.surfaces"
#: The README's examples: measured scans (``tests/data/``) and sweep configs (``analysis/sweeps/``).
SCANS_PACKAGE = "spine_mj._data.scans"
SWEEPS_PACKAGE = "spine_mj._data.sweeps"
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


def examples_dirs() -> dict[str, Path]:
    """The folders of the shipped examples by kind: ``"scan"`` (measured topographies, see
    their README for source and licence) and ``"sweep"`` (sweep configs)."""
    return {"scan": _folder(SCANS_PACKAGE), "sweep": _folder(SWEEPS_PACKAGE)}

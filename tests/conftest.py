"""Shared fixtures: the measured topographies shipped with the tests (tests/data)."""

import importlib.util
import sys
from pathlib import Path

import pytest

TOPOGRAPHIES = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def topography_dir() -> Path:
    """Folder with ``plu-1.plu`` and ``di-1.di`` (see tests/data/README.md)."""
    return TOPOGRAPHIES


@pytest.fixture(scope="session")
def analysis_script():
    """Load a script of ``analysis/`` by name as a module (its folder on ``sys.path``, for the
    scripts that import each other)."""
    folder = Path(__file__).resolve().parents[1] / "analysis"

    def load(name: str):
        if str(folder) not in sys.path:
            sys.path.insert(0, str(folder))
        spec = importlib.util.spec_from_file_location(name, folder / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module

    return load

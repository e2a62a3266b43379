"""Shared fixtures: the measured topographies shipped with the tests (tests/data)."""

from pathlib import Path

import pytest

TOPOGRAPHIES = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def topography_dir() -> Path:
    """Folder with ``plu-1.plu`` and ``di-1.di`` (see tests/data/README.md)."""
    return TOPOGRAPHIES

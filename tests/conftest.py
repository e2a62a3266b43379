"""Shared fixtures: paths to the measured topographies beside the repository."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
TOPOGRAPHIES = REPO.parent / "shared" / "data" / "topographies"


@pytest.fixture(scope="session")
def topography_dir() -> Path:
    if not TOPOGRAPHIES.is_dir():
        pytest.skip(f"measured topographies not found at {TOPOGRAPHIES}")
    return TOPOGRAPHIES

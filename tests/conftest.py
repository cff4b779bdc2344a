"""Shared test fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """The project's shared folder (reference data, the dissertation) beside the clone."""
    if not (SHARED / "reference-data").is_dir():
        raise FileNotFoundError(
            f"reference data not found at {SHARED / 'reference-data'}; "
            "tests expect the shared/ folder beside the repository"
        )
    return SHARED


@pytest.fixture(scope="session")
def reference_dir(shared_dir: Path) -> Path:
    """``shared/reference-data``."""
    return shared_dir / "reference-data"

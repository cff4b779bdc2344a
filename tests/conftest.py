"""Shared test fixtures."""

from __future__ import annotations

import os
from pathlib import Path

# Tests that compare solves bit for bit assume one BLAS/OpenMP thread (as .ci/run sets): set
# here, before numpy and the solvers load, so the README's test command alone is enough.
for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")
os.environ.setdefault("MPLBACKEND", "Agg")

import pytest  # noqa: E402 - after the environment above

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

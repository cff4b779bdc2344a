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

# The package imported the normal way before pytest collects the doctests of its modules: in
# importlib mode pytest executes a collected module from its file, and a module that its own
# imports reach again through its package (paths -> objectives -> fitness -> paths) would then
# exist twice, with two classes of one name that isinstance tells apart.
import pneumorph.design  # noqa: E402, F401

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


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto``: the cores this run may use, at least one.

    pytest-xdist counts the machine's physical cores; a run pinned to fewer (``taskset``, a
    container's CPU quota) gets one process per core it has, not one per core of the host.
    ``PYTEST_XDIST_AUTO_NUM_WORKERS`` still sets the number.
    """
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS", "").isdigit():
        return int(os.environ["PYTEST_XDIST_AUTO_NUM_WORKERS"])
    try:
        import psutil

        cores = psutil.cpu_count(logical=False) or os.cpu_count() or 1
    except ImportError:
        cores = os.cpu_count() or 1
    if hasattr(os, "sched_getaffinity"):
        cores = min(cores, len(os.sched_getaffinity(0)))
    try:  # cgroup v2: "<quota> <period>" or "max <period>"
        quota, period = Path("/sys/fs/cgroup/cpu.max").read_text().split()
        if quota != "max":
            cores = min(cores, max(1, int(quota) // int(period)))
    except (OSError, ValueError):
        pass
    return max(1, cores)

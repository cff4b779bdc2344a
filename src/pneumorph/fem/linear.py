"""Sparse linear solvers for the Newton iterations.

Intel MKL PARDISO (through ``pypardiso``) factorises the 3D tangent of an actuator 15-30x
faster than SciPy's SuperLU on this machine (``BENCHMARKS.md``); it is used where it is
installed (x86-64). Otherwise SuperLU with the minimum-degree ordering on A^T + A, which
is about twice as fast as SciPy's default ordering on these matrices.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np


def superlu(A: Any, b: Any) -> np.ndarray:
    """SciPy's SuperLU with the MMD_AT_PLUS_A column ordering."""
    from scipy.sparse.linalg import spsolve

    return spsolve(A.tocsc(), b, permc_spec="MMD_AT_PLUS_A")


def pardiso(A: Any, b: Any) -> np.ndarray:
    """MKL PARDISO through pypardiso (general, non-symmetric: follower pressure)."""
    import pypardiso

    return pypardiso.spsolve(A.tocsr(), np.asarray(b))


def default_solver() -> Callable[[Any, Any], np.ndarray]:
    """PARDISO if ``pypardiso`` imports, else SuperLU.

    Examples
    --------
    >>> import scipy.sparse as sp, numpy as np
    >>> A = sp.csr_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    >>> np.round(default_solver()(A, np.array([1.0, 2.0])), 6).tolist()
    [0.090909, 0.636364]
    """
    try:
        import pypardiso  # noqa: F401
    except ImportError:
        return partial(superlu)
    return pardiso

"""Sparse linear solvers for the Newton iterations.

Intel MKL PARDISO (through ``pypardiso``) factorises the 3D tangent of an actuator 15-30x
faster than SciPy's SuperLU on this machine (``BENCHMARKS.md``); it is used where it is
installed (x86-64). Otherwise SuperLU with the minimum-degree ordering on A^T + A, which
is about twice as fast as SciPy's default ordering on these matrices.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np


def superlu(A: Any, b: Any) -> np.ndarray:
    """SciPy's SuperLU with the MMD_AT_PLUS_A column ordering."""
    from scipy.sparse.linalg import spsolve

    return spsolve(A.tocsc(), b, permc_spec="MMD_AT_PLUS_A")


class Pardiso:
    """MKL PARDISO (general, non-symmetric: follower pressure) that reuses its analysis.

    The fill-reducing ordering and symbolic factorisation (PARDISO phase 11) depend only
    on the sparsity pattern, which stays the same through a whole pressure ramp; they are
    computed once and every later system with the same pattern only factorises and solves
    (phase 23). Use one instance per ramp; instances created in the same thread share
    that thread's PARDISO handle, so ramps must not be interleaved within a thread.
    """

    _local = threading.local()  # one MKL handle per thread: finding the library takes ~0.4 s

    def __init__(self) -> None:
        from pypardiso import PyPardisoSolver

        if getattr(Pardiso._local, "solver", None) is None:
            Pardiso._local.solver = PyPardisoSolver(mtype=11)
        self._solver = Pardiso._local.solver
        self._pattern: tuple[np.ndarray, np.ndarray] | None = None
        self.analyses = 0

    def __call__(self, A: Any, b: Any) -> np.ndarray:
        A = A.tocsr()
        A.sort_indices()
        b = np.asarray(b, dtype=float)
        s = self._solver
        s._check_A(A)
        b2 = s._check_b(A, b)
        same = (
            self._pattern is not None
            and np.array_equal(self._pattern[0], A.indptr)
            and np.array_equal(self._pattern[1], A.indices)
        )
        if same:
            s.set_phase(23)
        else:
            s.set_phase(13)
            self._pattern = (A.indptr.copy(), A.indices.copy())
            self.analyses += 1
        x = s._call_pardiso(A, b2)
        return x.reshape(b.shape)


def default_solver() -> Callable[[Any, Any], np.ndarray]:
    """A new PARDISO solver (reusing its analysis) if ``pypardiso`` imports, else SuperLU.

    Examples
    --------
    >>> import scipy.sparse as sp, numpy as np
    >>> A = sp.csr_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    >>> np.round(default_solver()(A, np.array([1.0, 2.0])), 6).tolist()
    [0.090909, 0.636364]
    """
    try:
        return Pardiso()
    except ImportError:
        return partial(superlu)

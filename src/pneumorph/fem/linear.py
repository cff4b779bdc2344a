"""Sparse linear solvers for the Newton iterations.

Intel MKL PARDISO (through ``pypardiso``) factorises the 3D tangent of an actuator 15-30x
faster than SciPy's SuperLU on this machine (``BENCHMARKS.md``); it is used where it is
installed (x86-64). Otherwise SuperLU with the minimum-degree ordering on A^T + A, which
is about twice as fast as SciPy's default ordering on these matrices.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from functools import partial
from typing import Any

import numpy as np


def superlu(A: Any, b: Any) -> np.ndarray:
    """SciPy's SuperLU with the MMD_AT_PLUS_A column ordering."""
    from scipy.sparse.linalg import spsolve

    return spsolve(A.tocsc(), b, permc_spec="MMD_AT_PLUS_A")


@contextlib.contextmanager
def _mkl_runtime() -> Iterator[None]:
    """Point ``pypardiso`` at MKL's runtime library where the ``mkl`` wheel puts it.

    Without ``PYPARDISO_MKL_RT``, ``pypardiso`` falls back to a recursive search of the
    whole environment (every file of site-packages: 0.3-0.5 s per process and thread);
    the wheel installs ``libmkl_rt.so.N`` straight into ``<prefix>/lib``. A path the user
    set is left alone.
    """
    import glob
    import os
    import sys

    found = [] if "PYPARDISO_MKL_RT" in os.environ else glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*"))
    if not found:
        yield
        return
    os.environ["PYPARDISO_MKL_RT"] = min(found, key=len)
    try:
        yield
    finally:
        os.environ.pop("PYPARDISO_MKL_RT", None)


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
        if getattr(Pardiso._local, "solver", None) is None:
            with _mkl_runtime():  # the import too: pypardiso makes a solver of its own as it is imported
                from pypardiso import PyPardisoSolver

                Pardiso._local.solver = PyPardisoSolver(mtype=11)
        self._solver = Pardiso._local.solver
        self._pattern: tuple[np.ndarray, np.ndarray] | None = None
        self.analyses = 0

    def __call__(self, A: Any, b: Any) -> np.ndarray:
        A = A.tocsr()
        A.sort_indices()
        b = np.asarray(b, dtype=float)
        if not (np.isfinite(A.data).all() and np.isfinite(b).all()):
            # a state outside the material's domain (an element turned inside out at a Newton iterate): the
            # solution is NaN, and PARDISO never sees the values, whose scaling its kept analysis would reuse
            return np.full(b.shape, np.nan)
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
        if not np.isfinite(x).all():
            self._pattern = None  # analyse afresh next time rather than reuse what gave this
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


class PardisoPattern:
    """MKL PARDISO for a sequence of matrices with one fixed CSR pattern.

    The ordering and symbolic analysis are done at the first call, each later call only
    factorises and solves. It has its own PARDISO handle (released when the object is
    collected), uses the minimum-degree ordering and no scaling or weighted matching,
    which on the 2D actuator tangents factorise about twice as fast as the defaults.

    Parameters
    ----------
    indptr, indices : ndarray
        The CSR pattern (sorted column indices), 0-based; of the upper triangle only for
        a symmetric matrix.
    symmetric : bool
        Real symmetric indefinite matrix (``mtype=-2``, Bunch-Kaufman pivoting), stored
        as its upper triangle: about half the work and memory of the general LU.
    ordering : int
        PARDISO's fill-reducing ordering ``iparm[1]``: 0 minimum degree (default; the
        best on the 2D tangents), 2 METIS nested dissection (on the 3D tangents a
        quarter less fill and factorisation time than minimum degree).
    single : bool
        Factorise and solve in single precision (``iparm[27] = 1``): half the time on
        the 3D tangents, solutions to about 1e-4 of the right-hand side - enough for a
        Newton method whose residual is evaluated in double precision (the same
        equilibrium, reached in about the same iterations).
    perm : ndarray, optional
        The fill-reducing permutation of an earlier solver's analysis of this pattern (its ``perm``): the
        analysis skips the ordering (about 0.4 s of the 15-unit 3D half model's 0.7 s) and the factors are the
        same. Without it, the analysis computes one and keeps it in ``perm``.

    Examples
    --------
    >>> import numpy as np
    >>> solve = PardisoPattern(np.array([0, 2, 4]), np.array([0, 1, 0, 1]))
    >>> np.round(solve(np.array([4.0, 1.0, 1.0, 3.0]), np.array([1.0, 2.0])), 6).tolist()
    [0.090909, 0.636364]
    """

    def __init__(
        self, indptr: np.ndarray, indices: np.ndarray, symmetric: bool = False, ordering: int = 0, single: bool = False,
        perm: np.ndarray | None = None,
    ) -> None:
        import ctypes

        Pardiso()  # loads MKL once per thread
        self._lib = Pardiso._local.solver
        self._ctypes = ctypes
        self.n = len(indptr) - 1
        self.ia = np.ascontiguousarray(indptr, dtype=np.int32) + 1
        self.ja = np.ascontiguousarray(indices, dtype=np.int32) + 1
        self.pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        self.mtype = -2 if symmetric else 11
        self.iparm[0] = 1  # user values: no scaling/matching
        self.iparm[1] = int(ordering)
        self.iparm[9] = 8 if symmetric else 13  # pivot perturbation 1e-8 / 1e-13 (MKL's defaults)
        self.iparm[27] = int(single)
        self.iparm[4] = 2 if perm is None else 1  # return the ordering's permutation / use the one given
        self.perm = np.zeros(self.n, dtype=np.int32) if perm is None else np.array(perm, dtype=np.int32)
        self.dtype = np.float32 if single else np.float64
        self.analysed = False
        self.factorisations = 0

    def _call(self, phase: int, data: np.ndarray, b: np.ndarray) -> np.ndarray:
        ct = self._ctypes
        x = np.zeros_like(b)
        error = ct.c_int32(0)
        i32 = ct.POINTER(ct.c_int32)
        f64 = ct.c_void_p  # double or single precision arrays
        self._lib._mkl_pardiso(
            self.pt.ctypes.data_as(ct.POINTER(ct.c_int64)), ct.byref(ct.c_int32(1)), ct.byref(ct.c_int32(1)),
            ct.byref(ct.c_int32(self.mtype)), ct.byref(ct.c_int32(phase)), ct.byref(ct.c_int32(self.n)),
            data.ctypes.data_as(f64), self.ia.ctypes.data_as(i32), self.ja.ctypes.data_as(i32),
            self.perm.ctypes.data_as(i32), ct.byref(ct.c_int32(1)),
            self.iparm.ctypes.data_as(i32), ct.byref(ct.c_int32(0)), b.ctypes.data_as(f64),
            x.ctypes.data_as(f64), ct.byref(error),
        )
        if error.value != 0:
            raise ArithmeticError(f"PARDISO failed with error {error.value} in phase {phase}")
        return x

    def __call__(self, data: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for the matrix with CSR values ``data`` on the pattern."""
        self.factorize(data)
        return self.solve(b)

    def factorize(self, data: np.ndarray) -> None:
        """Factorise the matrix with CSR values ``data`` (kept for :meth:`solve`)."""
        data = np.ascontiguousarray(data, dtype=self.dtype)
        b = np.zeros(self.n, dtype=self.dtype)
        if not self.analysed:
            self._call(11, data, b)
            self.analysed = True
        self._call(22, data, b)
        self._data = data
        self.factorisations += 1

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve with the last factorisation."""
        x = self._call(33, self._data, np.ascontiguousarray(b, dtype=self.dtype))
        return x.astype(np.float64, copy=False)

    def __del__(self) -> None:
        if getattr(self, "analysed", False):
            with contextlib.suppress(Exception):  # nothing to release at interpreter shutdown
                self._call(-1, np.zeros(0, dtype=self.dtype), np.zeros(0, dtype=self.dtype))


def pattern_operator(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, symmetric: bool = False,
                     remainder: Any = None) -> Callable[[np.ndarray], np.ndarray]:
    """The product ``x -> A x`` of the matrix with CSR values ``data`` on a pattern (its upper triangle if
    ``symmetric``) plus a sparse ``remainder`` (None: none), in double precision.

    >>> import numpy as np, scipy.sparse as sp
    >>> A = pattern_operator(np.array([0, 2, 3]), np.array([0, 1, 1]), np.array([4.0, 1.0, 3.0]), True,
    ...                      sp.csr_matrix(np.array([[0.0, 0.5], [-0.5, 0.0]])))
    >>> A(np.array([1.0, 1.0])).tolist()
    [5.5, 3.5]
    """
    import scipy.sparse as sp

    n = len(indptr) - 1
    matrix = sp.csr_matrix((np.asarray(data, dtype=np.float64), indices, indptr), shape=(n, n))
    diagonal = matrix.diagonal() if symmetric else None

    def product(x: np.ndarray) -> np.ndarray:
        y = matrix @ x
        if diagonal is not None:
            y += matrix.T @ x - diagonal * x
        if remainder is not None:
            y += remainder @ x
        return np.asarray(y, dtype=np.float64)

    return product


#: GMRES's tolerance (the residual over the right-hand side) and its most iterations in :func:`corrected`
CORRECTED_TOLERANCE = 1e-6
CORRECTED_ITERATIONS = 30


def corrected(solve: Callable[[np.ndarray], np.ndarray], product: Callable[[np.ndarray], np.ndarray],
              b: np.ndarray) -> np.ndarray:
    """The solution of ``A x = b`` by GMRES on the product ``x -> A x``, preconditioned on the right by ``solve``,
    an approximate inverse of ``A`` (the factorisation of most of it).

    The non-symmetric mode of a symmetric solver: the 3D tangent is factorised as a symmetric matrix, and the
    non-symmetric rest of the friction blocks (a few nodes' 3 x 3 blocks) is a matrix of low rank next to it,
    which GMRES resolves in a few products. Each iteration costs one ``solve`` and one ``product``; the first
    is the preconditioned solve itself, scaled, so a remainder that does not matter costs one product more.
    Right preconditioning minimises the true residual, which stops the iteration at :data:`CORRECTED_TOLERANCE`
    times ``|b|``, or after :data:`CORRECTED_ITERATIONS` with the best it found (a Newton step may be inexact).

    >>> import numpy as np
    >>> A = np.array([[4.0, 1.5], [0.5, 3.0]])
    >>> x = corrected(lambda b: b / np.diag(A), lambda x: A @ x, np.array([1.0, 2.0]))
    >>> np.allclose(A @ x, [1.0, 2.0])
    True
    """
    b = np.asarray(b, dtype=np.float64)
    beta = float(np.linalg.norm(b))
    if beta == 0.0:
        return np.zeros_like(b)
    m = CORRECTED_ITERATIONS
    V, Z = [b / beta], []
    H = np.zeros((m + 1, m))
    y: np.ndarray = np.zeros(0)
    for j in range(m):
        Z.append(np.asarray(solve(V[j]), dtype=np.float64))
        w = product(Z[j])
        for i in range(j + 1):  # modified Gram-Schmidt
            H[i, j] = float(V[i] @ w)
            w = w - H[i, j] * V[i]
        H[j + 1, j] = float(np.linalg.norm(w))
        e = np.zeros(j + 2)
        e[0] = beta
        y = np.linalg.lstsq(H[: j + 2, : j + 1], e, rcond=None)[0]
        if np.linalg.norm(H[: j + 2, : j + 1] @ y - e) <= CORRECTED_TOLERANCE * beta or H[j + 1, j] == 0.0:
            break
        V.append(w / H[j + 1, j])
    return np.asarray(np.column_stack(Z) @ y, dtype=np.float64)


class SuperLUPattern:
    """SciPy's SuperLU with :class:`PardisoPattern`'s interface (where MKL is missing).

    Examples
    --------
    >>> import numpy as np
    >>> solve = SuperLUPattern(np.array([0, 2, 3]), np.array([0, 1, 1]), symmetric=True)
    >>> np.round(solve(np.array([4.0, 1.0, 3.0]), np.array([1.0, 2.0])), 6).tolist()
    [0.090909, 0.636364]
    """

    def __init__(self, indptr: np.ndarray, indices: np.ndarray, symmetric: bool = False) -> None:
        self.indptr, self.indices, self.symmetric = indptr, indices, symmetric
        self.n = len(indptr) - 1
        self.factorisations = 0
        self._lu: Any = None

    def factorize(self, data: np.ndarray) -> None:
        import scipy.sparse as sp
        from scipy.sparse.linalg import splu

        A = sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))
        if self.symmetric:
            A = A + sp.triu(A, k=1).T
        self._lu = splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A")
        self.factorisations += 1

    def solve(self, b: np.ndarray) -> np.ndarray:
        return np.asarray(self._lu.solve(np.asarray(b, dtype=float)))

    def __call__(self, data: np.ndarray, b: np.ndarray) -> np.ndarray:
        self.factorize(data)
        return self.solve(b)

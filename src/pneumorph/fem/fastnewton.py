"""Newton's method on a :class:`~pneumorph.fem.fastassembly.PlaneStrainSystem`.

The convergence test is FElupe's (``felupe.tools._newton.check``): the norm of the
residual of the active dofs over ``1e-3`` plus the norm of the reaction forces,

    ||r[dof1]|| / (1e-3 + ||r[dof0]||) < tol,

checked after every update, so a converged state satisfies the same equilibrium as one
of ``felupe.newtonraphson``. Prescribed values stay as the ramp set them. Unlike FElupe's
method it gives up early - on a non-admissible start (a predictor that inverted an
element), a non-finite residual or a residual 1e3 times the reaction forces - and leaves
the cut-back to the ramp.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.fastassembly import PlaneStrainSystem

FloatArray = NDArray[np.float64]


#: A relative residual norm (residual over reaction forces) beyond which a substep is
#: abandoned at once: converging substeps of the 2D actuator stay below ~10, diverging
#: ones pass 1e4 on their way to inverted elements.
DIVERGED = 1e3


def pattern_solver(indptr: NDArray[np.int32], indices: NDArray[np.int32]) -> Callable[[Any, Any], FloatArray]:
    """``solve(data, b)`` for matrices on one CSR pattern: PARDISO if available, else SuperLU."""
    from pneumorph.fem.linear import PardisoPattern, superlu

    try:
        return PardisoPattern(indptr, indices)
    except ImportError:
        import scipy.sparse as sp

        n = len(indptr) - 1
        return lambda data, b: superlu(sp.csr_matrix((data, indices, indptr), shape=(n, n)), b)


def residual_norm(r: FloatArray, dof1: NDArray[np.int64], dof0: NDArray[np.int64]) -> float:
    """FElupe's relative residual norm ``||r1|| / (1e-3 + ||r0||)``."""
    return float(np.linalg.norm(r[dof1]) / (1e-3 + np.linalg.norm(r[dof0])))


class FastSubstep:
    """Solve one substep of :func:`pneumorph.fem.stepping.ramp` on the fast system.

    Called as ``solve(fields, settings)``, it iterates from the values in ``fields``
    (written back in place) and returns ``(iterations, cause of failure or None)``, like
    the FElupe path of the ramp.

    Parameters
    ----------
    system : PlaneStrainSystem
        The assembled model.
    solver : callable, optional
        ``solver(data, b)`` for the active block given by its CSR values on the
        system's pattern (default: :func:`pattern_solver`).
    """

    def __init__(self, system: PlaneStrainSystem, solver: Callable[[Any, Any], FloatArray] | None = None) -> None:
        self.system = system
        self.solver = solver or pattern_solver(system.indptr, system.indices)

    def __call__(self, fields: Any, settings: Any) -> tuple[int, str | None]:
        system = self.system
        dof1, dof0 = system.dof1, system.dof0
        values = fields[0].values
        u = values.ravel().copy()
        with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            r, jmin = system.residual(u)
            if not (jmin > 0.0 and np.all(np.isfinite(r))):
                # an over-reaching predictor: the ramp cuts the substep back at no Newton cost
                return 0, f"the predicted start is not admissible (det F = {jmin:.3g})"
            for iteration in range(1, settings.max_iterations + 1):
                try:
                    dx = self.solver(system.tangent_data(), -r[dof1])
                except (ArithmeticError, np.linalg.LinAlgError, ValueError, RuntimeError) as exc:
                    return iteration, f"{type(exc).__name__}: {exc}"
                if not np.all(np.isfinite(dx)):
                    return iteration, "the linear solve gave a non-finite increment"
                u[dof1] += dx
                r, jmin = system.residual(u)
                fnorm = residual_norm(r, dof1, dof0)
                if not np.isfinite(fnorm):
                    return iteration, "the residual is not finite"
                if fnorm > DIVERGED:
                    return iteration, f"diverging (residual norm {fnorm:.3g})"
                if fnorm < settings.tolerance:
                    values[:] = u.reshape(values.shape)
                    if not jmin > 0.0:
                        return iteration, f"an element inverted (det F = {jmin:.3g})"
                    return iteration, None
        values[:] = u.reshape(values.shape)
        return settings.max_iterations, "Newton iterations did not reach the tolerance"

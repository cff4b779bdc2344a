"""Newton's method on a fast system (:class:`~pneumorph.fem.fast.system.PlaneStrainSystem`,
:class:`~pneumorph.fem.fast.system.SolidSystem3D`).

The convergence test is the one of the FElupe path,
:func:`pneumorph.fem.stepping.relative_residual` below the tolerance: the norm of the
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
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.stepping import relative_residual

FloatArray = NDArray[np.float64]


#: A relative residual norm (residual over reaction forces) beyond which a substep is
#: abandoned at once: converging substeps of the 2D actuator stay below ~10, diverging
#: ones pass 1e4 on their way to inverted elements.
DIVERGED = 1e3

#: Halvings of a fresh tangent's step on a body with obstacles whose iterate is not admissible
#: (:meth:`FastSubstep._trial`): a contact that closes within the step (a node the tangent saw free)
#: threw the 15-unit actuator against a cylinder into inverted elements and cut-backs.
BACKTRACKS = 5

#: The growth of the relative residual norm beyond which a fresh tangent's iterate on a body with obstacles is
#: halved too: a node thrown into an obstacle by a step (a contact the tangent did not hold) multiplies the
#: residual. Without it a 3-unit 3D finger on a cylinder with friction 0.5 failed its ramp; with 10 it took 396
#: Newton iterations and 11 cut-backs, with 2 took 290 and 7. A 15-unit 2D finger grazing a cylinder: 210
#: iterations and 6 cut-backs without, 81 and 1 with 10, 87 and 1 with 2; the 15-unit 3D one: 115 and 0
#: with 10, 108 and 0 with 2.
GROWTH = 2.0

#: Fresh tangents in a row that each lower the residual norm by less than the reuse factor
#: before a single-precision factorisation is judged too inaccurate and replaced by a
#: double-precision one. A fresh Newton step near the solution converges quadratically;
#: with a factorisation whose forward error is near one (the condition number of the 3D
#: tangent grows as the elements shrink) each step removes only a fraction of the
#: residual: the 15-unit actuator at 1.0 mm elements stalled at 1e-7 (tolerance 1e-8)
#: with fresh single-precision tangents each gaining a factor 0.8, and converged in 5-11
#: iterations per level in double precision.
STALLED_FRESH = 2

#: Active unknowns above which a system that may factorise in single precision starts in
#: double precision: the 15-unit actuator at 1.0 mm elements (245,000) stalled in single
#: precision on every design tried, the default mesh (58,500) and 3-unit actuators at 1.0 mm
#: (50,000) never did. Waiting for the stall instead cost the 15-unit winner 407 s against
#: about 225 s in double precision throughout. Measured on half models: a body of the full
#: width (no plane of symmetry) has twice the unknowns at the same element size, and gets
#: twice the limit (:meth:`pneumorph.fem.body.PressurisedBody.stepper`).
SINGLE_PRECISION_MAX_DOFS = 100_000


def pattern_solver(
    indptr: NDArray[np.int32],
    indices: NDArray[np.int32],
    symmetric: bool = False,
    ordering: int = 0,
    single: bool = False,
) -> Any:
    """A solver for matrices on one CSR pattern: PARDISO if available, else SuperLU.

    It is called as ``solve(data, b)`` or as ``factorize(data)`` then ``solve(b)``. With
    ``symmetric`` the pattern is the upper triangle of a symmetric matrix; ``single``
    asks PARDISO for a single-precision factorisation.
    """
    from pneumorph.fem.linear import PardisoPattern, SuperLUPattern

    try:
        return PardisoPattern(indptr, indices, symmetric=symmetric, ordering=ordering, single=single)
    except ImportError:
        return SuperLUPattern(indptr, indices, symmetric=symmetric)


def inadmissible(r: FloatArray, jmin: float) -> str | None:
    """Why a substep's starting state cannot be iterated from, or None.

    An over-reaching predictor inverts elements; the ramp then cuts the substep back at no
    Newton cost.
    """
    if jmin > 0.0 and np.all(np.isfinite(r)):
        return None
    return f"the predicted start is not admissible (det F = {jmin:.3g})"


def contact_fraction(system: Any, u: FloatArray, step: FloatArray) -> float:
    """The fraction of a Newton ``step`` (over the active dofs) from ``u`` that carries no surface node deep into
    an obstacle it was not pressing on (:meth:`~pneumorph.fem.fast.contact.RigidContact.step_fraction`; 1
    without obstacles)."""
    contacts = getattr(system, "contacts", ())
    if not contacts:
        return 1.0
    du = np.zeros_like(u)
    du[system.dof1] = step
    d = system.points.shape[1]
    x, dx = system.points + u.reshape(-1, d), du.reshape(-1, d)
    return min(c.step_fraction(x, dx) for c in contacts)


def verdict(fnorm: float, jmin: float, u: FloatArray, values: FloatArray, tolerance: float,
            constraint: float = 0.0) -> tuple[bool, str | None]:
    """``(done, cause)`` after an iteration; on convergence (the relative residual ``fnorm`` and a constraint's
    relative error, e.g. a volume control's, both below ``tolerance``) ``u`` is written into ``values``."""
    if not np.isfinite(fnorm):
        return True, "the residual is not finite"
    if fnorm > DIVERGED:
        return True, f"diverging (residual norm {fnorm:.3g})"
    if fnorm < tolerance and constraint < tolerance:
        values[:] = u.reshape(values.shape)
        if not jmin > 0.0:
            return True, f"an element inverted (det F = {jmin:.3g})"
        return True, None
    return False, None


class FastSubstep:
    """Solve one substep of :func:`pneumorph.fem.stepping.ramp` on the fast system.

    Called as ``solve(fields, settings)``, it iterates from the values in ``fields``
    (written back in place) and returns ``(iterations, cause of failure or None)``, like
    the FElupe path of the ramp.

    With ``reuse`` it is a Newton method that keeps its factorised tangent while that
    still converges well (a chord method with refresh): every substep starts (by
    default) with a fresh tangent at its predicted state; an iteration whose residual norm falls by less
    than the factor ``reuse`` has the tangent re-assembled and factorised at the state it
    reached, and a step of a kept tangent that does not lower the residual at all is
    taken back and redone with a fresh tangent. Near the solution a kept tangent
    converges almost as fast as a fresh one, so where a factorisation costs many
    residual evaluations (3D) this saves most of them; the converged states satisfy the
    same criterion as Newton's.

    Parameters
    ----------
    system : PlaneStrainSystem or SolidSystem3D
        The assembled model (its ``symmetric`` and ``ordering`` attributes choose the
        default solver).
    solver : object, optional
        With ``factorize(data)`` and ``solve(b)`` for the active block given by its CSR
        values on the system's pattern (default: :func:`pattern_solver`); a plain
        callable ``solver(data, b)`` allows Newton's method only.
    reuse : float, optional
        Residual reduction factor per iteration below which a tangent is kept (None:
        Newton's method, a fresh tangent at every iteration).
    depth : int
        With ``reuse``: Anderson acceleration of the chord steps over this many previous
        steps (0: plain chord steps). Each step is the chord step minus the combination
        of the previous step and chord-step differences that best cancels the current
        chord step (least squares), which approximates the missing tangent update.
    fresh_start : bool
        With ``reuse``: assemble a fresh tangent at the start of every substep (default)
        instead of carrying the last one over.
    single_max_dofs : int, optional
        The limit of active unknowns for single precision (default
        :data:`SINGLE_PRECISION_MAX_DOFS`).

    A system with more than ``single_max_dofs`` active unknowns factorises in
    double precision from the start. A single-precision factorisation (the 3D default) whose
    fresh tangents stop converging (:data:`STALLED_FRESH` in a row each gaining less than
    ``reuse``) is replaced by a
    double-precision one for the rest of the ramp (:attr:`precision`), from the state
    reached: a finer mesh is worse conditioned and needs it.

    Attributes
    ----------
    factorisations : int
        Tangents assembled and factorised so far.
    precision : {"single", "double"}
        The precision the tangents are factorised in now.
    best : float
        The smallest residual norm of the last substep (reported when it fails).
    """

    def __init__(
        self, system: Any, solver: Any = None, reuse: float | None = None, depth: int = 0, fresh_start: bool = True,
        single_max_dofs: int | None = None,
    ) -> None:
        self.system = system
        limit = SINGLE_PRECISION_MAX_DOFS if single_max_dofs is None else single_max_dofs
        self.solver = solver or pattern_solver(
            system.indptr,
            system.indices,
            getattr(system, "symmetric", False),
            getattr(system, "ordering", 0),
            single=(reuse is not None and getattr(system, "single_precision", False)
                    and len(getattr(system, "dof1", ())) <= limit),
        )
        if getattr(self.solver, "dtype", None) == np.float32:
            # a tangent factorised in single precision may as well be assembled in it
            system.tangent_dtype = np.float32
        if reuse is not None and not (0.0 < reuse < 1.0 and hasattr(self.solver, "factorize")):
            raise ValueError(f"reuse must lie in (0, 1) with a solver that factorises once, got {reuse}")
        self.reuse = reuse
        self.depth = int(depth)
        self.fresh_start = bool(fresh_start)
        self.factorisations = 0
        self._factorised = False
        self.best = float("inf")
        self._converged: FloatArray | None = None  # the last converged state, on a body with obstacles
        #: set to a list to record ``(residual norm, tangent fresh)`` after every iteration
        self.trace: list[tuple[float, bool]] | None = None

    @property
    def precision(self) -> str:
        return "single" if getattr(self.solver, "dtype", None) == np.float32 else "double"

    def to_double(self) -> None:
        """Factorise in double precision from now on (tangents assembled in double too)."""
        system = self.system
        self.solver = pattern_solver(system.indptr, system.indices, getattr(system, "symmetric", False),
                                     getattr(system, "ordering", 0), single=False)
        system.tangent_dtype = np.float64
        self._factorised = False

    def _stalled(self, settings: Any) -> str:
        """Why a substep that used all its iterations failed."""
        return (f"the residual norm reached {self.best:.3g} in {settings.max_iterations} iterations, not the "
                f"tolerance {settings.tolerance:.3g} ({self.precision}-precision factorisation)")

    def factorize(self) -> None:
        """Assemble the tangent at the state of the system's last residual and factorise it."""
        data = self.system.tangent_data()
        if hasattr(self.solver, "factorize"):
            self.solver.factorize(data)
        else:
            self._data = data
        self._factorised = True
        self.factorisations += 1

    def solve(self, b: FloatArray) -> FloatArray:
        """``K^-1 b`` with the last factorised tangent (``b`` over the active dofs)."""
        if hasattr(self.solver, "factorize"):
            return np.asarray(self.solver.solve(b))
        return np.asarray(self.solver(self._data, b))

    def __call__(self, fields: Any, settings: Any) -> tuple[int, str | None]:
        contacts = getattr(self.system, "contacts", ())
        if contacts:
            self._hold_predictor(fields[0].values)
        if self.reuse is None:
            iterations, cause = self._newton(fields, settings)
        else:
            if self.fresh_start:
                self._factorised = False
            iterations, cause = self._chord(fields, settings)
            if cause is not None:
                self._factorised = False
        if contacts and cause is None:
            self._converged = fields[0].values.ravel().copy()
        return iterations, cause

    def _hold_predictor(self, values: FloatArray) -> None:
        """Shorten the ramp's predicted increment from the last converged state (in place in ``values``) as a
        Newton step (:func:`contact_fraction`): an extrapolation carried the nodes of a finger sliding round a
        cylinder 0.7-1.3 mm into it."""
        last = self._converged
        u = values.ravel()
        if last is None or last.shape != u.shape:
            return
        dof1 = self.system.dof1
        step = u[dof1] - last[dof1]
        fraction = contact_fraction(self.system, last, step)
        if fraction < 1.0:
            u[dof1] = last[dof1] + fraction * step
            values[:] = u.reshape(values.shape)

    def _trial(self, u: FloatArray, step: FloatArray, fresh: bool, previous: float = np.inf
               ) -> tuple[FloatArray, FloatArray, FloatArray, float, float]:
        """The iterate of ``step`` from ``u``: ``(step taken, u_new, its residual, smallest det F, relative
        residual)``.

        On a body with obstacles, the step is first shortened to carry no node deep into an obstacle it was not
        pressing on (:func:`contact_fraction`), and a fresh tangent's step whose iterate is not admissible
        (a non-finite residual, an inverted element, or a residual norm above :data:`DIVERGED` or :data:`GROWTH`
        times the ``previous`` one) is halved, up to :data:`BACKTRACKS` times: a contact that closes or opens
        within the step changes the tangent the step was computed with.
        """
        system = self.system
        dof1, dof0 = system.dof1, system.dof0
        backtracks = BACKTRACKS if fresh and len(getattr(system, "contacts", ())) else 0
        step = contact_fraction(system, u, step) * step
        for trial in range(backtracks + 1):
            if trial:
                step = 0.5 * step
            u_new = u.copy()
            u_new[dof1] += step
            r_new, jmin = system.residual(u_new)
            fnorm = relative_residual(r_new, dof1, dof0)
            if jmin > 0.0 and fnorm <= min(DIVERGED, GROWTH * previous):  # (a NaN residual norm fails this too)
                break
        return step, u_new, r_new, jmin, fnorm

    def _newton(self, fields: Any, settings: Any) -> tuple[int, str | None]:
        system = self.system
        dof1 = system.dof1
        values = fields[0].values
        u = values.ravel().copy()
        self.best = float("inf")
        with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            r, jmin = system.residual(u)
            if (cause := inadmissible(r, jmin)) is not None:
                return 0, cause
            fnorm = relative_residual(r, dof1, system.dof0)
            for iteration in range(1, settings.max_iterations + 1):
                try:
                    self.factorize()
                    dx = self.solve(-r[dof1])
                except (ArithmeticError, np.linalg.LinAlgError, ValueError, RuntimeError) as exc:
                    return iteration, f"{type(exc).__name__}: {exc}"
                if not np.all(np.isfinite(dx)):
                    return iteration, "the linear solve gave a non-finite increment"
                _, u, r, jmin, fnorm = self._trial(u, dx, True, fnorm)
                self.best = min(self.best, fnorm)
                if self.trace is not None:
                    self.trace.append((fnorm, True))
                done, cause = verdict(fnorm, jmin, u, values, settings.tolerance)
                if done:
                    return iteration, cause
        values[:] = u.reshape(values.shape)
        return settings.max_iterations, self._stalled(settings)

    def _chord(self, fields: Any, settings: Any) -> tuple[int, str | None]:
        """Chord iterations with Anderson acceleration and refresh (see the class notes)."""
        system = self.system
        dof1, dof0 = system.dof1, system.dof0
        reuse = float(self.reuse or 0.5)
        values = fields[0].values
        u = values.ravel().copy()
        with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            r, jmin = system.residual(u)
            if (cause := inadmissible(r, jmin)) is not None:
                return 0, cause
            fnorm = relative_residual(r, dof1, dof0)
            self.best = fnorm
            if self.trace is not None:
                self.trace.append((fnorm, False))
            f: FloatArray | None = None  # chord step -K0^-1 r at u
            dU: list[FloatArray] = []
            dF: list[FloatArray] = []
            fresh = False
            poor = 0  # fresh tangents in a row that gained less than the reuse factor
            for iteration in range(1, settings.max_iterations + 1):
                try:
                    if not self._factorised:
                        self.factorize()  # at the state of the last residual, u
                        fresh, f, dU, dF = True, None, [], []
                    if f is None:
                        f = -self.solve(r[dof1])
                except (ArithmeticError, np.linalg.LinAlgError, ValueError, RuntimeError) as exc:
                    return iteration, f"{type(exc).__name__}: {exc}"
                step = f
                if dF:
                    Fm = np.column_stack(dF)
                    gamma = np.linalg.lstsq(Fm, f, rcond=None)[0]
                    step = f - (np.column_stack(dU) + Fm) @ gamma
                if not np.all(np.isfinite(step)):
                    return iteration, "the linear solve gave a non-finite increment"
                step, u_new, r_new, jmin, fnorm_new = self._trial(u, step, fresh, fnorm)
                self.best = min(self.best, fnorm_new)
                if self.trace is not None:
                    self.trace.append((fnorm_new, fresh))
                if fresh:
                    poor = poor + 1 if not fnorm_new < reuse * fnorm else 0
                if not fresh and not (fnorm_new < fnorm and jmin > 0.0):
                    # a kept tangent that no longer helps: take the step back, refresh
                    system.residual(u)  # the state the tangent is assembled at
                    self._factorised = False
                    continue
                done, cause = verdict(fnorm_new, jmin, u_new, values, settings.tolerance)
                if done:
                    return iteration, cause
                if poor >= STALLED_FRESH and self.precision == "single":
                    self.to_double()  # refresh at u_new, in double precision from now on
                    f, poor = None, 0
                elif fnorm_new > reuse * fnorm:
                    self._factorised = False  # refresh at u_new
                    f = None
                else:
                    try:
                        f_new = -self.solve(r_new[dof1])
                    except (ArithmeticError, np.linalg.LinAlgError, ValueError, RuntimeError) as exc:
                        return iteration, f"{type(exc).__name__}: {exc}"
                    if self.depth > 0:
                        dU.append(step)
                        dF.append(f_new - f)
                        dU, dF = dU[-self.depth:], dF[-self.depth:]
                    f = f_new
                u, r, fnorm, fresh = u_new, r_new, fnorm_new, False
        values[:] = u.reshape(values.shape)
        return settings.max_iterations, self._stalled(settings)

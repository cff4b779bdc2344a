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

from pneumorph.fem.fast.contact import contact_fraction, contacts_changed, node_steps
from pneumorph.fem.linear import corrected, pattern_operator
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

#: The growth of the relative residual norm up to which a fresh tangent's step cut short by the obstacles' step limit
#: (:func:`contact_fraction`: the nodes it would carry into an obstacle land at the reach) is kept whole instead of
#: halved. Landed, the entering nodes touch and the next tangent holds them; halved to :data:`GROWTH`, they were carried
#: back out, and the 15-unit 3D finger's tip crept onto a frictionless cylinder in its way over 5-6 fresh steps per
#: level, each covering part of the distance (landings raised the residual 3.6-4.9 times): 114 Newton iterations and
#: 58 factorisations, 107 and 51 with 3 or 5, 112 and 56 with 10. The frictionless wall took 29 factorisations
#: against 27, the grazing cylinder 34 against 35 (``BENCHMARKS.md``, "A hard press"). With friction a fresh tangent's
#: iterate must lower the residual norm, landed or not (:data:`FRICTION_GROWTH`): 3 cost a cylinder in the way 3 more.
LANDING = 3.0

#: :data:`GROWTH` on a body with friction on an obstacle: a fresh tangent's iterate must lower the residual norm.
#: A node's switches between sticking and sliding, and in and out of contact, made the fresh steps of a 3-unit 3D
#: finger on a cylinder with friction 0.5 cycle at a residual norm of 1e-2: 290 Newton iterations and 7 cut-backs
#: with 2, 118 and 1 with 1 (99 and 1 with the whole tangent, :meth:`FastSubstep.solve`). Frictionless contact
#: keeps :data:`GROWTH` (85 iterations either way).
FRICTION_GROWTH = 1.0

#: Whether a step that changed a node's contact state (free, sticking, sliding) has the tangent refreshed at once,
#: on a body with obstacles, instead of kept while it lowers the residual.
REFRESH_ON_CHANGE = True

#: The farthest a Newton step on a body with obstacles may move a node, over the farthest the ramp's predicted start
#: of the substep moved one from the last converged state (at least the obstacles' stride:
#: :meth:`~pneumorph.fem.fast.contact.RigidContact.step_fraction`).
MOTION = 2.0

#: A kept tangent's step that raises the residual norm (plus a constraint's error) less than this, on a body without
#: obstacles, is kept and the tangent refreshed at its end (:func:`kept_rise`; ``docs/notes/fe-core.md``, "The ramp").
RISE = 3.0

#: Fresh tangents in a row that each lower the residual norm by less than the reuse factor
#: before a single-precision factorisation is judged too inaccurate and replaced by a
#: double-precision one. A fresh Newton step near the solution converges quadratically;
#: with a factorisation whose forward error is near one (the condition number of the 3D
#: tangent grows as the elements shrink) each step removes only a fraction of the
#: residual: the 15-unit actuator at 1.0 mm elements stalled at 1e-7 (tolerance 1e-8)
#: with fresh single-precision tangents each gaining a factor 0.8, and converged in 5-11
#: iterations per level in double precision. Steps cut short by an obstacle's step limit or
#: the line search do not count: on a finger pressed on a cylinder they turned the ramp to
#: double precision after its first substep in contact, where a factorisation costs 1.5-1.8
#: times one in single precision (``BENCHMARKS.md``, "A hard press").
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
    perm: NDArray[np.int32] | None = None,
) -> Any:
    """A solver for matrices on one CSR pattern: PARDISO if available, else SuperLU.

    It is called as ``solve(data, b)`` or as ``factorize(data)`` then ``solve(b)``. With
    ``symmetric`` the pattern is the upper triangle of a symmetric matrix; ``single``
    asks PARDISO for a single-precision factorisation; ``perm`` is the fill-reducing permutation of an earlier
    PARDISO analysis of the pattern (:class:`~pneumorph.fem.linear.PardisoPattern`).
    """
    from pneumorph.fem.linear import PardisoPattern, SuperLUPattern

    try:
        return PardisoPattern(indptr, indices, symmetric=symmetric, ordering=ordering, single=single, perm=perm)
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


def kept_rise(norm_new: float, norm: float, jmin: float) -> bool:
    """Whether a kept tangent's step that raised the residual norm from ``norm`` to ``norm_new`` is kept (:data:`RISE`).

    >>> kept_rise(2e-3, 1e-3, 0.9), kept_rise(5e-3, 1e-3, 0.9), kept_rise(2e-3, 1e-3, -0.1)
    (True, False, False)
    """
    return jmin > 0.0 and norm_new < RISE * norm and norm_new <= DIVERGED


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

    Called as ``solve(fields, settings)``, it iterates from the values in ``fields`` (written back in place)
    and returns ``(iterations, cause of failure or None)``, like the FElupe path of the ramp.

    With ``reuse`` it is a Newton method that keeps its factorised tangent while that still converges well (a
    chord method with refresh): every substep starts (by default) with a fresh tangent at its predicted state;
    an iteration whose residual norm falls by less than the factor ``reuse`` has the tangent re-assembled and
    factorised at the state it reached, and a step of a kept tangent that does not lower the residual at all
    is taken back and redone with a fresh tangent (on a body without obstacles one that raises it by less
    than :data:`RISE` is kept, the tangent refreshed at its end). Near the solution a kept tangent converges
    almost as fast as a fresh one, so where a factorisation costs many residual evaluations (3D) this saves
    most of them; the converged states satisfy the same criterion as Newton's.

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
    fresh tangents stop converging (:data:`STALLED_FRESH` whole steps in a row each gaining less than
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
            perm=self._ordering(),
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
        self._product: Any = None  # the whole tangent's product, where the factorised one is not all of it
        self.best = float("inf")
        self._converged: FloatArray | None = None  # the last converged state, on a body with obstacles
        self._motion = 0.0  # the farthest a Newton step may move a node beyond the obstacles' stride (mm)
        #: set to a list to record ``(residual norm, tangent fresh)`` after every iteration
        self.trace: list[tuple[float, bool]] | None = None

    @property
    def precision(self) -> str:
        return "single" if getattr(self.solver, "dtype", None) == np.float32 else "double"

    def _ordering(self) -> NDArray[np.int32] | None:
        """The fill-reducing permutation an earlier solver of the system's pattern found (the pattern is shared by
        the systems of one mesh: :attr:`~pneumorph.fem.fast.assembler.FastSystem.pattern`), or None."""
        orderings = getattr(getattr(self.system, "pattern", None), "orderings", {})
        return orderings.get((getattr(self.system, "symmetric", False), getattr(self.system, "ordering", 0)))

    def _keep_ordering(self) -> None:
        """Keep the solver's permutation for the next solver of the pattern (:meth:`_ordering`)."""
        orderings = getattr(getattr(self.system, "pattern", None), "orderings", None)
        perm = getattr(self.solver, "perm", None)
        if orderings is not None and perm is not None and getattr(self.solver, "analysed", False):
            key = (getattr(self.system, "symmetric", False), getattr(self.system, "ordering", 0))
            if key not in orderings:
                perm = perm.copy()
                perm.flags.writeable = False
                orderings[key] = perm

    def to_double(self) -> None:
        """Factorise in double precision from now on (tangents assembled in double too)."""
        system = self.system
        self.solver = pattern_solver(system.indptr, system.indices, getattr(system, "symmetric", False),
                                     getattr(system, "ordering", 0), single=False, perm=self._ordering())
        system.tangent_dtype = np.float64
        self._factorised = False

    def _stalled(self, settings: Any, error: float | None = None) -> str:
        """Why a substep that used all its iterations failed (``error``: its constraints' last relative error)."""
        constraint = "" if error is None else f" (constraint error {error:.3g})"
        return (f"the residual norm reached {self.best:.3g}{constraint} in {settings.max_iterations} iterations, "
                f"not the tolerance {settings.tolerance:.3g} ({self.precision}-precision factorisation)")

    def factorize(self) -> None:
        """Assemble the tangent at the state of the system's last residual and factorise it."""
        system = self.system
        data = system.tangent_data()
        if hasattr(self.solver, "factorize"):
            self.solver.factorize(data)
            if self.factorisations == 0:
                self._keep_ordering()
        else:
            self._data = data
        remainder = getattr(system, "remainder", None)  # a symmetric tangent's non-symmetric rest (friction)
        self._product = None if remainder is None else pattern_operator(
            system.indptr, system.indices, data, getattr(system, "symmetric", False), remainder)
        self._factorised = True
        self.factorisations += 1

    def solve(self, b: FloatArray) -> FloatArray:
        """``K^-1 b`` with the last factorised tangent (``b`` over the active dofs); a symmetric factorisation
        with a remainder (``FastSystem.remainder``) corrected by GMRES
        (:func:`~pneumorph.fem.linear.corrected`)."""
        if self._product is not None:
            return corrected(self._solve, self._product, b)
        return self._solve(b)

    def _solve(self, b: FloatArray) -> FloatArray:
        if hasattr(self.solver, "factorize"):
            return np.asarray(self.solver.solve(b))
        return np.asarray(self.solver(self._data, b))

    def __call__(self, fields: Any, settings: Any, border: Any = None) -> tuple[int, str | None]:
        """Solve one substep from the values in ``fields`` (written back on convergence).

        ``border`` adds unknowns to the displacements (e.g. the load factor of a
        :class:`~pneumorph.fem.fast.volume.VolumeControl`), with ``start()`` (their values now), ``set(x)``
        (the load they give), ``error(u)`` (the relative error of their constraints) and ``step(substep, u, r)``
        (the chord step over the active dofs and them, with ``substep.solve``); None: the load stays as it is.
        """
        contacts = getattr(self.system, "contacts", ())
        if contacts:
            self._hold_predictor(fields[0].values)
        if self.fresh_start or self.reuse is None:
            self._factorised = False
        with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            iterations, cause = self._iterate(fields, settings, _FixedLoad() if border is None else border)
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
        self._motion = MOTION * float(np.max(np.linalg.norm(node_steps(self.system, step), axis=1), initial=0.0))
        fraction = contact_fraction(self.system, last, step, self._motion)
        if fraction < 1.0:
            u[dof1] = last[dof1] + fraction * step
            values[:] = u.reshape(values.shape)

    def _trial(self, u: FloatArray, x: FloatArray, step: FloatArray, fresh: bool, previous: float, border: Any
               ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, float, float, bool]:
        """The iterate of ``step`` (over the active dofs, then the border's unknowns) from ``(u, x)``:
        ``(step taken, u_new, x_new, its residual, smallest det F, relative residual, whether the step was cut
        short)``, its load set.

        On a body with obstacles, the step is first shortened to carry no node deep into an obstacle it was not
        pressing on, nor farther than :data:`MOTION` times the substep's predicted motion or the obstacles'
        stride (:func:`contact_fraction`), and a fresh tangent's step whose iterate is not admissible
        (a non-finite residual, an inverted element, a residual norm above :data:`DIVERGED`, or a residual norm
        plus the border's constraint error above :data:`GROWTH` times the ``previous`` one, :data:`FRICTION_GROWTH`
        with friction; without, :data:`LANDING` for the step as cut) is halved, up to :data:`BACKTRACKS` times: a
        contact that closes or opens within the step changes the tangent the step was computed with. With a border's
        unknowns (a volume control) the growth only counts where the step changed which nodes touch
        (:func:`contacts_changed`): a volume-controlled substep starts from an equilibrium, at a residual norm near 0,
        which its first steps raise as they meet the volume (halving every step in free air failed a 3-unit finger's
        first substep with friction).
        """
        system = self.system
        dof1, dof0 = system.dof1, system.dof0
        n = len(dof1)
        contacts = getattr(system, "contacts", ())
        backtracks = BACKTRACKS if fresh and len(contacts) else 0
        frictional = any(c.friction > 0.0 for c in contacts)
        growth = FRICTION_GROWTH if frictional else GROWTH
        fraction = contact_fraction(system, u, step[:n], self._motion)
        step = fraction * step
        for trial in range(backtracks + 1):
            if trial:
                step = 0.5 * step
            u_new, x_new = u.copy(), x + step[n:]
            u_new[dof1] += step[:n]
            border.set(x_new)
            r_new, jmin = system.residual(u_new)
            fnorm = relative_residual(r_new, dof1, dof0)
            if not backtracks:
                break
            landed = trial == 0 and fraction < 1.0 and not frictional  # the step as cut, frictionless: LANDING
            limit = max(growth, LANDING) if landed else growth
            if jmin > 0.0 and fnorm <= DIVERGED and (  # (a NaN residual norm fails this too)
                    fnorm + border.error(u_new) <= limit * previous
                    or (x.size and not contacts_changed(system, u, u_new))):
                break
        return step, u_new, x_new, r_new, jmin, fnorm, fraction < 1.0 or trial > 0

    def _record(self, fnorm: float, fresh: bool) -> None:
        self.best = min(self.best, fnorm)
        if self.trace is not None:
            self.trace.append((fnorm, fresh))

    def _iterate(self, fields: Any, settings: Any, border: Any) -> tuple[int, str | None]:
        """Newton's method or chord iterations with Anderson acceleration and refresh (see the class notes)."""
        system = self.system
        contacts = getattr(system, "contacts", ())
        reuse = float(self.reuse or 0.5)
        values = fields[0].values
        u, x = values.ravel().copy(), border.start()
        r, jmin = system.residual(u)
        if (cause := inadmissible(r, jmin)) is not None:
            return 0, cause
        fnorm, error = relative_residual(r, system.dof1, system.dof0), border.error(u)
        self.best = float("inf")
        self._record(fnorm, False)
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
                    f = border.step(self, u, r)
            except (ArithmeticError, np.linalg.LinAlgError, ValueError, RuntimeError) as exc:
                return iteration, f"{type(exc).__name__}: {exc}"
            step = _anderson(f, dU, dF)
            if not np.all(np.isfinite(step)):
                return iteration, "the linear solve gave a non-finite increment"
            step, u_new, x_new, r_new, jmin, fnorm_new, cut = self._trial(u, x, step, fresh, fnorm + error, border)
            error_new = border.error(u_new)
            self._record(fnorm_new, fresh)
            changed = REFRESH_ON_CHANGE and bool(contacts) and contacts_changed(system, u, u_new, sliding=True)
            if fresh and not changed and not cut:  # (a step that changed the contacts or was cut short says
                # nothing of the precision: only a whole Newton step's gain measures the factorisation)
                poor = poor + 1 if not fnorm_new < reuse * fnorm else 0
            rose = not fresh and not (fnorm_new + error_new < fnorm + error and jmin > 0.0)
            if rose and (bool(contacts) or not kept_rise(fnorm_new + error_new, fnorm + error, jmin)):
                # a kept tangent that no longer helps: take the step back, refresh
                border.set(x)
                system.residual(u)  # the state the tangent is assembled at
                self._factorised = False
                continue
            done, cause = verdict(fnorm_new, jmin, u_new, values, settings.tolerance, error_new)
            if done:
                return iteration, cause
            if poor >= STALLED_FRESH and self.precision == "single":
                self.to_double()  # refresh at u_new, in double precision from now on
                f, poor = None, 0
            elif self.reuse is None or fnorm_new > reuse * fnorm or changed or rose:
                self._factorised = False  # refresh at u_new (at every iteration: Newton's method)
                f = None
            else:
                try:
                    f_new = border.step(self, u_new, r_new)
                except (ArithmeticError, np.linalg.LinAlgError, ValueError, RuntimeError) as exc:
                    return iteration, f"{type(exc).__name__}: {exc}"
                if self.depth > 0:
                    dU, dF = [*dU, step][-self.depth:], [*dF, f_new - f][-self.depth:]
                f = f_new
            u, x, r, fnorm, error, fresh = u_new, x_new, r_new, fnorm_new, error_new, False
        values[:] = u.reshape(values.shape)
        return settings.max_iterations, self._stalled(settings, error if x.size else None)


class _FixedLoad:
    """The border of a substep without extra unknowns (pressure control): Newton's step ``-K^-1 r``."""

    def start(self) -> FloatArray:
        return np.zeros(0)

    def set(self, x: FloatArray) -> None:
        pass

    def error(self, u: FloatArray) -> float:
        return 0.0

    def step(self, substep: FastSubstep, u: FloatArray, r: FloatArray) -> FloatArray:
        return -substep.solve(r[substep.system.dof1])


def _anderson(f: FloatArray, dU: list[FloatArray], dF: list[FloatArray]) -> FloatArray:
    """The chord step ``f`` minus the combination of the previous step and chord-step differences that best
    cancels it (least squares)."""
    if not dF:
        return f
    Fm = np.column_stack(dF)
    gamma = np.linalg.lstsq(Fm, f, rcond=None)[0]
    return f - (np.column_stack(dU) + Fm) @ gamma

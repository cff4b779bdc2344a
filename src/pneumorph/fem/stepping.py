"""Quasi-static load stepping on FElupe with reported levels, cut-back and a predictor.

A ramp from load factor 0 to 1 is reported at ``increments`` equally spaced levels (the
dissertation's "method 2", section 4.3: one solve gives the response at ten pressures).
Between two reported levels the solver takes ``substeps`` Newton solves; a substep that
fails is halved (cut-back) without changing the reported levels (optionally, the level
after one that needed a cut-back starts at the substep that converged last). Each substep starts from
the linear extrapolation of the last two converged states, which keeps the very soft
bending mode of a long actuator from costing hundreds of Newton iterations.

Everything a load factor changes (cavity pressure, a pressure-dependent filler modulus)
is set by one callable ``apply(t)``, so the stepping knows nothing about the model.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph import checks
from pneumorph.errors import LimitPointError, SimulationFailed


@dataclass(frozen=True)
class StepSettings:
    """Settings of a load ramp.

    Parameters
    ----------
    increments : int
        Number of reported, equally spaced load levels (the last one is the full load).
    substeps : int
        Substeps per reported increment before any cut-back.
    max_cutbacks : int
        How many times a failed substep may be halved before the solve is abandoned.
    max_iterations : int
        Newton iterations allowed per substep.
    tolerance : float
        Convergence tolerance of FElupe's Newton method on the residual norm.
    predictor : bool
        Start each substep from the linear extrapolation of the last two converged states.

    Examples
    --------
    >>> StepSettings(increments=10, substeps=2).levels()[:3]
    array([0.1, 0.2, 0.3])
    """

    increments: int = 10
    substeps: int = 2
    max_cutbacks: int = 6
    max_iterations: int = 16
    tolerance: float = 1e-8
    predictor: bool = True

    def __post_init__(self) -> None:
        checks.integer(self.increments, "increments", 1, checks.MAX_INCREMENTS, limit="MAX_INCREMENTS")
        checks.integer(self.substeps, "substeps", 1, checks.MAX_SUBSTEPS, limit="MAX_SUBSTEPS")
        checks.integer(self.max_iterations, "max_iterations", 1, 1000)
        checks.integer(self.max_cutbacks, "max_cutbacks", 0, 60)
        checks.real(self.tolerance, "tolerance", 0.0, 1.0, low_open=True)

    def levels(self) -> NDArray[np.float64]:
        """The reported load factors ``1/n, 2/n, ..., 1``."""
        return np.arange(1, self.increments + 1) / self.increments


@dataclass
class RampStatistics:
    """What a ramp cost: Newton iterations and substeps, cut-backs."""

    newton_iterations: int = 0
    substeps: int = 0
    cutbacks: int = 0
    reached: float = 0.0
    history: list[tuple[float, int]] = field(default_factory=list)


def _sumnorm(x: Any) -> float:
    """Euclidean norm of an array, or the sum of the norms of a list of arrays (one per field)."""
    if isinstance(x, (list, tuple)):
        return float(sum(np.linalg.norm(np.asarray(a)) for a in x))
    return float(np.linalg.norm(np.asarray(x)))


def relative_residual(r: Any, dof1: Any = None, dof0: Any = None, eps: float = 1e-3) -> float:
    """The residual norm every Newton method here converges on.

    The norm of the residual of the active degrees of freedom over ``eps`` plus the norm
    of the reaction forces of the prescribed ones, ``|r[dof1]| / (eps + |r[dof0]|)``
    (FElupe's measure, so that both backends stop at the same equilibrium).

    >>> relative_residual(np.array([3e-9, 4e-9, 2.0]), dof1=[0, 1], dof0=[2])
    2.4987...e-09
    """
    r = np.asarray(r)
    active = r[slice(None) if dof1 is None else dof1]
    reactions = r[slice(0, 0) if dof0 is None else dof0]
    return _sumnorm(active) / (eps + _sumnorm(reactions))


def newton_check(dx: Any, x: Any, f: Any, xtol: float, ftol: float, dof1: Any = None, dof0: Any = None,
                 items: Any = None, eps: float = 1e-3, still: float = 0.0,
                 still_residual: float = 1e-4) -> tuple[float, float, bool]:
    """The convergence test of a Newton iteration (FElupe's ``check`` signature).

    Converged when the :func:`relative_residual` is below ``ftol`` and the update ``|dx|``
    below ``xtol`` - FElupe's criterion. With ``still > 0``, an
    update below ``still`` with a relative residual below ``still_residual`` converges as
    well: near an unloaded state the reaction forces that scale the residual are tiny, and
    round-off alone can keep it above ``ftol`` (the paper-silicone coupon).

    Returns ``(|dx|, relative residual, converged)``.

    Examples
    --------
    >>> f = np.array([1e-9, 2.0])
    >>> newton_check(np.array([1e-12]), None, f, 1e-3, 1e-8, dof1=[0], dof0=[1])[2]
    True
    >>> newton_check(np.array([1e-12]), None, np.array([1e-3, 1e-3]), 1e-3, 1e-8, dof1=[0], dof0=[1])[2]
    False
    >>> newton_check(np.array([1e-12]), None, np.array([1e-9, 1e-4]), 1e-3, 1e-8, dof1=[0], dof0=[1], still=1e-9)[2]
    True
    """
    xnorm = _sumnorm(dx)
    fnorm = relative_residual(f, dof1, dof0, eps)
    success = (fnorm < ftol and xnorm < xtol) or (still > 0.0 and xnorm < still and fnorm < still_residual)
    return xnorm, fnorm, bool(success)


def _min_jacobian(fields: Any) -> float:
    """Smallest det F over all quadrature points of the displacement field."""
    import felupe as fem

    F = fields[0].extract(grad=True, sym=False, add_identity=True)
    return float(np.min(fem.math.det(F)))


class FElupeSubstep:
    """Solve one substep of :func:`ramp` with FElupe's assembly and ``newtonraphson``.

    The reference strategy (the other is :class:`pneumorph.fem.fast.newton.FastSubstep`):
    called as ``substep(fields, settings)``, it iterates from the values in ``fields``
    (the ramp's prediction; prescribed values as ``apply`` left them, which carries an
    enforced displacement) and returns ``(iterations, cause of failure or None)``.

    Parameters
    ----------
    items : sequence
        FElupe items (solid bodies, pressure bodies) whose sum is the residual.
    dof1, dof0 : ndarray
        Active and prescribed degrees of freedom.
    solver : callable, optional
        ``solver(A, b)`` for the linear systems (default:
        :func:`pneumorph.fem.linear.default_solver`).
    check : callable, optional
        The convergence test of each iteration (default :func:`newton_check`).

    A trial that fails is cut back, so the numerical warnings of its divergence (singular
    matrix, powers of negative volume ratios) are expected and not shown.
    """

    def __init__(self, items: Sequence[Any], dof1: NDArray[np.int64], dof0: NDArray[np.int64],
                 solver: Callable[[Any, Any], NDArray[np.float64]] | None = None,
                 check: Callable[..., tuple[float, float, bool]] | None = None) -> None:
        from pneumorph.fem.linear import default_solver

        self.items = list(items)
        self.dof1, self.dof0 = dof1, dof0
        self.solver = solver or default_solver()
        self.check = check or newton_check

    def __call__(self, fields: Any, settings: StepSettings) -> tuple[int, str | None]:
        import felupe as fem
        from scipy.sparse.linalg import MatrixRankWarning

        ext0 = np.concatenate([f.values.ravel() for f in fields.fields])[self.dof0]
        try:
            with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                warnings.simplefilter("ignore", MatrixRankWarning)
                res = fem.newtonraphson(
                    items=self.items,
                    x0=fields,
                    dof1=self.dof1,
                    dof0=self.dof0,
                    ext0=ext0,
                    tol=settings.tolerance,
                    maxiter=settings.max_iterations,
                    solver=self.solver,
                    verbose=0,
                    check=self.check,
                )
        except (fem.NewtonConvergenceError, ArithmeticError, np.linalg.LinAlgError, ValueError, RuntimeError) as exc:
            return settings.max_iterations, f"{type(exc).__name__}: {exc}"
        # FElupe iterates on copies of the unknowns and re-links the items' fields to them:
        # point the caller's container (and so every field linked to it) at the result.
        fields.link(res.x)
        iterations = int(res.iterations)
        if not res.success:
            return iterations, "Newton iterations did not reach the tolerance"
        if not all(np.all(np.isfinite(f.values)) for f in fields.fields):
            return iterations, "the solution is not finite"
        jmin = _min_jacobian(fields)
        if not jmin > 0.0:
            return iterations, f"an element inverted (det F = {jmin:.3g})"
        return iterations, None


def _extrapolate(
    states: Sequence[tuple[float, list[NDArray[np.float64]]]], t: float
) -> list[NDArray[np.float64]]:
    """Lagrange extrapolation of the field values of converged states to factor ``t``."""
    times = [s[0] for s in states]
    weights = []
    for j, tj in enumerate(times):
        w = 1.0
        for m, tm in enumerate(times):
            if m != j:
                w *= (t - tm) / (tj - tm)
        weights.append(w)
    return [sum((w * s[1][i] for w, s in zip(weights, states, strict=True)), start=np.zeros_like(states[0][1][i]))
            for i in range(len(states[0][1]))]


def _values(fields: Any) -> list[NDArray[np.float64]]:
    return [f.values.copy() for f in fields.fields]


def _restore(fields: Any, values: Sequence[NDArray[np.float64]]) -> None:
    for f, v in zip(fields.fields, values, strict=False):
        f.values[:] = v


def _failure(t_now: float, t_try: float, cutbacks: int, cause: str,
             fell: tuple[float, float] | None) -> SimulationFailed:
    """The failure of a ramp whose last cut-back failed too: a limit point if ``fell`` (the monitored values
    before and after), the kind a model explains in its own terms; else the plain failure."""
    first = (f"; it failed on the first load step, cut to {t_try:.3g} of the full load: not the size "
             "of the load but the model or the solver settings") if t_now == 0.0 else ""
    why = f"no convergence at load factor {t_try:.4g} after {cutbacks} cut-backs ({cause}){first}"
    if fell is not None:
        return LimitPointError(reached=t_now, cause=why, before=fell[0], after=fell[1], tried=t_try, cutbacks=cutbacks)
    return SimulationFailed(reached=t_now, cause=why)


def ramp(
    items: Sequence[Any],
    fields: Any,
    apply: Callable[[float], None],
    dof1: NDArray[np.int64],
    dof0: NDArray[np.int64],
    settings: StepSettings = StepSettings(),
    on_level: Callable[[int, float], None] | None = None,
    monitor: Callable[[], float] | None = None,
    solver: Callable[[Any, Any], NDArray[np.float64]] | None = None,
    on_substep: Callable[[float], None] | None = None,
    substep: Callable[[Any, StepSettings], tuple[int, str | None]] | None = None,
    predictor_order: int = 1,
    check: Callable[..., tuple[float, float, bool]] | None = None,
    carry: bool = False,
) -> RampStatistics:
    """Ramp a FElupe model from load factor 0 to 1.

    Parameters
    ----------
    items : sequence
        FElupe items (solid bodies, pressure bodies) whose sum is the residual.
    fields : felupe.FieldContainer
        The unknowns; updated in place, ending in the converged state at factor 1.
    apply : callable
        ``apply(t)`` sets every load and load-dependent property for factor ``t``; an
        enforced displacement is set by writing it into the prescribed values of ``fields``.
    dof1, dof0 : ndarray
        Active and prescribed degrees of freedom (prescribed values are held fixed).
    settings : StepSettings
        Increments, substeps, cut-back and Newton settings.
    on_level : callable, optional
        ``on_level(k, t)`` is called after reported level ``k`` (0-based) has converged,
        with the fields in that state: read the results there.
    monitor : callable, optional
        ``monitor()`` returns a scalar of the current state that cannot decrease along a
        stable, rising pressure ramp - the cavity volume, the work-conjugate of the
        pressure. A substep that converges to a state with a smaller value has jumped to
        another (non-physical or unstable) branch and is cut back like a failed one.
    solver : callable, optional
        ``solver(A, b)`` for the linear systems (default:
        :func:`pneumorph.fem.linear.default_solver`).
    on_substep : callable, optional
        ``on_substep(t)`` after every converged substep (before ``on_level``), e.g. to
        follow a rotation continuously.
    substep : callable, optional
        The substep strategy: ``substep(fields, settings)`` solves one substep and returns
        ``(iterations, cause of failure or None)``. Default: :class:`FElupeSubstep` on
        ``items`` with ``solver`` and ``check``; the fast path is a
        :class:`pneumorph.fem.fast.newton.FastSubstep` (``items``, ``solver`` and ``check``
        are then not used).
    predictor_order : int
        Degree of the polynomial through the last converged states that predicts the
        start of a substep (1: linear, 2: quadratic once three states are known).
    check : callable, optional
        The convergence test of each Newton iteration (default :func:`newton_check`).
    carry : bool
        Start a level that follows one that needed a cut-back at the substep that converged
        last, instead of the nominal one: where the load gets harder level by level (a long
        actuator curling up) this saves the failed attempts; where a ramp ends at a load it
        cannot reach, it creeps on in small substeps before it gives up.

    Returns
    -------
    RampStatistics

    Raises
    ------
    SimulationFailed
        If a substep still fails after ``max_cutbacks`` halvings; ``reached`` is the last
        converged load factor and the fields hold that state. Its subclass
        :class:`~pneumorph.errors.LimitPointError` when the last halving converged but the
        ``monitor`` fell: a limit point of the load, with the monitored values.
    """
    strategy = substep or FElupeSubstep(items, dof1, dof0, solver, check)
    stats = RampStatistics()
    current = _values(fields)
    history: list[tuple[float, list[NDArray[np.float64]]]] = [(0.0, current)]  # converged states
    t_now = 0.0
    apply(0.0)
    watched = monitor() if monitor is not None else 0.0
    nominal = 1.0 / (settings.increments * settings.substeps)
    dt, last, cut_back = nominal, nominal, False
    for k, level in enumerate(settings.levels()):
        # with ``carry``, a level after one that needed a cut-back starts at the substep that converged last
        dt = last if carry and cut_back else nominal
        cut_back = False
        cutbacks_here = 0
        while t_now < level - 1e-12:
            t_try = min(t_now + dt, level)
            if settings.predictor and len(history) > 1:
                _restore(fields, _extrapolate(history[-1 - predictor_order:], t_try))
            apply(t_try)
            iterations, cause = strategy(fields, settings)
            stats.newton_iterations += iterations
            value, fell = watched, False
            if cause is None and monitor is not None:
                value = monitor()
                fell = value < watched
                if fell:
                    cause = f"the monitored quantity fell from {watched:.6g} to {value:.6g}"
            if cause is None:
                watched = value
                last = t_try - t_now
                current, t_now = _values(fields), t_try
                history = [*history[-max(2, predictor_order):], (t_now, current)]
                stats.substeps += 1
                stats.history.append((t_now, iterations))
                if on_substep is not None:
                    on_substep(t_now)
                cutbacks_here = 0
                # grow back towards the nominal substep after a successful cut-back
                dt = min(2 * dt, nominal)
                continue
            _restore(fields, current)
            apply(t_now)
            cut_back = True
            cutbacks_here += 1
            stats.cutbacks += 1
            if cutbacks_here > settings.max_cutbacks:
                stats.reached = t_now
                raise _failure(t_now, t_try, settings.max_cutbacks, str(cause), (watched, value) if fell else None)
            dt = (t_try - t_now) / 2.0  # the step that failed, halved (dt may reach past the level)
        stats.reached = t_now
        if on_level is not None:
            on_level(k, level)
    return stats

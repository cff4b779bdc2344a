"""The result of asking a model for one design: a response or a recorded failure."""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

from pneumorph.errors import EvaluationError, SimulationFailed
from pneumorph.models.response import ActuatorModel, Response


@dataclass(frozen=True)
class Outcome:
    """One design's evaluation.

    Attributes
    ----------
    design : str
        The orientation vector, base first.
    response : Response or None
        The response; for a failed solve, the levels that converged before it failed (NaN
        after them), or None if nothing usable was solved.
    failure : str or None
        Why the solve failed (None if it converged).
    reached : float or None
        The highest converged pressure (MPa) of a failed solve.
    cached : bool
        True if it came from the evaluation cache instead of a solve.
    wall_time : float
        Seconds the solve took (of the original solve, for a cached outcome).
    transient : bool
        True for a failure that says nothing about the design itself (the worker process
        solving it died: ``failure`` starts with ``"worker died"``). Such an outcome is
        not to be stored in the evaluation cache; the next run solves the design again.
    screened : bool
        True for a design a screen answered without a solve (the chain's certified rejection of
        a design that cannot clear an obstacle): neither solved nor cached.

    Examples
    --------
    >>> Outcome("01", None, failure="diverged", reached=0.0315).ok
    False
    >>> Outcome("01", None, failure="worker died: exit code 1", transient=True).transient
    True
    >>> Outcome("01", None).solved, Outcome("01", None, cached=True).solved, Outcome("01", None, screened=True).solved
    (True, False, False)
    """

    design: str
    response: Response | None
    failure: str | None = None
    reached: float | None = None
    cached: bool = False
    wall_time: float = 0.0
    transient: bool = False
    screened: bool = False

    @property
    def solved(self) -> bool:
        """True for an outcome of a solve (neither the cache's answer nor a screen's)."""
        return not (self.cached or self.screened)

    @property
    def ok(self) -> bool:
        """True for a converged response."""
        return self.failure is None and self.response is not None and self.response.converged

    def as_cached(self) -> Outcome:
        return replace(self, cached=True)


def solve(model: ActuatorModel, design: str) -> Outcome:
    """Evaluate one design and turn a :class:`SimulationFailed` into a failed outcome.

    Any other exception is a fault of the model, not of the design; it is re-raised as
    :class:`EvaluationError` naming the design (it is never recorded in the cache).
    """
    start = time.perf_counter()
    try:
        response = model.evaluate(design)
    except SimulationFailed as exc:
        p_max = exc.pressure if exc.pressure is not None else float(model.pressures()[-1])
        partial = exc.partial if isinstance(exc.partial, Response) else None  # the levels it did converge
        return Outcome(design, partial, exc.cause or str(exc), exc.reached * p_max,
                       wall_time=time.perf_counter() - start)
    except Exception as exc:
        raise EvaluationError(f"design {design}: the model raised {type(exc).__name__}: {exc}") from exc
    wall = time.perf_counter() - start
    if not response.converged:
        return Outcome(design, response, response.failure or "did not converge", response.reached, wall_time=wall)
    return Outcome(design, response, wall_time=wall)

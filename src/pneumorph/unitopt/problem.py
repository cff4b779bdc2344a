"""The unit optimisation as a pymoo problem, and the evaluator that solves its candidates.

pymoo's style keeps the problem, the algorithm, the evaluator and the driver apart:

- :class:`CandidateEvaluator` turns rows of design variables into solved candidates: each
  row becomes a :class:`~pneumorph.unitopt.probe.UnitProbe` and goes, as a ``(model,
  design)`` case, through any of the package's evaluators (``iter_cases``; the cached one
  answers a rerun from its SQLite file). It keeps every candidate it was asked for.
- :class:`UnitProblem` (a :class:`pymoo.core.problem.Problem`): two objectives to minimise,
  ``-Omega`` and ``h_b``, and two inequality constraints ``g <= 0``: the strain
  ``strain / limit - 1``, and the ramp ``1 - reached / pressure`` (a unit whose ramp stops
  at a limit point before the design pressure is infeasible by the pressure it lacked).
- :class:`SnapRepair`: pymoo's repair operator that rounds every offspring to the space's
  resolution, so the population holds the dimensions that were solved.

The algorithm (NSGA-II) and the driver are in :mod:`pneumorph.unitopt.run`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from pymoo.core.problem import Problem
from pymoo.core.repair import Repair

from pneumorph.errors import SettingsError
from pneumorph.execution.outcome import Outcome
from pneumorph.geometry.unit import UnitSpec
from pneumorph.unitopt.measures import UnitMeasures
from pneumorph.unitopt.probe import DEFAULT_UNITS, UnitProbe, measures_of
from pneumorph.unitopt.space import DesignSpace, FloatArray

#: the objective values of a unit whose ramp failed (only its constraint violation ranks it)
FAILED_OBJECTIVES = (0.0, 1.0e3)


def check_strain_limit(limit: float) -> float:
    """``limit`` as a float, if it is a positive finite strain.

    Raises
    ------
    SettingsError
        Not a positive finite number.

    Examples
    --------
    >>> check_strain_limit(4.4)
    4.4
    >>> check_strain_limit(0)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: the strain limit must be a positive finite strain (e.g. 4.4 for 440 %), got 0
    """
    if isinstance(limit, bool) or not isinstance(limit, (int, float)) or not math.isfinite(limit) or limit <= 0:
        raise SettingsError(f"the strain limit must be a positive finite strain (e.g. 4.4 for 440 %), got {limit!r}")
    return float(limit)


@dataclass(frozen=True)
class UnitCandidate:
    """One solved candidate unit.

    Attributes
    ----------
    values : dict of str to float
        The varied dimensions (mm).
    unit : UnitSpec
        The unit.
    measures : UnitMeasures or None
        Omega, h_b and strain; None if the ramp failed.
    failure : str or None
        Why the ramp stopped.
    reached : float
        The highest pressure solved (MPa).
    cached : bool
        Answered from the evaluation cache.
    wall_time : float
        Seconds of its solve (of the original solve if cached).
    generation : int
        The generation that first asked for it (0: the initial population).
    """

    values: dict[str, float]
    unit: UnitSpec
    measures: UnitMeasures | None
    failure: str | None
    reached: float
    cached: bool
    wall_time: float
    generation: int

    def feasible(self, strain_limit: float) -> bool:
        """Solved to the design pressure with the strain within ``strain_limit``."""
        return self.measures is not None and self.measures.strain <= strain_limit

    def objectives(self) -> tuple[float, float]:
        """``(-Omega, h_b)``, both minimised; :data:`FAILED_OBJECTIVES` for a failed ramp."""
        if self.measures is None:
            return FAILED_OBJECTIVES
        return (-self.measures.omega_deg, self.measures.balloon_mm)

    def constraints(self, strain_limit: float, pressure: float) -> tuple[float, float]:
        """``(strain / limit - 1, 1 - reached / pressure)``: feasible where both are <= 0."""
        if self.measures is None:
            return (0.0, max(1e-6, 1.0 - self.reached / pressure))
        return (self.measures.strain / strain_limit - 1.0, 0.0)

    def row(self, strain_limit: float) -> dict[str, Any]:
        """A flat record for tables (lengths mm, angles degrees)."""
        m = self.measures.to_dict() if self.measures is not None else dict.fromkeys(UnitMeasures.__dataclass_fields__)
        return {**self.values, **m, "feasible": self.feasible(strain_limit), "failure": self.failure,
                "reached_kpa": self.reached * 1e3, "generation": self.generation, "cached": self.cached,
                "wall_time_s": self.wall_time}


class CandidateEvaluator:
    """Solves candidate units through one of the package's evaluators (see the module docstring).

    Parameters
    ----------
    space : DesignSpace
        Where the candidates come from.
    evaluator : Evaluator
        Anything with ``iter_cases`` (:mod:`pneumorph.execution`), e.g. a ``CachedEvaluator``.
    n_units : int
        Units of the probe actuator.
    pressure : float
        Design pressure, MPa.
    on_candidate : callable, optional
        ``on_candidate(candidate)`` as each one is solved (progress).
    """

    def __init__(self, space: DesignSpace, evaluator: Any, n_units: int = DEFAULT_UNITS, pressure: float = 0.045,
                 on_candidate: Callable[[UnitCandidate], None] | None = None) -> None:
        self.space = space
        self.evaluator = evaluator
        self.n_units = n_units
        self.pressure = pressure
        self.on_candidate = on_candidate
        self.generation = 0
        #: every candidate asked for, by its snapped values
        self.history: dict[tuple[float, ...], UnitCandidate] = {}

    def probe(self, unit: UnitSpec) -> UnitProbe:
        return UnitProbe(unit, self.n_units, self.pressure)

    def evaluate(self, rows: FloatArray) -> list[UnitCandidate]:
        """The candidates of ``rows`` (shape (m, n_var)), in order; each distinct one solved once."""
        keys = [tuple(self.space.snap(x).tolist()) for x in np.atleast_2d(rows)]
        todo = list(dict.fromkeys(k for k in keys if k not in self.history))
        probes = [self.probe(self.space.unit(k)) for k in todo]
        for i, outcome in self.evaluator.iter_cases([(p, p.design) for p in probes]):
            candidate = self._candidate(todo[i], probes[i].unit, outcome)
            self.history[todo[i]] = candidate
            if self.on_candidate is not None:
                self.on_candidate(candidate)
        return [self.history[k] for k in keys]

    def _candidate(self, key: tuple[float, ...], unit: UnitSpec, outcome: Outcome) -> UnitCandidate:
        measures = measures_of(outcome.response) if outcome.ok and outcome.response is not None else None
        reached = self.pressure if outcome.ok else float(outcome.reached or 0.0)
        return UnitCandidate(dict(zip(self.space.names, key, strict=True)), unit, measures, outcome.failure, reached,
                         outcome.cached, outcome.wall_time, self.generation)


class SnapRepair(Repair):
    """Rounds offspring to the design space's resolution (pymoo's repair operator)."""

    def __init__(self, space: DesignSpace) -> None:
        super().__init__()
        self.space = space

    def _do(self, problem: Any, X: FloatArray, **kwargs: Any) -> FloatArray:
        return np.array([self.space.snap(x) for x in X])


class UnitProblem(Problem):
    """Maximise Omega and minimise h_b within a strain limit (see the module docstring).

    Parameters
    ----------
    candidates : CandidateEvaluator
        Solves the rows pymoo asks for.
    strain_limit : float
        The largest principal nominal strain allowed in the body material.
    """

    def __init__(self, candidates: CandidateEvaluator, strain_limit: float) -> None:
        space = candidates.space
        super().__init__(n_var=len(space.variables), n_obj=2, n_ieq_constr=2, xl=space.lower, xu=space.upper)
        self.candidates = candidates
        self.strain_limit = check_strain_limit(strain_limit)

    def _evaluate(self, x: FloatArray, out: dict[str, Any], *args: Any, **kwargs: Any) -> None:
        solved = self.candidates.evaluate(x)
        out["F"] = np.array([c.objectives() for c in solved], dtype=float)
        out["G"] = np.array([c.constraints(self.strain_limit, self.candidates.pressure) for c in solved],
                            dtype=float)


__all__ = [
    "FAILED_OBJECTIVES",
    "CandidateEvaluator",
    "SnapRepair",
    "UnitCandidate",
    "UnitProblem",
    "check_strain_limit",
]

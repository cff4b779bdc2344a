"""Bookkeeping shared by the searches: scores of the designs seen, hall of fame."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from pneumorph.design.objectives.fitness import Score, score
from pneumorph.design.objectives.targets import Objective
from pneumorph.errors import SearchConfigError
from pneumorph.execution.evaluators import Evaluator, SerialEvaluator
from pneumorph.execution.outcome import Outcome
from pneumorph.models.response import ActuatorModel, Response


@dataclass(frozen=True)
class Candidate:
    """A design with its fitness.

    Attributes
    ----------
    design : str
        Orientation vector, base first.
    value : float
        Objective value at the best level (mm or degrees; worst for a failed design).
    level : int or None
        Index of the best reported level.
    pressure : float or None
        Pressure of the best level, in MPa: the unit of the models and their results
        (``Response.pressures``, ``model.ramp.pressure``). Settings, reports and JSON files
        give kPa (``pressure_kpa``): ``pressure * 1e3``.
    failure : str or None
        Why the solve failed, if it did.
    response : Response or None
        The response (for figures and reports).
    """

    design: str
    value: float
    level: int | None
    pressure: float | None
    failure: str | None = None
    response: Response | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary (pressure in kPa)."""
        return {
            "design": self.design,
            "value": self.value,
            "level": self.level,
            "pressure_kpa": None if self.pressure is None else round(self.pressure * 1e3, 9),
            "failure": self.failure,
        }


def check_units(model: ActuatorModel) -> int:
    """The model's number of units, checked to be at least 1."""
    n = int(getattr(model, "n_units", 0) or 0)
    if n < 1:
        raise SearchConfigError(f"the actuator needs at least 1 unit, got {n}")
    return n


class ScoreBook:
    """Scores of every design evaluated in one search (each design is solved once).

    ``solves`` counts the designs the evaluator solved, ``hits`` those it answered from
    the evaluation cache (a design scored before in this search is asked of neither).

    Parameters
    ----------
    model : ActuatorModel
    objective : ProfileTarget or TipGoal
    evaluator : Evaluator, optional
        Serial by default.
    """

    def __init__(self, model: ActuatorModel, objective: Objective, evaluator: Evaluator | None = None) -> None:
        self.n_units = check_units(model)
        self.model = model
        self.objective = objective
        self.sense = objective.sense
        self.evaluator = evaluator if evaluator is not None else SerialEvaluator()
        self.n_levels = len(model.pressures())
        self.scores: dict[str, Score] = {}
        self.outcomes: dict[str, Outcome] = {}
        self.solves = 0
        self.hits = 0

    def add(self, outcome: Outcome) -> Score:
        """Score an outcome and remember it."""
        s = score(outcome.response if outcome.failure is None else None, self.objective, self.n_levels)
        self.scores[outcome.design] = s
        self.outcomes[outcome.design] = outcome
        return s

    def score_many(self, designs: Sequence[str]) -> list[Score]:
        """Scores of ``designs``; the ones not seen before are evaluated as one batch."""
        new = [d for d in dict.fromkeys(designs) if d not in self.scores]
        if new:
            for outcome in self.evaluator.evaluate_many(self.model, new):
                self.solves += outcome.solved
                self.hits += outcome.cached
                self.add(outcome)
        return [self.scores[d] for d in designs]

    def ranking(self) -> list[str]:
        """All designs seen, best first (ties: the smaller orientation string first)."""
        sign = 1.0 if self.sense == "min" else -1.0
        return sorted(self.scores, key=lambda d: (sign * self.scores[d].value, d))

    def candidate(self, design: str) -> Candidate:
        s, o = self.scores[design], self.outcomes[design]
        return Candidate(design, s.value, s.level, s.pressure, o.failure, o.response)

    def hall_of_fame(self, k: int) -> tuple[Candidate, ...]:
        """The ``k`` best distinct designs, best first."""
        return tuple(self.candidate(d) for d in self.ranking()[:k])

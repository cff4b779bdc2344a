"""The FE exhaustive search as a search strategy: all 2^n designs of one unit type
(:func:`pneumorph.design.search.exhaustive.run_exhaustive`)."""

from __future__ import annotations

from typing import Any

from pneumorph.design.algorithms.problem import Problem, Search, SearchOutcome
from pneumorph.design.certified.refine import REFINE_TOP, refine_verified
from pneumorph.design.runs.comparison import compare_with_reference
from pneumorph.design.runs.robustness import winner_robustness
from pneumorph.design.search.exhaustive import run_exhaustive


class ExhaustiveSearch(Search):
    """Every design solved by the problem's evaluator, ranked; the winner's FE robustness after it, and with a
    reference model (the nominal one of an identified model) how the reference's optimum does here. A certified
    run handed to it (a short actuator) with ``[design] refine`` solves its best designs again on the finer mesh.

    Parameters
    ----------
    note : str
        Why this search (a certified run of an actuator too short for its chain table says so).
    """

    name = "exhaustive"

    def __init__(self, note: str = "") -> None:
        self.note = note

    def run(self, problem: Problem) -> SearchOutcome:
        """The ranking of all designs and its hall of fame."""
        ex = run_exhaustive(problem.model, problem.objective, problem.evaluator,
                            hall_of_fame=problem.config.ga.hall_of_fame, on_progress=problem.on_progress)
        best = ex.hall_of_fame[0] if ex.hall_of_fame else None
        comparison = None if best is None else compare_with_reference(problem, best, exhaustive=True)
        refinement = None if best is None else _refinement(problem, ex.ranking, ex.scores, best.design)
        return SearchOutcome(ex.hall_of_fame, ranking=[(d, ex.scores[d]) for d in ex.ranking],
                             robustness=winner_robustness(problem, best), comparison=comparison,
                             refinement=refinement)


def _refinement(problem: Problem, ranking: tuple[str, ...], scores: dict[str, Any],
                winner: str) -> dict[str, Any] | None:
    """With ``[design] refine``: the best designs (``[design] verify`` of them, else one batch of the workers, at
    least :data:`~pneumorph.design.certified.refine.REFINE_TOP`) solved again on the finer mesh, as the certified
    search refines its verified ones; None without it."""
    size = getattr(problem.config, "refine", 0.0)
    if not size:
        return None
    values = {d: scores[d].value for d in ranking if not scores[d].failed}
    top = list(values)[:max(getattr(problem.config, "verify", None) or problem.workers, REFINE_TOP)]
    return refine_verified(problem.model, problem.objective, top, {d: values[d] for d in top}, winner, size,
                           problem.evaluator, say=problem.say)

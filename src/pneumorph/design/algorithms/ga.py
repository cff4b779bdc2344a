"""The genetic algorithm as a search strategy: :func:`pneumorph.design.search.genetic.run_ga` on a
:class:`~pneumorph.design.algorithms.problem.Problem`, its generations logged to ``generations.csv``."""

from __future__ import annotations

from pneumorph.design.algorithms.problem import Problem, Search, SearchOutcome
from pneumorph.design.runs.folder import GenerationLog
from pneumorph.design.runs.robustness import winner_robustness
from pneumorph.design.search.genetic import GenerationStats, run_ga


class GeneticSearch(Search):
    """The GA of ``config.ga`` through the problem's evaluator; the winner's FE robustness after it.

    A resumed run appends to the folder's generation log (a generation is logged once, by the
    run that first computed it); a Ctrl-C keeps the generations run so far.
    """

    name = "ga"

    def __init__(self) -> None:
        self._log: GenerationLog | None = None

    def run(self, problem: Problem) -> SearchOutcome:
        """The GA's hall of fame and generations."""
        log = None if problem.folder is None else GenerationLog(problem.folder / "generations.csv",
                                                                 resume=problem.resumed)
        self._log = log

        def on_generation(stats: GenerationStats) -> None:
            if log is not None:
                log(stats)
            if problem.on_generation is not None:
                problem.on_generation(stats)

        try:
            ga = run_ga(problem.model, problem.objective, problem.config.ga, problem.evaluator, on_generation,
                        on_message=problem.say)
        finally:
            if log is not None:
                log.close()
        best = ga.hall_of_fame[0] if ga.hall_of_fame else None
        return SearchOutcome(ga.hall_of_fame, ga.history, robustness=winner_robustness(problem, best))

    def interrupted(self) -> SearchOutcome:
        """The generations logged before the interrupt."""
        return SearchOutcome(history=tuple(self._log.rows) if self._log is not None else ())

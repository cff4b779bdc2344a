"""The robust ranking as a search strategy (``[design] robust = "worst"`` or ``"mean"``): the
certified search, then every design it scored ranked by its worst or mean error under the
mould tolerance (the chain with the unit's tolerance tables), the most robust verified by FE."""

from __future__ import annotations

from dataclasses import replace

from pneumorph.design.algorithms.certified import CertifiedSearch
from pneumorph.design.algorithms.problem import Problem, SearchOutcome
from pneumorph.design.runs.robustness import chain_robustness, robust_ranking, robust_winner


class RobustSearch(CertifiedSearch):
    """:class:`CertifiedSearch` whose winner is the most robust design (:attr:`SearchOutcome.robust_winner`)."""

    def robustness(self, problem: Problem, outcome: SearchOutcome) -> SearchOutcome:
        """The certified winner's spread, the ranking by ``config.robust`` and the most robust design's."""
        config, cert = problem.config, outcome.certified
        if self.tables is None or cert is None or config.robust is None:  # no tolerance tables: as certified
            return super().robustness(problem, outcome)
        rows, _ = robust_ranking(config, self.chain, self.tables, problem.objective, cert.scores.bits)
        best = robust_winner(config, problem.model, problem.objective, problem.evaluator, rows)
        problem.say(f"most robust by the {config.robust} error under +-{config.tolerance:g} mm: {best.design} "
                    f"(chain {rows[0][config.robust]:.4g}; FE nominal {best.value:.4g})")
        outcome = super().robustness(problem, outcome)
        assert outcome.robustness is not None
        winner = chain_robustness(config, self.chain, self.tables, problem.objective, best)["winner"]
        robustness = {**outcome.robustness, "statistic": config.robust, "ranking": rows, "robust_winner": winner}
        return replace(outcome, robustness=robustness, robust_winner=best)

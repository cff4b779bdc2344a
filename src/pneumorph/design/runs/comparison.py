"""Designing again with an identified model: the nominal model's optimum judged by the new model.

``pneumorph design --model-file identified.toml`` certifies the optimum of the identified
model (:mod:`pneumorph.identify`). What a user wants to know next is whether the new design
is worth casting: how the design the nominal model chose does on the identified model. A
certified run given a *reference* model (the nominal one) finds the reference's optimum as
it finds its own (its chain table, the best verified by one FE solve of the reference
model) and solves that design on the run's model. Both designs are then judged by the run's
model, by FE: the run's winner at its verified value, the reference's winner at one more
solve. Nothing is built: a reference model that no shipped or kept chain table serves is
reported as such.
"""

from __future__ import annotations

from typing import Any

from pneumorph.design.certified.search import certified_search
from pneumorph.design.search.exhaustive import run_exhaustive
from pneumorph.design.search.scoring import Candidate, ScoreBook
from pneumorph.errors import PneumorphError
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import serve_table


def compare_with_reference(problem: Any, winner: Candidate, exhaustive: bool = False) -> dict[str, Any] | None:
    """The reference model's optimum and this run's winner, both by this run's model.

    Parameters
    ----------
    problem : Problem
        With ``reference``: the model whose optimum is compared (None: no comparison).
    winner : Candidate
        This run's FE-verified winner.
    exhaustive : bool
        This run searched every design by FE (an actuator too short for a chain table): the
        reference's optimum is searched so too (its solves are the nominal run's, from the
        evaluation cache, when that run was made with the same cache).

    Returns
    -------
    dict or None
        ``reference_design`` and ``reference_value`` (the reference's optimum and its
        value on the reference model), ``reference_on_model`` (that design's value on
        this run's model, FE), ``winner_design`` and ``winner_value`` (this run's), ``gain``
        (how much better the run's winner is on its model: positive when it is, in the
        objective's unit), ``same`` (the same design), ``unit``; or ``note`` alone when the
        reference has no chain table or a solve failed.
    """
    reference = problem.reference
    if reference is None:
        return None
    objective = problem.objective
    if exhaustive:
        ranked = run_exhaustive(reference, objective, problem.evaluator, hall_of_fame=1)
        if not ranked.hall_of_fame:
            return {"note": "no design of the nominal model solved"}
        ref = ranked.hall_of_fame[0]
    else:
        served = serve_table(reference, problem.table_dir)
        if served is None:
            return {"note": "the nominal model has no shipped or kept chain table: its optimum was not searched"}
        try:
            ref = certified_search(served.model, ChainModel(served.table, problem.config.units), objective,
                                   problem.evaluator, verify=1).winner
        except PneumorphError as exc:
            return {"note": f"the nominal model's search failed: {exc}"}
    problem.say(f"the nominal model's optimum {ref.design} ({ref.value:.4g} {objective.unit} on the nominal model): "
                "solved on this model")
    book = ScoreBook(problem.model, objective, problem.evaluator)
    book.score_many([ref.design])
    on_model = book.candidate(ref.design)
    if on_model.failure is not None or ref.failure is not None or winner.failure is not None:
        return {"note": f"a solve failed: {on_model.failure or ref.failure or winner.failure}"}
    sign = 1.0 if objective.sense == "min" else -1.0
    return {"reference_design": ref.design, "reference_value": ref.value, "reference_on_model": on_model.value,
            "winner_design": winner.design, "winner_value": winner.value,
            "gain": sign * (on_model.value - winner.value), "same": ref.design == winner.design,
            "unit": objective.unit}


def comparison_lines(comparison: dict[str, Any] | None) -> list[str]:
    """The comparison in words (the report's and the command line's lines; none without one).

    >>> line, = comparison_lines({"reference_design": "0011", "reference_value": 7.4, "reference_on_model": 9.1,
    ...                           "winner_design": "0111", "winner_value": 6.2, "gain": 2.9, "same": False,
    ...                           "unit": "mm"})
    >>> print(line)
    the nominal model chose 0011 (7.4 mm there); on this model it gives 9.1 mm, this design 0111 gives
    6.2 mm: 2.9 mm better
    """
    if comparison is None:
        return []
    if "note" in comparison:
        return [f"comparison with the nominal model: {comparison['note']}"]
    c, unit = comparison, comparison["unit"]
    if c["same"]:
        return [f"the nominal model chose the same design {c['winner_design']} ({c['reference_value']:.4g} {unit} "
                f"there, {c['winner_value']:.4g} {unit} on this model)"]
    better = "better" if c["gain"] >= 0 else "worse"
    return [f"the nominal model chose {c['reference_design']} ({c['reference_value']:.4g} {unit} there); on this "
            f"model it gives {c['reference_on_model']:.4g} {unit}, this design {c['winner_design']} gives "
            f"{c['winner_value']:.4g} {unit}: {abs(c['gain']):.4g} {unit} {better}"]


__all__ = ["compare_with_reference", "comparison_lines"]

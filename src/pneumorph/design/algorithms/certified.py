"""The certified search as a search strategy: every design scored by the chain model, the best
verified by FE (:func:`pneumorph.design.certified.search.certified_search`).

Before the folder is touched it picks its chain table (:func:`pneumorph.design.certified.planning.plan_search`):
a table of the model's source, or of a longer ramp of the same step restricted to the
levels at or below the model's pressure (the FE verifications then use the model remade with
those levels); for an actuator shorter than the table needs it hands over to the FE
exhaustive search of all its designs. A table that no shipped or kept table serves is built
under the run folder's lock (or, with ``build`` off, refused with
:class:`~pneumorph.errors.MissingTableError`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from pneumorph.design.algorithms.exhaustive import ExhaustiveSearch
from pneumorph.design.algorithms.problem import Algorithm, Problem, Search, SearchOutcome
from pneumorph.design.certified.branching import open_cap
from pneumorph.design.certified.planning import SearchPlan, check_handover, plan_search
from pneumorph.design.certified.refine import REFINE_TOP, check_refine
from pneumorph.design.certified.search import CertifiedResult, certified_search, chain_candidate
from pneumorph.design.objectives.fitness import Score
from pneumorph.design.runs.comparison import compare_with_reference
from pneumorph.design.runs.robustness import chain_robustness, winner_robustness
from pneumorph.errors import LocalityError, MissingTableError, PneumorphError, SearchConfigError
from pneumorph.models.chain.model import ChainModel, in_space
from pneumorph.models.chain.sources import limits_text, serve_table, served_as_built, table_for
from pneumorph.models.factory import make_model
from pneumorph.models.response import ActuatorModel
from pneumorph.sensitivity.robust import find_tolerance_tables, tolerance_plan_text, tolerance_tables_for
from pneumorph.sensitivity.tolerances import Tolerance

#: open prefixes the branch-and-bound keeps for a table served beyond its build's tolerance (its errors prune
#: little: the 2D table of the built-in library, 5.95 mm, held 6 GB for 20 minutes with the default 500,000),
#: unless ``[design] max_open`` says otherwise
LOOSE_NODES = 20_000


def max_open(config: Any, model: Any, loose: bool = False) -> int:
    """The open prefixes the certified search's branch-and-bound keeps at most for ``model``: ``[design] max_open``
    if given, else :data:`~pneumorph.design.certified.branching.MAX_NODES` lowered to fit
    :data:`~pneumorph.design.certified.branching.MAX_OPEN_MEMORY` (``2k`` children a prefix over ``k`` unit types;
    a chain in space's prefixes take more, :func:`~pneumorph.design.certified.branching.prefix_bytes`), and at most
    :data:`LOOSE_NODES` for a ``loose`` table.

    Raises :class:`~pneumorph.errors.SearchBudgetError` where the given cap's memory passes the budget.

    >>> from pneumorph.design.config import DesignConfig
    >>> from pneumorph.models import make_model
    >>> model = make_model(15, {"fidelity": "2d"})
    >>> max_open(DesignConfig(), model), max_open(DesignConfig(), model, loose=True)
    (500000, 20000)
    >>> max_open(DesignConfig(max_open=3_000_000), model)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchBudgetError: max_open 3,000,000: ... 18.0 GB at one depth ...; give at most 666,666
    """
    library = getattr(model, "library", None)
    choices = 2 * len(library.units) if library is not None else 2
    cap = open_cap(choices, len(model.pressures()), config.max_open, space=in_space(model))
    return cap if config.max_open is not None or not loose else min(cap, LOOSE_NODES)


class CertifiedSearch(Search):
    """The certified search of the problem's model through its chain table (see the module)."""

    name = "certified"

    def __init__(self) -> None:
        self.plan_: SearchPlan | None = None
        self.chain: ChainModel | None = None
        self.tables: Any = None

    def plan(self, problem: Problem) -> tuple[Algorithm, Problem]:
        """The table that serves the model (and the model remade with its levels), or the exhaustive search of a
        short actuator; refused under gravity, without a table it may build, or with a refinement that is not
        finer or would not fit in memory."""
        config, model = problem.config, problem.model
        if getattr(model, "gravity", None) is not None:
            raise LocalityError("the certified search needs a free actuator (its chain model does not hold under "
                                "gravity); search with --search ga or exhaustive")
        if getattr(model, "obstacles", ()):
            raise LocalityError("the certified search needs a free actuator (its chain model knows no contact with "
                                "obstacles); search with --search ga or exhaustive")
        plan = plan_search(config, model, problem.table_dir, build=problem.build, workers=problem.workers)
        self.plan_, self.note = plan, plan.note
        if plan.served is not None:
            model = plan.served.model  # the FE verifications report the chain's levels
            if not problem.build and _tolerance_tables_wanted(config, model):
                _check_tolerance_tables(config, model, problem)
        if config.refine:  # the exhaustive search of a short actuator refines its best designs too
            check_refine(model, config.refine, parallel=max(1, min(problem.workers, config.verify or 1024)))
        if plan.search == "exhaustive":
            check_handover(config, plan)  # what it has no use for, refused before any solve
            return ExhaustiveSearch(note=plan.note), problem
        max_open(config, model)  # a cap whose open prefixes would pass the memory budget: refused before the search
        return self, replace(problem, model=model)

    def setup(self, problem: Problem) -> tuple[Problem, dict[str, Any]]:
        """The chain table (built now, if its plan said so, under the table's lock) and the unit's tolerance
        tables; the table's fingerprint for the provenance. A table built to the levels every design reached
        (a design did not converge to the top pressure) remakes the model with those levels, saying so."""
        assert self.plan_ is not None
        if self.plan_.served is not None:
            table = self.plan_.served.table
        else:  # a model the chain cannot represent raises LocalityError and leaves nothing behind
            table = table_for(problem.model, _training(problem.model), folder=problem.table_dir,
                              evaluator=problem.evaluator, on_progress=problem.say)
            if limits_text(table):
                problem.say(f"the chain table: {limits_text(table)}")
            served = served_as_built(table, problem.model)
            if served.restricted:
                problem.say(f"the design goes on at the levels the table serves: {served.origin_text()}, "
                            f"{served.levels_text()}")
                problem = replace(problem, model=served.model)
        self.chain = ChainModel(table, problem.config.units)
        if _tolerance_tables_wanted(problem.config, problem.model):  # of one unit type
            self.tables = tolerance_tables_for(problem.model, Tolerance(problem.config.tolerance),
                                               folder=problem.table_dir, evaluator=problem.evaluator,
                                               on_progress=problem.say)
        entries: dict[str, Any] = {"chain_table": table.fingerprint()}
        if "restricted_from" in table.source:
            entries["chain_table_restricted_from"] = table.source["restricted_from"]
        if isinstance(cut := table.source.get("cut_from"), dict):  # the designs that failed, by name
            entries["chain_table_cut_from"] = {**cut, "failed": sorted(cut.get("failed", {}))}
        return problem, entries

    def run(self, problem: Problem) -> SearchOutcome:
        """The certificate, its winner and runners-up, the chain's best 1,000, the mesh note or refinement,
        the winner's robustness, the 2D model's opinion and, with a reference model, its optimum on this one."""
        config, chain = problem.config, self.chain
        assert chain is not None
        verify = max(config.verify or problem.workers, REFINE_TOP if config.refine else 1)
        cert = certified_search(problem.model, chain, problem.objective, problem.evaluator, verify=verify,
                                certify=config.certify, hall_of_fame=config.ga.hall_of_fame,
                                margin=config.margin, on_progress=problem.say, epsilon=config.epsilon,
                                max_nodes=max_open(config, problem.model, loose=bool(limits_text(chain.table))))
        order = cert.scores.order()[:1000]
        names = chain.table.texts(cert.scores.bits[order])
        outcome = SearchOutcome(cert.hall_of_fame, certified=cert, refinement=_refinement(problem, cert),
                          ranking=[(d, _chain_score(cert, i)) for d, i in zip(names, order, strict=False)])
        outcome = self.robustness(problem, outcome)
        return replace(outcome, opinion_2d=_opinion_2d(problem, cert),
                       comparison=compare_with_reference(problem, outcome.robust_winner or cert.winner))

    def robustness(self, problem: Problem, outcome: SearchOutcome) -> SearchOutcome:
        """The winner's spread under the mould tolerance: by the chain with the unit's tolerance tables, else by
        FE solves."""
        cert, config = outcome.certified, problem.config
        assert cert is not None
        if config.tolerance == 0 or self.tables is None:
            return replace(outcome, robustness=winner_robustness(problem, cert.winner))
        out = chain_robustness(config, self.chain, self.tables, problem.objective, cert.winner)
        w, u = out["winner"], problem.objective.unit
        problem.say(f"robustness of {w['design']} under +-{config.tolerance:g} mm ({config.samples(True)} samples, "
                    f"chain): mean {w['mean']:.4g} {u}, 95th percentile {w['p95']:.4g} {u}, worst {w['worst']:.4g} {u}")
        return replace(outcome, robustness=out)


def _check_tolerance_tables(config: Any, model: Any, problem: Problem) -> None:
    """Refuse a run that may not build the tolerance tables it needs (``build`` off)."""
    tolerance = Tolerance(config.tolerance)
    if find_tolerance_tables(model, tolerance, problem.table_dir) is None:
        raise MissingTableError(
            f"--no-build: the mould tolerance tables of this unit (+-{config.tolerance:g} mm) are neither "
            f"shipped nor kept in {problem.table_dir}; run without --no-build to build them "
            f"({tolerance_plan_text(model, tolerance, problem.workers, what=False)}), or leave the robustness "
            "report out with --tolerance 0")


def _refinement(problem: Problem, cert: CertifiedResult) -> dict[str, Any] | None:
    """With ``[design] refine`` the verified designs on the finer mesh (:func:`.refine.refine_verified`), else
    what the shipped mesh study says about them (:func:`.refine.mesh_note`)."""
    from pneumorph.design.certified.refine import mesh_note, refine_verified

    values = {d: c.value for d, c in cert.verified.items() if c.failure is None}
    if problem.config.refine:
        return refine_verified(problem.model, problem.objective, list(values), values, cert.winner.design,
                               problem.config.refine, problem.evaluator, say=problem.say)
    note = mesh_note(problem.model, problem.objective, values, cert.winner.design)
    return None if note is None else {"study": note}


def _tolerance_tables_wanted(config: Any, model: ActuatorModel) -> bool:
    """Whether a certified run scores its winner's robustness with the unit's tolerance tables (one unit type)."""
    return bool(config.tolerance > 0 and hasattr(model, "variant") and not getattr(model, "mixed", False))


def _training(model: ActuatorModel) -> Any:
    """``n -> the same model with n units`` (the training actuator of a new chain table)."""
    with_units = getattr(model, "with_units", None)
    if not callable(with_units):
        def refuse(n: int) -> Any:
            raise SearchConfigError(f"the {getattr(model, 'fidelity', '?')} model cannot be re-built with other "
                                    "lengths to fit a chain table; give a table (chain_table) or another search")
        return refuse
    return with_units


def _chain_score(cert: CertifiedResult, i: int) -> Score:
    """The chain's :class:`Score` of the ``i``-th scored design."""
    sc = cert.scores
    sign = 1.0 if cert.certificate["sense"] == "min" else -1.0
    level = int(sc.level[i])
    pressures = cert.winner.response.pressures if cert.winner.response is not None else None
    p = None if pressures is None else float(pressures[level])
    return Score(sc.per_level[i], level, sign * float(sc.cost[i]), p)


def _opinion_2d(problem: Problem, cert: CertifiedResult) -> dict[str, float]:
    """The 2D reduced-order model's values of the listed designs (its shipped chain table, at the levels the
    chain scored), if it has one."""
    model, config = problem.model, problem.config
    if getattr(model, "fidelity", None) != "3d":
        return {}
    try:
        model2d = make_model(config.units, {**config.model, "fidelity": "2d"})
        served = serve_table(model2d)
        if served is None or not np.allclose(served.table.pressures, model.pressures(), rtol=0, atol=1e-12):
            return {}
        chain = ChainModel(served.table, config.units)
    except PneumorphError:
        return {}
    designs = dict.fromkeys([cert.winner.design, *(c.design for c in cert.hall_of_fame)])
    return {d: chain_candidate(chain, problem.objective, d).value for d in designs}

"""A design problem, what a search algorithm makes of it, and the interface every algorithm has.

As in pymoo, the problem, the algorithm and the driver are apart:

- :class:`Problem` - what is searched: the settings, the model, the objective, the
  evaluator (with its cache) and where progress is said. Plain data, replaced (never
  changed) as the driver learns more (the evaluator once the folder is claimed).
- :class:`Algorithm` - how it is searched: the certified search, the genetic algorithm,
  the FE exhaustive search and the robust ranking, one module each in
  :mod:`pneumorph.design.algorithms`.
- :class:`SearchOutcome` - what an algorithm found: its hall of fame and whatever else it
  measured (generations, a ranking, a certificate, a robustness report).
- the driver, :func:`pneumorph.design.driver.run_design`, claims the run folder, runs the
  algorithm and writes its outcome.

An algorithm has four steps, each called once by the driver:

1. ``plan(problem)``: the checks and choices that need no solve, before the run folder is
   touched; returns the algorithm that will run (itself, or another: a certified search of
   an actuator too short for its chain table hands over to the FE exhaustive search) and
   the problem it will run on (a chain table's levels may remake the model).
2. ``setup(problem)``: under the run folder's lock, what the search needs built (a chain
   table, tolerance tables); returns the problem it runs on (a table built to the levels every
   design reached remakes the model with those levels) and the entries it adds to the run's
   provenance.
3. ``run(problem)``: the search; returns an :class:`SearchOutcome`.
4. ``interrupted()``: what survives a Ctrl-C during ``run`` (the GA's generations).

Examples
--------
>>> from pneumorph.design.config import DesignConfig
>>> from pneumorph.design.algorithms import algorithm_for
>>> algorithm_for(DesignConfig(search="ga")).name
'ga'
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from pneumorph.design.objectives.fitness import Score
from pneumorph.design.objectives.targets import Objective
from pneumorph.design.search.genetic import GenerationStats
from pneumorph.design.search.scoring import Candidate
from pneumorph.models.response import ActuatorModel

if TYPE_CHECKING:
    from pneumorph.design.certified.search import CertifiedResult
    from pneumorph.design.config import DesignConfig


def _silent(text: str) -> None:
    """Progress said to nobody."""


@dataclass(frozen=True)
class Problem:
    """What a design run searches.

    Attributes
    ----------
    config : DesignConfig
    model : ActuatorModel
        Built for ``config`` (``n_units == config.units``).
    objective : Objective
        ``config.make_objective()``.
    evaluator : Evaluator or None
        The cached evaluator the solves go through; None until the driver has claimed the folder.
    workers : int
        Designs the evaluator solves at once (planned before it exists).
    table_dir : Path or None
        The chain tables' folder beside the evaluation cache (None: a cache in memory).
    build : bool
        Whether a table that no shipped or kept table serves may be built.
    folder : Path or None
        The run folder (for the files an algorithm keeps as it goes: the GA's generation log).
    resumed : bool
        The folder holds this run's earlier start.
    say : callable
        A line of progress.
    on_generation, on_progress : callable or None
        A GA generation's stats; the exhaustive search's (done, total).
    reference : ActuatorModel or None
        A second model whose optimum the certified search also finds and judges by this one
        (the nominal model of an identified one: :mod:`pneumorph.design.runs.comparison`).
    """

    config: DesignConfig
    model: ActuatorModel
    objective: Objective
    evaluator: Any = None
    workers: int = 1
    table_dir: Path | None = None
    build: bool = True
    folder: Path | None = None
    resumed: bool = False
    say: Callable[[str], None] = _silent
    on_generation: Callable[[GenerationStats], Any] | None = None
    on_progress: Callable[[int, int], Any] | None = None
    reference: ActuatorModel | None = None


@dataclass(frozen=True)
class SearchOutcome:
    """What an algorithm found (the fields of :class:`~pneumorph.design.runs.report.RunResult` it fills).

    Attributes
    ----------
    hall_of_fame : tuple of Candidate
        Best first.
    history : tuple of GenerationStats
        The GA's generations.
    ranking : list of (design, Score) or None
        Designs by value (the exhaustive search's all; the certified search's best 1,000).
    certified : CertifiedResult or None
    refinement, robustness : dict or None
    robust_winner : Candidate or None
    opinion_2d : dict
        The 2D model's chain values of the listed designs (a certified 3D run).
    comparison : dict or None
        The reference model's optimum judged by this model
        (:func:`~pneumorph.design.runs.comparison.compare_with_reference`).
    """

    hall_of_fame: tuple[Candidate, ...] = ()
    history: tuple[GenerationStats, ...] = ()
    ranking: list[tuple[str, Score]] | None = None
    certified: CertifiedResult | None = None
    refinement: dict[str, Any] | None = None
    robustness: dict[str, Any] | None = None
    robust_winner: Candidate | None = None
    opinion_2d: dict[str, float] = field(default_factory=dict)
    comparison: dict[str, Any] | None = None


class Algorithm(Protocol):
    """A search strategy (see the module's description of the four steps).

    Attributes
    ----------
    name : str
        The search as a run names it (``"certified"``, ``"ga"``, ``"exhaustive"``).
    note : str
        Why this search, and on what (a certified run's table and levels); empty if nothing to say.
    """

    name: str
    note: str

    def plan(self, problem: Problem) -> tuple[Algorithm, Problem]:
        """The algorithm that runs and its problem; refuses (a specific error) before any solve."""
        ...

    def setup(self, problem: Problem) -> tuple[Problem, dict[str, Any]]:
        """Build what the search needs (under the folder's lock); the problem it runs on and the provenance entries
        it adds."""
        ...

    def run(self, problem: Problem) -> SearchOutcome:
        """Search."""
        ...

    def interrupted(self) -> SearchOutcome:
        """What a Ctrl-C during :meth:`run` leaves (the generations logged so far)."""
        ...


class Search:
    """The steps an algorithm need not change: no plan, nothing to set up, nothing left by a Ctrl-C."""

    name = ""
    note = ""

    def plan(self, problem: Problem) -> tuple[Algorithm, Problem]:
        """Itself, on the same problem."""
        return self, problem

    def setup(self, problem: Problem) -> tuple[Problem, dict[str, Any]]:
        """Nothing to build: the same problem, no entries."""
        return problem, {}

    def run(self, problem: Problem) -> SearchOutcome:  # pragma: no cover - every algorithm has its own
        """Search."""
        raise NotImplementedError

    def interrupted(self) -> SearchOutcome:
        """Nothing kept."""
        return SearchOutcome()


__all__ = ["Algorithm", "Problem", "Search", "SearchOutcome"]

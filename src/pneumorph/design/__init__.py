"""Design search: objectives, fitness (Eq 4.1), genetic algorithm, exhaustive search, runs.

The functions a front end calls:

- :func:`make_objective` - an objective from text (``"sin"``, ``"max-y"``, ``"y = ..."``).
- :func:`score` - a response's fitness at every pressure level and its best level.
- :func:`certified_search` - every design scored by a chain model, the best verified by FE,
  with a bound on what any other design could do; :func:`certificate_text` says it in words.
- :func:`run_ga` / :func:`run_exhaustive` - the searches, through any evaluator.
- :func:`run_design` - a whole run into a folder (resumable), from a :class:`DesignConfig`:
  the driver of the search strategies (:mod:`pneumorph.design.algorithms`), each an
  :class:`Algorithm` on a :class:`Problem` giving an :class:`SearchOutcome`; a new strategy
  subclasses :class:`Search` (documentation page extending).
- :func:`population_study` - the population-size study of section 6.1.

Examples
--------
>>> from pneumorph.design import make_objective
>>> make_objective("sin", amplitude=15).label
'sin: y = A*sin(2*pi*1*x/L), A = 15 mm'
"""

from pneumorph.design.algorithms.problem import Algorithm, Problem, Search, SearchOutcome
from pneumorph.design.certified.certificate import certificate_text
from pneumorph.design.certified.search import CertifiedResult, certified_search
from pneumorph.design.config import DesignConfig
from pneumorph.design.driver import run_design
from pneumorph.design.objectives.contact import CONTACT_GOALS, ContactGoal
from pneumorph.design.objectives.fitness import Score, score
from pneumorph.design.objectives.paths import PATH_PRESETS, PathTarget, path_target, preset_path, read_path
from pneumorph.design.objectives.targets import (
    PRESETS,
    TIP_GOALS,
    Objective,
    Polyline,
    ProfileTarget,
    TipGoal,
    curve_target,
    make_objective,
    profile_target,
    smooth_curve,
    tip_goal,
)
from pneumorph.design.runs.report import RunResult
from pneumorph.design.search.exhaustive import (
    ExhaustiveResult,
    mirror_response,
    run_exhaustive,
)
from pneumorph.design.search.genetic import GAConfig, GAResult, GenerationStats, run_ga
from pneumorph.design.search.population import PopulationStudy, plot_population_study, population_study
from pneumorph.design.search.scoring import Candidate

__all__ = [
    "CONTACT_GOALS",
    "PATH_PRESETS",
    "PRESETS",
    "TIP_GOALS",
    "Algorithm",
    "Candidate",
    "CertifiedResult",
    "ContactGoal",
    "DesignConfig",
    "ExhaustiveResult",
    "GAConfig",
    "GAResult",
    "GenerationStats",
    "Objective",
    "PathTarget",
    "Polyline",
    "PopulationStudy",
    "Problem",
    "ProfileTarget",
    "RunResult",
    "Score",
    "Search",
    "SearchOutcome",
    "TipGoal",
    "certificate_text",
    "certified_search",
    "curve_target",
    "make_objective",
    "mirror_response",
    "path_target",
    "plot_population_study",
    "population_study",
    "preset_path",
    "profile_target",
    "read_path",
    "run_design",
    "run_exhaustive",
    "run_ga",
    "score",
    "smooth_curve",
    "tip_goal",
]

"""A design problem and the searches over it that need no chain model.

- :mod:`~pneumorph.design.search.problem`: the problem, the interface of an algorithm, the
  outcome of a run (as in pymoo, problem, algorithm and driver apart);
- :mod:`~pneumorph.design.search.scoring`: the scores of the designs seen, the hall of fame;
- :mod:`~pneumorph.design.search.genetic`: the genetic algorithm (DEAP, section 4.5);
- :mod:`~pneumorph.design.search.exhaustive`: every design solved by FE, the ground truth;
- :mod:`~pneumorph.design.search.population`: the GA's population-size study (Fig 6.1).

The strategies a run chooses between are in :mod:`pneumorph.design.algorithms`; the names to
import are re-exported by :mod:`pneumorph.design`.
"""

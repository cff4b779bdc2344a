"""The searches over designs that need no chain model, and what every search keeps.

- :mod:`~pneumorph.design.search.scoring`: the scores of the designs seen, the hall of fame;
- :mod:`~pneumorph.design.search.genetic`: the genetic algorithm (DEAP, section 4.5);
- :mod:`~pneumorph.design.search.exhaustive`: every design solved by FE, the ground truth;
- :mod:`~pneumorph.design.search.population`: the GA's population-size study (Fig 6.1).

The strategies a run chooses between (and the problem they solve) are in
:mod:`pneumorph.design.algorithms`; the names to
import are re-exported by :mod:`pneumorph.design`.
"""

__all__: list[str] = []  # the names to import are re-exported by the parent package

"""What a design is asked to do and how far a response is from it.

- :mod:`~pneumorph.design.objectives.expressions`: safe math expressions of a target profile;
- :mod:`~pneumorph.design.objectives.profiles`: profile targets ``y = f(x)`` and ``r = f(theta)``;
- :mod:`~pneumorph.design.objectives.paths`: paths of any shape (points from the base to the end);
- :mod:`~pneumorph.design.objectives.targets`: every objective (profiles, paths, tip goals,
  staged targets) and how one is made from settings;
- :mod:`~pneumorph.design.objectives.fitness`: an objective's value at every pressure (Eq 4.1).

The names to import are re-exported by :mod:`pneumorph.design`.
"""

__all__: list[str] = []  # the names to import are re-exported by the parent package

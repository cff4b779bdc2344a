"""Unit geometry optimisation (Ellis 2020 section 8.3.2, Fig 8.1): ``pneumorph unit optimise``.

Maximise the bending angle per unit (Omega) and minimise the ballooning height (h_b) of the
articulating unit, subject to a largest principal strain of the body material, over a few
of its dimensions, with pymoo's NSGA-II on the package's 3D model of a short actuator.

- :mod:`~pneumorph.unitopt.measures`: Omega, h_b and the strain of a solved actuator;
- :mod:`~pneumorph.unitopt.space`: the varied dimensions and their bounds;
- :mod:`~pneumorph.unitopt.probe`: the model the evaluators solve (a 3-unit Full3D);
- :mod:`~pneumorph.unitopt.problem`: the pymoo problem, its repair, the candidate evaluator;
- :mod:`~pneumorph.unitopt.run`: NSGA-II, the front, the output folder;
- :mod:`~pneumorph.unitopt.figures`: the front's figure.

pymoo is imported by the problem and the driver only (``import pneumorph.unitopt`` does not).
"""

from pneumorph.unitopt.measures import UnitMeasures, measure
from pneumorph.unitopt.probe import UnitProbe
from pneumorph.unitopt.space import DesignSpace, Variable, parse_variable

__all__ = ["DesignSpace", "UnitMeasures", "UnitProbe", "Variable", "measure", "parse_variable"]

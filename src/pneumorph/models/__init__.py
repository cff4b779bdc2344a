"""Actuator models of every fidelity and what they return (:class:`Response`).

- :class:`Reduced2D` (plane strain with the pressure-dependent filler, chapter 5) and
  :class:`Full3D` (chapter 4), FE models on FElupe, with their ramp (:class:`RampSpec`) and
  full fields (:class:`Solution`);
- :func:`make_model`, the factory from plain settings (a config's ``[model]`` table, CLI
  options), with the model classes' own tuned defaults;
- :class:`ChainModel`, the chain model fitted to them (:class:`ChainTable`,
  :func:`build_table`);
- :class:`ActuatorModel`, the protocol every model implements, and :class:`Response`.

Examples
--------
>>> from pneumorph.models import make_model
>>> make_model(4, {"fidelity": "3d"}).fidelity
'3d'
"""

from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.factory import make_model
from pneumorph.models.fe import FEModel, Full3D, RampSpec, Reduced2D, Solution
from pneumorph.models.response import ActuatorModel, Response

__all__ = [
    "ActuatorModel",
    "ChainModel",
    "ChainTable",
    "FEModel",
    "Full3D",
    "RampSpec",
    "Reduced2D",
    "Response",
    "Solution",
    "build_table",
    "make_model",
]

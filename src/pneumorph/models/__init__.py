"""Actuator models of every fidelity and what they return (:class:`Response`).

The FE models live in :mod:`pneumorph.models.fe` (``Reduced2D``, ``Full3D``) and are built
from plain settings by :func:`pneumorph.models.factory.make_model`; the chain model fitted
to them is :class:`ChainModel` (:mod:`pneumorph.models.chain`).
"""

from pneumorph.models.chain import ChainModel, ChainTable, build_table
from pneumorph.models.response import ActuatorModel, Response

__all__ = ["ActuatorModel", "ChainModel", "ChainTable", "Response", "build_table"]

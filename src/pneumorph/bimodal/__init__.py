"""The bimodal actuator of section 3.3: a Slow Pneu-net on a bilinear composite layer.

:mod:`~pneumorph.bimodal.geometry` (layered geometry and mesh), :mod:`~pneumorph.bimodal.model`
(3D FE model and pressure ramp; imports FElupe), :mod:`~pneumorph.bimodal.figures`.
"""

from pneumorph.bimodal.geometry import ASSUMED, BimodalSpec, mesh_actuator

__all__ = ["ASSUMED", "BimodalSpec", "mesh_actuator"]

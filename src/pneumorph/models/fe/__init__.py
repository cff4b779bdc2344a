"""Finite-element actuator models on FElupe: the 2D reduced-order and the 3D model.

The public import place of the FE models; each concept has a module of its own:

- :mod:`pneumorph.models.fe.base`: the common machinery (:class:`FEModel`);
  :mod:`pneumorph.models.fe.solving`: one design's ramp solved, its levels recorded and the
  solved fields kept (:class:`Solution`); :mod:`pneumorph.models.fe.ramp`: the pressure ramp
  (:class:`RampSpec`); :mod:`pneumorph.models.fe.volumetric`: how the silicones' volumetric
  term is integrated (the u-p-J form for a nearly incompressible one);
- :mod:`pneumorph.models.fe.reduced2d`: :class:`Reduced2D`, the plane-strain section whose
  cavities hold the pressure-dependent filler (chapter 5);
- :mod:`pneumorph.models.fe.full3d`: :class:`Full3D`, quadratic hexahedra and empty cavities
  (chapter 4);
- :mod:`pneumorph.models.fe.obstacles`: rigid obstacles against the outer surface
  (``[[model.obstacle]]``), the forces on them and the blocked-force wall.

Both take a unit, an orientation vector and a pressure ramp and return a
:class:`~pneumorph.models.response.Response`.

Examples
--------
>>> from pneumorph.models.fe import Full3D, RampSpec
>>> Full3D(2, ramp_spec=RampSpec(pressure=0.01)).fidelity
'3d'
"""

from pneumorph.models.fe.base import (
    MODEL_REVISION as MODEL_REVISION,
)
from pneumorph.models.fe.base import (
    FEModel as FEModel,
)
from pneumorph.models.fe.base import (
    model_library as model_library,
)
from pneumorph.models.fe.full3d import (
    Full3D as Full3D,
)
from pneumorph.models.fe.ramp import (
    RampSpec as RampSpec,
)
from pneumorph.models.fe.reduced2d import (
    Reduced2D as Reduced2D,
)
from pneumorph.models.fe.solving import (
    Solution as Solution,
)

# the public place of these names is :mod:`pneumorph.models` (its reference page); here they are
# importable by their package too
__all__: list[str] = []

"""How much to trust a design: sensitivities of the actuator's shape (appendices D and E).

- :class:`Tolerance`, :func:`perturbed` - mould tolerances on the unit's thicknesses (E.2).

A uniform temperature change (D.3) is a model option:
``Full3D(n, temperature_change=dT)`` (:mod:`pneumorph.models.fe`).
"""

from pneumorph.sensitivity.tolerances import FIELDS, MACHINED, PRINTED, Tolerance, perturbed

__all__ = ["FIELDS", "MACHINED", "PRINTED", "Tolerance", "perturbed"]

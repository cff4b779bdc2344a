"""How a model integrates its silicones' volumetric term: at every point, or on each element's own dilatation.

The displacement form integrates ``9/2 K (J^(1/3) - 1)^2`` at every quadrature point; a nearly
incompressible silicone locks there, and the u-p-J form (:mod:`pneumorph.fem.fast.mixed`) integrates it on
each element's own dilatation and pressure instead. A model's ``formulation`` chooses: ``"auto"`` (the
default) by the material's bulk modulus, ``"displacement"`` or ``"u-p-J"`` for every silicone.
"""

from __future__ import annotations

from typing import Any

from pneumorph.fem.fast.mixed import nearly_incompressible

#: a model's choices: by the bulk modulus ("auto": the u-p-J form from a Poisson's ratio of 0.45), at every point
#: ("displacement") or on each element's own dilatation ("u-p-J")
FORMULATIONS = ("auto", "displacement", "u-p-J")


def element_volume(material: Any, formulation: str = "auto") -> bool:
    """Whether ``material``'s volumetric term is integrated on each element's own dilatation (the u-p-J form):
    always with ``"u-p-J"``, never with ``"displacement"``; with ``"auto"`` for a nearly incompressible silicone,
    its bulk modulus at least :data:`~pneumorph.fem.fast.mixed.MIXED_BULK_RATIO` times its shear modulus
    (Poisson's ratio 0.45 or more: :func:`~pneumorph.fem.fast.mixed.nearly_incompressible`).

    >>> from pneumorph.materials import get
    >>> element_volume(get("mold_star_15")), element_volume(get("mold_star_15"), "u-p-J")
    (False, True)
    """
    if formulation != "auto":
        return formulation == "u-p-J"
    return nearly_incompressible(material.bulk_modulus.value, material.shear_modulus)


__all__ = ["FORMULATIONS", "element_volume"]

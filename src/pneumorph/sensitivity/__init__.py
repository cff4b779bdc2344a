"""How much to trust a design: sensitivities of the actuator's shape (appendices D and E).

- :class:`Tolerance`, :func:`perturbed` - mould tolerances on the unit's thicknesses (E.2).
- :func:`shape_difference` - the largest distance between matching centreline points and
  its X and Y errors in %, as the dissertation measures.
- :func:`scaled_bulk_modulus`, :func:`tension_only` - the material variants of E.1;
  :func:`scaled_shear_modulus` - the body's Ogden moduli scaled (model identification).
- :func:`converge`, :func:`mesh_points`, :class:`MeshStudy` - mesh convergence: observed
  order, Richardson limit and grid convergence index of a design's shape over element sizes.
- :class:`Study` and its builders (:func:`simplifications`, :func:`tolerances`,
  :func:`bulk_modulus`, :func:`calibration`, :func:`temperature`), solved by
  :func:`run_study` through any evaluator.

The model options the studies vary are the models' own: ``Full3D(n, passage=...,
base_block=..., temperature_change=..., materials=...)`` (:mod:`pneumorph.models.fe`).
"""

from pneumorph.sensitivity.compare import ShapeDifference, shape_difference
from pneumorph.sensitivity.mesh import (
    Convergence,
    MeshPoint,
    MeshStudy,
    converge,
    mesh_points,
    refined,
    representative_size,
)
from pneumorph.sensitivity.studies import (
    BUILDERS,
    DISSERTATION,
    STUDIES,
    Case,
    CaseResult,
    Study,
    StudyResult,
    bulk_modulus,
    calibration,
    run_study,
    simplifications,
    temperature,
    tolerances,
)
from pneumorph.sensitivity.tolerances import FIELDS, MACHINED, PRINTED, Tolerance, perturbed
from pneumorph.sensitivity.variants import scaled_bulk_modulus, scaled_shear_modulus, tension_only

__all__ = [
    "BUILDERS",
    "DISSERTATION",
    "FIELDS",
    "MACHINED",
    "PRINTED",
    "STUDIES",
    "Case",
    "CaseResult",
    "Convergence",
    "MeshPoint",
    "MeshStudy",
    "ShapeDifference",
    "Study",
    "StudyResult",
    "Tolerance",
    "bulk_modulus",
    "calibration",
    "converge",
    "mesh_points",
    "perturbed",
    "refined",
    "representative_size",
    "run_study",
    "scaled_bulk_modulus",
    "scaled_shear_modulus",
    "shape_difference",
    "simplifications",
    "temperature",
    "tension_only",
    "tolerances",
]

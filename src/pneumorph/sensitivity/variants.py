"""Materials of the sensitivity studies' variants (appendix E.1).

- :func:`scaled_bulk_modulus` - a silicone with its bulk modulus raised (E.1.2: +5 %, +10 %).
- :func:`scaled_shear_modulus` - a silicone with its Ogden moduli scaled (every ``mu_n``, so its
  shear modulus and its whole stress-stretch curve by the same factor; the exponents kept).
  Both live in :mod:`pneumorph.materials.library.scaling`, below the models that apply them (the
  ``[model]`` table's ``body_bulk_scale`` and ``body_shear_scale``).
- :func:`tension_only` - a silicone's Ogden model refitted to its uniaxial *tension* curve
  alone (E.1.1), the calibration a lab without compression grips would make.

Where the data come from. The dissertation's measured curves are not public; its Table
A.4 model of each silicone was calibrated on tension and compression tests (appendix
A.2). :func:`tension_only` therefore samples that model's uniaxial curve over the tension
range of the tests (stretch 1 to 3: the dumbbells were preconditioned to 200 % strain) and
fits the same Ogden N = 3 form to the tension points only, with pneumorph's fitter
(:func:`pneumorph.materials.fitting.fit.fit`). The reference is the library's (tension and
compression) model itself; refitting it to tension and compression points together
recovers it (R^2 = 1 to 6 digits), so the two differ by the calibration data alone.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from pneumorph.materials.characterisation.testdata import TestCurve
from pneumorph.materials.fitting.fit import FitResult, fit
from pneumorph.materials.library.material import Material, ModelRecord
from pneumorph.materials.library.scaling import scaled_bulk_modulus, scaled_shear_modulus

#: the tension range of the calibration data (stretch), appendix A.2: preconditioned to 200 % strain
TENSION_RANGE = (1.0, 3.0)
#: the compression range the tension-only fit leaves out (stretch), ISO 7743 pucks to 40 % strain
COMPRESSION_RANGE = (0.6, 1.0)


def tension_curve(material: Material, stretch: tuple[float, float] = TENSION_RANGE, points: int = 41) -> TestCurve:
    """The uniaxial curve of ``material``'s model at ``points`` stretches in ``stretch``."""
    assert material.model is not None
    lam = np.linspace(stretch[0], stretch[1], points)
    lam = lam[lam != 1.0]
    return TestCurve("uniaxial", lam, material.model.uniaxial(lam), description=f"{material.name} model curve")


def tension_only(material: Material, seed: int = 0) -> tuple[Material, FitResult]:
    """``material`` with an Ogden N = 3 model fitted to its model's tension curve alone.

    Returns the material (same name, new model and provenance) and the fit.

    Examples
    --------
    >>> from pneumorph.materials import get
    >>> ms, result = tension_only(get("mold_star_15"))
    >>> round(result.r2["uniaxial"], 6)   # tension is matched ...
    1.0
    >>> bool(ms.model.uniaxial(np.array([0.6]))[0] > get("mold_star_15").model.uniaxial(np.array([0.6]))[0])
    True
    """
    result = fit("ogden-3", tension_curve(material), seed=seed)
    mu = tuple(float(result.parameters[f"mu{i}"]) for i in (1, 2, 3))
    alpha = tuple(float(result.parameters[f"alpha{i}"]) for i in (1, 2, 3))
    record = ModelRecord(type="ogden", convention="marc", unit="MPa", parameters=(("mu", mu), ("alpha", alpha)),
                         source=f"Ogden N=3 fitted to the tension branch (stretch {TENSION_RANGE[0]:g}-"
                                f"{TENSION_RANGE[1]:g}) of {material.display_name}'s model (sensitivity study, "
                                "appendix E.1.1)")
    return replace(material, model=result.model, model_record=record), result


__all__ = ["COMPRESSION_RANGE", "TENSION_RANGE", "scaled_bulk_modulus", "scaled_shear_modulus", "tension_curve",
           "tension_only"]

"""The one recipe that fits the library's silicones to their tensile tests.

The built-in entries fitted to the Soft Robotics Materials Database (Marechal et al. 2021,
doi:10.1089/soro.2019.0115; one uniaxial pull-to-failure curve per material) are made by
:func:`fit_tensile_curve` with the settings of :data:`TENSILE_FIT`, and
``docs/scripts/fit_database_silicones.py`` writes them into ``data/materials.toml``; the
tests refit with the same function and get the stored numbers back.

The recipe, and why:

- Ogden with two terms (the FE kernels are Ogden's), fitted to the whole loading curve,
  from the first recorded point to the peak stress;
- signs constrained for stability (``mu_n alpha_n >= 0``, ``stable=True``): the model is
  then Drucker-stable at every stretch in every mode, which an FE solve of a cavity wall
  (compressed, stretched in two directions) needs; the best unconstrained fits of these
  curves are unstable in tension or compression (``docs/material-fits.md``);
- relative residuals: a curve to failure spans three decades of stress, and plain
  residuals leave the small strains of an actuator's walls (stretch below 2) to the
  points near failure;
- eight starts, seed 0: the same numbers on every run;
- a term the constrained fit ends with at (nearly) zero modulus, less than a millionth of
  the initial shear modulus (its exponent at the +-0.001 bound, where a curve is best
  fitted by one term), is dropped; the goodness of fit is that of the terms kept.

Examples
--------
>>> from pneumorph.materials.characterisation.testdata import TestCurve
>>> from pneumorph.materials.laws.hyperelastic import Ogden
>>> lam = np.linspace(1.05, 4.0, 30)
>>> truth = Ogden(mu=(0.02,), alpha=(2.5,))
>>> r = fit_tensile_curve(TestCurve("uniaxial", lam, truth.uniaxial(lam)))
>>> [round(a, 6) for a in r.model.alpha], round(r.mu0, 6), round(r.r2["uniaxial"], 6)
([2.5], 0.025, 1.0)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from pneumorph.materials.characterisation.testdata import TestCurve
from pneumorph.materials.fitting.fit import FitResult, fit, r_squared
from pneumorph.materials.laws.hyperelastic import Ogden

__all__ = ["TENSILE_FIT", "fit_tensile_curve"]

#: Settings of :func:`fit_tensile_curve` (keyword arguments of :func:`~pneumorph.materials.fitting.fit.fit`).
TENSILE_FIT: Mapping[str, Any] = MappingProxyType({"model_name": "ogden-2", "stable": True, "weighting": "relative",
                                "starts": 8, "seed": 0})

#: A term whose share of the initial shear modulus is below this is dropped.
_NULL_TERM = 1e-6


def fit_tensile_curve(curve: TestCurve) -> FitResult:
    """Fit the library's Ogden model to one uniaxial tension curve (the recipe above).

    Parameters
    ----------
    curve : TestCurve
        Uniaxial tension, nominal stress in MPa (``read_curve`` of a database file).

    Returns
    -------
    FitResult
        With the null terms dropped from ``model`` and ``parameters``, and the goodness
        of fit (``r2``, ``r2_overall``, ``rmse``, ``residual_norm``) of the terms kept.

    Raises
    ------
    FitError
        Too few points, or a fit that fails from every start.
    """
    settings = dict(TENSILE_FIT)
    result = fit(settings.pop("model_name"), curve, **settings)
    model = result.model
    assert isinstance(model, Ogden)  # an ogden-N fit
    share = np.abs(np.asarray(model.mu) * np.asarray(model.alpha)) / 2.0 / result.mu0
    keep = [i for i in range(model.terms) if share[i] > _NULL_TERM]
    if len(keep) == model.terms:
        return result
    kept = Ogden(mu=tuple(model.mu[i] for i in keep), alpha=tuple(model.alpha[i] for i in keep))
    error = curve.stress - kept.nominal_stress(curve.mode, curve.stretch)
    r2 = r_squared(curve.stress, curve.stress - error)
    return dataclasses.replace(
        result, model=kept, parameters=MappingProxyType(kept.parameters), mu0=float(kept.shear_modulus),
        r2=MappingProxyType({curve.mode: r2}), r2_overall=r2, residual_norm=float(np.linalg.norm(error)),
        rmse=MappingProxyType({curve.mode: float(np.sqrt(np.mean(error**2)))}))

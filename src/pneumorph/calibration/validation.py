"""The calibrated 2D model against 3D on held-out designs: unit-centre distances per level.

Examples
--------
>>> from pneumorph.models.fe import Reduced2D, RampSpec
>>> r = Reduced2D(2, ramp_spec=RampSpec(pressure=0.005)).evaluate("01")
>>> float(centre_distances(r, r).max())
0.0
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pneumorph.calibration.references import Solve3D
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D
from pneumorph.models.response import Response


def centre_distances(r2: Response, r3: Response) -> np.ndarray:
    """(levels, units) distances between matching unit centres of two responses, mm."""
    return np.linalg.norm(r2.centres - r3.centres, axis=-1)


@dataclass(frozen=True)
class Validation:
    """2D against 3D on held-out designs: distances between matching unit centres (mm).

    Attributes
    ----------
    designs : tuple of str
    pressures : ndarray
        (k,) the reported levels, MPa.
    mean, max : ndarray
        (k,) mean and largest distance over the designs and units, per level.
    per_design_mean : ndarray
        (d, k) mean over the units, per design and level.
    """

    designs: tuple[str, ...]
    pressures: np.ndarray  # (k,) MPa
    mean: np.ndarray  # (k,) mean over designs and units
    max: np.ndarray  # (k,)
    per_design_mean: np.ndarray  # (d, k)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data, pressures in kPa and distances in mm."""
        return {"designs": list(self.designs), "pressures_kpa": (self.pressures * 1e3).tolist(),
                "mean_mm": self.mean.tolist(), "max_mm": self.max.tolist(),
                "per_design_mean_mm": self.per_design_mean.tolist()}


def validate(
    unit: UnitSpec,
    n_units: int,
    designs: Sequence[str],
    ramp: RampSpec,
    solve_3d: Solve3D | None = None,
) -> Validation:
    """Distances between matching unit centres, 2D (the unit's law) against 3D, per level.

    Parameters
    ----------
    unit : UnitSpec
        The unit carrying the filler law to check (:meth:`Calibration.unit_with_law
        <pneumorph.calibration.Calibration.unit_with_law>`).
    n_units : int
    designs : sequence of str
        Held-out designs (:func:`~pneumorph.calibration.holdout_designs`).
    ramp : RampSpec
        The ramp of both models.
    solve_3d : callable, optional
        ``solve_3d(model, design) -> Response`` (default: solve the model).

    Returns
    -------
    Validation
    """
    model2d = Reduced2D(n_units, unit, ramp)
    model3d = Full3D(n_units, unit, ramp)
    solve_3d = solve_3d or (lambda model, design: model.evaluate(design))
    per = []
    for design in designs:
        r2 = model2d.evaluate(design)
        r3 = solve_3d(model3d, design)
        per.append(centre_distances(r2, r3))  # (k, n)
    d = np.stack(per)  # (designs, k, n)
    return Validation(tuple(designs), model2d.pressures(), d.mean(axis=(0, 2)), d.max(axis=(0, 2)),
                      d.mean(axis=2))

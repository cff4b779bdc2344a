"""Filler laws E(P) fitted to the calibration points (Fig 5.3, Eqs A.1-A.3).

Polynomial laws are fitted by weighted least squares with their R^2 (:func:`fit_law`); a
law that fits badly or is not positive over the calibrated range carries its problems, so
that it is reported (:class:`CalibrationWarning`) and not silently used.

Examples
--------
>>> fit = fit_law([0.005, 0.01, 0.02], [0.05, 0.04, 0.02], 1, (0.0, 0.02))
>>> fit.problems
()
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from pneumorph.materials.laws.filler import FillerLaw

#: R^2 below which a fitted law is reported as a poor fit.
R2_WARNING = 0.9


class CalibrationWarning(UserWarning):
    """A fitted filler law that fits badly or is not positive over its range."""


@dataclass(frozen=True)
class LawFit:
    """A polynomial law E(P) fitted to the calibration points.

    Attributes
    ----------
    degree : int
        Degree of the polynomial.
    coefficients : tuple of float
        ``c_0, c_1, ...`` (E in MPa, P in MPa); empty if the points cannot test the law.
    r_squared : float
        R^2 in the fit's own weighting.
    minimum : (float, float)
        ``(pressure, modulus)`` of the smallest modulus over the range, MPa.
    problems : tuple of str
        Why the law is not to be used (poor fit, not positive, too few levels).
    weighting : str
        The weighting of the points (:data:`~pneumorph.calibration.WEIGHTINGS`).
    r_squared_unweighted : float
        R^2 without the weights (comparable with Fig 5.3).
    """

    degree: int
    coefficients: tuple[float, ...]  # c_0, c_1, ... (MPa, P in MPa)
    r_squared: float  # in the fit's own weighting
    minimum: tuple[float, float]  # (pressure, modulus) over the range
    problems: tuple[str, ...] = ()
    weighting: str = "uniform"
    r_squared_unweighted: float = float("nan")


def fit_law(pressures: Sequence[float], moduli: Sequence[float], degree: int,
            pressure_range: tuple[float, float], weights: Sequence[float] | np.ndarray | None = None,
            weighting: str = "uniform") -> LawFit:
    """Weighted least-squares polynomial E(P) of a degree, with R^2 (Eqs A.1-A.3) and checks.

    Parameters
    ----------
    pressures, moduli : sequence of float
        The calibration points (MPa).
    degree : int
        Degree of the polynomial.
    pressure_range : (float, float)
        Range over which the law must stay positive (MPa).
    weights : sequence of float, optional
        Multiply the residuals ``E_i - E(P_i)`` (default: all 1). R^2 is computed with the
        same weights, about the weighted mean; ``r_squared_unweighted`` without them.
    weighting : str
        Name of the weighting, recorded in the result.

    Returns
    -------
    LawFit

    Raises
    ------
    ValueError
        If the weights are not finite, negative, all zero or not one per point.

    Examples
    --------
    >>> f = fit_law([0.005, 0.01, 0.02], [0.05, 0.04, 0.02], 1, (0.0, 0.02))
    >>> [round(c, 6) for c in f.coefficients], round(f.r_squared, 6)
    ([0.06, -2.0], 1.0)
    """
    p = np.asarray(pressures, dtype=float)
    e = np.asarray(moduli, dtype=float)
    w = np.ones_like(e) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != e.shape or not np.all(np.isfinite(w)) or np.any(w < 0) or not np.any(w > 0):
        raise ValueError(f"weights must be finite, non-negative, not all zero and one per point, got {w}")
    levels = len(np.unique(p[w > 0]))
    if levels <= degree + 1:
        nan = float("nan")
        return LawFit(degree, (), nan, (nan, nan),
                      ((f"degree {degree}: {levels} pressure levels cannot test a law with "
                       f"{degree + 1} coefficients"),), weighting)
    coeffs = np.polynomial.polynomial.polyfit(p, e, degree, w=w)
    pred = np.polynomial.polynomial.polyval(p, coeffs)

    def r2_of(w2: np.ndarray) -> float:
        mean = np.sum(w2 * e) / np.sum(w2)
        ssto = float(np.sum(w2 * (e - mean) ** 2))
        return 1.0 - float(np.sum(w2 * (e - pred) ** 2)) / ssto if ssto > 0 else 1.0

    r2 = r2_of(w**2)
    grid = np.linspace(*pressure_range, 201)
    values = np.polynomial.polynomial.polyval(grid, coeffs)
    i = int(np.argmin(values))
    problems = []
    if r2 < R2_WARNING:
        problems.append(f"degree {degree}: R^2 = {r2:.4f} ({weighting} weighting) is below {R2_WARNING}")
    if values[i] <= 0:
        problems.append(f"degree {degree}: modulus {values[i]:.4g} MPa at {grid[i] * 1e3:.4g} kPa is not positive")
    return LawFit(degree, tuple(float(c) for c in coeffs), r2, (float(grid[i]), float(values[i])), tuple(problems),
                  weighting, r2_of(np.ones_like(e)))


def constant_law(law: FillerLaw, pressure: float, name: str) -> FillerLaw:
    """A constant filler law equal to ``law`` at ``pressure`` (MPa), over the same range.

    Examples
    --------
    >>> law = FillerLaw("l", "l", (0.05, -1.0), (0.0, 0.045), 0.3)
    >>> constant_law(law, 0.01, "E(10 kPa)").coefficients
    (0.04,)
    """
    return replace(law, name=name, display_name=name, coefficients=(float(law.modulus(pressure)),))

"""Calibration points: the best constant filler modulus for one 3D state (Eq 5.1).

At one pressure level the filler modulus E that makes the 2D model reproduce a 3D state
best is found with a SciPy optimiser from a random starting point, minimising Eq 5.1:

    Gamma(E) = sum over units [(X2 - X3)^2 + (Y2 - Y3)^2]

over the unit-centre displacements at that pressure (:func:`gamma`,
:func:`best_filler_modulus`). Each point may carry the curvature of Eq 5.1 in ln E at its
optimum, which :func:`point_weights` turns into the weights of the law fits (see
:mod:`pneumorph.calibration`).

Examples
--------
>>> pts = [FillerPoint(0, 0.01, "00", 0.04, 0.0, 0.04, 1)]
>>> point_weights(pts, "relative")
array([25.])
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from pneumorph.errors import SimulationFailed
from pneumorph.models.fe import Reduced2D
from pneumorph.models.response import Response

#: How the calibration points are weighted in the fits of E(P) (see :mod:`pneumorph.calibration`).
WEIGHTINGS = ("relative", "sensitivity", "uniform")
#: Step in ln E of the finite difference that measures the curvature of Eq 5.1.
CURVATURE_STEP = 0.05


@dataclass(frozen=True)
class FillerPoint:
    """The best constant filler modulus for one design at one pressure.

    Attributes
    ----------
    run : int
        The calibration run (0-based; -1 before :func:`~pneumorph.calibration.calibrate`
        assigns it).
    pressure : float
        The pressure level, MPa.
    design : str
        The orientation vector of the run's design.
    modulus : float
        The filler modulus minimising Eq 5.1, MPa.
    gamma : float
        Eq 5.1 at that modulus, mm^2.
    start : float
        The optimiser's random starting modulus, MPa.
    evaluations : int
        2D solves the search took.
    curvature : float or None
        ``d^2 Gamma / d(ln E)^2`` at the optimum, mm^2, if measured.
    """

    run: int
    pressure: float  # MPa
    design: str
    modulus: float  # MPa
    gamma: float  # Eq 5.1 at the optimum, mm^2
    start: float  # the optimiser's random starting modulus, MPa
    evaluations: int
    curvature: float | None = None  # d^2 Gamma / d(ln E)^2 at the optimum, mm^2 (if measured)


def unit_centre_displacements(response: Response, level: int) -> np.ndarray:
    """(n, 2) displacements of the unit centres at a reported level."""
    return response.centres[level] - response.reference_centres


def gamma(d2: np.ndarray, d3: np.ndarray) -> float:
    """Eq 5.1: summed squared differences of the unit-centre displacements (mm^2).

    Examples
    --------
    >>> gamma(np.array([[1.0, 0.0], [0.0, 2.0]]), np.array([[0.0, 0.0], [0.0, 0.0]]))
    5.0
    """
    return float(np.sum((np.asarray(d2) - np.asarray(d3)) ** 2))


def point_weights(points: Sequence[FillerPoint], weighting: str) -> np.ndarray:
    """Weights of the calibration points' residuals in E for a weighting of :data:`WEIGHTINGS`.

    ``"uniform"``: 1; ``"relative"``: 1/E; ``"sensitivity"``: sqrt(kappa)/E with kappa the
    measured curvature of Eq 5.1 in ln E, so that the weighted squared residual is twice
    the second-order rise of Eq 5.1 from missing the point.

    Examples
    --------
    >>> pts = [FillerPoint(0, 0.01, "00", 0.04, 0.0, 0.04, 1, curvature=16.0)]
    >>> point_weights(pts, "relative"), point_weights(pts, "sensitivity")
    (array([25.]), array([100.]))
    """
    e = np.array([pt.modulus for pt in points], dtype=float)
    if weighting == "uniform":
        return np.ones_like(e)
    if weighting == "relative":
        return 1.0 / e
    if weighting == "sensitivity":
        kappa = np.array([np.nan if pt.curvature is None else pt.curvature for pt in points], dtype=float)
        if np.any(np.isnan(kappa)):
            raise ValueError("sensitivity weighting needs the curvature of every point (best_filler_modulus "
                             "with curvature=True)")
        return np.sqrt(np.maximum(kappa, 0.0)) / e
    raise ValueError(f"weighting must be one of {', '.join(WEIGHTINGS)}, got {weighting!r}")


def best_filler_modulus(
    design: str,
    level: int,
    reference: Response,
    make_2d: Callable[[float, float], Reduced2D],
    start: float,
    bounds: tuple[float, float] = (1e-4, 1.0),
    curvature: bool = False,
) -> FillerPoint:
    """The constant filler modulus minimising Eq 5.1 for one design at one reported level.

    Brent's method on log10(E), its first bracket at ``start`` (relative tolerance about
    0.5 % in E); trial moduli outside ``bounds`` are clipped and penalised. A 2D solve that
    fails for a trial modulus scores as a very large Gamma, so the search moves away from it.
    With ``curvature``, two more 2D solves at ``E* exp(+-h)`` (h = :data:`CURVATURE_STEP`)
    measure ``d^2 Gamma / d(ln E)^2`` at the optimum by a central difference.

    Parameters
    ----------
    design : str
        The orientation vector solved in 2D.
    level : int
        The reported level of ``reference`` to match.
    reference : Response
        The 3D response of ``design``.
    make_2d : callable
        ``make_2d(modulus, pressure) -> Reduced2D``: the 2D model with a constant filler of
        that modulus (MPa), ramped to that pressure (MPa).
    start : float
        The optimiser's starting modulus, MPa.
    bounds : (float, float)
        Search range of the modulus, MPa.
    curvature : bool
        Also measure the curvature of Eq 5.1 at the optimum.

    Returns
    -------
    FillerPoint
        With ``run = -1``.
    """
    from scipy.optimize import minimize_scalar

    pressure = float(reference.pressures[level])
    target = unit_centre_displacements(reference, level)
    counter = {"n": 0}

    lo, hi = np.log10(bounds[0]), np.log10(bounds[1])

    def objective(x: float) -> float:
        clipped = min(max(float(x), lo), hi)
        penalty = 1e6 * (float(x) - clipped) ** 2
        counter["n"] += 1
        model = make_2d(10.0**clipped, pressure)
        try:
            r = model.evaluate(design)
        except SimulationFailed:
            return 1e12 + penalty
        return gamma(unit_centre_displacements(r, -1), target) + penalty

    x0 = float(np.log10(start))
    res = minimize_scalar(objective, bracket=(x0, x0 + 0.2), method="brent", options={"xtol": 2e-3, "maxiter": 50})
    x = min(max(float(res.x), lo), hi)
    best = float(objective(x))
    kappa = None
    if curvature:
        dx = CURVATURE_STEP / np.log(10.0)
        kappa = (objective(x + dx) - 2.0 * best + objective(x - dx)) / CURVATURE_STEP**2
    return FillerPoint(run=-1, pressure=pressure, design=design, modulus=float(10.0**x),
                       gamma=best, start=float(start), evaluations=counter["n"], curvature=kappa)

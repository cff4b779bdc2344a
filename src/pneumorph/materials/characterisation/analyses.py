"""Material characterisation from test data (Ellis 2020, Appendix A and section 3.2.6).

Pure functions on numpy arrays:

* :func:`poisson_ratio`, :func:`bulk_modulus` and :func:`characterise_bulk_modulus` -
  Poisson's ratio ``nu = -eps_y / eps_x`` (Eq A.5) and bulk modulus
  ``kappa = E / (3 (1 - 2 nu))`` (Eq A.4) as functions of axial strain from DIC strains,
  averaged over a strain range (0-150 % for Table A.5);
* :func:`thermal_expansion` - ``alpha = d eps / d T`` by linear regression (Eq A.6);
* :func:`bilinear` - the two-line characterisation of a composite tensile curve (primary
  modulus from the first 10 % of strain, secondary from the last ten points, transition
  where the lines meet; section 3.2.6, Table 3.2).

Strains are engineering strains as fractions (0.10 = 10 %), stresses in MPa, temperatures
in degC (= K for differences).

Which modulus in Eq A.4?
    Eq A.5 is a ratio of total strains, i.e. a secant quantity measured from the
    undeformed state, and Eq A.4 is the linear-elastic relation between such quantities.
    Used "as a function of axial strain" (Appendix A.2.4) the consistent modulus is
    therefore the secant modulus ``E_s = sigma / eps_x``. The tangent modulus
    ``d sigma / d eps_x`` is available as an option; for a linear material they agree.

Examples
--------
>>> import numpy as np
>>> eps = np.linspace(0.0, 1.5, 31)
>>> r = characterise_bulk_modulus(eps, -0.3 * eps, 0.5 * eps)   # E = 0.5 MPa, nu = 0.3
>>> round(r.mean_poisson_ratio, 12), round(r.mean_bulk_modulus, 12)  # 0.5 / (3 * 0.4)
(0.3, 0.416666666667)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.errors import DataFormatError, FitError

FloatArray = NDArray[np.float64]
ModulusKind = Literal["secant", "tangent"]


def _columns(*arrays: ArrayLike, names: tuple[str, ...]) -> tuple[FloatArray, ...]:
    """1-D float arrays of equal length without NaN/inf (DataFormatError otherwise)."""
    out = tuple(np.asarray(a, dtype=float) for a in arrays)
    for a, name in zip(out, names, strict=False):
        if a.ndim != 1:
            raise DataFormatError(f"{name} must be a 1-D sequence, got shape {a.shape}")
    lengths = {name: a.size for a, name in zip(out, names, strict=False)}
    if len(set(lengths.values())) > 1:
        got = ", ".join(f"{k} {v}" for k, v in lengths.items())
        raise DataFormatError(f"columns must have the same length, got {got}")
    for a, name in zip(out, names, strict=False):
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise DataFormatError(f"{name} has a non-finite value at index {bad[0]}: {a[bad[0]]}")
    return out


@dataclass(frozen=True)
class LineFit:
    """Ordinary least-squares line ``y = slope x + intercept``.

    Attributes
    ----------
    slope, intercept : float
    r_squared : float
        ``1 - SSE / SSTO`` (Eqs A.1-A.3).
    slope_standard_error : float
        ``sqrt(SSE / (n - 2) / Sxx)``; NaN for two points.
    n : int
        Number of points.
    """

    slope: float
    intercept: float
    r_squared: float
    slope_standard_error: float
    n: int


def linear_fit(x: ArrayLike, y: ArrayLike) -> LineFit:
    """Least-squares straight line through ``(x, y)`` with R^2 and slope standard error.

    Raises
    ------
    FitError
        Fewer than two points, or all ``x`` equal.

    Examples
    --------
    >>> f = linear_fit([0, 1, 2, 3], [1, 3, 5, 7])
    >>> f.slope, f.intercept, f.r_squared
    (2.0, 1.0, 1.0)
    """
    xa, ya = _columns(x, y, names=("x", "y"))
    n = xa.size
    if n < 2:
        raise FitError(f"a straight line needs at least 2 points, got {n}")
    xm, ym = xa.mean(), ya.mean()
    sxx = float(np.sum((xa - xm) ** 2))
    if sxx == 0.0:
        raise FitError(f"all {n} x values are equal ({xa[0]:g}); the slope is undefined")
    slope = float(np.sum((xa - xm) * (ya - ym)) / sxx)
    intercept = float(ym - slope * xm)
    sse = float(np.sum((ya - (slope * xa + intercept)) ** 2))
    ssto = float(np.sum((ya - ym) ** 2))
    r2 = 1.0 - sse / ssto if ssto > 0.0 else 1.0
    se = float(np.sqrt(sse / (n - 2) / sxx)) if n > 2 else float("nan")
    return LineFit(slope, intercept, r2, se, n)


# ---------------------------------------------------------------------------------------
# Poisson's ratio and bulk modulus (Eqs A.4, A.5)
# ---------------------------------------------------------------------------------------


def poisson_ratio(axial_strain: ArrayLike, transverse_strain: ArrayLike) -> FloatArray:
    """Poisson's ratio ``nu = -eps_y / eps_x`` (Eq A.5) at each point.

    Points with zero axial strain give NaN (the ratio is 0/0 there).

    Examples
    --------
    >>> poisson_ratio([0.1, 0.2], [-0.04, -0.09]).round(3).tolist()
    [0.4, 0.45]
    """
    ex, ey = _columns(axial_strain, transverse_strain, names=("axial strain", "transverse strain"))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ex != 0.0, -ey / np.where(ex != 0.0, ex, 1.0), np.nan)


def bulk_modulus(youngs_modulus: ArrayLike, poisson: ArrayLike) -> FloatArray:
    """Bulk modulus ``kappa = E / (3 (1 - 2 nu))`` (Eq A.4).

    Raises
    ------
    FitError
        If any ``nu >= 0.5`` (infinite or negative bulk modulus); the message gives the
        first such value.

    Examples
    --------
    >>> bulk_modulus(0.6, 0.25).round(12).tolist()
    0.4
    """
    e, nu = (np.asarray(a, dtype=float) for a in (youngs_modulus, poisson))
    bad = np.flatnonzero(np.atleast_1d(nu >= 0.5))
    if bad.size:
        first = float(np.atleast_1d(nu)[bad[0]])
        raise FitError(
            f"Poisson's ratio {first:.6g} >= 0.5 at {bad.size} point(s) (first at index "
            f"{bad[0]}): the bulk modulus E / (3 (1 - 2 nu)) is infinite or negative there; "
            "the data describe an incompressible (or dilating) response"
        )
    return np.asarray(e / (3.0 * (1.0 - 2.0 * nu)), dtype=float)


def secant_modulus(strain: ArrayLike, stress: ArrayLike) -> FloatArray:
    """Secant modulus ``sigma / eps`` (NaN where ``eps = 0``)."""
    eps, sig = _columns(strain, stress, names=("strain", "stress"))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(eps != 0.0, sig / np.where(eps != 0.0, eps, 1.0), np.nan)


def tangent_modulus(strain: ArrayLike, stress: ArrayLike) -> FloatArray:
    """Tangent modulus ``d sigma / d eps`` by second-order finite differences.

    Raises
    ------
    DataFormatError
        If the strain is not strictly increasing or has fewer than 3 points.
    """
    eps, sig = _columns(strain, stress, names=("strain", "stress"))
    if eps.size < 3 or np.any(np.diff(eps) <= 0.0):
        raise DataFormatError("the tangent modulus needs at least 3 points of strictly increasing strain")
    return np.gradient(sig, eps, edge_order=2)


@dataclass(frozen=True)
class BulkModulusResult:
    """Poisson's ratio and bulk modulus as functions of axial strain, and their averages.

    Attributes
    ----------
    axial_strain : ndarray
        The points used: inside ``strain_range`` and with non-zero axial strain.
    poisson_ratio : ndarray
        ``nu`` at those points (Eq A.5).
    youngs_modulus, bulk_modulus : ndarray or None
        ``E`` (secant or tangent, MPa) and ``kappa`` (MPa, Eq A.4); None without stress.
    mean_poisson_ratio : float
        Arithmetic mean over the points.
    mean_youngs_modulus, mean_bulk_modulus : float or None
        Arithmetic means over the points (the "average over the range" of Table A.5).
    strain_average_bulk_modulus : float or None
        ``int kappa d eps / (eps_max - eps_min)`` (trapezoidal); equals the mean for
        evenly spaced strains.
    strain_range : (float, float)
    modulus : {"secant", "tangent"}
    """

    axial_strain: FloatArray
    poisson_ratio: FloatArray
    youngs_modulus: FloatArray | None
    bulk_modulus: FloatArray | None
    mean_poisson_ratio: float
    mean_youngs_modulus: float | None
    mean_bulk_modulus: float | None
    strain_average_bulk_modulus: float | None
    strain_range: tuple[float, float]
    modulus: ModulusKind

    @property
    def n(self) -> int:
        """Number of points used."""
        return int(self.axial_strain.size)


def characterise_bulk_modulus(
    axial_strain: ArrayLike,
    transverse_strain: ArrayLike,
    axial_stress: ArrayLike | None = None,
    strain_range: tuple[float, float] = (0.0, 1.5),
    modulus: ModulusKind = "secant",
) -> BulkModulusResult:
    """Poisson's ratio and bulk modulus from a uniaxial test with DIC (Appendix A.2.4).

    Parameters
    ----------
    axial_strain, transverse_strain : array_like
        Engineering strains ``eps_x`` (loaded direction) and ``eps_y`` (fractions).
    axial_stress : array_like, optional
        Engineering stress in MPa; without it only Poisson's ratio is computed.
    strain_range : (float, float)
        Axial-strain interval (fractions, inclusive) to use and average over; default
        0-150 % as for Table A.5. Points with zero axial strain are skipped (0/0).
    modulus : {"secant", "tangent"}
        ``E`` in Eq A.4: ``sigma/eps`` (default, consistent with Eq A.5) or
        ``d sigma / d eps`` (computed on the whole curve, then restricted to the range).

    Returns
    -------
    BulkModulusResult

    Raises
    ------
    DataFormatError
        Columns of different length, non-finite values, bad range, unknown modulus kind.
    FitError
        No usable point in the range, or ``nu >= 0.5`` at a point in the range.

    Examples
    --------
    >>> eps = np.array([0.0, 0.5, 1.0, 1.5, 2.0])
    >>> r = characterise_bulk_modulus(eps, -0.2 * eps, 0.9 * eps, strain_range=(0.0, 1.5))
    >>> r.n, round(r.mean_bulk_modulus, 12)   # 0.9 / (3 * 0.6)
    (3, 0.5)
    """
    lo, hi = (float(x) for x in strain_range)
    if not lo < hi:
        raise DataFormatError(f"strain range must satisfy lower < upper, got {strain_range}")
    if modulus not in ("secant", "tangent"):
        raise DataFormatError(f"modulus must be 'secant' or 'tangent', got {modulus!r}")
    names = ("axial strain", "transverse strain")
    if axial_stress is None:
        ex, ey = _columns(axial_strain, transverse_strain, names=names)
        sig = None
    else:
        ex, ey, sig = _columns(axial_strain, transverse_strain, axial_stress, names=(*names, "axial stress"))
    use = _in_range(ex, lo, hi)
    nu = poisson_ratio(ex[use], ey[use])
    e: FloatArray | None = None
    k: FloatArray | None = None
    mean_e = mean_k = avg_k = None
    if sig is not None:
        e, k, mean_e, mean_k, avg_k = _moduli(ex, sig, use, nu, modulus)
    return BulkModulusResult(axial_strain=ex[use], poisson_ratio=nu, youngs_modulus=e, bulk_modulus=k,
                             mean_poisson_ratio=float(nu.mean()), mean_youngs_modulus=mean_e,
                             mean_bulk_modulus=mean_k, strain_average_bulk_modulus=avg_k, strain_range=(lo, hi),
                             modulus=modulus)


def _in_range(ex: FloatArray, lo: float, hi: float) -> NDArray[np.bool_]:
    """The points of axial strain ``ex`` in ``lo``-``hi`` and not zero; :class:`FitError` if none."""
    use = (ex >= lo) & (ex <= hi) & (ex != 0.0)
    if not np.any(use):
        raise FitError(
            f"no data point with non-zero axial strain in the range {lo * 100:g}-{hi * 100:g} % "
            f"(data span {ex.min() * 100:g}-{ex.max() * 100:g} %)" if ex.size else "no data points"
        )
    return use


def _moduli(ex: FloatArray, sig: FloatArray, use: NDArray[np.bool_], nu: FloatArray,
            modulus: ModulusKind) -> tuple[FloatArray, FloatArray, float, float, float]:
    """Young's (Eq A.4) and bulk (Eq A.5) moduli at the points ``use``, their means, and K averaged over strain.

    Raises
    ------
    FitError
        ``nu >= 0.5`` at a point, naming its axial strain.
    """
    e_all = secant_modulus(ex, sig) if modulus == "secant" else tangent_modulus(ex, sig)
    e = e_all[use]
    try:
        k = bulk_modulus(e, nu)
    except FitError as exc:
        first = ex[use][np.flatnonzero(nu >= 0.5)[0]]
        raise FitError(f"at axial strain {first * 100:.4g} %: {exc}") from None
    mean_e, mean_k = float(e.mean()), float(k.mean())
    x = ex[use]
    span = x[-1] - x[0] if x.size > 1 else 0.0
    area = float(np.sum(0.5 * (k[1:] + k[:-1]) * np.diff(x)))
    return e, k, mean_e, mean_k, area / span if span != 0.0 else mean_k


# ---------------------------------------------------------------------------------------
# thermal expansion (Eq A.6)
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ThermalExpansionResult:
    """Linear thermal expansion coefficient from a strain-temperature regression.

    Attributes
    ----------
    alpha : float
        Slope ``d eps / d T`` in 1/K (multiply by 1e6 for micro-mm/mm/degC, Table A.6).
    standard_error : float
        Standard error of ``alpha`` (1/K).
    intercept : float
        Strain at 0 degC of the fitted line.
    r_squared : float
    n : int
    temperature_range : (float, float)
    """

    alpha: float
    standard_error: float
    intercept: float
    r_squared: float
    n: int
    temperature_range: tuple[float, float]


def thermal_expansion(temperature: ArrayLike, strain: ArrayLike) -> ThermalExpansionResult:
    """Linear thermal expansion ``alpha = d eps / d T`` by least squares (Eq A.6).

    Parameters
    ----------
    temperature : array_like
        Temperatures in degC (or K).
    strain : array_like
        Engineering thermal strain (fraction) at those temperatures; any reference.

    Raises
    ------
    FitError
        Fewer than 3 points (no standard error) or a single temperature.

    Examples
    --------
    >>> r = thermal_expansion([20, 40, 60, 85], [0.0, 4.906e-3, 9.812e-3, 15.9445e-3])
    >>> round(r.alpha * 1e6, 1), round(r.r_squared, 6)
    (245.3, 1.0)
    """
    t, eps = _columns(temperature, strain, names=("temperature", "strain"))
    if t.size < 3:
        raise FitError(f"thermal expansion needs at least 3 points for a standard error, got {t.size}")
    fit = linear_fit(t, eps)
    return ThermalExpansionResult(
        alpha=fit.slope,
        standard_error=fit.slope_standard_error,
        intercept=fit.intercept,
        r_squared=fit.r_squared,
        n=fit.n,
        temperature_range=(float(t.min()), float(t.max())),
    )


# ---------------------------------------------------------------------------------------
# bilinear composite (section 3.2.6)
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BilinearResult:
    """Two-line characterisation of a bilinear tensile curve (Table 3.2).

    Attributes
    ----------
    primary, secondary : LineFit
        Line through the first ``primary_strain_limit`` of strain / the last
        ``secondary_points`` points.
    transition_strain, transition_stress : float
        Where the two lines intersect (strain as a fraction, stress in MPa).
    primary_strain_limit : float
    secondary_points : int
    """

    primary: LineFit
    secondary: LineFit
    transition_strain: float
    transition_stress: float
    primary_strain_limit: float
    secondary_points: int

    @property
    def primary_modulus(self) -> float:
        """Slope of the primary line (MPa)."""
        return self.primary.slope

    @property
    def secondary_modulus(self) -> float:
        """Slope of the secondary line (MPa)."""
        return self.secondary.slope


def bilinear(
    strain: ArrayLike,
    stress: ArrayLike,
    primary_strain_limit: float = 0.10,
    secondary_points: int = 10,
) -> BilinearResult:
    """Bilinear (two-line) characterisation of a composite tensile curve (section 3.2.6).

    "The primary modulus was calculated using a linear regression model fit to the first
    10% of strain. The secondary modulus was calculated using a linear regression model
    fit to the last ten data points. The transition point is the strain value at which
    these two linear models intersect." Both lines are ordinary least squares with a free
    intercept.

    Parameters
    ----------
    strain : array_like
        Engineering strain (fraction), in test order.
    stress : array_like
        Stress (MPa) or any load measure (the moduli then carry its unit).
    primary_strain_limit : float
        Points with ``strain <= primary_strain_limit`` form the primary fit (0.10 = 10 %).
    secondary_points : int
        Number of final points in the secondary fit.

    Returns
    -------
    BilinearResult

    Raises
    ------
    DataFormatError
        Bad columns.
    FitError
        Fewer than 2 points in a fit, or parallel lines (no transition).

    Examples
    --------
    >>> eps = np.linspace(0.0, 0.5, 51)
    >>> sig = np.where(eps < 0.3, 0.08 * eps, 0.024 + 16.5 * (eps - 0.3))
    >>> r = bilinear(eps, sig)
    >>> round(r.primary_modulus, 9), round(r.secondary_modulus, 9), round(r.transition_strain, 9)
    (0.08, 16.5, 0.3)
    """
    eps, sig = _columns(strain, stress, names=("strain", "stress"))
    if secondary_points < 2:
        raise FitError(f"the secondary fit needs at least 2 points, got secondary_points={secondary_points}")
    first = eps <= primary_strain_limit
    if np.count_nonzero(first) < 2:
        raise FitError(
            f"only {np.count_nonzero(first)} point(s) with strain <= {primary_strain_limit * 100:g} %; "
            "the primary fit needs at least 2"
        )
    if eps.size < secondary_points:
        raise FitError(f"the secondary fit needs the last {secondary_points} points, but the data have {eps.size}")
    primary = linear_fit(eps[first], sig[first])
    secondary = linear_fit(eps[-secondary_points:], sig[-secondary_points:])
    dm = primary.slope - secondary.slope
    if abs(dm) <= 1e-12 * max(abs(primary.slope), abs(secondary.slope)):
        raise FitError(
            f"primary and secondary slopes are equal ({primary.slope:.6g}); the curve is not bilinear"
        )
    x = (secondary.intercept - primary.intercept) / dm
    return BilinearResult(
        primary=primary,
        secondary=secondary,
        transition_strain=float(x),
        transition_stress=float(primary.slope * x + primary.intercept),
        primary_strain_limit=float(primary_strain_limit),
        secondary_points=int(secondary_points),
    )

"""Virtual strain gauges on a deforming surface (section 3.2.6, Eq 3.5).

Digital image correlation gives the displacement of every point of the coupon surface;
the dissertation's "improved processing" places virtual strain gauges (VSG) of lengths
in multiples of 5 mm at random on it, takes the engineering strain of each (change of
length over gauge length) and averages them. The number of gauges comes from the sample
size for estimating a proportion in an infinite population (Eq 3.5),

    N = Z^2 sigma (1 - sigma) / e^2,

with ``Z`` the two-sided normal quantile of the confidence level, ``sigma`` the assumed
spread and ``e`` the margin of error: 385 for 95 %, 5 % and 0.5.

The gauge ends are interpolated linearly in the deformed positions of the surface
nodes (here: the nodes of a finite-element coupon, :mod:`pneumorph.composite.coupon`).

Examples
--------
>>> sample_size()
385
>>> g = place_gauges(4, surface_length=100.0, rng=np.random.default_rng(1))
>>> bool(np.all(g.length % 5.0 == 0.0)), bool(np.all(g.start + g.length <= 100.0))
(True, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.errors import FitError

FloatArray = NDArray[np.float64]


def sample_size(confidence: float = 0.95, margin: float = 0.05, spread: float = 0.5) -> int:
    """Minimum number of virtual strain gauges, Eq 3.5, rounded up.

    Parameters
    ----------
    confidence : float
        Two-sided confidence level (0.95: ``Z = 1.95996``).
    margin : float
        Margin of error ``e`` (0.05 = 5 %).
    spread : float
        Assumed spread (proportion) ``sigma``; 0.5 gives the largest sample.

    Examples
    --------
    >>> sample_size(), sample_size(0.99), sample_size(margin=0.1)
    (385, 664, 97)
    """
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must lie between 0 and 1, got {confidence}")
    if not 0.0 < margin < 1.0:
        raise ValueError(f"margin must lie between 0 and 1, got {margin}")
    if not 0.0 < spread < 1.0:
        raise ValueError(f"spread must lie between 0 and 1, got {spread}")
    z = NormalDist().inv_cdf(0.5 + confidence / 2.0)
    # a relative guard against round-off pushing an exact integer over the next one
    return math.ceil(z * z * spread * (1.0 - spread) / margin**2 * (1.0 - 1e-12))


@dataclass(frozen=True)
class Gauges:
    """Virtual strain gauges on a line: start positions and lengths (reference ``x``, mm)."""

    start: FloatArray
    length: FloatArray

    def __len__(self) -> int:
        return int(self.start.size)


def place_gauges(
    count: int,
    surface_length: float,
    rng: np.random.Generator,
    unit: float = 5.0,
    max_multiple: int = 10,
    origin: float = 0.0,
) -> Gauges:
    """Random gauges of lengths ``unit * k`` (``k`` uniform in 1..max_multiple) on a line.

    Each gauge lies wholly on ``[origin, origin + surface_length]``; its start is uniform
    over the positions where it fits.

    Parameters
    ----------
    count : int
        Number of gauges.
    surface_length : float
        Length of the surface (mm).
    rng : numpy.random.Generator
        Source of randomness (pass a seeded one for a repeatable placement).
    unit : float
        Length step (mm); 5 mm in the dissertation, the wavelength of its CR 0.3 crimp.
    max_multiple : int
        Longest gauge in units; lengths that do not fit the surface are not drawn.
    origin : float
        Reference ``x`` of the start of the surface.

    Examples
    --------
    >>> g = place_gauges(3, 12.0, np.random.default_rng(0))
    >>> set(g.length.tolist()) <= {5.0, 10.0}
    True
    """
    if int(count) < 1:
        raise ValueError(f"count must be at least 1, got {count}")
    if not unit > 0:
        raise ValueError(f"unit must be positive, got {unit}")
    kmax = min(int(max_multiple), math.floor(surface_length / unit + 1e-9))
    if kmax < 1:
        raise ValueError(f"no gauge of length {unit:g} mm fits a surface of {surface_length:g} mm")
    length = unit * rng.integers(1, kmax + 1, size=int(count))
    start = origin + rng.uniform(0.0, 1.0, size=int(count)) * (surface_length - length)
    return Gauges(start=start, length=length.astype(float))


def gauge_strains(gauges: Gauges, x0: ArrayLike, x: ArrayLike) -> FloatArray:
    """Engineering strain of each gauge: deformed over reference distance of its ends, minus 1.

    Parameters
    ----------
    gauges : Gauges
    x0 : array_like, shape (m,)
        Reference positions of the surface points, increasing.
    x : array_like, shape (m,) or (levels, m)
        Deformed axial positions of those points (one row per load level).

    Returns
    -------
    ndarray, shape (count,) or (levels, count)

    Examples
    --------
    >>> g = Gauges(start=np.array([0.0, 2.5]), length=np.array([5.0, 5.0]))
    >>> x0 = np.linspace(0.0, 10.0, 11)
    >>> gauge_strains(g, x0, 1.2 * x0).round(12).tolist()   # uniform 20 % stretch
    [0.2, 0.2]
    """
    x0 = np.asarray(x0, dtype=float)
    xs = np.atleast_2d(np.asarray(x, dtype=float))
    a, b = gauges.start, gauges.start + gauges.length
    out = np.empty((xs.shape[0], len(gauges)))
    for k, row in enumerate(xs):
        out[k] = (np.interp(b, x0, row) - np.interp(a, x0, row)) / gauges.length - 1.0
    return out if np.ndim(x) > 1 else out[0]


@dataclass(frozen=True)
class GaugeStudy:
    """Virtual strain gauges applied to a simulated coupon.

    Attributes
    ----------
    gauges : Gauges
    strains : ndarray, shape (levels, count)
        Strain of each gauge at each load level.
    mean_strain : ndarray, shape (levels,)
        Average over the gauges per level.
    transition_strain : float
        Two-line transition of force against ``mean_strain`` (the averaged result).
    gauge_transitions : ndarray
        Two-line transition of force against each gauge's own strain (gauges whose curve
        has no two-line fit, e.g. no point up to 10 % strain, are left out).
    mean_transition, std_transition : float
        Mean and sample standard deviation of ``gauge_transitions``.
    """

    gauges: Gauges
    strains: FloatArray
    mean_strain: FloatArray
    transition_strain: float
    gauge_transitions: FloatArray
    mean_transition: float
    std_transition: float

    @property
    def confidence_halfwidth(self) -> float:
        """Half-width of the 95 % confidence interval of ``mean_transition`` (normal)."""
        n = self.gauge_transitions.size
        return 1.959963984540054 * self.std_transition / math.sqrt(n) if n > 1 else math.nan

    def to_dict(self) -> dict[str, Any]:
        """Plain-data summary (no per-gauge arrays)."""
        return {
            "count": len(self.gauges),
            "fitted": int(self.gauge_transitions.size),
            "transition_strain": self.transition_strain,
            "mean_transition": self.mean_transition,
            "std_transition": self.std_transition,
            "confidence_halfwidth_95": self.confidence_halfwidth,
        }


def gauge_study(
    result: Any,
    count: int | None = None,
    rng: np.random.Generator | int | None = 0,
    unit: float = 5.0,
    max_multiple: int = 10,
) -> GaugeStudy:
    """Place virtual strain gauges on a coupon's top surface and characterise the result.

    Parameters
    ----------
    result : CouponResult
        A simulated coupon (its top surface per level and its force).
    count : int, optional
        Number of gauges; default :func:`sample_size` (385).
    rng : Generator or int or None
        A Generator, or a seed for one (default seed 0: repeatable).
    unit, max_multiple : float, int
        Gauge lengths ``unit * k``, ``k = 1..max_multiple`` (5-50 mm by default).

    Returns
    -------
    GaugeStudy
    """
    from pneumorph.materials.characterisation.analyses import bilinear

    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    n = sample_size() if count is None else int(count)
    x0 = np.asarray(result.surface_x0, dtype=float)
    gauges = place_gauges(n, float(x0[-1] - x0[0]), gen, unit, max_multiple, origin=float(x0[0]))
    strains = gauge_strains(gauges, x0, np.asarray(result.surface)[:, :, 0])
    mean = strains.mean(axis=1)
    force = np.asarray(result.force, dtype=float)
    overall = bilinear(mean, force).transition_strain
    each = []
    for j in range(n):
        try:
            each.append(bilinear(strains[:, j], force).transition_strain)
        except FitError:
            continue
    each_arr = np.asarray(each, dtype=float)
    return GaugeStudy(
        gauges=gauges,
        strains=strains,
        mean_strain=mean,
        transition_strain=float(overall),
        gauge_transitions=each_arr,
        mean_transition=float(each_arr.mean()) if each_arr.size else math.nan,
        std_transition=float(each_arr.std(ddof=1)) if each_arr.size > 1 else math.nan,
    )

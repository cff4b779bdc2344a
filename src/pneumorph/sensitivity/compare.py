"""How far one inflated shape is from another: the measures of appendices D and E.

The dissertation compares two models of the same design by the *maximum Euclidean distance
between matching nodes* of their centrelines, and states that distance as X and Y errors in
percent. pneumorph's matching points are those every model reports: the base point, the
unit centres and the tip (:meth:`~pneumorph.models.response.Response.centreline`). The X
and Y errors are the components of the largest distance, each as a percentage of the
reference centreline's extent in that direction (for appendix D.1, 11.7 mm on an actuator
about 150 mm long read as 4.5 % and 6.5 %).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from pneumorph.models.response import Response


@dataclass(frozen=True)
class ShapeDifference:
    """One shape against a reference at one pressure level each.

    Attributes
    ----------
    distance_mm : float
        The largest distance between matching centreline points.
    x_error_pct, y_error_pct : float
        The x and y components of that distance, in % of the reference's x and y extents.
    tip_mm : float
        The distance between the tips.
    curl_deg, reference_curl_deg : float
        The curl (end-face rotation) of the shape and of the reference.
    """

    distance_mm: float
    x_error_pct: float
    y_error_pct: float
    tip_mm: float
    curl_deg: float
    reference_curl_deg: float

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def shape_difference(reference: Response, other: Response, level: int = -1,
                     other_level: int | None = None) -> ShapeDifference:
    """The difference of ``other`` (at ``other_level``, default ``level``) from ``reference`` at ``level``.

    Examples
    --------
    >>> from pneumorph.models.response import Response
    >>> p = np.array([0.045])
    >>> a = Response.empty("0", p, np.array([[5.0, 0.0]]), np.array([10.0, 0.0]))
    >>> a.centres[0], a.tip[0], a.curl[0] = [5.0, 0.0], [10.0, 0.0], 0.0
    >>> b = Response.empty("0", p, np.array([[5.0, 0.0]]), np.array([10.0, 0.0]))
    >>> b.centres[0], b.tip[0], b.curl[0] = [5.0, 0.0], [9.0, 1.0], 10.0
    >>> d = shape_difference(a, b)
    >>> round(d.distance_mm, 4), round(d.x_error_pct, 1), d.curl_deg
    (1.4142, 10.0, 10.0)
    """
    k = level % reference.n_levels
    j = k if other_level is None else other_level % other.n_levels
    ref, oth = reference.centreline(k), other.centreline(j)
    gaps = np.linalg.norm(oth - ref, axis=1)
    worst = int(np.argmax(gaps))
    extent = np.ptp(ref, axis=0)
    extent = np.where(extent > 0, extent, 1.0)
    dx, dy = np.abs(oth[worst] - ref[worst])
    return ShapeDifference(
        distance_mm=float(gaps[worst]),
        x_error_pct=float(100 * dx / extent[0]),
        y_error_pct=float(100 * dy / extent[1]),
        tip_mm=float(np.linalg.norm(other.tip[j] - reference.tip[k])),
        curl_deg=float(other.curl[j]),
        reference_curl_deg=float(reference.curl[k]),
    )


__all__ = ["ShapeDifference", "shape_difference"]

"""Does a scan match its design? Its size, every unit seen, no part of the scan beyond them.

Checked before the fit's many solves: on the shape a chain table predicts before any solve
(:mod:`pneumorph.identify.extent`, widened by :data:`CHAIN_MARGIN`), and on the solved
shape after the nominal solve.

- **Size** (:func:`check_size`). The scan must span within :data:`MATCH_RANGE` times its
  design's shape: a design typed with a very different unit count, or a scan in other units.
- **Units** (:func:`check_coverage`). A design one or two units off its scan spans within
  what a cast's material moves (docs/identify.md), so its size cannot refuse it. Its shape
  can, once the scan is aligned to it (:func:`~pneumorph.correlation.compare.correlate`):

  - *points beyond the design*: a design with fewer units than the cast leaves about half a
    unit's share of the scan farther than half a pitch from its shape (measured: 2.8-15 % of
    the points at 15 units; a right design: none). More than :data:`BEYOND_SHARE` of one unit's
    share so far refuses the design;
  - *an end unit the scan does not reach*: a design with more units than the cast has an end
    unit that few scan points are nearest to. Each unit's share of the scan's points (nearest
    unit centre in the bending plane) over its share of the model's own points is about 1 for
    every unit of a right design (measured 0.87-1.14 for the end units); an end unit below
    :data:`MIN_END_SHARE` refuses the design (measured 0-0.46 for one or two units more). A
    scan cut short of an end looks the same, so the message names both.

With the shapes at the two levels around the scan's pressure, a scan is refused only if it
fails against both.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from pneumorph.correlation.compare import ModelShape, correlate
from pneumorph.correlation.scans import Scan
from pneumorph.errors import ScanError
from pneumorph.identify.scans import ScanSpec

FloatArray = NDArray[np.float64]

#: a scan spanning outside this times its design's model (solved at nominal) is not of that design
MATCH_RANGE = (0.8, 1.25)
#: the chain table's rigid units span up to 2 % less than the solved shape (docs/identify.md): the
#: size check before any solve is widened by this
CHAIN_MARGIN = 0.05
#: the share of one unit's points that may lie beyond half a pitch from the design's shape
BEYOND_SHARE = 0.25
#: the least share an end unit must have of the scan's points, over its share of the model's
MIN_END_SHARE = 0.6


@dataclass(frozen=True)
class Coverage:
    """How a scan aligned to a design's shape covers its units.

    Attributes
    ----------
    beyond : float
        The fraction of the scan's points farther than half a pitch from the shape.
    shares : ndarray, shape (units,)
        Each unit's share of the scan's points over its share of the model's (nearest unit
        centre in the bending plane; the base block counts to the first unit, the end cap to
        the last).
    """

    beyond: float
    shares: FloatArray

    @property
    def units(self) -> int:
        return len(self.shares)

    def problem(self) -> str:
        """What the coverage says is wrong ("" when the scan shows the design's units)."""
        if self.beyond > BEYOND_SHARE / self.units:
            return (f"{100 * self.beyond:.2g} % of the scan lies more than half a unit from the design's shape "
                    f"(a unit holds {100 / self.units:.2g} %): the cast has more units than the design, or was scanned "
                    "at another pressure?")
        ends = {"first": float(self.shares[0]), "last": float(self.shares[-1])}
        low = {k: v for k, v in ends.items() if v < MIN_END_SHARE}
        if low:
            which = " and ".join(f"its {k} unit ({v:.2f} of its share)" for k, v in low.items())
            return (f"the scan hardly reaches {which}: the design has more units than the cast, or the scan "
                    "misses an end of the actuator?")
        return ""


def coverage(points: FloatArray, shape: ModelShape) -> Coverage:
    """The :class:`Coverage` of ``shape`` by scan ``points`` aligned to it (mm).

    A 3D scan is compared with the shape's surface, a 2D trace with its outline.

    Examples
    --------
    >>> from pneumorph.models.factory import make_model
    >>> from pneumorph.identify.extent import chain_shape
    >>> shape = chain_shape(make_model(8, {"fidelity": "2d", "pressure_kpa": 36}), "01100110")
    >>> own = coverage(shape.samples[::20], shape)   # the shape's own outline
    >>> own.beyond, own.shares.round(1).tolist(), own.problem()
    (0.0, [1.0, 1.0, 1.0, 1.0, 0.9, 1.1, 1.0, 1.0], '')
    >>> short = shape.samples[np.linalg.norm(shape.samples - shape.centres[-1], axis=1) > 8]   # the last unit cut off
    >>> coverage(short, shape).problem()[:43]   # the points within 8 mm of its centre lost
    'the scan hardly reaches its last unit (0.19'
    """
    model = shape.surface if points.shape[1] == 3 else shape.samples  # a photo trace: the outline
    dist, _ = cKDTree(model).query(points)
    tree = cKDTree(shape.centres)
    n = len(shape.centres)
    seen = np.bincount(tree.query(points[:, :2])[1], minlength=n) / len(points)
    own = np.bincount(tree.query(model[:, :2])[1], minlength=n) / len(model)
    return Coverage(float(np.mean(dist > 0.5 * shape.pitch)), seen / np.maximum(own, 1e-300))


def check_size(scan: Scan, spec: ScanSpec, shapes: Sequence[ModelShape], predicted: bool = False) -> None:
    """Refuse a scan whose size is not its design's (another unit count, another scan unit).

    The scan must span within :data:`MATCH_RANGE` times its design's deformed shape (the
    diagonal of the box along their principal axes, whichever way the scan lies); a cast off
    the model by the parameters the fit can change spans within a few percent of it. A
    ``predicted`` shape (by a chain table, before any solve) widens the range by
    :data:`CHAIN_MARGIN` both ways; given the shapes at the levels around the scan's
    pressure, from the smallest one's to the largest's.

    Raises
    ------
    ScanError
        The scan and the model differ in size beyond the range.
    """
    margin = CHAIN_MARGIN if predicted else 0.0
    sizes = [_size(s.surface if len(s.surface) else s.samples) for s in shapes]
    size, lo, hi = _size(scan.points), min(sizes), max(sizes)
    within = MATCH_RANGE[0] / (1 + margin) <= size / max(lo, 1e-12) and \
        size / max(hi, 1e-12) <= MATCH_RANGE[1] * (1 + margin)
    if not within:
        span = f"{lo:.4g} mm" if len(shapes) == 1 else f"{lo:.4g} to {hi:.4g} mm (the table's levels around it)"
        ratio = size / (lo if size < lo else hi)
        raise ScanError(f"scan {spec.file} spans {size:.4g} mm but design {spec.design} "
                        f"({len(spec.design)} units) spans {span} at {spec.pressure_kpa:g} kPa{_how(predicted)} "
                        f"({ratio:.3g} times): is it the design scanned? (check its unit count and --scan-unit)")


def check_coverage(scan: Scan, spec: ScanSpec, shapes: Sequence[ModelShape], predicted: bool = False,
                   aligned: Sequence[FloatArray] | None = None) -> None:
    """Refuse a scan that does not show its design's units (see the module docstring).

    ``shapes``: the design's shape (solved, or ``predicted`` by a chain table), or the shapes
    at the two levels around the scan's pressure; the scan is refused only if it fails
    against each of them. ``aligned``: the scan's points already aligned to each shape
    (:func:`~pneumorph.correlation.compare.correlate`'s ``aligned``), else aligned here.

    Raises
    ------
    ScanError
        The scan does not show the design's units.
    """
    problems = []
    for k, shape in enumerate(shapes):
        points = correlate(scan, shape).aligned if aligned is None else aligned[k]
        problem = coverage(points, shape).problem()
        if not problem:
            return
        problems.append(problem)
    raise ScanError(f"scan {spec.file} is not design {spec.design} ({len(spec.design)} units) at "
                    f"{spec.pressure_kpa:g} kPa{_how(predicted)}: {problems[0]} (check its unit count and pressure)")


def _how(predicted: bool) -> str:
    return " by its chain table" if predicted else ""


def _size(points: FloatArray) -> float:
    """The diagonal of the points' box along their principal axes (independent of their orientation)."""
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    return float(np.linalg.norm(np.ptp(centred @ vt.T, axis=0)))


__all__ = ["BEYOND_SHARE", "CHAIN_MARGIN", "MATCH_RANGE", "MIN_END_SHARE", "Coverage", "check_coverage",
           "check_size", "coverage"]

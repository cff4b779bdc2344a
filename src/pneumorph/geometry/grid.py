"""Grid lines of the structured actuator mesh: where they must fall, and how they fill the gaps.

The assembly (:mod:`pneumorph.geometry.assembly`) meshes a whole actuator as one tensor grid;
its lines go through every interface of every unit (the breaks of :func:`section_breaks`),
and :func:`grid_lines` fills the gaps between breaks with lines no further apart than the
element size. Units of a library share their cross-section lines
(:func:`cross_section_lines`), so that any mix of them meshes as one conforming grid.
"""

from __future__ import annotations

from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from pneumorph.geometry.unit import UnitSpec

FloatArray = NDArray[np.float64]


def grid_lines(breaks: list[float], size: float) -> FloatArray:
    """Coordinates through every break, no gap wider than ``size``.

    Breaks closer than 1e-6 mm are merged.

    Examples
    --------
    >>> grid_lines([0.0, 1.5, 4.5], 1.5).tolist()
    [0.0, 1.5, 3.0, 4.5]
    """
    b = np.unique(np.round(np.asarray(breaks, dtype=float), 6))
    out = [b[0]]
    for lo, hi in pairwise(b):
        n = max(1, int(np.ceil((hi - lo) / size - 1e-9)))
        out.extend(np.linspace(lo, hi, n + 1)[1:])
    return np.asarray(out)


def section_breaks(spec: UnitSpec) -> tuple[list[float], list[float]]:
    """The x breaks of one unit (its own frame) and the y breaks of both its orientations.

    Examples
    --------
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> xb, yb = section_breaks(UnitSpec())
    >>> xb
    [0.0, 3.0, 7.5, 10.5, 10.5]
    >>> sorted(set(yb))
    [0.0, 1.5, 3.0, 4.5, 7.5, 9.0, 10.5, 12.0]
    """
    x0, x1, y0, y1 = spec.cavity
    xb = [0.0, x0, x1, x1 + spec.end_wall, spec.pitch]
    yb = [0.0, y0, y1, spec.height - spec.top_layer, spec.height]
    if spec.slit is not None:
        yb.append(spec.slit_depth)
    # mirrored after rounding as the grid rounds (grid_lines): the lines of both orientations then lie exactly
    # symmetric about mid-height whatever the unit's decimals (an identified unit's 1.591632525 mm wall)
    yb = [round(y, 6) for y in yb]
    top = round(spec.height, 6)
    yb += [round(top - y, 6) for y in yb]
    return xb, yb


def width_breaks(spec: UnitSpec, half: bool = False) -> list[float]:
    """The z breaks across the width (3D): the side walls, the mid-plane and a side layer in both orientations.

    ``half``: those of the half ``0 <= z <= width / 2``. A sideways unit (``layer_side``) adds
    its layer's and cavity's faces, at ``width - side_wall - layer`` and ``width - layer``
    and (turned over) mirrored.

    Examples
    --------
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> width_breaks(UnitSpec(), half=True)
    [0.0, 1.5, 7.5]
    >>> width_breaks(UnitSpec(cavity_height=9.0, layer_side=True))
    [0.0, 1.5, 7.5, 13.5, 15.0, 10.5, 12.0, 4.5, 3.0]
    """
    W = spec.width
    breaks = [0.0, spec.side_wall, W / 2] if half else [0.0, spec.side_wall, W / 2, W - spec.side_wall, W]
    if spec.layer_side:  # mirrored after rounding, as section_breaks does: `l` and `L` exact mirror images
        side = [round(W - spec.side_wall - spec.layer, 6), round(W - spec.layer, 6)]
        breaks += [z for z in [*side, *(round(round(W, 6) - z, 6) for z in side)] if not half or z < W / 2]
    return breaks


def cross_section_lines(spec: UnitSpec) -> tuple[FloatArray, FloatArray]:
    """The y lines (height, both orientations) and z lines (full width) of a unit meshed alone.

    Two units can follow each other in one actuator only if these are the same: then the
    faces they share carry the same nodes, and each unit is meshed as it would be alone.

    Examples
    --------
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> y, z = cross_section_lines(UnitSpec())
    >>> y.tolist()
    [0.0, 1.5, 3.0, 4.5, 6.0, 7.5, 9.0, 10.5, 12.0]
    >>> len(z)
    11
    """
    h = spec.element_size
    return grid_lines(section_breaks(spec)[1], h), grid_lines(width_breaks(spec), h)


__all__ = ["cross_section_lines", "grid_lines", "section_breaks", "width_breaks"]

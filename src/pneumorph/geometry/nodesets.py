"""The named point sets of an actuator's mesh: where the loads act, where it is held, where results are read.

:func:`~pneumorph.geometry.assembly.assemble` meshes the cells; these functions pick out of its
points the ones the models need by name: the cavity walls (the pressure's surface, the passages'
walls included), each unit's four tracked cavity vertices (Fig 4.4: its centre), the clamped
points (the base face, or the base block's jaws) and the free end face (the tip and the curl).
Each is found from the units' geometry, within :data:`TOLERANCE` of the lines the grid has.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import GeometryError
from pneumorph.geometry.features import BaseBlock, Box
from pneumorph.geometry.unit import UnitSpec

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
FloatArray = NDArray[np.float64]

#: How near a point must lie to a cavity's wall or vertex, or to a clamped or end face, to be on it (mm).
TOLERANCE = 1e-6


def cavity_box(unit: UnitSpec, o: str, start: float, H: float) -> Box:
    """A unit's cavity ``(x0, x1, y0, y1, z0, z1)`` in the actuator's frame (mm): starting at ``start``, in
    orientation ``o``, in a section of height ``H``; turned over it is mirrored (a sideways unit across the
    width too).

    >>> cavity_box(UnitSpec(), "1", 10.5, 12.0)
    (13.5, 18.0, 4.5, 10.5, 1.5, 13.5)
    """
    x0, x1, y0, y1 = unit.cavity
    z0, z1 = unit.cavity_z
    if o == "1":
        y0, y1 = H - y1, H - y0
        z0, z1 = (unit.width - z1, unit.width - z0) if unit.layer_side else (z0, z1)
    return start + x0, start + x1, y0, y1, z0, z1


def cavity_points(points: FloatArray, ref: UnitSpec, units: Sequence[UnitSpec], orientation: str,
                  starts: FloatArray, dim: int, side: float) -> BoolArray:
    """The points on the cavity walls (in 2D inside the filler too) and on the passages' walls.

    ``ref`` is the unit whose cross-section all share; a solid unit has no cavity; a
    passage of side ``side`` joins cavity i to cavity i + 1.

    >>> units = [UnitSpec(), UnitSpec()]
    >>> points = np.array([[3.0, 1.5], [5.0, 4.0], [1.0, 1.0], [13.5, 4.5]])
    >>> cavity_points(points, units[0], units, "01", np.array([0.0, 10.5, 21.0]), 2, 0.0).tolist()
    [True, True, False, True]
    """
    H, W = ref.height, ref.width
    found = np.zeros(len(points), dtype=bool)
    for i, (unit, o) in enumerate(zip(units, orientation, strict=True)):
        if unit.solid:
            continue
        x0, x1, cy0, cy1, z0, z1 = cavity_box(unit, o, float(starts[i]), H)
        inside = (
            (points[:, 0] > x0 - TOLERANCE)
            & (points[:, 0] < x1 + TOLERANCE)
            & (points[:, 1] > cy0 - TOLERANCE)
            & (points[:, 1] < cy1 + TOLERANCE)
        )
        if dim == 3:
            inside &= (points[:, 2] > z0 - TOLERANCE) & (points[:, 2] < z1 + TOLERANCE)
        found |= inside
    if side:  # the passages' walls are loaded by the pressure too
        for i in range(len(units) - 1):
            inside = ((points[:, 0] > float(starts[i]) + units[i].cavity[1] - TOLERANCE)
                      & (points[:, 0] < float(starts[i + 1]) + units[i + 1].cavity[0] + TOLERANCE)
                      & (np.abs(points[:, 1] - H / 2) < side / 2 + TOLERANCE))
            if dim == 3:
                inside &= np.abs(points[:, 2] - W / 2) < side / 2 + TOLERANCE
            found |= inside
    return found


def tracked_points(points: FloatArray, ref: UnitSpec, units: Sequence[UnitSpec], orientation: str,
                   starts: FloatArray, dim: int) -> IntArray:
    """Per unit, the points at its cavity's four vertices (a solid unit's box too; mid-width of ``ref`` in 3D).

    Raises
    ------
    GeometryError
        A vertex without a mesh point (never for :func:`~pneumorph.geometry.assembly.assemble`'s
        meshes: the grid has these lines).

    Examples
    --------
    >>> points = np.array([[0.0, 0.0], [7.5, 7.5], [3.0, 1.5], [7.5, 1.5], [3.0, 7.5]])
    >>> tracked_points(points, UnitSpec(), [UnitSpec()], "0", np.array([0.0, 10.5]), 2).tolist()
    [[2, 3, 1, 4]]
    """
    H, W = ref.height, ref.width
    tracked = np.zeros((len(units), 4), dtype=np.int64)
    for i, (unit, o) in enumerate(zip(units, orientation, strict=True)):
        x0, x1, cy0, cy1, _, _ = cavity_box(unit, o, float(starts[i]), H)
        corners = [(x0, cy0), (x1, cy0), (x1, cy1), (x0, cy1)]
        for k, (cx, cy) in enumerate(corners):
            d = (points[:, 0] - cx) ** 2 + (points[:, 1] - cy) ** 2
            if dim == 3:
                d = d + (points[:, 2] - W / 2) ** 2
            tracked[i, k] = int(np.argmin(d))
            if d[tracked[i, k]] > TOLERANCE**2:
                raise GeometryError(f"no mesh point at cavity vertex {k} of unit {i}")
    return tracked


def clamped_points(points: FloatArray, height: float, base: BaseBlock | None) -> BoolArray:
    """The clamped points: the base face x = 0, or the jaws on the base block's bottom and top faces.

    >>> clamped_points(np.array([[0.0, 0.0], [0.0, 12.0], [5.0, 0.0]]), 12.0, None).tolist()
    [True, True, False]
    """
    if base is None:
        return np.isclose(points[:, 0], 0.0)
    jaws = np.isclose(points[:, 1], -base.margin) | np.isclose(points[:, 1], height + base.margin)
    return jaws & (points[:, 0] < TOLERANCE)


def end_face_points(points: FloatArray, ref: UnitSpec, starts: FloatArray, dim: int) -> IntArray:
    """The points of the free end face (after ``ref``'s end cap) in the section plane, ordered by height.

    >>> points = np.array([[21.0, 12.0], [21.0, 0.0], [10.0, 0.0]])
    >>> end_face_points(points, UnitSpec(), np.array([0.0, 10.5, 21.0]), 2).tolist()
    [1, 0]
    """
    on_end = np.isclose(points[:, 0], float(starts[-1]) + ref.end_cap)
    if dim == 3:
        on_end &= np.isclose(points[:, 2], ref.width / 2)
    end_points = np.flatnonzero(on_end)
    return end_points[np.argsort(points[end_points, 1])]

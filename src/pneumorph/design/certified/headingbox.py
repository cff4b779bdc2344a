"""The cruder bound of a search's first units: a box from the chords' heading intervals.

Before the prefixes are long enough for the support functions of :mod:`pneumorph.design.certified.reach`,
a chord ``i`` units ahead has turned by at most ``i`` of the table's greatest turns and at
least ``i`` of its least, and its length lies between the table's least and greatest; so
every tip the remaining chords reach lies in a box, and a tip goal's or a profile's cost is
at least the box's.

Examples
--------
>>> import numpy as np
>>> lo, hi = _cos_range(np.array([-0.5]), np.array([0.5]))
>>> float(lo[0]) == float(np.cos(0.5)), float(hi[0])
(True, 1.0)
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.objectives.targets import Objective, TipGoal
from pneumorph.models.chain.model import ChainModel

FloatArray = NDArray[np.float64]


def _contains(lo: FloatArray, hi: FloatArray, phase: float) -> NDArray[np.bool_]:
    """True where [lo, hi] contains ``phase + 2 pi m`` for some integer m."""
    return 2 * np.pi * np.ceil((lo - phase) / (2 * np.pi)) + phase <= hi


def _cos_range(lo: FloatArray, hi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Least and greatest cosine over the angle intervals [lo, hi]."""
    c_lo, c_hi = np.cos(lo), np.cos(hi)
    top = np.where(_contains(lo, hi, 0.0), 1.0, np.maximum(c_lo, c_hi))
    bottom = np.where(_contains(lo, hi, np.pi), -1.0, np.minimum(c_lo, c_hi))
    return bottom, top


def _sin_range(lo: FloatArray, hi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Least and greatest sine over the angle intervals [lo, hi]."""
    s_lo, s_hi = np.sin(lo), np.sin(hi)
    top = np.where(_contains(lo, hi, np.pi / 2), 1.0, np.maximum(s_lo, s_hi))
    bottom = np.where(_contains(lo, hi, -np.pi / 2), -1.0, np.minimum(s_lo, s_hi))
    return bottom, top


def _reach_box(table: Any, state: dict[str, Any], remaining: int, axes: str = "xy") -> tuple[FloatArray, ...]:
    """A box (per prefix and level) holding every tip its remaining chords can reach.

    Chord ``i`` of the remaining ones turns by ``i`` tabulated turns at most, so its angle
    lies in ``[a + i t_min, a + i t_max]``; its length in ``[L_min, L_max]``. Only the
    ``axes`` asked for are bounded (the others stay at the current point).
    """
    tmin, tmax = table.turn.min(axis=0), table.turn.max(axis=0)
    lmin, lmax = table.length.min(axis=0), table.length.max(axis=0)
    a = state["angle"]
    x, y = state["point"][..., 0], state["point"][..., 1]
    xlo, xhi, ylo, yhi = x.copy(), x.copy(), y.copy(), y.copy()
    for i in range(1, remaining + 1):
        lo, hi = a + i * tmin, a + i * tmax
        if "x" in axes:
            cmin, cmax = _cos_range(lo, hi)
            xhi += np.where(cmax >= 0, lmax * cmax, lmin * cmax)
            xlo += np.where(cmin <= 0, lmax * cmin, lmin * cmin)
        if "y" in axes:
            smin, smax = _sin_range(lo, hi)
            yhi += np.where(smax >= 0, lmax * smax, lmin * smax)
            ylo += np.where(smin <= 0, lmax * smin, lmin * smin)
    return xlo, xhi, ylo, yhi


def box_bound(chain: ChainModel, objective: Objective, state: dict[str, Any], remaining: int) -> FloatArray:
    """Per level, a lower bound on the cost of every completion from the chords' heading intervals (m, k)."""
    table = chain.table
    name = objective.name
    if name == "max-curl":  # the rest of the turns and the end turn at their largest
        turns = np.degrees(remaining * table.turn.max(axis=0) + table.end.max(axis=0))
        return -(np.degrees(state["angle"]) + turns)
    axes = {"max-x": "x", "min-x": "x", "max-y": "y", "min-y": "y"}.get(name, "xy")
    xlo, xhi, ylo, yhi = _reach_box(table, state, remaining, axes)
    ylo, yhi = ylo - table.tip_ref[1], yhi - table.tip_ref[1]
    if name == "max-x":
        return -xhi
    if name == "min-x":
        return xlo
    if name == "max-y":
        return -yhi
    if name == "min-y":
        return ylo
    # distance to the base or to a point: from the point to the box
    q = (0.0, 0.0) if name == "min-distance" else cast(TipGoal, objective).point
    assert q is not None
    dx = np.maximum(np.maximum(xlo - q[0], q[0] - xhi), 0.0)
    dy = np.maximum(np.maximum(ylo - q[1], q[1] - yhi), 0.0)
    if len(q) == 3:  # a point off the plane: the planar chain's tip lies at z = 0
        return np.hypot(np.hypot(dx, dy), q[2])
    return np.hypot(dx, dy)


__all__ = ["box_bound"]

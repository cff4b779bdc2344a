"""Lower bounds on what the units still to place add to a cost.

They come from the boxes of :mod:`pneumorph.design.certified.reach`.

A profile target's term at a centre not yet fixed is at least the gap between the box that
holds the centre and the target's heights over the box's x range (:class:`CurveRange`: the
least and greatest of ``f`` over an interval in two look-ups); a tip goal's value is at
least the hull's best x or y, or its distance from a point (:func:`tip_goal_rest`).

Examples
--------
>>> import numpy as np
>>> r = CurveRange.of(np.sin, 0.0, 10.0, slope=1.0)
>>> lo, hi = r.between(np.array([0.0]), np.array([np.pi]))
>>> bool(lo[0] <= 0.0 and hi[0] >= 1.0)
True
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.certified.reach import AHEAD, EMPTY, Reach
from pneumorph.design.objectives.paths import PathTarget

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class CurveRange:
    """Least and greatest value of ``y = f(x)`` over x intervals, from a fine grid and the slope.

    A sparse table of the grid's minima and maxima over runs of ``2^i`` points answers an
    interval in two look-ups; ``slope * step / 2`` covers the curve between grid points.
    """

    lo: float
    step: float
    slack: float
    mins: tuple[FloatArray, ...]
    maxs: tuple[FloatArray, ...]

    @classmethod
    def of(cls, f: Callable[[FloatArray], FloatArray], lo: float, hi: float, slope: float,
           step: float = 0.05) -> CurveRange:
        x = np.arange(lo, hi + step, step)
        with np.errstate(all="ignore"):
            v = np.asarray(f(x), dtype=float)
        v = np.broadcast_to(v, x.shape)
        mins = [np.where(np.isfinite(v), v, -np.inf)]
        maxs = [np.where(np.isfinite(v), v, np.inf)]
        span = 1
        while 2 * span <= len(x):
            mins.append(np.minimum(mins[-1][:-span], mins[-1][span:]))
            maxs.append(np.maximum(maxs[-1][:-span], maxs[-1][span:]))
            span *= 2
        return cls(float(lo), float(step), float(slope) * step / 2 + 1e-9, tuple(mins), tuple(maxs))

    def between(self, x_lo: FloatArray, x_hi: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Least and greatest ``f`` over ``[x_lo, x_hi]`` (arrays of one shape), widened by the slack."""
        size = len(self.mins[0])
        i = np.clip(np.floor((x_lo - self.lo) / self.step), 0, size - 1).astype(np.int64)
        j = np.clip(np.ceil((x_hi - self.lo) / self.step), 0, size - 1).astype(np.int64)
        j = np.maximum(i, j)
        level = np.floor(np.log2(j - i + 1)).astype(np.int64)
        lo = np.full(i.shape, np.inf)
        hi = np.full(i.shape, -np.inf)
        for lv in np.unique(level):
            sel = level == lv
            span = 1 << int(lv)
            a, z = i[sel], j[sel] - span + 1
            lo[sel] = np.minimum(self.mins[lv][a], self.mins[lv][z])
            hi[sel] = np.maximum(self.maxs[lv][a], self.maxs[lv][z])
        return lo - self.slack, hi + self.slack


def profile_rest(reach: Reach, heights: FloatArray, curve: CurveRange, bits: NDArray[np.integer],
                 point: FloatArray, heading: FloatArray, placed: int, n_units: int, window: int) -> FloatArray:
    """A lower bound on the summed squared Eq 4.1 terms of the centres the prefixes have not fixed, (m, k).

    Centre ``i`` (``placed < i <= n - w + 1``: its chords see no tip) lies in the box of the
    ``i - placed`` chords from the prefixes' point; its term ``f(x) - (y - y_ref)`` is at least
    the gap between the box's heights (less the unit's undeformed centre height, known for the
    prefix's units, else its least and greatest) and the target's values over the box's x
    range. The last ``w - 1`` centres add nothing (their boxes, a chord or two wide, measured:
    no prefix more is dropped), nor do those more than :data:`AHEAD` chords ahead (their boxes
    are wide: they would cost more than they add).
    """
    state = reach.state(bits)
    p = bits.shape[1]
    total = np.zeros(heading.shape)
    h_lo, h_hi = float(np.min(heights)), float(np.max(heights))
    for i in range(placed + 1, min(n_units - window + 2, placed + 1 + AHEAD)):
        x_lo, x_hi, y_lo, y_hi = reach.box("centre", i - placed, state, point, heading)
        lo_ref: FloatArray | float = h_lo
        hi_ref: FloatArray | float = h_hi
        if i <= p:
            lo_ref = hi_ref = heights[np.asarray(bits[:, i - 1], dtype=np.int64)][:, None]
        f_lo, f_hi = curve.between(x_lo, x_hi)
        gap = np.maximum(np.maximum(f_lo - (y_hi - lo_ref), (y_lo - hi_ref) - f_hi), 0.0)
        total += np.where(y_lo <= EMPTY / 2, 0.0, gap * gap)
    return total


#: directions in which the distance from a point to the tip's hull is bounded
_DISTANCE_DIRECTIONS = 8


def tip_goal_rest(reach: Reach, name: str, target: tuple[float, ...] | None, tip_height: float,
                  bits: NDArray[np.integer], point: FloatArray, heading: FloatArray, n_units: int) -> FloatArray:
    """A lower bound on a tip goal's cost (its value; minus it when maximising) of every completion, (m, k).

    The tip lies in the hull of the displacements of the chords still to place; the bound is
    the hull's best x or y, its distance from the base or a point (at least ``u . (P - q) -
    h(-u)`` for every unit vector ``u``), or the curl with the greatest remaining turn.
    """
    state = reach.state(bits)
    a = n_units - bits.shape[1]
    if name == "max-curl":
        turn = reach.turn[a][state]
        return np.where(turn <= EMPTY / 2, np.inf, -np.degrees(heading + turn) - 1e-9)
    x, y = point[..., 0], point[..., 1] - tip_height
    if name in ("max-x", "min-x", "max-y", "min-y"):
        phi = {"max-x": 0.0, "min-x": np.pi, "max-y": np.pi / 2, "min-y": -np.pi / 2}[name]
        h = reach.support("tip", a, state, phi - heading)
        if name == "max-x":
            out = -(x + h)
        elif name == "min-x":
            out = x - h
        elif name == "max-y":
            out = -(y + h)
        else:
            out = y - h
        return np.where(h <= EMPTY / 2, np.inf, out)
    q = (0.0, 0.0) if name == "min-distance" else target
    assert q is not None
    best = np.zeros(heading.shape)
    toward = np.arctan2(y - q[1], x - q[0])  # from the point to the prefix's point, then a fan around it
    h = reach.support("tip", a, state, toward + np.pi - heading, fan=_DISTANCE_DIRECTIONS)
    for i in range(_DISTANCE_DIRECTIONS):
        psi = toward + 2 * np.pi * i / _DISTANCE_DIRECTIONS
        lb = np.cos(psi) * (x - q[0]) + np.sin(psi) * (y - q[1]) - h[i]
        best = np.maximum(best, np.where(h[i] <= EMPTY / 2, np.inf, lb))
    if len(q) == 3:  # a point off the plane: the planar chain's tip lies at z = 0, q[2] away from it
        return np.hypot(best, q[2])
    return best



def path_rest(target: PathTarget, n_units: int, point: FloatArray, placed: int, longest: FloatArray,
              partial: FloatArray | None = None, limit: float = np.inf) -> FloatArray:
    """A lower bound on the summed path terms of the next centres the prefixes have not fixed, (m, k).

    Centre ``i`` (1-based, ``placed < i``, at most :data:`~pneumorph.design.certified.reach.AHEAD` on) lies
    within ``(i - placed) L_k`` of the prefix's last point ``point`` (m, k, 2 or 3; the base for
    ``placed = 0``), ``L_k`` the longest chord at level ``k``: its distance to its stretch of the
    path is at least the point's less that, the term at least the square of what is left.

    With the prefixes' ``partial`` sums (m, k) and a ``limit`` on the squared cost, a level whose
    partial sum and bound so far reach it is not looked at again (its bound is infinite: no
    design of the prefix costs less than the limit there).

    Examples
    --------
    >>> from pneumorph.design.objectives.paths import path_target
    >>> t = path_target([[0, 0], [20, 0]])  # centre 2 of 2: its stretch is x from 12 to 18
    >>> path_rest(t, 2, np.array([[[15.0, 20.0]]]), 1, np.array([10.0])).round(6).tolist()  # (20 - 10)^2
    [[100.0]]
    """
    total = np.zeros(point.shape[:2])
    base = np.zeros(point.shape[:2]) if partial is None else partial
    for i in range(placed + 1, min(n_units, placed + AHEAD) + 1):
        alive = base + total < limit
        if not alive.any():
            break
        d = target.distance_to(i - 1, n_units, point[alive])
        gap = np.maximum(d - np.broadcast_to((i - placed) * longest, alive.shape)[alive], 0.0)
        total[alive] += gap * gap
    return np.where(base + total < limit, total, np.inf)


__all__ = ["CurveRange", "path_rest", "profile_rest", "tip_goal_rest"]

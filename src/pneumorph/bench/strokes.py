"""Drawn strokes: a graph ``y = f(x)`` or a path, and a path stroke smoothed along its arc length.

The page's drawing canvas gives a stroke in the profile frame: x from the base along the
undeformed actuator, y above its undeformed axis (mm). A stroke that keeps going one way in x
is a graph and is smoothed by :func:`pneumorph.design.objectives.targets.smooth_curve` as it always was.
A stroke that turns back in x (a hook, a letter, a spiral), or so steep that its span in x
is less than :data:`~pneumorph.design.objectives.profiles.MIN_GRAPH_SPAN` of its length, is no graph:
:func:`smooth_path` makes it a path (:mod:`pneumorph.design.objectives.paths`), in order, in the frame
of the unit centres (the axis height added to y).

Hand jitter is not a turn: a stroke turns back when its x falls more than
``max(TURN_BACK_MM, TURN_BACK_SHARE * span)`` below the furthest x it had reached (and rises as
far above the least, so that a graph drawn from the tip to the base stays a graph). The
distance is measured from the running extreme, not summed, so a jitter of a pixel back and
forth never adds up to a turn.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.objectives.paths import MAX_PATH_POINTS, path_points
from pneumorph.design.objectives.profiles import MIN_GRAPH_SPAN, smooth_curve
from pneumorph.errors import TargetExpressionError

FloatArray = NDArray[np.float64]

TURN_BACK_MM = 1.0
"""Least fall of x (mm) below the furthest x reached that makes a stroke turn back."""

TURN_BACK_SHARE = 0.02
"""The same as a share of the stroke's span in x, where that is more (3.2 mm over 157.5 mm)."""

AXIS_MM = 6.0
"""The built-in unit's undeformed axis above its bottom face (mm; its chain tables' ``tip_ref[1]``): where a
stroke's y = 0 lies in a path's frame when no chain says otherwise."""

PATH_KNOTS = 61
"""Points of a path made from a stroke, evenly spaced along its arc length (at most :data:`MAX_PATH_POINTS`)."""


def turns_back(points: Any) -> float:
    """How far (mm) a stroke's x goes back against its way: the least of its fall below the running maximum of x
    and its rise above the running minimum (0 for a stroke that keeps going one way).

    Examples
    --------
    >>> turns_back([[0, 0], [50, 0], [49.5, 1], [100, 0]])  # a jitter of half a mm
    0.5
    >>> turns_back([[0, 0], [50, 0], [60, 20], [40, 40]])  # a hook: 20 mm back from x = 60
    20.0
    """
    x = np.asarray(points, dtype=float)[:, 0]
    fall = float(np.max(np.maximum.accumulate(x) - x))
    rise = float(np.max(x - np.minimum.accumulate(x)))
    return min(fall, rise)


def is_path_stroke(points: Any) -> bool:
    """True for a stroke of finite ``[x, y]`` points that is no graph: it turns back in x by more than
    ``max(TURN_BACK_MM, TURN_BACK_SHARE * span)``, or its span in x is less than ``MIN_GRAPH_SPAN`` of its length.

    Anything else (a graph, or points that are not a stroke: text, NaN, too few) is False, for
    :func:`~pneumorph.design.objectives.targets.smooth_curve` to smooth or refuse as before.

    Examples
    --------
    >>> x = np.linspace(0.0, 150.0, 100)
    >>> is_path_stroke(np.c_[x, 10 * np.sin(x / 20)]), is_path_stroke(np.c_[x[::-1], x])  # graphs either way
    (False, False)
    >>> arc = np.linspace(0.0, np.pi, 50)
    >>> is_path_stroke(np.r_[np.c_[x[:60], 0 * x[:60]], np.c_[90 + 20 * np.sin(arc), 20 - 20 * np.cos(arc)]])
    True
    >>> is_path_stroke([[0, 0], [5, 40]]), is_path_stroke([[0, 0], ["nan", 1]])  # steep; not numbers
    (True, False)
    """
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        return False
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 2 or not np.isfinite(p).all():
        return False
    span = float(p[:, 0].max() - p[:, 0].min())
    if turns_back(p) > max(TURN_BACK_MM, TURN_BACK_SHARE * span):
        return True
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    return length > 0.0 and span < MIN_GRAPH_SPAN * length


def smooth_path(points: Any, length: float, axis: float, knots: int = PATH_KNOTS,
                bandwidth: float | None = None) -> FloatArray:
    """A drawn stroke as a path: ``knots`` points evenly spaced along its arc length, in the centres' frame.

    Along the stroke's arc length ``s``, x(s) and y(s) are each smoothed as
    :func:`~pneumorph.design.objectives.targets.smooth_curve` smooths y(x): at every knot a straight line
    fitted with a Gaussian weight in ``s`` (standard deviation ``bandwidth``, default
    ``length / 40``, the graph's), which takes out the hand's jitter and keeps the ends true.
    The first point is the stroke's own (where it was begun). ``axis`` (mm) is added to y: the
    stroke's y is a height above the undeformed axis, a path's is from the bottom face.

    Raises
    ------
    TargetExpressionError
        Points :func:`~pneumorph.design.objectives.paths.path_points` refuses (text, NaN, fewer than 2,
        all at one place).

    Examples
    --------
    >>> s = np.linspace(0.0, np.pi, 200)
    >>> p = smooth_path(np.c_[25 * np.sin(s), 25 - 25 * np.cos(s)], 157.5, 6.0)  # a half circle from the axis
    >>> p.shape, p[0].tolist(), round(float(np.abs(np.hypot(p[:, 0], p[:, 1] - 31.0) - 25.0).max()), 2)
    ((61, 2), [0.0, 6.0], 0.31)

    (the smoothing's bias on a circle of radius ``r``: about ``bandwidth^2 / (2 r)`` inwards.)
    """
    p = path_points(points, "the drawn stroke")[:, :2]
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.r_[0.0, np.cumsum(steps)]
    total = float(s[-1])
    h = float(bandwidth) if bandwidth is not None else length / 40.0
    k = int(min(max(knots, 2), MAX_PATH_POINTS))
    with np.errstate(all="ignore"):
        x = smooth_curve(np.c_[s, p[:, 0]], total, k, h)
        y = smooth_curve(np.c_[s, p[:, 1]], total, k, h)
    out = np.c_[x[:, 1], y[:, 1] + axis]
    out[0] = p[0, 0], p[0, 1] + axis
    if not np.isfinite(out).all():  # pragma: no cover - a weighted fit of finite points is finite
        raise TargetExpressionError("the drawn stroke could not be smoothed; draw it again")
    return out


__all__ = ["AXIS_MM", "PATH_KNOTS", "TURN_BACK_MM", "TURN_BACK_SHARE", "is_path_stroke", "smooth_path", "turns_back"]

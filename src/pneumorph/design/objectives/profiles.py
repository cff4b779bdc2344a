"""Profile targets (section 6.3): a curve the inflated actuator should follow, ``y = f(x)``
(Cartesian) or ``r = f(theta)`` (polar), from a safe math expression (:class:`ProfileTarget`)
or a drawn curve (:func:`curve_target`, :class:`Polyline`, :func:`smooth_curve`); the
objectives together: :mod:`pneumorph.design.objectives.targets`.
"""


from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.design.objectives.expressions import Expression
from pneumorph.errors import (
    TargetExpressionError,
)

Sense = Literal["min", "max"]


CARTESIAN = ("x", "L", "A")

POLAR = ("theta", "L", "A")

HINTS_CARTESIAN = {
    "theta": " - theta is the variable of polar targets; write 'r = f(theta)' for one",
    "y": " - the expression is the right-hand side of y = f(x)",
}

HINTS_POLAR = {
    "x": " - x is the variable of Cartesian targets; write 'y = f(x)' for one",
    "r": " - the expression is the right-hand side of r = f(theta)",
}

MAX_TARGET_MM = 1e5
"""Largest size of a target anywhere (mm): a profile's values, a curve's points."""

MAX_CURVE_POINTS = 2000
"""Most points accepted for a drawn curve."""

MIN_CURVE_SPAN = 0.2
"""Least part of the actuator length a drawn curve must span."""

MIN_GRAPH_SPAN = 0.5
"""Least share of a drawn curve's length its span in x must be: a steeper curve is no graph ``y = f(x)`` to match
by x (a path is)."""


@dataclass(frozen=True)
class Polyline:
    """A piecewise-linear ``y(x)`` through knots, level beyond the first and last knot.

    It stands in for an :class:`~pneumorph.design.objectives.expressions.Expression` in a
    :class:`ProfileTarget` (same call signature; ``L`` and ``A`` are ignored).

    Examples
    --------
    >>> f = Polyline((0.0, 10.0, 20.0), (0.0, 5.0, 0.0))
    >>> f(x=[-5.0, 5.0, 10.0, 30.0], L=20.0, A=1.0).tolist()
    [0.0, 2.5, 5.0, 0.0]
    """

    xs: tuple[float, ...]
    ys: tuple[float, ...]
    variables: tuple[str, ...] = field(default=CARTESIAN, init=False)
    used: frozenset[str] = field(default=frozenset({"x"}), init=False)

    @property
    def text(self) -> str:
        return f"curve through {len(self.xs)} points"

    def __call__(self, **values: ArrayLike) -> NDArray[np.float64]:
        return np.interp(np.asarray(values["x"], dtype=float), self.xs, self.ys)


def target_points(points: ArrayLike, columns: tuple[int, ...] = (2,), what: str = "a curve") -> NDArray[np.float64]:
    """Points as a checked (n, 2) (or, where ``columns`` allows, (n, 3)) array of finite mm values (numbers only:
    not text, not true/false); ``what`` names them in the messages ("a curve", "a path")."""
    kinds = " or [x, y, z]" if 3 in columns else ""
    if isinstance(points, (str, bytes)):
        raise TargetExpressionError(f"{what} is a list of [x, y]{kinds} points in mm")
    if not isinstance(points, np.ndarray):
        try:
            rows = list(points)  # type: ignore[arg-type]
            bad = next((v for row in rows for v in (row if isinstance(row, (list, tuple)) else [row])
                        if isinstance(v, (bool, str, bytes)) or not isinstance(v, (int, float, np.number))), None)
        except TypeError:
            raise TargetExpressionError(f"{what} is a list of [x, y]{kinds} points in mm") from None
        if bad is not None:
            raise TargetExpressionError(f"{what}'s points are numbers of mm, got {bad!r}")
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise TargetExpressionError(f"{what} is a list of [x, y]{kinds} points in mm (all of one size)") from None
    if p.ndim != 2 or p.shape[1] not in columns:
        raise TargetExpressionError(f"{what} is a list of [x, y]{kinds} points in mm, got an array of shape "
                                    f"{p.shape}")
    if not 2 <= len(p) <= MAX_CURVE_POINTS:
        raise TargetExpressionError(f"{what} needs 2 to {MAX_CURVE_POINTS} points, got {len(p)}")
    if not np.isfinite(p).all() or np.abs(p).max() > MAX_TARGET_MM:
        raise TargetExpressionError(f"every point of {what} must be a finite number of mm, at most 1e5 in size")
    return p


def smooth_curve(points: ArrayLike, length: float, knots: int = 41,
                 bandwidth: float | None = None) -> NDArray[np.float64]:
    """A hand-drawn stroke as ``knots`` evenly spaced points of a smooth curve.

    At knots evenly spaced over the range the stroke covers (clipped to ``0 <= x <= length``),
    a straight line is fitted to the stroke's points with a Gaussian weight in x (standard
    deviation ``bandwidth``, default ``length / 40``): local linear smoothing, which follows a
    sloped stroke to its ends where a plain weighted mean would pull it flat.

    Raises
    ------
    TargetExpressionError
        Too few or too many points, values that are not finite, or a stroke spanning less than
        :data:`MIN_CURVE_SPAN` of the length.

    Examples
    --------
    >>> x = np.linspace(0.0, 100.0, 400)
    >>> knots = smooth_curve(np.c_[x, 0.5 * x], 100.0, knots=5, bandwidth=1.0)
    >>> knots[:, 0].tolist(), np.round(knots[1:-1, 1], 3).tolist()
    ([0.0, 25.0, 50.0, 75.0, 100.0], [12.5, 25.0, 37.5])
    """
    p = target_points(points)
    if not (np.isfinite(length) and length > 0):
        raise TargetExpressionError(f"the actuator length must be positive, got {length!r}")
    lo, hi = max(float(p[:, 0].min()), 0.0), min(float(p[:, 0].max()), float(length))
    if hi - lo < MIN_CURVE_SPAN * length:
        raise TargetExpressionError(
            f"the curve spans {max(hi - lo, 0.0):.3g} mm of the actuator; draw at least "
            f"{MIN_CURVE_SPAN * length:.3g} mm ({MIN_CURVE_SPAN:.0%} of its {length:g} mm)")
    h = float(bandwidth) if bandwidth is not None else length / 40.0
    xk = np.linspace(lo, hi, int(knots))
    d = p[None, :, 0] - xk[:, None]
    w = np.exp(-0.5 * (d / h) ** 2)
    # a local straight line through the weighted points (no bias at the ends of a sloped stroke)
    s0, s1, s2 = w.sum(axis=1), (w * d).sum(axis=1), (w * d * d).sum(axis=1)
    t0, t1 = w @ p[:, 1], (w * d) @ p[:, 1]
    det = s0 * s2 - s1 * s1
    flat = det <= 1e-9 * np.maximum(s0 * s2, 1e-300)  # points at one x only: their mean
    yk = np.where(flat, t0 / np.maximum(s0, 1e-300), (s2 * t0 - s1 * t1) / np.where(flat, 1.0, det))
    return np.c_[xk, yk]


def check_span(xs: ArrayLike, length: float) -> None:
    """Refuse a curve that covers less than :data:`MIN_CURVE_SPAN` of the actuator's ``0 <= x <= length``."""
    x = np.asarray(xs, dtype=float)
    lo, hi = max(float(x.min()), 0.0), min(float(x.max()), float(length))
    if hi - lo < MIN_CURVE_SPAN * length:
        raise TargetExpressionError(
            f"the curve spans {max(hi - lo, 0.0):.3g} mm of the actuator's 0 to {length:g} mm; give points over "
            f"at least {MIN_CURVE_SPAN * length:.3g} mm of it ({MIN_CURVE_SPAN:.0%})")


def _check_graph(p: NDArray[np.float64]) -> None:
    """Refuse drawn points that are not a graph ``y = f(x)`` (:func:`curve_target`)."""
    back = np.flatnonzero(np.diff(p[:, 0]) < 0.0)
    how = ('give it as a path (objective = "path", path = [[x, y], ...] or --target path:FILE), which keeps its '
           'order')
    if back.size:
        i = int(back[0])
        raise TargetExpressionError(f"the curve turns back in x at its point {i + 2} (x = {p[i, 0]:.6g} then "
                                    f"{p[i + 1, 0]:.6g}): a curve is a graph y = f(x) and would be matched as another "
                                    f"shape; {how}")
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    span = float(p[:, 0].max() - p[:, 0].min())
    if length > 0 and span < MIN_GRAPH_SPAN * length:
        raise TargetExpressionError(f"the curve spans {span:.3g} mm in x over its {length:.3g} mm: less than "
                                    f"{MIN_GRAPH_SPAN:.0%} (MIN_GRAPH_SPAN), too steep to be matched as a graph "
                                    f"y = f(x); {how}")


def curve_target(points: ArrayLike, length: float | None = None) -> ProfileTarget:
    """A profile target through the points ``(x, y)`` or ``(x, y, z)`` (mm): the polyline joining them.

    The curve is a graph ``y = f(x)``: its points come in order of x (a repeated x is averaged,
    a step). A curve whose x turns back, or whose span in x is less than
    :data:`MIN_GRAPH_SPAN` of its length, is refused: as a graph it would be another shape; a
    path (:func:`~pneumorph.design.objectives.paths.path_target`) keeps it. The target is level beyond the
    first and last point. Three columns make a space curve (:attr:`ProfileTarget.depth`: ``z``
    of the polyline too).

    Examples
    --------
    >>> t = curve_target([[0, 0], [50, 10], [100, 0]])
    >>> t.curve([25.0, 50.0, 120.0], length=100.0).tolist()
    [5.0, 10.0, 0.0]
    >>> t.label
    'curve: y = curve through 3 points'
    >>> s = curve_target([[0, 0, 0], [100, 10, -20]])
    >>> s.curve_z([50.0], length=100.0).tolist(), s.spatial
    ([-10.0], True)
    >>> curve_target([[0, 0], [50, 10], [40, 20]])
    Traceback (most recent call last):
    ...
    pneumorph.errors.TargetExpressionError: the curve turns back in x at its point 3 (x = 50 then 40): a curve is
    a graph y = f(x) and would be matched as another shape; give it as a path (objective = "path", path = [[x,
    y], ...] or --target path:FILE), which keeps its order
    """
    p = target_points(points, (2, 3))
    _check_graph(p)
    xs, inverse = np.unique(p[:, 0], return_inverse=True)
    if len(xs) < 2:
        raise TargetExpressionError("a curve needs points at two different x at least")
    if length is not None:
        check_span(xs, length)

    def polyline(column: int) -> Polyline:
        values = np.bincount(inverse, weights=p[:, column]) / np.bincount(inverse)
        return Polyline(tuple(float(v) for v in xs), tuple(float(v) for v in values))

    depth = polyline(2) if p.shape[1] == 3 else None
    return ProfileTarget(polyline(1), "cartesian", 0.0, length, "curve", depth=depth)


@dataclass(frozen=True)
class ProfileTarget:
    """A target curve for the unit centres, matched by Eq 4.1 (minimised).

    Attributes
    ----------
    expression : Expression or Polyline
        The checked right-hand side (or a drawn curve's polyline).
    coordinates : {"cartesian", "polar"}
        ``y = f(x)`` or ``r = f(theta)`` (theta in radians from the x axis, about the base).
    amplitude : float
        The value of ``A`` (mm).
    length : float or None
        The value of ``L`` (mm); None takes the undeformed length of the actuator.
    name : str
        A short label ("sin", "cos" or the expression).
    depth : Expression or Polyline or None
        ``z = g(x)``: the target leaves the plane of the actuator's bending (a *space
        curve*, Cartesian only); None (default): a planar target, ``z = 0``.

    Notes
    -----
    Eq 4.1 of a space curve sums, over the unit centres, the squared distance from the
    target at the centre's current x in y and in z (:meth:`squared_error`). A planar design
    has every centre at ``z = 0``, so a planar target keeps its value exactly and a space
    curve adds ``g(x)^2`` for each of its centres.

    Examples
    --------
    >>> from pneumorph.design.objectives.targets import profile_target
    >>> t = profile_target("sin", amplitude=10.0)
    >>> t.curve([0.0, 25.0, 50.0], length=100.0).round(6).tolist()
    [0.0, 10.0, 0.0]
    >>> profile_target("y = 0.1*x").curve([10.0], length=100.0).tolist()
    [1.0]
    """

    expression: Expression | Polyline
    coordinates: Literal["cartesian", "polar"] = "cartesian"
    amplitude: float = 10.0
    length: float | None = None
    name: str = ""
    depth: Expression | Polyline | None = None
    sense: Sense = field(default="min", init=False)
    unit: str = field(default="mm", init=False)

    def __post_init__(self) -> None:
        if self.depth is not None and self.coordinates != "cartesian":
            raise TargetExpressionError("a space curve (z = g(x)) is Cartesian: a polar target r = f(theta) has no z")

    @property
    def spatial(self) -> bool:
        """True for a space curve (a ``z = g(x)``)."""
        return self.depth is not None

    def curve(self, s: ArrayLike, length: float) -> NDArray[np.float64]:
        """The target at ``s`` (x in mm, or theta in rad) for an actuator of ``length`` mm."""
        L = self.length if self.length is not None else length
        var = "x" if self.coordinates == "cartesian" else "theta"
        return self.expression(**{var: np.asarray(s, dtype=float)}, L=L, A=self.amplitude)

    def curve_z(self, x: ArrayLike, length: float) -> NDArray[np.float64]:
        """The target's ``z`` at ``x`` (mm): ``g(x)``, zero for a planar target."""
        x = np.asarray(x, dtype=float)
        if self.depth is None:
            return np.zeros_like(x)
        L = self.length if self.length is not None else length
        return np.broadcast_to(self.depth(x=x, L=L, A=self.amplitude), x.shape)

    def squared_error(self, x: ArrayLike, y: ArrayLike, length: float, z: ArrayLike | None = None,
                      ) -> NDArray[np.float64]:
        """A centre's term of Eq 4.1 (Cartesian): ``(f(x) - y)^2``, plus ``(g(x) - z)^2`` for a space curve or a
        centre off the plane (``z``; None: 0).

        >>> from pneumorph.design.objectives.targets import profile_target
        >>> t = profile_target("y = 0.1*x, z = -0.2*x")
        >>> t.squared_error([10.0], [1.0], 100.0).tolist(), t.squared_error([10.0], [1.0], 100.0, z=[-1.0]).tolist()
        ([4.0], [1.0])
        """
        out = (self.curve(x, length) - np.asarray(y, dtype=float)) ** 2
        if self.depth is None and z is None:
            return out
        return out + (self.curve_z(x, length) - (0.0 if z is None else np.asarray(z, dtype=float))) ** 2

    def check(self, length: float) -> ProfileTarget:
        """Refuse a target that is not finite somewhere on the actuator's range.

        The range is ``0 <= x <= L`` for ``y = f(x)`` and ``0 <= theta <= pi`` for
        ``r = f(theta)``, sampled at 201 points.

        Raises
        ------
        TargetExpressionError
            Naming the first point where the target is NaN or infinite, or beyond
            :data:`MAX_TARGET_MM` in size (a constant ``y = 1e100``, say).

        Examples
        --------
        >>> from pneumorph.design.objectives.targets import profile_target
        >>> profile_target("y = 1/x").check(157.5)
        Traceback (most recent call last):
        ...
        pneumorph.errors.TargetExpressionError: the target y = 1/x is not finite at x = 0 (inf); it must be
        finite for 0 <= x <= L = 157.5 mm
        """
        polar = self.coordinates == "polar"
        s = np.linspace(0.0, np.pi if polar else float(length), 201)
        with np.errstate(all="ignore"):
            try:
                values = np.broadcast_to(np.asarray(self.curve(s, length), dtype=float), s.shape)
                depth = None if self.depth is None else np.asarray(self.curve_z(s, length), dtype=float)
            except (ArithmeticError, ValueError) as exc:
                raise TargetExpressionError(f"the target {self.label} cannot be evaluated: {exc}") from None
        for coordinate, v in (("", values), *((("z ", depth),) if depth is not None else ())):
            self._check_values(s, v, length, coordinate)
        return self

    def _check_values(self, s: NDArray[np.float64], values: NDArray[np.float64], length: float,
                      coordinate: str) -> None:
        """Refuse values (of y or r, or with ``coordinate`` "z ", of z) not finite or too large (:meth:`check`)."""
        polar = self.coordinates == "polar"
        bad = np.flatnonzero(~np.isfinite(values))
        large = np.flatnonzero(np.abs(np.where(np.isfinite(values), values, 0.0)) > MAX_TARGET_MM)
        if large.size and not bad.size:
            where = f"theta = {s[large[0]]:.4g} rad" if polar else f"x = {s[large[0]]:.4g}"
            raise TargetExpressionError(
                f"the target {self.label} is {values[large[0]]:.4g} mm {coordinate}at {where}, beyond "
                f"{MAX_TARGET_MM:g} mm (MAX_TARGET_MM): no actuator reaches it"
            )
        if bad.size:
            where = f"theta = {s[bad[0]]:.4g} rad" if polar else f"x = {s[bad[0]]:.4g}"
            span = "0 <= theta <= pi" if polar else f"0 <= x <= L = {length:g} mm"
            raise TargetExpressionError(
                f"the target {self.label} is not finite {coordinate}at {where} ({values[bad[0]]}); it must be finite "
                f"for {span}"
            )

    @property
    def display(self) -> str:
        """The target as a figure shows it: ``y = A·sin(2·π·x/L), A = 10 mm``.

        >>> from pneumorph.design.objectives.targets import profile_target
        >>> profile_target("sin", amplitude=10.0).display
        'y = A·sin(2·π·x/L), A = 10 mm'
        >>> profile_target("y = 0.5*x**2/L").display
        'y = 0.5·x^2/L'
        """
        def shown(expression: str) -> str:
            text = re.sub(r"2\*pi\*1\*(x|theta)", r"2*pi*\1", expression)
            text = text.replace("**", "^").replace("*", "·").replace("theta", "θ")
            return re.sub(r"\bpi\b", "π", text)

        lhs = "y" if self.coordinates == "cartesian" else "r"
        text = f"{lhs} = {shown(self.expression.text)}"
        if self.depth is not None:
            text += f", z = {shown(self.depth.text)}"
        return text + self._amplitude_text

    @property
    def label(self) -> str:
        own = self.expression.text if self.depth is None else f"{self.expression.text}, z = {self.depth.text}"
        text = f"{'y' if self.coordinates == 'cartesian' else 'r'} = {own}{self._amplitude_text}"
        return text if not self.name or self.name == own else f"{self.name}: {text}"

    @property
    def _amplitude_text(self) -> str:
        """``, A = 10 mm`` where the expressions use ``A``, else nothing."""
        used = self.expression.used | (self.depth.used if self.depth is not None else frozenset())
        return f", A = {self.amplitude:g} mm" if "A" in used else ""

"""Design objectives: target profiles (section 6.3) and tip goals (Table 6.1).

An objective says *what* is wanted; :mod:`pneumorph.design.fitness` measures a
:class:`~pneumorph.models.Response` against it.

- :class:`ProfileTarget` - a curve the inflated actuator should follow, ``y = f(x)``
  (Cartesian) or ``r = f(theta)`` (polar), given as a safe math expression in the variables
  ``x`` (or ``theta``), ``L`` (the undeformed actuator length, mm) and ``A`` (an amplitude,
  mm); always minimised (it is an error in mm, Eq 4.1).
- :class:`TipGoal` - a single goal for the tip: ``max-x``, ``min-x``, ``max-y``, ``min-y``,
  ``min-distance`` (tip to base, Table 6.1's "minimum radius of curvature"), ``max-curl``
  and ``reach`` (a given tip point).

A profile can also be a drawn curve: :func:`curve_target` takes points ``(x, y)`` in mm and
follows the polyline through them (:class:`Polyline`, held level beyond its ends);
:func:`smooth_curve` turns a hand-drawn stroke into such points.

Presets (section 6.3): ``sin`` is ``A*sin(2*pi*m*x/L)`` and ``cos`` is
``A*(cos(2*pi*m*x/L) - 1)``, ``m`` periods over the actuator length (one by default).
The dissertation does not print its cos formula; the actuator's base is clamped at
``y = 0``, so the preset is shifted to pass through the base (``anchored=False`` gives the
plain ``A*cos(...)``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.design.expressions import Expression, parse_expression
from pneumorph.errors import (
    SearchConfigError,
    TargetExpressionError,
    UnknownObjectiveError,
)

Sense = Literal["min", "max"]

_CARTESIAN = ("x", "L", "A")
_POLAR = ("theta", "L", "A")
_HINTS_CARTESIAN = {
    "theta": " - theta is the variable of polar targets; write 'r = f(theta)' for one",
    "y": " - the expression is the right-hand side of y = f(x)",
}
_HINTS_POLAR = {
    "x": " - x is the variable of Cartesian targets; write 'y = f(x)' for one",
    "r": " - the expression is the right-hand side of r = f(theta)",
}


MAX_TARGET_MM = 1e5
"""Largest size of a target anywhere (mm): a profile's values, a curve's points."""
MAX_CURVE_POINTS = 2000
"""Most points accepted for a drawn curve."""
MIN_CURVE_SPAN = 0.2
"""Least part of the actuator length a drawn curve must span."""


@dataclass(frozen=True)
class Polyline:
    """A piecewise-linear ``y(x)`` through knots, level beyond the first and last knot.

    It stands in for an :class:`~pneumorph.design.expressions.Expression` in a
    :class:`ProfileTarget` (same call signature; ``L`` and ``A`` are ignored).

    Examples
    --------
    >>> f = Polyline((0.0, 10.0, 20.0), (0.0, 5.0, 0.0))
    >>> f(x=[-5.0, 5.0, 10.0, 30.0], L=20.0, A=1.0).tolist()
    [0.0, 2.5, 5.0, 0.0]
    """

    xs: tuple[float, ...]
    ys: tuple[float, ...]
    variables: tuple[str, ...] = field(default=_CARTESIAN, init=False)
    used: frozenset[str] = field(default=frozenset({"x"}), init=False)

    @property
    def text(self) -> str:
        return f"curve through {len(self.xs)} points"

    def __call__(self, **values: ArrayLike) -> NDArray[np.float64]:
        return np.interp(np.asarray(values["x"], dtype=float), self.xs, self.ys)


def _curve_points(points: ArrayLike) -> NDArray[np.float64]:
    """Points as a checked (n, 2) array of finite mm values (numbers only: not text, not true/false)."""
    if not isinstance(points, np.ndarray):
        try:
            rows = list(points)  # type: ignore[arg-type]
            bad = next((v for row in rows for v in (row if isinstance(row, (list, tuple)) else [row])
                        if isinstance(v, (bool, str, bytes)) or not isinstance(v, (int, float, np.number))), None)
        except TypeError:
            raise TargetExpressionError("a curve is a list of [x, y] points in mm") from None
        if bad is not None:
            raise TargetExpressionError(f"a curve's points are numbers of mm, got {bad!r}")
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise TargetExpressionError("a curve is a list of [x, y] points in mm") from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise TargetExpressionError(f"a curve is a list of [x, y] points in mm, got an array of shape {p.shape}")
    if not 2 <= len(p) <= MAX_CURVE_POINTS:
        raise TargetExpressionError(f"a curve needs 2 to {MAX_CURVE_POINTS} points, got {len(p)}")
    if not np.isfinite(p).all() or np.abs(p).max() > MAX_TARGET_MM:
        raise TargetExpressionError("every point of a curve must be a finite number of mm, at most 1e5 in size")
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
    p = _curve_points(points)
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


def _check_span(xs: ArrayLike, length: float) -> None:
    """Refuse a curve that covers less than :data:`MIN_CURVE_SPAN` of the actuator's ``0 <= x <= length``."""
    x = np.asarray(xs, dtype=float)
    lo, hi = max(float(x.min()), 0.0), min(float(x.max()), float(length))
    if hi - lo < MIN_CURVE_SPAN * length:
        raise TargetExpressionError(
            f"the curve spans {max(hi - lo, 0.0):.3g} mm of the actuator's 0 to {length:g} mm; give points over "
            f"at least {MIN_CURVE_SPAN * length:.3g} mm of it ({MIN_CURVE_SPAN:.0%})")


def curve_target(points: ArrayLike, length: float | None = None) -> ProfileTarget:
    """A profile target through the points ``(x, y)`` (mm): the polyline joining them.

    Points are sorted by x; repeated x are averaged. The target is level beyond the first
    and last point.

    Examples
    --------
    >>> t = curve_target([[0, 0], [50, 10], [100, 0]])
    >>> t.curve([25.0, 50.0, 120.0], length=100.0).tolist()
    [5.0, 10.0, 0.0]
    >>> t.label
    'curve: y = curve through 3 points'
    """
    p = _curve_points(points)
    xs, inverse = np.unique(p[:, 0], return_inverse=True)
    ys = np.bincount(inverse, weights=p[:, 1]) / np.bincount(inverse)
    if len(xs) < 2:
        raise TargetExpressionError("a curve needs points at two different x at least")
    if length is not None:
        _check_span(xs, length)
    line = Polyline(tuple(float(v) for v in xs), tuple(float(v) for v in ys))
    return ProfileTarget(line, "cartesian", 0.0, length, "curve")


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

    Examples
    --------
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
    sense: Sense = field(default="min", init=False)
    unit: str = field(default="mm", init=False)

    def curve(self, s: ArrayLike, length: float) -> NDArray[np.float64]:
        """The target at ``s`` (x in mm, or theta in rad) for an actuator of ``length`` mm."""
        L = self.length if self.length is not None else length
        var = "x" if self.coordinates == "cartesian" else "theta"
        return self.expression(**{var: np.asarray(s, dtype=float)}, L=L, A=self.amplitude)

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
            except (ArithmeticError, ValueError) as exc:
                raise TargetExpressionError(f"the target {self.label} cannot be evaluated: {exc}") from None
        bad = np.flatnonzero(~np.isfinite(values))
        large = np.flatnonzero(np.abs(np.where(np.isfinite(values), values, 0.0)) > MAX_TARGET_MM)
        if large.size and not bad.size:
            where = f"theta = {s[large[0]]:.4g} rad" if polar else f"x = {s[large[0]]:.4g}"
            raise TargetExpressionError(
                f"the target {self.label} is {values[large[0]]:.4g} mm at {where}, beyond {MAX_TARGET_MM:g} mm "
                "(MAX_TARGET_MM): no actuator reaches it"
            )
        if bad.size:
            where = f"theta = {s[bad[0]]:.4g} rad" if polar else f"x = {s[bad[0]]:.4g}"
            span = "0 <= theta <= pi" if polar else f"0 <= x <= L = {length:g} mm"
            raise TargetExpressionError(
                f"the target {self.label} is not finite at {where} ({values[bad[0]]}); it must be finite for {span}"
            )
        return self

    @property
    def display(self) -> str:
        """The target as a figure shows it: ``y = A·sin(2·π·x/L), A = 10 mm``.

        >>> profile_target("sin", amplitude=10.0).display
        'y = A·sin(2·π·x/L), A = 10 mm'
        >>> profile_target("y = 0.5*x**2/L").display
        'y = 0.5·x^2/L'
        """
        lhs = "y" if self.coordinates == "cartesian" else "r"
        text = re.sub(r"2\*pi\*1\*(x|theta)", r"2*pi*\1", self.expression.text)
        text = text.replace("**", "^").replace("*", "·").replace("theta", "θ")
        text = re.sub(r"\bpi\b", "π", text)
        text = f"{lhs} = {text}"
        if "A" in self.expression.used:
            text += f", A = {self.amplitude:g} mm"
        return text

    @property
    def label(self) -> str:
        lhs = "y" if self.coordinates == "cartesian" else "r"
        text = f"{lhs} = {self.expression.text}"
        if "A" in self.expression.used:
            text += f", A = {self.amplitude:g} mm"
        return text if not self.name or self.name == self.expression.text else f"{self.name}: {text}"


@dataclass(frozen=True)
class TipGoal:
    """A goal for the tip position or rotation (Table 6.1).

    Attributes
    ----------
    name : str
        One of :data:`TIP_GOALS`.
    sense : {"min", "max"}
        Whether the value is minimised or maximised.
    point : tuple of float or None
        The tip point to reach (mm, relative to the base), for ``reach`` only.

    Examples
    --------
    >>> tip_goal("max-y").sense, tip_goal("Min distance").name
    ('max', 'min-distance')
    """

    name: str
    sense: Sense
    point: tuple[float, float] | None = None

    @property
    def unit(self) -> str:
        return "deg" if self.name == "max-curl" else "mm"

    @property
    def label(self) -> str:
        if self.name == "reach" and self.point is not None:
            return f"reach the tip point ({self.point[0]:g}, {self.point[1]:g}) mm"
        return TIP_GOALS[self.name][1]


#: relative difference within which a stage's pressure is a level of the ramp
LEVEL_MATCH = 1e-6
#: most stages of one staged target
MAX_STAGES = 20


@dataclass(frozen=True)
class Stage:
    """One stage of a :class:`StagedTarget`: a target to meet at one pressure of the ramp.

    Attributes
    ----------
    pressure : float
        The pressure (MPa), a level of the model's ramp.
    target : ProfileTarget or TipGoal
        A Cartesian profile (preset, expression or drawn curve; Eq 4.1 in mm) or the tip goal
        ``reach`` (the tip's distance to a point, mm).
    weight : float
        The stage's weight in the root-sum-square (positive).
    """

    pressure: float
    target: ProfileTarget | TipGoal
    weight: float = 1.0

    @property
    def label(self) -> str:
        weight = f" (weight {self.weight:g})" if self.weight != 1.0 else ""
        return f"{self.pressure * 1e3:g} kPa: {self.target.label}{weight}"


@dataclass(frozen=True)
class StagedTarget:
    """Targets at several pressures of one ramp, met together (minimised).

    The cost of a design is the weighted root-sum-square of its stages' values,
    ``sqrt(sum_s (w_s v_s)^2)``, each ``v_s`` the stage's value at its own level: Eq 4.1 of a
    profile (mm) or the tip's distance to a point (mm). Every other level of the ramp counts
    as the worst value, so the cost stands at the level of the highest stage (its best
    level).

    Examples
    --------
    >>> t = staged_target([(0.018, make_objective("y = 0.02*x")), (0.045, make_objective("sin"))])
    >>> t.levels(np.linspace(0.0045, 0.045, 10))
    (3, 9)
    >>> float(t.combine(np.array([3.0, 4.0])))
    5.0
    >>> t.label
    'stages: 18 kPa: y = 0.02*x; 45 kPa: sin: y = A*sin(2*pi*1*x/L), A = 10 mm'
    """

    stages: tuple[Stage, ...]
    name: str = field(default="stages", init=False)
    sense: Sense = field(default="min", init=False)
    unit: str = field(default="mm", init=False)
    point: None = field(default=None, init=False)

    @property
    def label(self) -> str:
        return "stages: " + "; ".join(stage.label for stage in self.stages)

    @property
    def weights(self) -> NDArray[np.float64]:
        return np.array([stage.weight for stage in self.stages], dtype=float)

    def levels(self, pressures: ArrayLike) -> tuple[int, ...]:
        """The level of each stage among a ramp's ``pressures`` (MPa).

        Raises
        ------
        SearchConfigError
            A stage's pressure that is not one of the levels, naming the levels.
        """
        p = np.asarray(pressures, dtype=float)
        out = []
        for stage in self.stages:
            near = np.flatnonzero(np.abs(p - stage.pressure) <= LEVEL_MATCH * max(abs(stage.pressure), 1e-12))
            if not near.size:
                levels = ", ".join(f"{v * 1e3:.4g}" for v in p)
                raise SearchConfigError(f"stage at {stage.pressure * 1e3:g} kPa: not a level of the model's ramp; "
                                        f"the levels are {levels} kPa (a stage's pressure must be one of them)")
            out.append(int(near[0]))
        return tuple(out)

    def combine(self, values: ArrayLike) -> NDArray[np.float64]:
        """The weighted root-sum-square over the last axis (one value per stage)."""
        v = np.asarray(values, dtype=float)
        return np.sqrt(np.sum((v * self.weights) ** 2, axis=-1))

    def at_levels(self, per_stage: ArrayLike, pressures: ArrayLike) -> NDArray[np.float64]:
        """Values per level, shape (..., k): the combined value at the highest stage's level, worst elsewhere.

        ``per_stage`` holds each stage's value at its own level, shape (..., S).
        """
        k = len(np.asarray(pressures))
        combined = self.combine(per_stage)
        out = np.full((*combined.shape, k), np.inf)
        out[..., max(self.levels(pressures))] = combined
        return out


def staged_target(stages: Any) -> StagedTarget:
    """A staged target from ``(pressure_MPa, target[, weight])`` entries, checked.

    Raises
    ------
    SearchConfigError
        No stages or more than :data:`MAX_STAGES`, a pressure that is not positive and finite,
        a weight that is not positive and finite, two stages at one pressure, or a target that
        cannot be staged (polar profiles, tip goals other than
        ``reach``: a maximum or minimum has no distance to add up).

    Examples
    --------
    >>> staged_target([(0.03, tip_goal("max-x"))])
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: stage at 30 kPa: 'max-x' is a maximum, not a distance to add up with the
    other stages; a stage's target is a Cartesian profile, a drawn curve or 'reach' (a tip point)
    """
    entries = list(stages)
    if not 1 <= len(entries) <= MAX_STAGES:
        raise SearchConfigError(f"a staged target needs 1 to {MAX_STAGES} stages (MAX_STAGES), got {len(entries)}")
    out = []
    for entry in entries:
        pressure, target, *rest = entry
        weight = float(rest[0]) if rest else 1.0
        if not (np.isfinite(pressure) and pressure > 0):
            raise SearchConfigError(f"a stage's pressure must be a positive number of kPa, got {pressure * 1e3!r}")
        where = f"stage at {pressure * 1e3:g} kPa"
        if not (np.isfinite(weight) and weight > 0):
            raise SearchConfigError(f"{where}: the weight must be a positive number, got {weight!r}")
        if isinstance(target, ProfileTarget) and target.coordinates == "polar":
            raise SearchConfigError(f"{where}: polar profiles r = f(theta) cannot be staged yet; give y = f(x), a "
                                    "preset or a drawn curve")
        if isinstance(target, TipGoal) and target.name != "reach":
            kind = "a maximum" if target.sense == "max" else "a minimum"
            raise SearchConfigError(f"{where}: {target.name!r} is {kind}, not a distance to add up with the other "
                                    "stages; a stage's target is a Cartesian profile, a drawn curve or 'reach' (a "
                                    "tip point)")
        if not isinstance(target, ProfileTarget | TipGoal):
            raise SearchConfigError(f"{where}: a stage's target must be a profile or a tip point, not a staged target")
        out.append(Stage(float(pressure), target, weight))
    seen: set[float] = set()
    for stage in out:
        if stage.pressure in seen:
            raise SearchConfigError(f"stage at {stage.pressure * 1e3:g} kPa: two stages at one pressure; give each "
                                    "pressure once (one target per stage)")
        seen.add(stage.pressure)
    return StagedTarget(tuple(out))


#: What a search optimises: a target profile, a goal for the tip, or targets at several pressures.
Objective = ProfileTarget | TipGoal | StagedTarget

#: The tip goals by name: whether they are minimised or maximised, and their label.
TIP_GOALS: dict[str, tuple[Sense, str]] = {
    "max-x": ("max", "maximum horizontal tip position (max X)"),
    "min-x": ("min", "minimum horizontal tip position (min X)"),
    "max-y": ("max", "maximum vertical tip position (max Y)"),
    "min-y": ("min", "minimum vertical tip position (min Y)"),
    "min-distance": ("min", "minimum distance of the tip to the base"),
    "max-curl": ("max", "maximum curl of the tip (counter-clockwise, degrees)"),
    "reach": ("min", "distance of the tip to a given point"),
}
_ALIASES = {"min-radius": "min-distance", "min-dist": "min-distance", "curl": "max-curl"}
#: The target profiles known by name (:func:`profile_target`); any other profile is an expression.
PRESETS = ("sin", "cos")


def _normalise(name: str) -> str:
    return re.sub(r"[\s_]+", "-", name.strip().lower())


def tip_goal(name: str, point: tuple[float, float] | None = None) -> TipGoal:
    """The tip goal called ``name`` (case, spaces and underscores do not matter).

    Raises
    ------
    UnknownObjectiveError
        For a name that is not a tip goal.
    SearchConfigError
        ``reach`` without a point, or a point for another goal.
    """
    key = _ALIASES.get(_normalise(name), _normalise(name))
    if key not in TIP_GOALS:
        raise UnknownObjectiveError(name, [*TIP_GOALS, *PRESETS])
    if key == "reach":
        if point is None or len(point) != 2 or not np.all(np.isfinite(point)):
            raise SearchConfigError("the objective 'reach' needs a tip point (x, y) in mm: --point X Y "
                                    "(point = [x, y] in [design] of a config file), e.g. --point 60 40")
        point = (float(point[0]), float(point[1]))
    elif point is not None:
        raise SearchConfigError(f"a tip point is only used by the objective 'reach', not by {key!r}")
    return TipGoal(key, TIP_GOALS[key][0], point)


def profile_target(
    spec: str,
    amplitude: float = 10.0,
    periods: float = 1.0,
    length: float | None = None,
    anchored: bool = True,
) -> ProfileTarget:
    """A target profile from a preset name or an expression.

    Parameters
    ----------
    spec : str
        ``"sin"``, ``"cos"``, ``"y = <expression in x>"``, ``"r = <expression in theta>"``
        or a bare expression (polar if it uses ``theta``).
    amplitude : float
        ``A`` in mm (presets: the amplitude).
    periods : float
        Presets: the number of periods over the actuator length.
    length : float, optional
        ``L`` in mm; by default the undeformed length of the actuator evaluated.
    anchored : bool
        The cos preset: shift it by ``-A`` so that it starts at the base (default).

    Raises
    ------
    TargetExpressionError
        An expression outside the whitelist, or non-positive periods.
    """
    if not np.isfinite(amplitude):
        raise TargetExpressionError(f"the amplitude must be a finite number of mm, got {amplitude!r}")
    key = _normalise(spec)
    if key in PRESETS:
        if not (np.isfinite(periods) and periods > 0):
            raise TargetExpressionError(f"the number of periods must be positive, got {periods!r}")
        arg = f"2*pi*{periods:.17g}*x/L"
        text = f"A*sin({arg})" if key == "sin" else (f"A*(cos({arg}) - 1)" if anchored else f"A*cos({arg})")
        return ProfileTarget(parse_expression(text, _CARTESIAN), "cartesian", amplitude, length, key)
    lhs, _, rhs = spec.partition("=")
    if rhs:
        side = lhs.strip().lower()
        if side not in ("y", "r"):
            raise TargetExpressionError(
                f"the left-hand side of {spec!r} must be y (for y = f(x)) or r (for r = f(theta)), got {lhs.strip()!r}"
            )
        polar = side == "r"
    else:
        rhs = spec
        polar = re.search(r"\btheta\b", spec) is not None
    variables, hints = (_POLAR, _HINTS_POLAR) if polar else (_CARTESIAN, _HINTS_CARTESIAN)
    expr = parse_expression(rhs, variables, hints)
    return ProfileTarget(expr, "polar" if polar else "cartesian", amplitude, length, expr.text)


def make_objective(
    spec: str,
    amplitude: float = 10.0,
    periods: float = 1.0,
    point: tuple[float, float] | None = None,
    anchored: bool = True,
    length: float | None = None,
    curve: ArrayLike | None = None,
) -> Objective:
    """Any objective from its text: a tip goal, a preset or a profile expression.

    With ``length`` (mm), a profile is also checked to be finite along an actuator that long
    (:meth:`ProfileTarget.check`). ``"curve"`` takes its points from ``curve``
    (:func:`curve_target`).

    Examples
    --------
    >>> make_objective("max_x").label
    'maximum horizontal tip position (max X)'
    >>> make_objective("cos", amplitude=20).label
    'cos: y = A*(cos(2*pi*1*x/L) - 1), A = 20 mm'
    >>> make_objective("max-z")
    Traceback (most recent call last):
    ...
    pneumorph.errors.UnknownObjectiveError: unknown objective 'max-z'; known objectives: max-x, min-x, max-y,
    min-y, min-distance, max-curl, reach, sin, cos, or a profile 'y = f(x)' / 'r = f(theta)'
    """
    key = _ALIASES.get(_normalise(spec), _normalise(spec))
    if (key == "curve") != (curve is not None):
        raise SearchConfigError("the objective 'curve' needs its points: curve = [[x, y], ...] in mm"
                                if key == "curve" else f"curve points are only used by the objective 'curve', "
                                f"not by {spec!r}")
    if key == "curve":
        if point is not None:
            raise SearchConfigError("a tip point is only used by the objective 'reach', not by 'curve'")
        target = curve_target(curve)  # type: ignore[arg-type]
        if length is not None:
            _check_span(np.asarray(curve, dtype=float)[:, 0], length)
        return target if length is None else target.check(length)
    if key in TIP_GOALS:
        return tip_goal(key, point)
    if point is not None:
        raise SearchConfigError(f"a tip point is only used by the objective 'reach', not by {spec!r}")
    if key not in PRESETS and "=" not in spec:
        words = re.fullmatch(r"[A-Za-z_][\w\- ]*", spec.strip())
        if words and spec.strip() not in (*_CARTESIAN, *_POLAR, "pi", "e"):
            raise UnknownObjectiveError(spec, [*TIP_GOALS, *PRESETS])
    target = profile_target(spec, amplitude, periods, anchored=anchored)
    return target if length is None else target.check(length)

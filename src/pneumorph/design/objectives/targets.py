"""Design objectives: target profiles (section 6.3) and tip goals (Table 6.1).

An objective says *what* is wanted; :mod:`pneumorph.design.objectives.fitness` measures a
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
``helix`` is the space curve ``y = A*(1 - cos(2*pi*m*x/L))``, ``z = -A*sin(2*pi*m*x/L)``
(right-handed about x, radius ``A``, ``m`` turns; ``helix-left`` has ``+A*sin``); any space
curve is ``y = f(x), z = g(x)`` or a drawn curve of ``(x, y, z)`` points.
The dissertation does not print its cos formula; the actuator's base is clamped at
``y = 0``, so the preset is shifted to pass through the base (``anchored=False`` gives the
plain ``A*cos(...)``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.design.objectives.contact import CONTACT_GOALS, LEVEL_MATCH, ContactGoal, contact_goal
from pneumorph.design.objectives.expressions import parse_expression
from pneumorph.design.objectives.paths import PATH_PRESETS, PathTarget, path_target, preset_path
from pneumorph.design.objectives.profiles import (
    CARTESIAN,
    HINTS_CARTESIAN,
    HINTS_POLAR,
    MAX_CURVE_POINTS,
    MAX_TARGET_MM,
    MIN_CURVE_SPAN,
    POLAR,
    Polyline,
    ProfileTarget,
    Sense,
    check_span,
    curve_target,
    smooth_curve,
)
from pneumorph.errors import (
    SearchConfigError,
    TargetExpressionError,
    UnknownObjectiveError,
)


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
        The tip point to reach (mm, relative to the base), for ``reach`` only: ``(x, y)``, or
        ``(x, y, z)`` off the plane of bending.

    Examples
    --------
    >>> tip_goal("max-y").sense, tip_goal("Min distance").name
    ('max', 'min-distance')
    """

    name: str
    sense: Sense
    point: tuple[float, ...] | None = None

    @property
    def unit(self) -> str:
        return "deg" if self.name == "max-curl" else "mm"

    @property
    def label(self) -> str:
        if self.name == "reach" and self.point is not None:
            return f"reach the tip point ({', '.join(f'{v:g}' for v in self.point)}) mm"
        return TIP_GOALS[self.name][1]


#: most stages of one staged target
MAX_STAGES = 20


@dataclass(frozen=True)
class Stage:
    """One stage of a :class:`StagedTarget`: a target to meet at one pressure of the ramp.

    Attributes
    ----------
    pressure : float
        The pressure (MPa), a level of the model's ramp.
    target : ProfileTarget or PathTarget or TipGoal
        A Cartesian profile (preset, expression or drawn curve; Eq 4.1 in mm), a path (mm) or the
        tip goal ``reach`` (the tip's distance to a point, mm).
    weight : float
        The stage's weight in the root-sum-square (positive).
    """

    pressure: float
    target: ProfileTarget | PathTarget | TipGoal
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

    def levels(self, pressures: ArrayLike, how: str = " (a stage's pressure, --stage KPA:... or pressure_kpa of "
               "[[design.stage]], must be one of them)") -> tuple[int, ...]:
        """The level of each stage among a ramp's ``pressures`` (MPa); ``how`` ends the refusal (where the pressure
        is given: the command line's words by default).

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
                                        f"the levels are {levels} kPa{how}")
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


def on_actuator(objective: Objective, length: float, height: float) -> Objective:
    """The objective with its preset paths drawn for an actuator ``length`` mm long whose axis lies ``height`` mm up
    (:meth:`~pneumorph.design.objectives.paths.PathTarget.at`; a staged target's stages alike): drawn once for a run, so
    that the chain and every FE response are matched against one path whatever their designs' lengths.

    >>> on_actuator(make_objective("hook"), 100.0, 6.0).points[0], on_actuator(tip_goal("max-x"), 100.0, 6.0).name
    ((0.0, 6.0, 0.0), 'max-x')
    """
    if isinstance(objective, PathTarget):
        return objective.at(length, height)
    if isinstance(objective, StagedTarget):
        return StagedTarget(tuple(replace(st, target=st.target.at(length, height)) if isinstance(st.target, PathTarget)
                                  else st for st in objective.stages))
    return objective


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
        if not isinstance(target, ProfileTarget | PathTarget | TipGoal):
            raise SearchConfigError(f"{where}: a stage's target must be a profile, a path or a tip point, not a "
                                    "staged target")
        out.append(Stage(float(pressure), target, weight))
    seen: set[float] = set()
    for stage in out:
        if stage.pressure in seen:
            raise SearchConfigError(f"stage at {stage.pressure * 1e3:g} kPa: two stages at one pressure; give each "
                                    "pressure once (one target per stage)")
        seen.add(stage.pressure)
    return StagedTarget(tuple(out))


#: What a search optimises: a target profile, a path, a goal for the tip, or targets at several pressures.
Objective = ProfileTarget | PathTarget | TipGoal | StagedTarget | ContactGoal

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
#: The target profiles known by name (:func:`profile_target`); any other profile is an expression. The helices
#: are space curves.
PRESETS = ("sin", "cos", "helix", "helix-left")


def _normalise(name: str) -> str:
    return re.sub(r"[\s_]+", "-", name.strip().lower())


def tip_goal(name: str, point: tuple[float, ...] | None = None) -> TipGoal:
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
        raise UnknownObjectiveError(name, [*TIP_GOALS, *CONTACT_GOALS, *PRESETS])
    if key == "reach":
        if point is None or len(point) not in (2, 3) or not np.all(np.isfinite(point)):
            raise SearchConfigError("the objective 'reach' needs a tip point (x, y) or (x, y, z) in mm: --point X Y "
                                    "(point = [x, y] in [design] of a config file), e.g. --point 60 40")
        point = tuple(float(v) for v in point)
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
        ``"sin"``, ``"cos"``, ``"helix"``, ``"helix-left"``, ``"y = <expression in x>"``,
        ``"r = <expression in theta>"``, a space curve ``"y = <expression>, z = <expression>"``
        (both in x) or a bare expression (polar if it uses ``theta``).
    amplitude : float
        ``A`` in mm (presets: the amplitude; a helix's radius).
    periods : float
        Presets: the number of periods (a helix's turns) over the actuator length.
    length : float, optional
        ``L`` in mm; by default the undeformed length of the actuator evaluated.
    anchored : bool
        The cos preset: shift it by ``-A`` so that it starts at the base (default).

    Raises
    ------
    TargetExpressionError
        An expression outside the whitelist, or non-positive periods.

    Examples
    --------
    A helix of radius ``A`` about an axis parallel to x through ``(0, A, 0)``, right-handed
    (``helix-left``: left-handed), ``periods`` turns over the actuator:

    >>> h = profile_target("helix", amplitude=25.0)
    >>> x = [0.0, 25.0, 50.0]
    >>> h.curve(x, 100.0).round(6).tolist(), h.curve_z(x, 100.0).round(6).tolist()
    ([0.0, 25.0, 50.0], [-0.0, -25.0, -0.0])
    >>> profile_target("y = 0.1*x, z = x**2/L").label
    'y = 0.1*x, z = x**2/L'
    """
    if not np.isfinite(amplitude):
        raise TargetExpressionError(f"the amplitude must be a finite number of mm, got {amplitude!r}")
    key = _normalise(spec)
    if key in PRESETS:
        if not (np.isfinite(periods) and periods > 0):
            raise TargetExpressionError(f"the number of periods must be positive, got {periods!r}")
        arg = f"2*pi*{periods:.17g}*x/L"
        if key.startswith("helix"):  # radius A, `periods` turns about an axis parallel to x, through (0, A, 0)
            sign = "-" if key == "helix" else ""
            return ProfileTarget(parse_expression(f"A*(1 - cos({arg}))", CARTESIAN), "cartesian", amplitude, length,
                                 key, depth=parse_expression(f"{sign}A*sin({arg})", CARTESIAN))
        text = f"A*sin({arg})" if key == "sin" else (f"A*(cos({arg}) - 1)" if anchored else f"A*cos({arg})")
        return ProfileTarget(parse_expression(text, CARTESIAN), "cartesian", amplitude, length, key)
    space = re.match(r"^\s*y\s*=(?P<y>.+?),\s*z\s*=(?P<z>.+)$", spec)
    if space:  # a space curve: y = f(x), z = g(x)
        y = parse_expression(space["y"], CARTESIAN, HINTS_CARTESIAN)
        z = parse_expression(space["z"], CARTESIAN, HINTS_CARTESIAN)
        return ProfileTarget(y, "cartesian", amplitude, length, f"{y.text}, z = {z.text}", depth=z)
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
    variables, hints = (POLAR, HINTS_POLAR) if polar else (CARTESIAN, HINTS_CARTESIAN)
    expr = parse_expression(rhs, variables, hints)
    return ProfileTarget(expr, "polar" if polar else "cartesian", amplitude, length, expr.text)


def make_objective(
    spec: str,
    amplitude: float = 10.0,
    periods: float = 1.0,
    point: tuple[float, ...] | None = None,
    anchored: bool = True,
    length: float | None = None,
    curve: ArrayLike | None = None,
    path: ArrayLike | None = None,
) -> Objective:
    """Any objective from its text: a tip goal, a contact goal (``grip``, ``wrap``:
    :mod:`~pneumorph.design.objectives.contact`), a preset, a profile expression or a path.

    With ``length`` (mm), a profile is also checked to be finite along an actuator that long
    (:meth:`ProfileTarget.check`). ``"curve"`` takes its points from ``curve``
    (:func:`curve_target`), ``"path"`` from ``path`` (:func:`~pneumorph.design.objectives.paths.path_target`);
    the path presets (:data:`~pneumorph.design.objectives.paths.PATH_PRESETS`: ``letter-l``, ``hook``, ...)
    are drawn for the actuator they are matched on.

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
    min-y, min-distance, max-curl, reach, grip, wrap, sin, cos, helix, helix-left, letter-l, letter-s,
    letter-r, hook, spiral, coil, path, or a profile 'y = f(x)' / 'r = f(theta)' / 'y = f(x), z = g(x)'
    """
    key = _ALIASES.get(_normalise(spec), _normalise(spec))
    if (key == "path") != (path is not None):
        raise SearchConfigError("the objective 'path' needs its points: path = [[x, y], ...] in mm (or --target "
                                "path:FILE)" if key == "path" else f"path points are only used by the objective "
                                f"'path', not by {spec!r}")
    if key == "path" or key in PATH_PRESETS:
        if point is not None or curve is not None:
            raise SearchConfigError(f"a path takes neither a tip point nor curve points, not {spec!r}")
        if not anchored:
            raise SearchConfigError("anchored = false (the path's best rigid placement) is not offered yet: a path "
                                    "is matched where it is given, base at the origin")
        return path_target(path) if key == "path" else preset_path(key)  # type: ignore[arg-type]
    if (key == "curve") != (curve is not None):
        raise SearchConfigError("the objective 'curve' needs its points: curve = [[x, y], ...] in mm"
                                if key == "curve" else f"curve points are only used by the objective 'curve', "
                                f"not by {spec!r}")
    if key == "curve":
        if point is not None:
            raise SearchConfigError("a tip point is only used by the objective 'reach', not by 'curve'")
        target = curve_target(curve)  # type: ignore[arg-type]
        if length is not None:
            check_span(np.asarray(curve, dtype=float)[:, 0], length)
        return target if length is None else target.check(length)
    if key in TIP_GOALS:
        return tip_goal(key, point)
    if key in CONTACT_GOALS:
        if point is not None:
            raise SearchConfigError(f"a tip point is only used by the objective 'reach', not by {spec!r}")
        return contact_goal(key)
    if point is not None:
        raise SearchConfigError(f"a tip point is only used by the objective 'reach', not by {spec!r}")
    if key not in PRESETS and "=" not in spec:
        words = re.fullmatch(r"[A-Za-z_][\w\- ]*", spec.strip())
        if words and spec.strip() not in (*CARTESIAN, *POLAR, "pi", "e"):
            raise UnknownObjectiveError(spec, [*TIP_GOALS, *CONTACT_GOALS, *PRESETS, *PATH_PRESETS, "path"])
    target = profile_target(spec, amplitude, periods, anchored=anchored)
    return target if length is None else target.check(length)


__all__ = [
    "LEVEL_MATCH",
    "MAX_CURVE_POINTS",
    "MAX_STAGES",
    "MAX_TARGET_MM",
    "MIN_CURVE_SPAN",
    "PRESETS",
    "TIP_GOALS",
    "ContactGoal",
    "Objective",
    "PathTarget",
    "Polyline",
    "ProfileTarget",
    "Sense",
    "Stage",
    "StagedTarget",
    "TipGoal",
    "curve_target",
    "make_objective",
    "on_actuator",
    "profile_target",
    "smooth_curve",
    "staged_target",
    "tip_goal",
]

"""A design query from the bench page, checked field by field.

The page sends JSON; :func:`parse_query` turns it into a :class:`Query` or raises
:class:`QueryError` naming the field to show the message beside. Nothing a user types is
executed: expressions go through the same safe parser as the command line
(:mod:`pneumorph.design.expressions`), drawn curves are smoothed into a polyline
(:func:`pneumorph.design.targets.smooth_curve`).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from pneumorph import checks
from pneumorph.design.config import DesignConfig
from pneumorph.design.targets import PRESETS, TIP_GOALS, Objective, make_objective, smooth_curve
from pneumorph.errors import PneumorphError, SettingsError

KINDS = ("preset", "expression", "tip", "curve")
MODELS = ("3d", "2d")
MAX_TOP = 100
MAX_TEXT = 400


class QueryError(SettingsError):
    """A query the bench cannot answer; ``field`` names the input to show the message beside.

    Examples
    --------
    >>> QueryError("amplitude", "must be positive").field
    'amplitude'
    """

    def __init__(self, field: str, message: str) -> None:
        super().__init__(message)
        self.field = field
        self.message = message

    def __reduce__(self) -> tuple[type, tuple[str, str]]:  # crosses process boundaries whole
        return (QueryError, (self.field, self.message))


@dataclass(frozen=True)
class Query:
    """What the page asks: a target, a model fidelity and how many designs to list.

    Attributes
    ----------
    kind : {"preset", "expression", "tip", "curve"}
    spec : str
        The objective's text for :func:`~pneumorph.design.targets.make_objective` ("sin",
        "y = ...", "max-x", "curve").
    amplitude, periods : float
    point : (float, float) or None
        The tip point of the goal "reach" (mm).
    curve : tuple of (x, y) or None
        A drawn curve's smoothed knots (mm).
    model : {"3d", "2d"}
    top : int
        Designs listed, best first.
    unit : str
        ``"builtin"`` or the id of a unit uploaded to the bench.
    """

    kind: str
    spec: str
    amplitude: float = 10.0
    periods: float = 1.0
    point: tuple[float, float] | None = None
    curve: tuple[tuple[float, float], ...] | None = None
    model: str = "3d"
    top: int = 10
    unit: str = "builtin"

    def objective(self, length: float) -> Objective:
        """The objective, a profile checked along ``length`` mm."""
        return make_objective(self.spec, self.amplitude, self.periods, self.point, length=length, curve=self.curve)

    def key(self) -> str:
        """A canonical text of the query (equal queries, equal keys)."""
        return json.dumps(asdict(self), sort_keys=True)

    def config(self, units: int, unit: dict[str, Any] | None = None, **settings: Any) -> DesignConfig:
        """The design run of this query (certified search on its model), as the CLI would run it.

        ``unit`` is the unit's parameters when it is not the built-in one.
        """
        model: dict[str, Any] = {"fidelity": self.model}
        if unit is not None:
            model["unit"] = dict(unit)
        return DesignConfig(objective=self.spec, amplitude=self.amplitude, periods=self.periods, point=self.point,
                            curve=self.curve, units=units, search="certified", model=model, **settings)


def _number(data: dict[str, Any], name: str, default: float, low: float, high: float) -> float:
    value = data.get(name, default)
    try:
        return float(checks.real(value, name, low, high, low_open=True, error=SettingsError))
    except SettingsError as exc:
        raise QueryError(name, str(exc)) from None


def _text(data: dict[str, Any], name: str) -> str:
    value = data.get(name)
    if not isinstance(value, str) or not value.strip():
        raise QueryError(name, f"{name} must be given as text")
    if len(value) > MAX_TEXT:
        raise QueryError(name, f"{name} is longer than {MAX_TEXT} characters")
    return value.strip()


def parse_query(body: Any, length: float, units: tuple[str, ...] = ("builtin",)) -> Query:
    """Check a query's JSON body against an actuator ``length`` mm long.

    Parameters
    ----------
    body : dict
        ``{"target": {...}, "model": "3d", "top": 10}``; the target is one of
        ``{"kind": "preset", "name": "sin", "amplitude": 10, "periods": 1}``,
        ``{"kind": "expression", "expression": "y = ...", "amplitude": 10}``,
        ``{"kind": "tip", "goal": "max-x", "point": [x, y]}`` or
        ``{"kind": "curve", "points": [[x, y], ...]}`` (a drawn stroke, mm).
    length : float
        The undeformed actuator length (mm): profiles must be finite on it, strokes are
        smoothed over it.
    units : tuple of str
        The unit ids the query may name in ``"unit"`` (default: the built-in unit only).

    Raises
    ------
    QueryError
        Naming the field at fault.

    Examples
    --------
    >>> q = parse_query({"target": {"kind": "preset", "name": "cos", "amplitude": 20}}, 157.5)
    >>> q.spec, q.amplitude, q.model
    ('cos', 20.0, '3d')
    >>> bad = {"target": {"kind": "expression", "expression": "y = __import__('os')"}}
    >>> parse_query(bad, 157.5)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.bench.query.QueryError: in expression "__import__('os')": unknown function '__import__' ...
    """
    if not isinstance(body, dict):
        raise QueryError("target", "the query must be a JSON object")
    target = body.get("target")
    if not isinstance(target, dict):
        raise QueryError("target", "the query needs a target object")
    model = body.get("model", "3d")
    if model not in MODELS:
        raise QueryError("model", f"model must be one of {', '.join(MODELS)}, got {model!r}")
    top = body.get("top", 10)
    if isinstance(top, bool) or not isinstance(top, int) or not 1 <= top <= MAX_TOP:
        raise QueryError("top", f"top must be a whole number from 1 to {MAX_TOP}, got {top!r}")
    kind = target.get("kind")
    if kind not in KINDS:
        raise QueryError("target", f"the target kind must be one of {', '.join(KINDS)}, got {kind!r}")
    unit = body.get("unit", "builtin")
    if unit not in units:
        raise QueryError("unit", f"unknown unit {unit!r}; upload its TOML file to build its chain table first")
    fields: dict[str, Any] = {"kind": kind, "model": model, "top": top, "unit": unit}
    if kind == "preset":
        name = target.get("name", "sin")
        if name not in PRESETS:
            raise QueryError("preset", f"the preset must be one of {', '.join(PRESETS)}, got {name!r}")
        fields.update(spec=name, amplitude=_number(target, "amplitude", 10.0, 0.0, 1e4),
                      periods=_number(target, "periods", 1.0, 0.0, 1000.0))
        blame = "amplitude"
    elif kind == "expression":
        fields.update(spec=_text(target, "expression"), amplitude=_number(target, "amplitude", 10.0, 0.0, 1e4))
        blame = "expression"
    elif kind == "tip":
        goal = target.get("goal")
        if goal not in TIP_GOALS:
            raise QueryError("goal", f"the tip goal must be one of {', '.join(TIP_GOALS)}, got {goal!r}")
        point = target.get("point")
        if goal == "reach":
            try:
                point = checks.pair(point, "point", unit="mm", error=SettingsError)
            except SettingsError as exc:
                raise QueryError("point", str(exc)) from None
        fields.update(spec=goal, point=point if goal == "reach" else None)
        blame = "point" if goal == "reach" else "goal"
    else:
        try:
            knots = smooth_curve(target.get("points", []), length)
        except PneumorphError as exc:
            raise QueryError("points", str(exc)) from None
        fields.update(spec="curve", curve=tuple((float(x), float(y)) for x, y in np.round(knots, 6)))
        blame = "points"
    query = Query(**fields)
    try:
        query.objective(length)
    except PneumorphError as exc:
        raise QueryError(blame, str(exc)) from None
    return query


__all__ = ["KINDS", "MODELS", "Query", "QueryError", "parse_query"]

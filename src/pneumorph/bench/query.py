"""A design query from the bench page, checked field by field.

The page sends JSON; :func:`parse_query` turns it into a :class:`Query` or raises
:class:`QueryError` naming the field to show the message beside. Nothing a user types is
executed: expressions go through the same safe parser as the command line
(:mod:`pneumorph.design.objectives.expressions`), drawn curves are smoothed into a polyline
(:func:`pneumorph.design.objectives.targets.smooth_curve`), or into a path where the stroke turns back
in x (:mod:`pneumorph.bench.strokes`).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from pneumorph import checks
from pneumorph.bench.strokes import AXIS_MM, is_path_stroke, smooth_path
from pneumorph.design.config import DesignConfig
from pneumorph.design.objectives.paths import PATH_PRESETS, path_points
from pneumorph.design.objectives.targets import (
    MAX_STAGES,
    PRESETS,
    TIP_GOALS,
    Objective,
    make_objective,
    smooth_curve,
    staged_target,
)
from pneumorph.errors import PneumorphError, SettingsError
from pneumorph.io.files import nested_deeper

KINDS = ("preset", "expression", "tip", "curve", "path", "stages")
#: the kinds of target a stage may hold (a stage's tip goal is ``reach``)
STAGE_KINDS = ("preset", "expression", "tip", "curve", "path")
MODELS = ("3d", "2d")
MAX_TOP = 100
MAX_TEXT = 400
MAX_DEPTH = 32  # nesting of a request's JSON (a query needs 4)
MAX_INT_DIGITS = 18  # longer integers in a request are read as floats (then refused where not finite)


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
    kind : {"preset", "expression", "tip", "curve", "path", "stages"}
    spec : str
        The objective's text for :func:`~pneumorph.design.objectives.targets.make_objective` ("sin",
        "y = ...", "max-x", "curve", "path" or a path preset such as "hook").
    amplitude, periods : float
    point : (float, float), (float, float, float) or None
        The tip point of the goal "reach" (mm): (x, y), or (x, y, z) off the plane of bending.
    curve : tuple of (x, y) or (x, y, z), or None
        A drawn curve's smoothed knots (mm; with z when it was drawn seen from above too).
    model : {"3d", "2d"}
    top : int
        Designs listed, best first.
    unit : str
        ``"builtin"`` or the id of a unit uploaded to the bench.
    stages : tuple of (float, float, Query), optional
        For ``kind = "stages"``: per stage its pressure (kPa), its weight and its target (a
        query of one of :data:`STAGE_KINDS`).
    path : tuple of (x, y) or (x, y, z), or None
        A path's points (mm, in the frame of the unit centres: y from the actuator's bottom
        face, z from its mid-plane), for ``spec = "path"``: given, or a drawn stroke that
        turns back in x, smoothed (:func:`~pneumorph.bench.strokes.smooth_path`).
    obstacle : (float, float, float) or None
        A circle ``(x, y, r)`` beside the actuator (mm, the model's frame) that the answer's design is solved
        against by the 2D FE model with contact (:mod:`pneumorph.bench.contact`).
    """

    kind: str
    spec: str
    amplitude: float = 10.0
    periods: float = 1.0
    point: tuple[float, ...] | None = None
    curve: tuple[tuple[float, ...], ...] | None = None
    model: str = "3d"
    top: int = 10
    unit: str = "builtin"
    stages: tuple[tuple[float, float, Query], ...] | None = None
    path: tuple[tuple[float, ...], ...] | None = None
    obstacle: tuple[float, float, float] | None = None

    def objective(self, length: float) -> Objective:
        """The objective, a profile checked along ``length`` mm (stages: their staged target)."""
        if self.stages is not None:
            return staged_target([(p * 1e-3, q.objective(length), w) for p, w, q in self.stages])
        return make_objective(self.spec, self.amplitude, self.periods, self.point, length=length, curve=self.curve,
                              path=self.path)

    def key(self) -> str:
        """A canonical text of the query (equal queries, equal keys); an absent object is left out, so that the key
        (and the query id) of a query without one does not depend on the field."""
        fields = asdict(self)
        if fields["obstacle"] is None:
            del fields["obstacle"]
        return json.dumps(fields, sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Query:
        """The query of ``json.loads(query.key())`` (lists back to tuples).

        Examples
        --------
        >>> q = Query("reach", "reach", point=(100.0, 50.0))
        >>> Query.from_dict(json.loads(q.key())) == q
        True
        """
        point, curve, stages, path = data.get("point"), data.get("curve"), data.get("stages"), data.get("path")
        obstacle = data.get("obstacle")
        return cls(**{**data, "point": None if point is None else tuple(float(v) for v in point),
                      "obstacle": None if obstacle is None else tuple(float(v) for v in obstacle),
                      "curve": None if curve is None else tuple(tuple(float(v) for v in c) for c in curve),
                      "path": None if path is None else tuple(tuple(float(v) for v in c) for c in path),
                      "stages": None if stages is None else tuple((float(p), float(w), cls.from_dict(q))
                                                                  for p, w, q in stages)})

    def config(self, units: int, model: dict[str, Any] | None = None, **settings: Any) -> DesignConfig:
        """The design run of this query (certified search on its model), as the CLI would run it.

        ``model`` is the model's settings (the bench's, :meth:`Bench.model_settings`; default: the query's
        fidelity of the built-in unit).
        """
        model = dict(model) if model is not None else {"fidelity": self.model}
        if self.stages is not None:
            stage = tuple({"pressure_kpa": p, "weight": w, "objective": q.spec, "amplitude": q.amplitude,
                           "periods": q.periods, **({"point": list(q.point)} if q.point is not None else {}),
                           **({"curve": [list(c) for c in q.curve]} if q.curve is not None else {}),
                           **({"path": [list(c) for c in q.path]} if q.path is not None else {})}
                          for p, w, q in self.stages)
            return DesignConfig(objective="stages", stage=stage, units=units, search="certified", model=model,
                                **settings)
        return DesignConfig(objective=self.spec, amplitude=self.amplitude, periods=self.periods, point=self.point,
                            curve=self.curve, path=self.path, units=units, search="certified", model=model,
                            **settings)


def load_json(raw: bytes | str, field: str = "target") -> Any:
    """A request's JSON, refused as a :class:`QueryError` when it is not JSON or nested too deep.

    Integers of more than :data:`MAX_INT_DIGITS` digits are read as floats (an integer of
    400 digits is then an infinite number, refused by the field's check), so that no
    conversion of a huge integer fails later; nesting deeper than :data:`MAX_DEPTH` is refused.

    Examples
    --------
    >>> load_json(b'{"top": 3, "a": [1.5]}')
    {'top': 3, 'a': [1.5]}
    >>> load_json("1" * 400)
    inf
    >>> load_json("\\ufeff[1]"), load_json(b"\\xef\\xbb\\xbf[1]")  # a byte-order mark is not part of the value
    ([1], [1])
    >>> load_json("[" * 40 + "]" * 40)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.bench.query.QueryError: the request is nested deeper than 32 levels
    """
    if isinstance(raw, str):  # json reads a byte-order mark off bytes, not off text
        raw = raw.removeprefix("\ufeff")
    try:
        data = json.loads(raw or b"null", parse_int=lambda t: int(t) if len(t) <= MAX_INT_DIGITS else float(t))
    except RecursionError:
        raise QueryError(field, f"the request is nested deeper than {MAX_DEPTH} levels") from None
    except (ValueError, UnicodeDecodeError):
        raise QueryError(field, "the request is not valid JSON") from None
    if nested_deeper(data, MAX_DEPTH):
        raise QueryError(field, f"the request is nested deeper than {MAX_DEPTH} levels")
    return data


def choice(value: Any, options: Any, field: str, what: str) -> str:
    """``value`` if it is one of ``options`` (texts), else a :class:`QueryError` naming ``field``.

    A list or a dict given for a name is refused as any other wrong value.

    Examples
    --------
    >>> choice("3d", MODELS, "model", "model")
    '3d'
    >>> choice(["max-x"], ("max-x",), "goal", "the tip goal")
    Traceback (most recent call last):
    ...
    pneumorph.bench.query.QueryError: the tip goal must be one of max-x, got a list
    """
    if isinstance(value, str) and value in options:
        return value
    shown = repr(value[:40]) if isinstance(value, str) else "null" if value is None else \
        f"a {'list' if isinstance(value, list) else 'JSON object' if isinstance(value, dict) else type(value).__name__}"
    raise QueryError(field, f"{what} must be one of {', '.join(options)}, got {shown}")


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


def parse_query(body: Any, length: float, units: tuple[str, ...] = ("builtin",), axis: float = AXIS_MM) -> Query:
    """Check a query's JSON body against an actuator ``length`` mm long.

    Parameters
    ----------
    body : dict
        ``{"target": {...}, "model": "3d", "top": 10}``; the target is one of
        ``{"kind": "preset", "name": "sin", "amplitude": 10, "periods": 1}``,
        ``{"kind": "expression", "expression": "y = ...", "amplitude": 10}``,
        ``{"kind": "tip", "goal": "max-x", "point": [x, y]}`` (``[x, y, z]``: a point off the plane),
        ``{"kind": "curve", "points": [[x, y], ...]}`` (a drawn stroke, mm, y above the undeformed
        axis; with ``"top_points": [[x, z], ...]``, the same curve drawn seen from above: a space
        curve; a stroke that turns back in x is a path, :mod:`pneumorph.bench.strokes`) or
        ``{"kind": "path", "points": [[x, y], ...]}`` (``[x, y, z]``: in space; mm in the frame of
        the unit centres, y from the bottom face, as ``path = [...]`` of a design config) or
        ``{"kind": "path", "preset": "hook"}`` (a path preset, drawn for the actuator).
    length : float
        The undeformed actuator length (mm): profiles must be finite on it, strokes are
        smoothed over it.
    units : tuple of str
        The unit ids the query may name in ``"unit"`` (default: the built-in unit only).
    axis : float
        The undeformed axis's height above the bottom face (mm; the chain table's
        ``tip_ref[1]``): a stroke that becomes a path is lifted by it.

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
    model = choice(body.get("model", "3d"), MODELS, "model", "model")
    top = body.get("top", 10)
    if isinstance(top, bool) or not isinstance(top, int) or not 1 <= top <= MAX_TOP:
        raise QueryError("top", f"top must be a whole number from 1 to {MAX_TOP}, got {str(top)[:40]}")
    kind = choice(target.get("kind"), KINDS, "target", "the target kind")
    unit = body.get("unit", "builtin")
    if not isinstance(unit, str) or unit not in units:
        raise QueryError("unit", f"unknown unit {str(unit)[:40]!r}; upload its TOML file to build its chain table "
                                 "first")
    fields: dict[str, Any] = {"kind": kind, "model": model, "top": top, "unit": unit}
    if kind == "stages":
        fields.update(spec="stages", stages=_stages(target.get("stages"), length, model, unit, axis))
        blame = "stages"
    else:
        target_fields, blame = _target_fields(kind, target, length, axis)
        fields.update(target_fields)
    query = Query(**fields)
    try:
        query.objective(length)
    except PneumorphError as exc:
        raise QueryError(blame, str(exc)) from None
    return query


def _target_fields(kind: str, target: dict[str, Any], length: float, axis: float) -> tuple[dict[str, Any], str]:
    """The :class:`Query` fields of one target (not stages) and the field to blame for a bad one."""
    if kind == "preset":
        name = choice(target.get("name", "sin"), PRESETS, "preset", "the preset")
        return {"spec": name, "amplitude": _number(target, "amplitude", 10.0, 0.0, 1e4),
                "periods": _number(target, "periods", 1.0, 0.0, 1000.0)}, "amplitude"
    if kind == "expression":
        return {"spec": _text(target, "expression"),
                "amplitude": _number(target, "amplitude", 10.0, 0.0, 1e4)}, "expression"
    if kind == "tip":
        goal = choice(target.get("goal"), tuple(TIP_GOALS), "goal", "the tip goal")
        point = target.get("point")
        if goal == "reach":
            try:
                if isinstance(point, (list, tuple)) and len(point) == 3:  # (x, y, z): off the plane of bending
                    point = (*checks.pair(point[:2], "point", unit="mm", error=SettingsError),
                             checks.real(point[2], "point", unit="mm", error=SettingsError))
                else:
                    point = checks.pair(point, "point", unit="mm", error=SettingsError)
            except SettingsError as exc:
                raise QueryError("point", str(exc)) from None
        return {"spec": goal, "point": point if goal == "reach" else None}, "point" if goal == "reach" else "goal"
    if kind == "path":
        return _path_fields(target)
    if is_path_stroke(target.get("points", [])):  # no graph y = f(x): a path, in order
        if target.get("top_points") is not None:
            raise QueryError("points", "the stroke turns back in x, so it is a path in the plane: the view from "
                                       "above gives z by x and cannot say which pass of the path a z belongs to; "
                                       "give a path in space by its points (kind path, [x, y, z])")
        try:
            path = smooth_path(target["points"], length, axis)
        except PneumorphError as exc:
            raise QueryError("points", str(exc)) from None
        return {"spec": "path", "path": _rows(np.round(path, 6))}, "points"
    try:
        knots = smooth_curve(target.get("points", []), length)
    except PneumorphError as exc:
        raise QueryError("points", str(exc)) from None
    if target.get("top_points") is None:
        return {"spec": "curve", "curve": tuple((float(x), float(y)) for x, y in np.round(knots, 6))}, "points"
    try:  # the same curve seen from above: its z at the side view's knots
        top = smooth_curve(target["top_points"], length)
    except PneumorphError as exc:
        raise QueryError("points", f"seen from above: {exc}") from None
    z = np.interp(knots[:, 0], top[:, 0], top[:, 1])  # held at the ends beyond the stroke from above
    space = np.round(np.column_stack([knots, z]), 6)
    return {"spec": "curve", "curve": tuple(tuple(float(v) for v in row) for row in space)}, "points"


def _rows(points: Any) -> tuple[tuple[float, ...], ...]:
    return tuple(tuple(float(v) for v in row) for row in points)


def _path_fields(target: dict[str, Any]) -> tuple[dict[str, Any], str]:
    """A path's :class:`Query` fields: a preset's name, or its points as given (2 or 3 columns, repeats dropped)."""
    if target.get("preset") is not None:
        if target.get("points") is not None:
            raise QueryError("points", "a path is given by its points or by a preset, not both")
        return {"spec": choice(target["preset"], tuple(PATH_PRESETS), "preset", "the path preset")}, "preset"
    if target.get("points") is None:
        raise QueryError("points", "a path needs its points, [[x, y], ...] in mm from the base to the free end, or "
                                   "a preset")
    try:
        points = path_points(target["points"], "the path")
    except PneumorphError as exc:
        raise QueryError("points", str(exc)) from None
    columns = len(target["points"][0])  # as given: a path in the plane keeps its two columns
    return {"spec": "path", "path": _rows(points[:, :columns])}, "points"


def _stages(stages: Any, length: float, model: str, unit: str, axis: float) -> tuple[tuple[float, float, Query], ...]:
    """The stages of a ``kind = "stages"`` target: ``[{"pressure_kpa": P, "target": {...}, "weight": w}, ...]``."""
    if not isinstance(stages, list) or not 1 <= len(stages) <= MAX_STAGES:
        raise QueryError("stages", f"stages must be a list of 1 to {MAX_STAGES} stages (a pressure and a target "
                                   "each)")
    out = []
    for i, stage in enumerate(stages, 1):
        if not isinstance(stage, dict) or not isinstance(stage.get("target"), dict) or "pressure_kpa" not in stage:
            raise QueryError("stages", f"stage {i} must be an object with pressure_kpa (kPa, a level of the ramp) "
                                       "and a target")
        try:
            pressure = _number(stage, "pressure_kpa", float("nan"), 0.0, 1e4)
            weight = _number(stage, "weight", 1.0, 0.0, 1e6)
        except QueryError as exc:
            raise QueryError("stages", f"stage {i}: {exc.message}") from None
        if not pressure > 0 or not weight > 0:
            raise QueryError("stages", f"stage {i}: the pressure and the weight must be positive")
        kind = choice(stage["target"].get("kind"), STAGE_KINDS, "stages", f"stage {i}'s target kind")
        try:
            fields, _ = _target_fields(kind, stage["target"], length, axis)
        except QueryError as exc:
            raise QueryError("stages", f"stage {i}: {exc.message}") from None
        out.append((pressure, weight, Query(kind=kind, model=model, unit=unit, **fields)))
    return tuple(out)


__all__ = ["KINDS", "MAX_DEPTH", "MODELS", "STAGE_KINDS", "Query", "QueryError", "choice", "load_json",
           "parse_query"]

"""The checks of a design config's values (:class:`~pneumorph.design.config.DesignConfig`), each raising
:class:`~pneumorph.errors.SearchConfigError` and naming the setting: numbers, flags, names and addresses (the
checks of :mod:`pneumorph.checks`), tip points, drawn curves and paths, and the ``[[design.stage]]`` tables.

Examples
--------
>>> stage_tables("stages", [{"pressure_kpa": 18, "objective": "reach", "point": [60, 40]}])
({'pressure_kpa': 18.0, 'objective': 'reach', 'point': (60.0, 40.0)},)
>>> curve_points([[0, 0], [80, "2"]], "[design] curve")
Traceback (most recent call last):
...
pneumorph.errors.SearchConfigError: [design] curve must be a list of [x, y] (or all [x, y, z]) points in mm, ...
"""

from __future__ import annotations

from functools import partial
from typing import Any

from pneumorph import checks
from pneumorph.errors import SearchConfigError

# the checks of pneumorph.checks, raising the search's own error
integer = partial(checks.integer, error=SearchConfigError)
real = partial(checks.real, error=SearchConfigError)
flag = partial(checks.flag, error=SearchConfigError)
text = partial(checks.text, error=SearchConfigError)
address = partial(checks.address, error=SearchConfigError)
_pair = partial(checks.pair, error=SearchConfigError)

#: the settings of one ``[[design.stage]]`` table, and those it must have
STAGE_KEYS = ("pressure_kpa", "objective", "amplitude", "periods", "curve", "path", "point", "anchored", "weight")
_STAGE_NEEDS = ("pressure_kpa", "objective")


def curve_points(points: Any, name: str) -> tuple[tuple[float, ...], ...]:
    """A drawn curve's or a path's points as numbers (mm): all ``[x, y]`` or all ``[x, y, z]`` (in space), refusing
    text and true/false."""
    try:
        if any(isinstance(v, (bool, str, bytes)) for xy in points for v in xy):
            raise TypeError("text or true/false")
        out = tuple(tuple(float(v) for v in xy) for xy in points)
        if len({len(xy) for xy in out}) != 1 or len(out[0]) not in (2, 3):
            raise ValueError("mixed or wrong point sizes")
        return out
    except (TypeError, ValueError, IndexError):
        raise SearchConfigError(f"{name} must be a list of [x, y] (or all [x, y, z]) points in mm, got "
                                f"{_short(points)}") from None


def _short(value: Any, limit: int = 80) -> str:
    """``repr(value)``, cut to ``limit`` characters (a long list of points in an error message)."""
    shown = repr(value)
    return shown if len(shown) <= limit else shown[:limit] + " ..."


def tip_point(value: Any, name: str) -> tuple[float, ...]:
    """A tip point: ``[x, y]``, or ``[x, y, z]`` off the plane of bending (mm).

    >>> tip_point([60, 40, -10], "[design] point")
    (60.0, 40.0, -10.0)
    """
    if isinstance(value, (list, tuple)) and len(value) == 3:
        return (*_pair(value[:2], name, unit="mm"), checks.real(value[2], name, unit="mm", error=SearchConfigError))
    return _pair(value, name, unit="mm")


def stage_tables(objective: str, stages: Any) -> tuple[dict[str, Any], ...] | None:
    """The ``[[design.stage]]`` tables checked (types and ranges; the targets when the objective is made)."""
    staged = objective.strip().lower() == "stages"
    if stages is None:
        if staged:
            raise SearchConfigError("objective = \"stages\" needs its stages: [[design.stage]] tables with "
                                    "pressure_kpa and objective (or --stage KPA:TARGET)")
        return None
    if not staged:
        raise SearchConfigError(f"[[design.stage]] only applies to objective = \"stages\", not to {objective!r}")
    if isinstance(stages, dict) or not isinstance(stages, (list, tuple)):
        raise SearchConfigError(f"[[design.stage]] must be a list of tables, got {stages!r}")
    out = []
    for i, stage in enumerate(stages, 1):
        where = f"[[design.stage]] {i}"
        if not isinstance(stage, dict):
            raise SearchConfigError(f"{where} must be a table of settings, got {stage!r}")
        for key in set(stage) - set(STAGE_KEYS):
            raise SearchConfigError(f"unknown key {key!r} in {where}; known keys: {', '.join(STAGE_KEYS)}")
        for key in _STAGE_NEEDS:
            if key not in stage:
                raise SearchConfigError(f"{where} needs {key}")
        s = dict(stage)
        s["pressure_kpa"] = real(s["pressure_kpa"], f"{where} pressure_kpa", 0.0, 1000.0, low_open=True, unit="kPa")
        text(s["objective"], f"{where} objective")
        if s["objective"].strip().lower() == "stages":
            raise SearchConfigError(f"{where} objective: a stage cannot hold stages")
        for key, low, high in (("amplitude", 0.0, 1e5), ("periods", 0.0, 1000.0), ("weight", 0.0, 1e6)):
            if key in s:
                s[key] = real(s[key], f"{where} {key}", low, high, low_open=True)
        if "anchored" in s:
            flag(s["anchored"], f"{where} anchored")
        if "point" in s:
            s["point"] = tip_point(s["point"], f"{where} point")
        for key in ("curve", "path"):
            if key in s:
                s[key] = curve_points(s[key], f"{where} {key}")
        out.append(s)
    return tuple(out)


__all__ = ["STAGE_KEYS", "address", "curve_points", "flag", "integer", "real", "stage_tables", "text", "tip_point"]

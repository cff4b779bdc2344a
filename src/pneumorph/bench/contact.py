"""An object on the bench's page: a circle placed beside the actuator, the answer's design solved against it by the
2D FE model with contact, and what the page draws of it.

A query may carry ``"obstacle": {"centre": [x, y], "radius": r}`` (mm, the model's frame: x from the clamped base,
y from the actuator's bottom face; the page's profiles draw heights above the undeformed axis, ``axis_mm`` higher
up). The object does not change the search: the chain model knows no contact, and the answer's winner is the
target's. That winner is then solved by the 2D FE model with the circle as a rigid cylinder
(:mod:`pneumorph.models.fe.obstacles`, frictionless), and the answer's ``contact`` holds, at every level, the force
on the object, the contact length, the clearance, the base's reaction, the nodes in contact (where they are and
their contact pressure) and the FE centreline.

The object is checked as every obstacle is (:func:`~pneumorph.fem.fast.shapes.obstacle_from_dict`: a finite
centre, a finite radius > 0), and by the page's own limits: its centre within :data:`PAGE` actuator lengths of the
base in x and y, its radius at most :data:`MAX_RADIUS` of the length. One that starts inside the actuator (or in a
cavity) is refused before the solve (:func:`~pneumorph.models.fe.obstacles.check_reach`). A query with an object
is a slow one: the bench answers it on the worker of the slow queries, a few at a time.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from pneumorph.bench.query import QueryError
from pneumorph.bench.samples import centrelines
from pneumorph.errors import SettingsError, SimulationFailed
from pneumorph.fem.fast.shapes import Cylinder, obstacle_from_dict
from pneumorph.models.fe.obstacles import check_reach

#: how far from the clamped base an object's centre may lie, in x and in y, over the actuator's length
PAGE = 1.25
#: the largest radius of an object, over the actuator's length
MAX_RADIUS = 0.5
#: decimals of the positions (mm) and pressures (kPa) the page draws
DECIMALS = 4


def parse_obstacle(value: Any, length: float) -> tuple[float, float, float] | None:
    """The circle ``(x, y, r)`` of a query's ``"obstacle"`` (None: none) beside an actuator ``length`` mm long.

    Raises
    ------
    QueryError
        Naming the field ``obstacle``: not an object of ``centre`` and ``radius``, no valid obstacle (NaN, a radius
        <= 0) or past the page.

    Examples
    --------
    >>> parse_obstacle({"centre": [80, 40], "radius": 8}, 157.5)
    (80.0, 40.0, 8.0)
    >>> parse_obstacle({"centre": [80, 400], "radius": 8}, 157.5)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.bench.query.QueryError: the object's centre (80, 400) mm is past the page: within 196.875 mm of ...
    """
    if value is None:
        return None
    if not isinstance(value, Mapping) or set(value) != {"centre", "radius"}:
        raise QueryError("obstacle", "the object must be {\"centre\": [x, y], \"radius\": r} (mm)")
    try:
        circle = obstacle_from_dict({"kind": "cylinder", "centre": value["centre"], "radius": value["radius"]}, 2,
                                    "the object")
    except SettingsError as exc:
        raise QueryError("obstacle", str(exc)) from None
    assert isinstance(circle, Cylinder)
    (x, y), r = (float(v) for v in circle.centre), float(circle.radius)
    if max(abs(x), abs(y)) > PAGE * length:
        raise QueryError("obstacle", f"the object's centre ({x:g}, {y:g}) mm is past the page: within "
                                     f"{PAGE * length:g} mm of the base in x and y")
    if r > MAX_RADIUS * length:
        raise QueryError("obstacle", f"the object's radius {r:g} mm is larger than the page takes "
                                     f"({MAX_RADIUS * length:g} mm)")
    return x, y, r


def contact_answer(model: Any, design: str, circle: tuple[float, float, float]) -> dict[str, Any]:
    """``design`` solved by the 2D FE ``model`` against the ``circle`` ``(x, y, r)``: the answer's ``contact``.

    Keys: ``obstacle`` (its table), ``design``, ``levels`` (per level ``pressure_kpa``, ``force_n``,
    ``force_magnitude_n``, ``contact_length_mm``, ``clearance_mm``, ``base_reaction_n``, ``points`` - the nodes in
    contact where they are, mm - ``node_pressures_kpa`` and ``centreline``: the base, unit centres and tip, mm,
    the model's frame) and ``failure`` (None, or why the ramp stopped: then ``levels`` is empty).

    Raises
    ------
    QueryError
        The object starts inside the actuator or one of its cavities (before any solve).
    """
    table = {"kind": "cylinder", "centre": [circle[0], circle[1]], "radius": circle[2]}
    solver = model.variant(obstacles=[table])
    try:
        check_reach(solver, design)
    except SettingsError as exc:
        raise QueryError("obstacle", str(exc)) from None
    out: dict[str, Any] = {"obstacle": table, "design": design, "levels": [], "failure": None}
    try:
        solution = solver.solve(design)
    except SimulationFailed as exc:
        out["failure"] = str(exc.cause or exc)[:300]
        return out
    response = solution.response
    lines = centrelines(response)  # base, unit centres and tip per level, as a path is matched
    for k, level in enumerate(response.metadata["contact"]["levels"]):
        touch = level["obstacles"][0]
        x = solution.mesh.points[touch["nodes_in_contact"]] + solution.displacements[k][touch["nodes_in_contact"]]
        out["levels"].append({
            "pressure_kpa": round(float(level["pressure_kpa"]), 9),
            "force_n": touch["force_n"], "force_magnitude_n": touch["force_magnitude_n"],
            "contact_length_mm": touch["contact_length_mm"], "clearance_mm": touch["clearance_mm"],
            "base_reaction_n": level["base_reaction_n"],
            "points": np.round(x, DECIMALS).tolist(),
            "node_pressures_kpa": np.round(touch["node_pressures_kpa"], DECIMALS).tolist(),
            "centreline": lines[k],
        })
    return out


__all__ = ["DECIMALS", "MAX_RADIUS", "PAGE", "contact_answer", "parse_obstacle"]

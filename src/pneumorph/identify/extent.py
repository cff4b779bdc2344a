"""A design's deformed shape before any solve: the chain table's centreline carrying rigid units.

A scan whose design was typed with the wrong unit count is refused by its size
(:func:`~pneumorph.identify.match.check_size`). The deformed size depends on how far the
design curls, which only a solve knows, unless a chain table of the model serves the scan's
pressure: then the table's unit centres (exact to hundredths of a millimetre on the nominal
model, :mod:`pneumorph.models.chain.model`) place every unit of the undeformed mesh as a rigid
body, turned by the mean turn of the two chords at its centre. The walls do not balloon in
this shape, so its size is a little smaller than the solved one's;
:data:`~pneumorph.identify.match.CHAIN_MARGIN` widens the size check by what that was measured
to cost (docs/identify.md). A pressure between two of a table's levels is checked against
the shapes at both (:func:`chain_shapes`): the size between them.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.correlation.compare import ModelShape, model_shape
from pneumorph.geometry.assembly import ActuatorMesh, unit_starts
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import serve_table
from pneumorph.models.factory import make_model

FloatArray = NDArray[np.float64]


def chain_shape(model: Any, design: str, folder: str | Path | None = None) -> ModelShape | None:
    """The deformed shape of ``design`` at ``model``'s top pressure from a chain table, or None.

    None when no table (shipped, or kept in ``folder``) has a level at exactly the model's top
    pressure, or when the actuator is too short for the table's window.

    Examples
    --------
    >>> from pneumorph.models.factory import make_model
    >>> shape = chain_shape(make_model(15, {"fidelity": "2d", "pressure_kpa": 36}), "001111010001001")
    >>> round(float(shape.extent), 1)   # the solved 2D model's outline: 173.3 mm
    172.9
    >>> chain_shape(make_model(15, {"fidelity": "2d", "pressure_kpa": 37}), "001111010001001") is None
    True
    """
    served = serve_table(model, folder)
    if served is None or not np.isclose(served.table.pressures[-1], served.requested, rtol=0, atol=1e-9):
        return None
    n = len(design)
    if n < 2 * served.table.window + 1:
        return None
    response = ChainModel(served.table, n).evaluate(design)
    mesh = model.mesh(design)
    return model_shape(SimpleNamespace(mesh=mesh, displacements=[rigid_units(mesh, response)]))


def chain_shapes(settings: dict[str, Any], design: str, folder: str | Path | None = None) -> list[ModelShape]:
    """The chain shapes that bracket ``design`` at the model ``settings``' pressure (``pressure_kpa``).

    One shape where a table has a level at that pressure (:func:`chain_shape`); else the two at
    the levels just below and above it, of the table of the same model on its default ramp;
    none past the table's levels, below its first, or without a table.

    Examples
    --------
    >>> shapes = chain_shapes({"fidelity": "2d", "pressure_kpa": 37}, "001111010001001")  # levels 36 and 40.5
    >>> len(shapes), [round(float(s.extent), 1) for s in shapes]
    (2, [172.9, 176.1])
    """
    n = len(design)
    shape = chain_shape(make_model(n, settings), design, folder)
    if shape is not None:
        return [shape]
    default = {k: v for k, v in settings.items() if k not in ("pressure_kpa", "increments")}
    served = serve_table(make_model(n, default), folder)
    if served is None:
        return []
    levels = served.table.pressures
    p = float(settings.get("pressure_kpa", np.nan)) * 1e-3
    below, above = np.flatnonzero(levels < p), np.flatnonzero(levels > p)
    if not (len(below) and len(above)):
        return []
    out = []
    for i in (below[-1], above[0]):
        at_level = {**default, "pressure_kpa": float(levels[i]) * 1e3, "increments": int(i) + 1}
        shape = chain_shape(make_model(n, at_level), design, folder)
        if shape is None:
            return []
        out.append(shape)
    return out


def rigid_units(mesh: ActuatorMesh, response: Any, level: int = -1) -> FloatArray:
    """Displacements that carry each unit of ``mesh`` rigidly to the response's centreline.

    Unit ``i`` moves its reference centre to its centre at ``level`` and turns by the mean of
    the turns of its two chords (base -> centre 1 -> ... -> centre n -> tip); the base block
    stays, an end cap follows the last unit.
    """
    current = response.centreline(level)  # base -> centres -> tip
    ref_c = np.asarray(response.reference_centres)
    reference = np.vstack([current[:1], ref_c, np.asarray(response.reference_tip)[None]])
    rotation = _angles(current) - _angles(reference)  # of every chord
    turn = 0.5 * (rotation[:-1] + rotation[1:])
    cur_c = current[1:-1]
    units = mesh.units or tuple(mesh.spec for _ in range(len(ref_c)))
    starts = unit_starts(units)
    x = mesh.points
    unit = np.clip(np.searchsorted(starts, x[:, 0], side="right") - 1, 0, len(ref_c) - 1)
    rel = x[:, :2] - ref_c[unit]
    cos, sin = np.cos(turn[unit]), np.sin(turn[unit])
    moved = cur_c[unit] + np.c_[cos * rel[:, 0] - sin * rel[:, 1], sin * rel[:, 0] + cos * rel[:, 1]]
    u = np.zeros_like(x)
    u[:, :2] = moved - x[:, :2]
    u[x[:, 0] < 0.0] = 0.0  # the base block
    return u


def _angles(points: FloatArray) -> FloatArray:
    """Unwrapped angles of the chords of a polyline."""
    d = np.diff(points, axis=0)
    return np.unwrap(np.arctan2(d[:, 1], d[:, 0]))


__all__ = ["chain_shape", "rigid_units"]

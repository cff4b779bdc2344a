"""Pieces every actuator model builds the same way on FElupe."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray


def linked_solid(umat: Any, points: NDArray[Any], cells: NDArray[Any], cell_type: str, region: Any, field_type: Any,
                 dim: int, field: Any) -> Any:
    """A ``SolidBody`` of ``umat`` on some cells, its field linked to the global ``field``.

    All materials share one set of points and one displacement field; each gets its own
    region over its cells.
    """
    import felupe as fem

    sub = fem.Mesh(points, cells, cell_type)
    sub_field = fem.FieldContainer([field_type(region(sub), dim=dim)])
    sub_field.link(field)
    return fem.SolidBody(umat, sub_field)


def clamped_dofs(field: Any, base_points: NDArray[np.bool_],
                 symmetry_points: NDArray[np.bool_] | None = None) -> tuple[NDArray[Any], NDArray[Any]]:
    """``(dof0, dof1)``: the base clamped, and u_z = 0 on a mid-width symmetry plane if given."""
    import felupe as fem

    bounds = {"base": fem.Boundary(field[0], mask=base_points)}
    if symmetry_points is not None:
        bounds["symmetry"] = fem.Boundary(field[0], mask=symmetry_points, skip=(1, 1, 0))
    return fem.dof.partition(field, bounds)

"""Dead loads (gravity) of FElupe ``SolidBodyForce`` items for the fast assemblies.

A body force ``rho g`` does not follow the deformation, so its nodal vector
``f_a = scale * values * integral(N_a dV)`` needs the shape-function integrals of its region
once; each evaluation reads the item's current ``values`` and ``scale`` (the load factor is
applied through them, as FElupe's own assembly does) and adds nothing to the tangent.
FElupe adds the item to the residual with the multiplier -1, so the residual of the fast
systems is ``internal - f``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def nodal_volumes(region: Any, npoints: int) -> FloatArray:
    """``integral(N_a dV)`` of every point over a FElupe region (zero off the region).

    Examples
    --------
    >>> import felupe as fem
    >>> region = fem.RegionHexahedron(fem.Cube(n=2))
    >>> w = nodal_volumes(region, 8)
    >>> [round(float(x), 6) for x in w[:2]], round(float(w.sum()), 12)
    ([0.125, 0.125], 1.0)
    """
    cells = np.asarray(region.mesh.cells, dtype=np.int64)
    h = np.asarray(region.h)  # (n, q) or (n, q, 1) or (n, q, c)
    if h.ndim == 2:
        h = h[:, :, None]
    dV = np.asarray(region.dV)  # (q, c)
    per_cell = np.einsum("aqc,qc->ca", np.broadcast_to(h, (*h.shape[:2], dV.shape[1])), dV)
    return np.asarray(np.bincount(cells.ravel(), weights=per_cell.ravel(), minlength=npoints), dtype=np.float64)


class DeadLoads:
    """The summed nodal forces of ``SolidBodyForce`` items on one global field.

    Parameters
    ----------
    items : sequence
        ``felupe.SolidBodyForce`` items whose fields are linked to the global field.
    npoints, dim : int
        Points and components of the global field.

    Examples
    --------
    >>> import felupe as fem
    >>> field = fem.FieldContainer([fem.Field(fem.RegionHexahedron(fem.Cube(n=2)), dim=3)])
    >>> loads = DeadLoads([fem.SolidBodyForce(field, values=[0.0, 0.0, -9810.0], scale=1e-9)], 8, 3)
    >>> round(float(loads.vector().reshape(-1, 3)[:, 2].sum()), 12)   # the weight of 1 mm^3, N
    -9.81e-06
    """

    def __init__(self, items: Sequence[Any], npoints: int, dim: int) -> None:
        self.dim = dim
        self.npoints = npoints
        self.items = [(item, nodal_volumes(item.field[0].region, npoints)) for item in items]

    def __bool__(self) -> bool:
        return bool(self.items)

    def vector(self) -> FloatArray:
        """Nodal forces over all dofs (FElupe numbering ``dim * point + component``)."""
        f = np.zeros((self.npoints, self.dim))
        for item, w in self.items:
            g = np.asarray(item.results.values, dtype=float).ravel()[: self.dim]
            f += float(item.results.scale) * w[:, None] * g[None, :]
        return f.ravel()

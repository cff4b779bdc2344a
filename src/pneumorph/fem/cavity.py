"""Cavity volume from the pressurised boundary (the work-conjugate of the pressure)."""

from __future__ import annotations

from typing import Any

import numpy as np


def cavity_volume(boundary_field: Any) -> float:
    """Current volume enclosed by a pressurised surface (area per unit thickness in 2D).

    By the divergence theorem ``V = -1/d * sum x . n da`` over the cavity walls, with the
    current area vectors ``n da = cof(F) N dA`` (Nanson) and ``n`` the outward normal of
    the solid, which points into the cavity. Planes of symmetry through the origin add
    nothing (``x . n = 0`` there), so a symmetric part of a cavity gives that part's volume.

    Parameters
    ----------
    boundary_field : felupe.FieldContainer
        The displacement field on the boundary region of the cavity walls (the field the
        pressure acts on): 3D ``Field`` or 2D ``FieldPlaneStrain`` (``ensure_3d=True``).

    Returns
    -------
    float
        Volume in mm^3 (3D) or area in mm^2 (2D plane strain, per unit thickness).

    Examples
    --------
    >>> import felupe as fem, numpy as np
    >>> mesh = fem.Rectangle(n=3).add_midpoints_edges()   # unit square
    >>> walls = fem.RegionQuadraticQuadBoundary(mesh, ensure_3d=True)
    >>> field = fem.FieldContainer([fem.FieldPlaneStrain(walls, dim=2)])
    >>> round(-cavity_volume(field), 12)   # the square is solid: outward normals give -area
    1.0
    """
    import felupe as fem

    u = boundary_field[0]
    region = u.region
    dim = u.dim
    reference = fem.Field(region, dim=dim, values=region.mesh.points[:, :dim].copy())
    x = reference.interpolate()[:dim] + u.interpolate()[:dim]
    F = u.extract(grad=True, sym=False, add_identity=True)
    da = np.einsum("ij...,j...->i...", fem.math.cof(F), region.dA)
    return float(-np.sum(x * da[:dim]) / dim)

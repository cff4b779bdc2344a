"""The actuator's 3D surface for the bench's viewer: from an FE solution, or laid along the chain.

:func:`surface` triangulates the outer faces of a 3D mesh (a half model mirrored to the
full width). :func:`chain_placement` moves the undeformed nodes onto the centreline the
chain model predicts: every cross-section turns with the interpolated tangent of the
centreline and keeps its shape (no ballooning) - an approximate picture until an FE solve
gives the real one.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.geometry.assembly import ActuatorMesh
from pneumorph.geometry.boundary import outer_facets
from pneumorph.models.response import Response

FloatArray = NDArray[np.float64]


def surface(mesh: ActuatorMesh, x: FloatArray) -> dict[str, Any]:
    """Triangles of the outer surface of a 3D ``mesh`` whose nodes are at ``x`` (n, 3).

    Returns ``positions`` (flat x, y, z), ``indices`` (flat triangles, outward by the
    right-hand rule) and ``bounds`` ([min, max]); a half model is mirrored to the full width.

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> m = assemble(UnitSpec(element_size=3.0), "0", dim=3, half=True)
    >>> s = surface(m, m.points)
    >>> s["bounds"][0][2], s["bounds"][1][2], len(s["indices"]) % 3
    (0.0, 15.0, 0)
    """
    if mesh.dim != 3:
        raise ValueError("a surface is drawn from a 3D mesh")
    facets, _ = outer_facets(mesh)
    nodes, local = np.unique(facets, return_inverse=True)
    quads = local.reshape(facets.shape)
    tris = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    pos = np.asarray(x, dtype=float)[nodes]
    if mesh.symmetry_points is not None:  # the other half: z mirrored, welded to this one on the mid-plane
        seam = mesh.symmetry_points[nodes]
        index = np.where(seam, np.arange(len(nodes)), len(nodes) + np.cumsum(~seam) - 1)
        other = pos[~seam].copy()
        other[:, 2] = mesh.spec.width - other[:, 2]
        tris = np.concatenate([tris, index[tris][:, ::-1]])
        pos = np.concatenate([pos, other])
    return {"positions": np.round(pos, 4).ravel().tolist(), "indices": tris.ravel().astype(int).tolist(),
            "bounds": [pos.min(axis=0).round(4).tolist(), pos.max(axis=0).round(4).tolist()]}


def chain_placement(mesh: ActuatorMesh, response: Response, level: int) -> FloatArray:
    """The mesh's nodes laid along a predicted centreline at ``level`` (approximate shape).

    The centreline runs through the base (fixed), the unit centres and the tip; its tangent
    angle is the chord direction at the base, the centres (central differences) and the
    tip's curl, linear in between. A node at ``(X, Y, Z)`` goes to the centreline point at
    arc ``X`` plus its height ``Y`` above the undeformed axis, turned with the tangent.

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> from pneumorph.models.response import Response
    >>> m = assemble(UnitSpec(element_size=3.0), "00", dim=3, half=True)
    >>> ref = m.unit_centres(); tip = np.array([m.points[:, 0].max(), ref[0, 1]])
    >>> r = Response("00", np.array([0.01]), ref[None], ref, tip[None], tip, np.zeros(1))
    >>> bool(np.allclose(chain_placement(m, r, 0), m.points))  # straight: nothing moves
    True
    """
    ref_c, ref_t = response.reference_centres, response.reference_tip
    c, tip, curl = response.centres[level], response.tip[level], np.radians(response.curl[level])
    s = np.concatenate([[0.0], ref_c[:, 0], [ref_t[0]]])
    axis_y = np.concatenate([[ref_c[0, 1]], ref_c[:, 1], [ref_t[1]]])
    base = np.array([0.0, ref_c[0, 1]])
    pts = np.vstack([base, c, tip])
    chords = np.diff(pts, axis=0)
    along = np.unwrap(np.arctan2(chords[:, 1], chords[:, 0]))
    angle = np.concatenate([[0.0], 0.5 * (along[:-1] + along[1:]), [curl]])
    angle[-1] = angle[-2] + (angle[-1] - angle[-2] + np.pi) % (2 * np.pi) - np.pi
    X = mesh.points[:, 0]
    cx, cy = np.interp(X, s, pts[:, 0]), np.interp(X, s, pts[:, 1])
    a = np.interp(X, s, angle)
    h = mesh.points[:, 1] - np.interp(X, s, axis_y)
    out = mesh.points.astype(float).copy()
    out[:, 0] = cx - h * np.sin(a)
    out[:, 1] = cy + h * np.cos(a)
    return out


__all__ = ["chain_placement", "surface"]

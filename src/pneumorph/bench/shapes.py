"""The actuator's 3D surface for the bench's viewer: from an FE solution, or laid along the chain.

:func:`surface` triangulates the outer faces of a 3D mesh (a half model mirrored to the
full width). :func:`chain_placement` moves the undeformed nodes onto the centreline the
chain model predicts: every cross-section turns with the interpolated tangent of the
centreline (in the plane or in space) and keeps its shape (no ballooning) - an approximate
picture until an FE solve gives the real one.
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

    The centreline is the polyline base -> unit centres -> tip (a planar response's in the
    plane z = 0). Each chord turns from its undeformed direction by the rotation between the
    two chords' frames transported along the polylines without twist
    (:func:`~pneumorph.models.chain.space.transported_frames`). A centre turns halfway between
    its two chords (spherical linear interpolation), the base not at all, the tip as its
    end face (a planar response's curl) or, in space, as the last chord; a node at arc ``X``
    turns as interpolated between them. It goes to the centreline point at ``X`` plus its
    offset from the undeformed centreline, turned. Cross-sections keep their shape (no
    ballooning).

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.library import builtin_library
    >>> from pneumorph.models.response import Response
    >>> m = assemble(builtin_library("spatial"), "al", dim=3, half=False)   # centres at two heights
    >>> ref = m.unit_centres(axes=3); tip = np.array([m.points[:, 0].max(), 6.0, 7.5])
    >>> r = Response("al", np.array([0.01]), ref[None], ref, tip[None], tip, np.zeros(1))
    >>> bool(np.allclose(chain_placement(m, r, 0), m.points))  # undeformed: nothing moves
    True
    """
    from scipy.spatial.transform import Rotation, Slerp

    from pneumorph.models.chain.space import space_elements, transported_frames

    def polyline(centres: FloatArray, tip: FloatArray) -> FloatArray:
        out = np.vstack([response.reference_centres[:1], centres, tip[None]]).astype(float)
        out[0, 0] = 0.0  # the base: the first centre's height and width at x = 0
        return out if out.shape[1] == 3 else np.column_stack([out, np.zeros(len(out))])

    ref = polyline(response.reference_centres, response.reference_tip)
    pts = polyline(response.centres[level], response.tip[level])
    undeformed, deformed = (transported_frames(space_elements(p)[0]) for p in (ref, pts))
    chords = Rotation.from_matrix(deformed @ np.swapaxes(undeformed, -1, -2))
    halves = chords[:-1] * Rotation.from_rotvec(0.5 * (chords[:-1].inv() * chords[1:]).as_rotvec())  # slerp at 1/2
    end = (Rotation.from_rotvec([0.0, 0.0, np.radians(response.curl[level])])
           if response.centres.shape[-1] == 2 else chords[-1])
    s = ref[:, 0]
    X = np.clip(mesh.points[:, 0], s[0], s[-1])
    turn = Slerp(s, Rotation.concatenate([Rotation.identity(), halves, end]))(X)
    along = np.column_stack([np.interp(X, s, pts[:, i]) for i in range(3)])
    offset = mesh.points - np.column_stack([np.interp(X, s, ref[:, i]) for i in range(3)])
    return np.asarray(along + turn.apply(offset), dtype=float)


__all__ = ["chain_placement", "surface"]

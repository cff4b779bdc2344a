"""Each unit's frame in a deformed actuator: the rotation of its cavity's corners.

A chain in space (:mod:`pneumorph.models.chain.space`, docs/unit-library.md) must know
how each unit's frame has turned, its roll about the actuator's axis included: where
sideways and planar units meet, the frames roll by a degree or more, and the chords alone
cannot show it. A unit's frame is the rotation that best carries the four corners of its
cavity on the mid-width plane (the points its centre is the mean of, ``ActuatorMesh.tracked``)
from the undeformed mesh to the deformed one (least squares, Kabsch: scipy's
``Rotation.align_vectors``). A full-width response keeps it per level and unit as a rotation
vector (:attr:`Response.frames`).

Examples
--------
>>> import numpy as np
>>> from scipy.spatial.transform import Rotation
>>> from pneumorph.geometry.assembly import assemble
>>> from pneumorph.geometry.unit import UnitSpec
>>> mesh = assemble(UnitSpec(element_size=3.0), "01", dim=3)
>>> turn = Rotation.from_rotvec([0.1, -0.2, 0.3])
>>> frames = unit_frames(mesh, turn.apply(mesh.points) - mesh.points)   # the whole actuator turned rigidly
>>> frames.round(12).tolist()
[[0.1, -0.2, 0.3], [0.1, -0.2, 0.3]]
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def unit_frames(mesh: Any, displacement: FloatArray) -> FloatArray:
    """Each unit's rotation (a rotation vector, rad) from the undeformed ``mesh`` by ``displacement``, shape (n, 3).

    ``mesh`` is a 3D :class:`~pneumorph.geometry.assembly.ActuatorMesh`.
    """
    from scipy.spatial.transform import Rotation  # (a third of a second to import: only where frames are kept)

    p = mesh.points[mesh.tracked]  # (n, 4, 3): the cavity's corners on the mid-width plane
    q = p + displacement[mesh.tracked][..., :3]
    out = np.empty((len(p), 3))
    for i, (a, b) in enumerate(zip(p - p.mean(axis=1, keepdims=True), q - q.mean(axis=1, keepdims=True),
                                   strict=True)):
        out[i] = Rotation.align_vectors(b, a)[0].as_rotvec()  # the rotation that best takes a onto b
    return out


def end_frame(mesh: Any, displacement: FloatArray) -> FloatArray:
    """The free end face's rotation (a rotation vector, rad) from the undeformed ``mesh`` by ``displacement``, (3,).

    The face's frame is its line up the height - from the lowest to the highest of the
    section's end points (``ActuatorMesh.end_points``), the line whose angle is the curl - and
    its line across the width, from the mean of its nodes on one side face to the other's,
    made normal to the first; the third axis completes them. The rotation takes the
    undeformed frame to the deformed one, so a planar bend turns it about z by the curl.

    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> mesh = assemble(UnitSpec(element_size=3.0), "0", dim=3, half=False)
    >>> from scipy.spatial.transform import Rotation
    >>> turn = Rotation.from_rotvec([0.2, 0.0, 0.5])
    >>> end_frame(mesh, turn.apply(mesh.points) - mesh.points).round(12).tolist()
    [0.2, 0.0, 0.5]
    """
    from scipy.spatial.transform import Rotation

    points = np.asarray(mesh.points, dtype=float)[:, :3]
    ends = mesh.end_points
    face = np.flatnonzero(np.isclose(points[:, 0], points[ends[0], 0]))
    z = points[face, 2]
    sides = face[np.isclose(z, z.min())], face[np.isclose(z, z.max())]

    def frame(x: FloatArray) -> FloatArray:
        up = x[ends[-1]] - x[ends[0]]
        up /= np.linalg.norm(up)
        across = x[sides[1]].mean(axis=0) - x[sides[0]].mean(axis=0)
        across -= np.dot(across, up) * up
        across /= np.linalg.norm(across)
        return np.column_stack([np.cross(up, across), up, across])

    turned = frame(points + displacement[:, :3]) @ frame(points).T
    return np.asarray(Rotation.from_matrix(turned).as_rotvec())


def record_frames(response: Any, k: int, mesh: Any, displacement: FloatArray) -> None:
    """Write level ``k``'s unit frames and end face's frame into a full-width ``response`` (no-op for the arrays it
    lacks: a planar response keeps neither)."""
    if response.frames is not None:
        response.frames[k] = unit_frames(mesh, displacement)
    if response.end_frame is not None:
        response.end_frame[k] = end_frame(mesh, displacement)


def twist(rotations: FloatArray) -> FloatArray:
    """The twist (deg) of end-face rotations about the face's own normal, the actuator's axis x.

    A rotation splits into a *swing*, whose axis is normal to x (it tilts the face: the
    curl and the sideways bend), followed by a *twist* about x: ``R = swing * twist`` with
    the twist's angle ``2 atan2(q_x, q_w)`` of the rotation's unit quaternion ``q``, in
    (-180, 180]. Rotations (..., 3) as rotation vectors; NaN stays NaN.

    >>> twist(np.radians([[0.0, 0.0, 90.0], [30.0, 0.0, 0.0]])).round(9).tolist()  # a pure curl, a pure twist
    [0.0, 30.0]
    """
    r = np.asarray(rotations, dtype=float)
    flat = r.reshape(-1, 3)
    out = np.full(len(flat), np.nan)
    ok = np.isfinite(flat).all(axis=1)
    if ok.any():
        from scipy.spatial.transform import Rotation

        q = Rotation.from_rotvec(flat[ok]).as_quat()  # (x, y, z, w)
        angle = np.degrees(2.0 * np.arctan2(q[:, 0], q[:, 3]))
        out[ok] = (angle + 180.0) % 360.0 - 180.0
        out[ok & np.isclose(out, -180.0)] = 180.0
    return out.reshape(r.shape[:-1])


__all__ = ["end_frame", "record_frames", "twist", "unit_frames"]

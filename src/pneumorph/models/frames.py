"""Each unit's frame in a deformed actuator: the rotation of its cavity's corners.

A chain in space (:mod:`pneumorph.models.spacechords`, docs/unit-library.md) must know
how each unit's frame has turned, its roll about the actuator's axis included: where
sideways and planar units meet, the frames roll by a degree or more, and the chords alone
cannot show it. A unit's frame is the rotation that best carries the four corners of its
cavity on the mid-width plane (the points its centre is the mean of, ``ActuatorMesh.tracked``)
from the undeformed mesh to the deformed one (least squares, Kabsch). A full-width response
keeps it per level and unit as a rotation vector (:attr:`Response.frames`).

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
from scipy.spatial.transform import Rotation

FloatArray = NDArray[np.float64]


def unit_frames(mesh: Any, displacement: FloatArray) -> FloatArray:
    """Each unit's rotation (a rotation vector, rad) from the undeformed ``mesh`` by ``displacement``, shape (n, 3).

    ``mesh`` is a 3D :class:`~pneumorph.geometry.assembly.ActuatorMesh`.
    """
    p = mesh.points[mesh.tracked]  # (n, 4, 3): the cavity's corners on the mid-width plane
    q = p + displacement[mesh.tracked][..., :3]
    a, b = p - p.mean(axis=1, keepdims=True), q - q.mean(axis=1, keepdims=True)
    u, _, vt = np.linalg.svd(np.einsum("nki,nkj->nij", a, b))
    d = np.sign(np.linalg.det(np.einsum("nji,nkj->nik", vt, u)))  # a proper rotation, never a reflection
    fix = np.stack([np.ones_like(d), np.ones_like(d), d], axis=-1)
    rotation = np.einsum("nji,nj,nkj->nik", vt, fix, u)  # V diag(1, 1, d) U^T
    return Rotation.from_matrix(rotation).as_rotvec()


__all__ = ["unit_frames"]

"""Each unit's frame in a deformed actuator: the rotation of its cavity's corners.

A chain in space (:mod:`pneumorph.models.spacechords`, docs/unit-library.md) must know
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
from scipy.spatial.transform import Rotation

FloatArray = NDArray[np.float64]


def unit_frames(mesh: Any, displacement: FloatArray) -> FloatArray:
    """Each unit's rotation (a rotation vector, rad) from the undeformed ``mesh`` by ``displacement``, shape (n, 3).

    ``mesh`` is a 3D :class:`~pneumorph.geometry.assembly.ActuatorMesh`.
    """
    p = mesh.points[mesh.tracked]  # (n, 4, 3): the cavity's corners on the mid-width plane
    q = p + displacement[mesh.tracked][..., :3]
    out = np.empty((len(p), 3))
    for i, (a, b) in enumerate(zip(p - p.mean(axis=1, keepdims=True), q - q.mean(axis=1, keepdims=True),
                                   strict=True)):
        out[i] = Rotation.align_vectors(b, a)[0].as_rotvec()  # the rotation that best takes a onto b
    return out

__all__ = ["unit_frames"]

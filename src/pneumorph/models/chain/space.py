"""Chords of a space polyline as twist-free turns and lengths: the chain's elements in 3D.

The chain model (:mod:`pneumorph.models.chain.model`) describes a planar response by the turn and
length of each chord of the polyline base -> unit centres -> tip. In space, a chord's
direction relative to the one before is a rotation, and the chords alone do not say how the
frame rolls about them. Here each chord carries the frame transported from the base without
twist (a *discrete parallel transport*, or Bishop frame): chord ``j``'s frame is chord
``j - 1``'s turned by the smallest rotation that takes one direction to the other. That
rotation's axis is normal to chord ``j - 1``, so in its frame it has two components: the
turn about the frame's y axis and the turn about its z axis. The base's frame is the
actuator's own (x along it, y up, z across the width), and chord ``-1`` points along x.

Twist. A unit of the built-in kinds bends about one of its section's axes and its section is
symmetric about the plane of that bend (a planar unit: the mid-width plane; a sideways unit:
the mid-height plane), so by symmetry it does not twist alone. Where the two kinds meet,
neither symmetry holds: measured, the units' frames roll by about 1.2-1.5 deg at each such
junction and keep that roll after it (docs/unit-library.md, "A chain in space"). The chords
cannot show a roll, so these twist-free elements are not local in designs that mix the two
kinds. :func:`frame_elements` writes the chords in the units' own frames instead (from the
full model's :attr:`~pneumorph.models.response.Response.frames`), roll included: measured,
those are local (0.001-0.004 mm, 0.005-0.016 deg between designs that differ beyond +-2 units,
against 0.3-0.8 deg for the twist-free turns).

A planar polyline (z = 0) has no turn about y and its turn about z is the planar chain's
turn (:func:`~pneumorph.models.response.response_elements`), to rounding.

Examples
--------
>>> import numpy as np
>>> up = np.array([[0, 0, 0], [10, 0, 0], [20, 10, 0.0]])      # a turn of 45 degrees in the plane
>>> side = np.array([[0, 0, 0], [10, 0, 0], [20, 0, 10.0]])    # the same towards +z: about y, negative
>>> np.degrees(space_elements(up)[0][1]).round(9).tolist(), np.degrees(space_elements(side)[0][1]).round(9).tolist()
([0.0, 45.0], [-45.0, 0.0])
>>> points = np.array([[0, 0, 0], [10, 0, 0], [20, 1, 0], [29, 2, 3.0]])
>>> turns, lengths = space_elements(points)
>>> bool(np.allclose(space_polyline(turns, lengths, points[0]), points, rtol=0, atol=1e-12))
True
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def space_elements(points: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The twist-free turns (about the frame's y and z, rad) and the lengths (mm) of a polyline's chords.

    Parameters
    ----------
    points : ndarray, shape (..., m + 1, 3) or (..., m + 1, 2)
        Polylines (base first); leading axes are kept (levels, designs). Planar points
        (x, y) lie in the plane z = 0.

    Returns
    -------
    turns : ndarray, shape (..., m, 2)
    lengths : ndarray, shape (..., m)
    """
    points = np.asarray(points, dtype=float)
    if points.shape[-1] == 2:
        points = np.concatenate([points, np.zeros((*points.shape[:-1], 1))], axis=-1)
    chords = np.diff(points, axis=-2)
    lengths = np.linalg.norm(chords, axis=-1)
    d = chords / lengths[..., None]
    frame = np.broadcast_to(np.eye(3), (*d.shape[:-2], 3, 3)).copy()  # columns: the frame's axes
    turns = np.zeros((*d.shape[:-1], 2))
    for j in range(d.shape[-2]):
        before = frame[..., :, 0]
        axis = np.cross(before, d[..., j, :])
        sin, cos = np.linalg.norm(axis, axis=-1), np.sum(before * d[..., j, :], axis=-1)
        angle = np.arctan2(sin, cos)
        unit = np.divide(axis, sin[..., None], out=np.zeros_like(axis), where=sin[..., None] > 0)
        local = np.einsum("...ki,...k->...i", frame, unit * angle[..., None])  # in the frame: (0, turn_y, turn_z)
        turns[..., j, :] = local[..., 1:]
        frame = frame @ _rotation(local)
    return turns, lengths


def space_polyline(turns: FloatArray, lengths: FloatArray, start: FloatArray) -> FloatArray:
    """The polyline of chords with twist-free ``turns`` (about the frame's y and z) and ``lengths`` from ``start``.

    The inverse of :func:`space_elements`: shapes ``(..., m, 2)``, ``(..., m)`` and
    ``(..., 3)``; returns ``(..., m + 1, 3)``.
    """
    lengths = np.asarray(lengths, dtype=float)
    steps = lengths[..., None] * transported_frames(turns)[..., :, 0]  # each chord along its frame's x axis
    start = np.broadcast_to(np.asarray(start, dtype=float), (*lengths.shape[:-1], 3))
    return np.concatenate([start[..., None, :], start[..., None, :] + np.cumsum(steps, axis=-2)], axis=-2)


def transported_frames(turns: FloatArray) -> FloatArray:
    """Each chord's twist-free frame (columns: its axes; x along the chord) from :func:`space_elements`' turns.

    Shapes ``(..., m, 2)`` -> ``(..., m, 3, 3)``; the frame before the first chord is the actuator's own.

    >>> transported_frames(np.radians([[0.0, 90.0]]))[0].round(12).tolist()   # a quarter turn about z
    [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    turns = np.asarray(turns, dtype=float)
    frame = np.broadcast_to(np.eye(3), (*turns.shape[:-2], 3, 3)).copy()
    frames = []
    for j in range(turns.shape[-2]):
        local = np.concatenate([np.zeros((*turns.shape[:-2], 1)), turns[..., j, :]], axis=-1)
        frame = frame @ _rotation(local)
        frames.append(frame)
    return np.stack(frames, axis=-3)


def frame_elements(points: FloatArray, frames: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The chords in the frames of the units they start from, and each unit's frame in the one before.

    The roll these keep is what the twist-free elements lose (module docstring).

    Parameters
    ----------
    points : ndarray, shape (..., n + 2, 3)
        Base, the ``n`` unit centres, tip.
    frames : ndarray, shape (..., n, 3)
        Each unit's rotation vector (:attr:`~pneumorph.models.response.Response.frames`);
        the base's frame is the actuator's own.

    Returns
    -------
    chords : ndarray, shape (..., n + 1, 3)
        Chord ``j`` (from point ``j``) in the frame of point ``j`` (the base's, then unit ``j``'s).
    turns : ndarray, shape (..., n, 3)
        Unit ``j``'s frame in the frame of point ``j - 1``, as a rotation vector.

    Examples
    --------
    >>> import numpy as np
    >>> pts = np.array([[0, 0, 0], [10, 0, 0], [20, 1, 0], [30, 3, 0.0]])
    >>> fr = np.array([[0, 0, 0.05], [0, 0, 0.15]])    # two planar units turned about z
    >>> chords, turns = frame_elements(pts, fr)
    >>> turns.round(6).tolist()
    [[0.0, 0.0, 0.05], [0.0, 0.0, 0.1]]
    >>> bool(np.allclose(frame_polyline(chords, turns, pts[..., 0, :]), pts))
    True
    """
    points, frames = np.asarray(points, dtype=float), np.asarray(frames, dtype=float)
    eye = np.broadcast_to(np.eye(3), (*frames.shape[:-2], 1, 3, 3))
    m = np.concatenate([eye, _rotation(frames)], axis=-3)  # the base's frame, then each unit's
    chords = np.einsum("...ji,...j->...i", m, np.diff(points, axis=-2))
    relative = np.einsum("...ji,...jk->...ik", m[..., :-1, :, :], m[..., 1:, :, :])
    return chords, _rotvec(relative)


def frame_polyline(chords: FloatArray, turns: FloatArray, start: FloatArray) -> FloatArray:
    """The polyline of :func:`frame_elements`' ``chords`` and ``turns`` from ``start`` (its inverse).

    :func:`chain_points` with the base's frame (the actuator's own) before the units' turns.
    """
    return chain_points(chords, _rotation(_with_base(np.asarray(turns, dtype=float))), start)


def _with_base(turns: FloatArray) -> FloatArray:
    """The units' turns (..., n, 3) after the base's, which is none: (..., n + 1, 3), one per chord."""
    return np.concatenate([np.zeros_like(turns[..., :1, :]), turns], axis=-2)


#: the signs of a space element's six values (its chord in its frame, then its frame's turn as a rotation vector)
#: when every unit is turned over: the actuator turned half a turn about its axis (y and z change sign; a rotation
#: vector is turned as a vector)
MIRROR_SIGNS = np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])


def response_space_elements(response: Any) -> FloatArray:
    """The chain's elements in space of a full-width response, per level: shape (k, n + 1, 6).

    Element ``j`` (``j = 0 .. n``, the chord from point ``j``: the base, then unit ``j``'s
    centre) holds the chord in the frame of point ``j`` and the turn of that frame from the
    one before it (a rotation vector; zero for the base, whose frame is the actuator's own):
    :func:`frame_elements`, keyed by the same window as the planar chain's turn and length of
    chord ``j``. :func:`chain_points` composes them back.

    Raises
    ------
    ValueError
        A response without its units' frames (not of the full-width model).
    """
    if response.frames is None or response.reference_tip.shape != (3,):
        raise ValueError(f"design {response.orientation}: a chain in space needs the full 3D model's response "
                         "(points in space and each unit's frame)")
    points = np.stack([response.centreline(i) for i in range(response.n_levels)])  # (k, n + 2, 3)
    chords, turns = frame_elements(points, response.frames)
    return np.concatenate([chords, _with_base(turns)], axis=-1)


def space_rows(response: Any) -> list[FloatArray]:
    """A response's elements in space as one row per chord, the levels' six values side by side: ``[(n + 1, 6 k)]``.

    An empty list for a planar response (without its units' frames), so that a planar
    table's values stay as they were; turned over, they take :data:`MIRROR_SIGNS` per level.
    """
    if response.frames is None:
        return []
    e = response_space_elements(response)
    return [e.transpose(1, 0, 2).reshape(e.shape[1], -1)]


def end_turns(response: Any) -> FloatArray | None:
    """The end face's frame in the last unit's frame per level, as rotation vectors (k, 3); ``None`` without them.

    A full-width response keeps each unit's frame (:attr:`~pneumorph.models.response.Response.frames`)
    and the end face's (:attr:`~pneumorph.models.response.Response.end_frame`); the chain in space
    keys this turn by the last chord's window, as the planar chain its end turn, and composes
    the end face's frame from the last unit's (:meth:`~pneumorph.models.chain.table.ChainTable.end_frames`).
    Turned over, it takes the signs of :data:`MIRROR_SIGNS`' turn.

    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> r = SimpleNamespace(frames=np.array([[[0, 0, 0.1], [0, 0, 0.3]]]), end_frame=np.array([[0, 0, 0.4]]))
    >>> end_turns(r).round(12).tolist()
    [[0.0, 0.0, 0.1]]
    """
    frames, end = getattr(response, "frames", None), getattr(response, "end_frame", None)
    if frames is None or end is None or not np.shape(frames)[1]:
        return None
    last = _rotation(np.asarray(frames, dtype=float)[:, -1, :])
    return _rotvec(np.einsum("kji,kjl->kil", last, _rotation(np.asarray(end, dtype=float))))


def chain_points(chords: FloatArray, turns: FloatArray, start: FloatArray) -> FloatArray:
    """The polyline of the chain's elements in space from ``start``: the inverse of :func:`response_space_elements`.

    Parameters
    ----------
    chords : ndarray, shape (..., n + 1, 3)
        Each chord in the frame of the point it starts from.
    turns : ndarray, shape (..., n + 1, 3, 3)
        Each point's frame in the one before, as rotation matrices (the base's: its frame in the
        actuator's own).
    start : ndarray, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., n + 2, 3)

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.spatial.transform import Rotation
    >>> chords = np.array([[10.0, 0, 0], [10.0, 0, 0]])
    >>> quarter = Rotation.from_rotvec([[0, 0, 0], [0, np.pi / 2, 0]]).as_matrix()   # the second frame turned about y
    >>> chain_points(chords, quarter, np.zeros(3)).round(9).tolist()
    [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 0.0, -10.0]]
    """
    chords = np.asarray(chords, dtype=float)
    steps = np.einsum("...ij,...j->...i", chain_frames(turns), chords)
    start = np.broadcast_to(np.asarray(start, dtype=float), (*chords.shape[:-2], 3))
    return np.concatenate([start[..., None, :], start[..., None, :] + np.cumsum(steps, axis=-2)], axis=-2)


def chain_frames(turns: FloatArray) -> FloatArray:
    """Each point's frame in the actuator's (..., n + 1, 3, 3): the turns (..., n + 1, 3, 3) composed from the base.

    >>> from scipy.spatial.transform import Rotation
    >>> quarter = Rotation.from_rotvec([[0, 0, np.pi / 2]] * 2).as_matrix()
    >>> chain_frames(quarter)[-1].round(12).tolist()   # two quarter turns about z: a half turn
    [[-1.0, -0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    turns = np.asarray(turns, dtype=float)
    frames = np.empty_like(turns)
    frame = np.broadcast_to(np.eye(3), (*turns.shape[:-3], 3, 3))
    for j in range(turns.shape[-3]):
        frame = frames[..., j, :, :] = frame @ turns[..., j, :, :]
    return frames


def rotation_matrices(vectors: FloatArray) -> FloatArray:
    """Rotation matrices (..., 3, 3) of rotation vectors (..., 3)."""
    return _rotation(np.asarray(vectors, dtype=float))


def rotation_vectors(matrices: FloatArray) -> FloatArray:
    """Rotation vectors (..., 3) of rotation matrices (..., 3, 3): :func:`rotation_matrices`' inverse."""
    return _rotvec(np.asarray(matrices, dtype=float))


def angle_between(a: FloatArray, b: FloatArray) -> FloatArray:
    """The angle (rad) of the rotation from frame ``a`` to frame ``b``, both rotation vectors (..., 3).

    >>> float(angle_between(np.array([0, 0, 0.1]), np.array([0, 0, 0.4])).round(12))
    0.3
    """
    turn = np.swapaxes(_rotation(np.asarray(a, dtype=float)), -1, -2) @ _rotation(np.asarray(b, dtype=float))
    return np.asarray(np.linalg.norm(_rotvec(turn), axis=-1))


def _rotvec(matrix: FloatArray) -> FloatArray:
    """Rotation vectors of rotation matrices (..., 3, 3) -> (..., 3)."""
    from scipy.spatial.transform import Rotation  # (a third of a second to import: not on every command's path)

    return Rotation.from_matrix(matrix.reshape(-1, 3, 3)).as_rotvec().reshape(*matrix.shape[:-2], 3)


def _rotation(vector: FloatArray) -> FloatArray:
    """Rotation matrices of rotation vectors (..., 3) -> (..., 3, 3)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(vector.reshape(-1, 3)).as_matrix().reshape(*vector.shape[:-1], 3, 3)


__all__ = ["MIRROR_SIGNS", "angle_between", "chain_frames", "chain_points", "end_turns", "frame_elements",
           "frame_polyline", "response_space_elements", "rotation_matrices", "rotation_vectors", "space_elements",
           "space_polyline", "space_rows", "transported_frames"]

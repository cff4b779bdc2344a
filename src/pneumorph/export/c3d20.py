"""CalculiX's 20-node brick (C3D20) and FElupe's ``hexahedron20``: node order, faces, checks.

The natural coordinates of C3D20's nodes (:data:`C3D20_NATURAL`), its faces
(:data:`C3D20_FACES`) and edges (:data:`C3D20_EDGES`) as the CalculiX/Abaqus manuals list
them; the permutation from FElupe's element (:func:`c3d20_permutation`, derived, not
assumed), the check of every element of a deck (:func:`check_element_order`), and the
faces a cavity pressure acts on (:func:`cavity_faces`). :mod:`pneumorph.export.calculix`
writes the deck with them (and re-exports them).

Examples
--------
>>> len(C3D20_NATURAL), sorted(C3D20_FACES)
(20, [1, 2, 3, 4, 5, 6])
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import GeometryError

__all__ = [
    "C3D20_EDGES",
    "C3D20_FACES",
    "C3D20_NATURAL",
    "c3d20_permutation",
    "cavity_faces",
    "check_element_order",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Natural coordinates (xi, eta, zeta) of C3D20's nodes 1..20 (CalculiX/Abaqus manuals).
C3D20_NATURAL: tuple[tuple[float, float, float], ...] = (
    (-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
    (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1),
    (0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1),
    (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
    (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0),
)

#: C3D20's faces as (natural axis, side): face 1 is zeta = -1, ..., face 6 is xi = -1.
_FACE_PLANES = {1: (2, -1), 2: (2, 1), 3: (1, -1), 4: (0, 1), 5: (1, 1), 6: (0, -1)}

#: Nodes (0-based, C3D20 order) of each face, the manuals' listing: 1-2-3-4, 5-8-7-6,
#: 1-5-6-2, 2-6-7-3, 3-7-8-4, 4-8-5-1 and their midside nodes; checked against
#: :data:`C3D20_NATURAL` in the tests.
C3D20_FACES: dict[int, tuple[int, ...]] = {
    1: (0, 1, 2, 3, 8, 9, 10, 11),
    2: (4, 7, 6, 5, 15, 14, 13, 12),
    3: (0, 4, 5, 1, 16, 12, 17, 8),
    4: (1, 5, 6, 2, 17, 13, 18, 9),
    5: (2, 6, 7, 3, 18, 14, 19, 10),
    6: (3, 7, 4, 0, 19, 15, 16, 11),
}

#: The 12 edges as (corner, corner, midside), 0-based C3D20 numbering.
C3D20_EDGES: tuple[tuple[int, int, int], ...] = (
    (0, 1, 8), (1, 2, 9), (2, 3, 10), (3, 0, 11),
    (4, 5, 12), (5, 6, 13), (6, 7, 14), (7, 4, 15),
    (0, 4, 16), (1, 5, 17), (2, 6, 18), (3, 7, 19),
)

def c3d20_permutation() -> IntArray:
    """``perm`` with C3D20 node ``k`` (0-based) = FElupe ``hexahedron20`` node ``perm[k]``.

    Derived by matching the natural coordinates of FElupe's element to
    :data:`C3D20_NATURAL`; the two orders coincide, so this is ``0, 1, ..., 19``.

    Raises
    ------
    GeometryError
        If FElupe's element has nodes that C3D20 has not (a changed FElupe element).

    Examples
    --------
    >>> c3d20_permutation().tolist() == list(range(20))
    True
    """
    import felupe as fem

    felupe_points = np.asarray(fem.QuadraticHexahedron().points, dtype=float)
    natural = np.asarray(C3D20_NATURAL, dtype=float)
    d = np.abs(natural[:, None, :] - felupe_points[None, :, :]).sum(axis=-1)
    perm = np.argmin(d, axis=1)
    if not (np.allclose(d[np.arange(20), perm], 0.0) and len(set(perm.tolist())) == 20):
        raise GeometryError("FElupe's hexahedron20 nodes do not match C3D20's natural coordinates")
    return perm.astype(np.int64)


def _corner_jacobians(x: FloatArray) -> FloatArray:
    """det of dx/d(xi) of the trilinear corner map at each of the 8 corners, shape (c, 8)."""
    signs = np.asarray(C3D20_NATURAL[:8], dtype=float)  # (8, 3)
    dets = []
    for corner in signs:
        # derivatives of N_i = 1/8 prod(1 + s_i r) at r = corner
        dN = np.empty((8, 3))
        for a in range(3):
            others = [b for b in range(3) if b != a]
            dN[:, a] = signs[:, a] / 8 * np.prod(1 + signs[:, others] * corner[others], axis=1)
        jac = np.einsum("cid,ie->cde", x[:, :8], dN)
        dets.append(np.linalg.det(jac))
    return np.stack(dets, axis=1)


def check_element_order(points: FloatArray, cells: IntArray) -> None:
    """Check that ``cells`` are valid C3D20 (or C3D8) connectivities of straight-edged elements.

    Every element must have a positive Jacobian at each corner (CalculiX refuses a
    negative one) and, for 20 nodes, each midside node at the middle of the edge C3D20
    puts it on (:data:`C3D20_EDGES`).

    Parameters
    ----------
    points : ndarray, shape (p, 3)
    cells : ndarray, shape (c, 20) or (c, 8)
        0-based node indices in C3D20 order.

    Raises
    ------
    GeometryError
        Naming the first element (1-based, as in the deck) that fails.

    Examples
    --------
    >>> import numpy as np
    >>> pts = np.array(C3D20_NATURAL, dtype=float)
    >>> check_element_order(pts, np.arange(20)[None])
    >>> check_element_order(pts, np.arange(20)[None][:, [1, 0, *range(2, 20)]])
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: element 1: ...
    """
    x = np.asarray(points, dtype=float)[np.asarray(cells)]
    dets = _corner_jacobians(x)
    bad = np.flatnonzero((dets <= 0).any(axis=1))
    if bad.size:
        raise GeometryError(f"element {bad[0] + 1}: a non-positive Jacobian at a corner; the nodes are not "
                            "in C3D20 order (bottom face counter-clockwise seen from the top face)")
    if x.shape[1] == 20:
        size = np.ptp(x, axis=1).max(axis=1)
        for a, b, m in C3D20_EDGES:
            off = np.linalg.norm(x[:, m] - (x[:, a] + x[:, b]) / 2, axis=1)
            wrong = np.flatnonzero(off > 1e-9 * size)
            if wrong.size:
                raise GeometryError(f"element {wrong[0] + 1}: node {m + 1} is not the middle of the edge of "
                                    f"nodes {a + 1}-{b + 1}; the node order is not C3D20's")


def _face_nodes(n_nodes: int) -> dict[int, tuple[int, ...]]:
    return C3D20_FACES if n_nodes == 20 else {k: v[:4] for k, v in C3D20_FACES.items()}


def cavity_faces(cells: IntArray, cavity_points: NDArray[np.bool_]) -> tuple[IntArray, IntArray]:
    """The element faces the cavity pressure acts on: on the surface, all nodes on the cavity walls.

    The rule of pneumorph's pressure (FElupe's boundary region with the mask
    ``ActuatorMesh.cavity_points``): a face that belongs to one element only and whose
    nodes all lie on the cavity walls.

    Parameters
    ----------
    cells : ndarray, shape (c, 20) or (c, 8)
        Connectivity in C3D20 (C3D8) order.
    cavity_points : ndarray of bool, shape (p,)

    Returns
    -------
    elements : ndarray
        0-based element index of each loaded face.
    faces : ndarray
        Its C3D20 face number (1..6).

    Examples
    --------
    >>> import numpy as np
    >>> cells = np.arange(20)[None]
    >>> mask = np.zeros(20, bool); mask[list(C3D20_FACES[4])] = True
    >>> cavity_faces(cells, mask)
    (array([0]), array([4]))
    """
    cells = np.asarray(cells)
    table = _face_nodes(cells.shape[1])
    numbers = np.array(sorted(table))
    nodes = np.stack([cells[:, list(table[k])] for k in numbers], axis=1)  # (c, 6, m)
    flat = np.sort(nodes.reshape(-1, nodes.shape[-1]), axis=1)
    _, inverse, counts = np.unique(flat, axis=0, return_inverse=True, return_counts=True)
    on_surface = counts[inverse.ravel()] == 1
    on_wall = np.asarray(cavity_points, dtype=bool)[flat].all(axis=1)
    chosen = np.flatnonzero(on_surface & on_wall)
    return (chosen // len(numbers)).astype(np.int64), numbers[chosen % len(numbers)].astype(np.int64)

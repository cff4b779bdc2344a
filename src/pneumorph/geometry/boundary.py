"""The boundary of a meshed actuator: its outer surface (3D) or outline (2D), cavities apart.

Dimension-generic: a facet is an edge of a quad (2D) or a face of a hexahedron (3D), given
by its corner nodes; a boundary facet belongs to exactly one cell. The cavity walls are
boundary facets too (the 3D model has no cells in its cavities); :func:`outer_facets`
leaves them out, so what remains is what a scan or a photo of the actuator sees.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.geometry.assembly import ActuatorMesh

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]

#: Corner faces of a hexahedron (FElupe/VTK order), outward for a positive cell.
HEX_FACES = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
#: Corner edges of a quadrilateral, counter-clockwise.
QUAD_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0))


def boundary_facets(cells: IntArray, dim: int | None = None) -> tuple[IntArray, IntArray]:
    """Facets that belong to one cell only, and the cell each belongs to.

    Parameters
    ----------
    cells : ndarray, shape (c, 4 or 8 or more)
        Cells by their corner nodes first (quad4/quad8 or hex8/hex20).
    dim : {2, 3}, optional
        The cells' dimension. Eight nodes are a quad8 or a hex8; without ``dim`` they are
        taken as a hexahedron, so a 2D mesh of quad8 cells must say ``dim=2``.

    Returns
    -------
    facets : ndarray, shape (m, 2) or (m, 4)
        Corner nodes of the boundary edges (quads) or faces (hexahedra).
    owner : ndarray, shape (m,)
        The cell of each facet.

    Examples
    --------
    >>> two = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])  # two quads side by side
    >>> facets, owner = boundary_facets(two)
    >>> len(facets), sorted(owner.tolist())
    (6, [0, 0, 0, 1, 1, 1])
    >>> quad8 = np.array([[0, 1, 2, 3, 4, 5, 6, 7]])  # one quad8: its four edges, not a hexahedron's faces
    >>> boundary_facets(quad8, dim=2)[0].shape
    (4, 2)
    """
    cells = np.asarray(cells)
    hexahedra = dim == 3 if dim is not None else cells.shape[1] >= 8 and _is_hex(cells)
    local = HEX_FACES if hexahedra else QUAD_EDGES
    corners = cells[:, : (8 if local is HEX_FACES else 4)]
    facets = corners[:, np.array(local)].reshape(-1, len(local[0]))
    owner = np.repeat(np.arange(len(cells)), len(local))
    _, first, counts = np.unique(np.sort(facets, axis=1), axis=0, return_index=True, return_counts=True)
    keep = np.sort(first[counts == 1])
    return facets[keep], owner[keep]


def _is_hex(cells: IntArray) -> bool:
    return cells.shape[1] in (8, 20, 27)


def outer_facets(mesh: ActuatorMesh) -> tuple[IntArray, IntArray]:
    """Boundary facets of ``mesh`` without the cavity walls (and without a half model's mid-plane).

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> m = assemble(UnitSpec(element_size=3.0), "0", dim=2)
    >>> facets, _ = outer_facets(m)
    >>> bool(np.all(~m.cavity_points[facets].all(axis=1))), facets.shape[1]   # the edges of the section
    (True, 2)
    """
    cells = mesh.cells if mesh.dim == 3 else np.concatenate([mesh.cells[idx] for name, idx in mesh.regions.items()
                                                             if name != "filler"])
    facets, owner = boundary_facets(cells, mesh.dim)
    inner = mesh.cavity_points[facets].all(axis=1)
    if mesh.symmetry_points is not None:
        inner |= mesh.symmetry_points[facets].all(axis=1)
    return facets[~inner], owner[~inner]


def outline(mesh: ActuatorMesh) -> IntArray:
    """Node pairs of the actuator's outline in its bending plane, cavities left out.

    2D meshes: the outer edges of the section. 3D meshes: the outer edges of the section
    in the mid-plane (a half model's symmetry plane; a full model's nodes at mid-width).

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> edges = outline(assemble(UnitSpec(element_size=3.0), "0", dim=3, half=True))
    >>> edges.shape[1]
    2
    """
    if mesh.dim == 2:
        return outer_facets(mesh)[0]
    on_plane = mesh.symmetry_points
    if on_plane is None:
        on_plane = np.isclose(mesh.points[:, 2], mesh.spec.width / 2)
    corners = mesh.cells[:, :8]
    faces = corners[:, np.array(HEX_FACES)].reshape(-1, 4)
    quads = faces[on_plane[faces].all(axis=1)]
    quads = np.unique(np.sort(quads, axis=1), axis=0, return_index=True)[1]
    plane = faces[on_plane[faces].all(axis=1)][np.sort(quads)]
    edges, _ = boundary_facets(plane)
    return edges[~mesh.cavity_points[edges].all(axis=1)]


def mirrored_surface_points(mesh: ActuatorMesh, displacement: FloatArray | None = None) -> FloatArray:
    """The nodes of the outer surface (deformed by ``displacement``); a half model mirrored to the full width.

    The order depends on the mesh only, so the reference and a deformed call match point by point.

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> m = assemble(UnitSpec(element_size=3.0), "0", dim=3, half=True)
    >>> p = mirrored_surface_points(m)
    >>> float(p[:, 2].min()), float(p[:, 2].max())
    (0.0, 15.0)
    """
    x = mesh.points if displacement is None else mesh.points + displacement
    facets, _ = outer_facets(mesh)
    nodes = np.unique(facets)
    return _full_width(mesh, nodes, x[nodes], lambda z: mesh.spec.width - z)


def surface_normals(mesh: ActuatorMesh, displacement: FloatArray | None = None) -> FloatArray:
    """Unit normals at the points of :func:`mirrored_surface_points`, in the same order (3D meshes).

    Each outer face adds its area-weighted outward normal to its corners.

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> m = assemble(UnitSpec(element_size=3.0), "0", dim=3, half=True)
    >>> n = surface_normals(m)
    >>> n.shape == mirrored_surface_points(m).shape, bool(np.allclose(np.linalg.norm(n, axis=1), 1))
    (True, True)
    """
    x = mesh.points if displacement is None else mesh.points + displacement
    facets, owner = outer_facets(mesh)
    face = np.cross(x[facets[:, 2]] - x[facets[:, 0]], x[facets[:, 3]] - x[facets[:, 1]])
    outward = x[facets].mean(axis=1) - x[mesh.cells[owner, :8]].mean(axis=1)  # away from the owner cell
    face *= np.sign((face * outward).sum(axis=1))[:, None]
    nodes = np.unique(facets)
    total = np.zeros_like(x)
    for corner in range(4):
        np.add.at(total, facets[:, corner], face)
    normals = total[nodes]
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    return _full_width(mesh, nodes, normals, np.negative)


def _full_width(mesh: ActuatorMesh, nodes: IntArray, values: FloatArray, mirror_z: Any) -> FloatArray:
    """``values`` at ``nodes``, then, for a half model, at their mirror images (mid-plane nodes once).

    The one place that fixes the order of the full-width surface, so points and normals match.
    """
    if mesh.symmetry_points is None:
        return values
    mirror = values[~mesh.symmetry_points[nodes]].copy()
    mirror[:, 2] = mirror_z(mirror[:, 2])
    return np.vstack([values, mirror])


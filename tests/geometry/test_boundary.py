"""The 2D outline is made of the section's edges (quad8 cells are not hexahedra)."""

from __future__ import annotations

import numpy as np

from pneumorph.geometry.assembly import assemble
from pneumorph.geometry.boundary import outline
from pneumorph.geometry.unit import UnitSpec


def test_the_2d_outline_is_the_sections_boundary_edges() -> None:
    mesh = assemble(UnitSpec(element_size=3.0), "01", dim=2)
    edges = outline(mesh)
    assert edges.shape[1] == 2
    a, b = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
    # every edge runs along x or along y (a structured grid); the hexahedron reading gave diagonals
    assert np.all(np.isclose(a[:, 0], b[:, 0]) | np.isclose(a[:, 1], b[:, 1]))
    # a closed outline: every corner node ends two edges
    _, counts = np.unique(edges, return_counts=True)
    assert np.all(counts == 2)
    # its length is the section's perimeter (the cavities apart): 2 x length + 2 x height
    length = np.linalg.norm(b - a, axis=1).sum()
    height = float(mesh.points[:, 1].max() - mesh.points[:, 1].min())
    span = float(mesh.points[:, 0].max() - mesh.points[:, 0].min())
    assert length >= 2 * (span + height) - 1e-9

"""Assemble an actuator mesh from a unit and an orientation vector.

One structured grid whose lines fall on every interface of every unit in either
orientation; each cell is labelled (body, stiff layer, cavity, slit) from its unit's
section, mirrored for orientation 1; cavity cells become the filler of the 2D
reduced-order model (section 5.2) and are removed in 3D; slit cells are removed. The
linear grid is then made quadratic (quad8 in 2D, hex20 in 3D) so that all materials share
one set of points.

The result is plain data (:class:`ActuatorMesh`): the model builders turn it into FElupe
regions and fields.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import GeometryError
from pneumorph.geometry.features import BaseBlock, check_passage
from pneumorph.geometry.grid import grid_lines, section_breaks
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.geometry.unit import UnitSpec

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
FloatArray = NDArray[np.float64]

BODY, LAYER, CAVITY, SLIT, BASE, VOID = 0, 1, 2, 3, 4, 5


@dataclass(frozen=True)
class ActuatorMesh:
    """A meshed actuator: points, cells per region, and the nodes the results are read at.

    Attributes
    ----------
    points : ndarray, shape (p, dim)
        Coordinates (mm): x along the actuator, y across its height, z across its width.
    cells : ndarray, shape (c, 8) or (c, 20)
        Quadratic cells (``quad8`` in 2D, ``hexahedron20`` in 3D) in FElupe's ordering.
    cell_type : str
    regions : dict of str to ndarray
        Cell indices of ``"body"``, ``"layer"``, in 2D ``"filler"`` (the cavities), and
        ``"base"`` (the base block) if there is one.
    cavity_points : ndarray of bool, shape (p,)
        Points on the cavity walls, passages included (and, in 2D, inside the filler).
    tracked : ndarray, shape (n, 4)
        Per unit, the points at the cavity's four vertices (Fig 4.4; mid-width in 3D).
    end_points : ndarray
        Points of the free end face in the section plane, ordered by height.
    base_points : ndarray of bool, shape (p,)
        The clamped points: the base face x = 0, or the jaw faces of the base block.
    orientation : str
    spec : UnitSpec
    symmetry_points : ndarray of bool, shape (p,)
        3D half models: points on the mid-plane z = width / 2, where u_z = 0.
    """

    points: FloatArray
    cells: IntArray
    cell_type: str
    regions: dict[str, IntArray]
    cavity_points: BoolArray
    tracked: IntArray
    end_points: IntArray
    base_points: BoolArray
    orientation: str
    spec: UnitSpec
    symmetry_points: BoolArray | None = None

    @property
    def dim(self) -> int:
        return int(self.points.shape[1])

    @property
    def n_units(self) -> int:
        return len(self.orientation)

    @property
    def length(self) -> float:
        return self.n_units * self.spec.pitch + self.spec.end_cap

    def unit_centres(self, displacement: FloatArray | None = None) -> FloatArray:
        """Mean (x, y) of each unit's four tracked points, shape (n, 2)."""
        x = self.points if displacement is None else self.points + displacement
        return x[self.tracked][..., :2].mean(axis=1)

    def submesh(self, region: str) -> tuple[FloatArray, IntArray]:
        """Points (all of them, shared) and the cells of one region."""
        return self.points, self.cells[self.regions[region]]


def _label(spec: UnitSpec, orientation: str, centres: FloatArray, passage: float = 0.0,
           base: BaseBlock | None = None) -> IntArray:
    """Label of each linear cell from its centroid: BODY, LAYER, CAVITY, SLIT, BASE or VOID.

    ``passage`` is the side of the square channels between adjacent cavities (labelled
    CAVITY); cells outside the actuator's section (beside a base block with a margin) are VOID.
    """
    n, P, H = len(orientation), spec.pitch, spec.height
    unit = np.clip(np.floor(centres[:, 0] / P).astype(int), 0, n - 1)
    lx = centres[:, 0] - unit * P
    cap = centres[:, 0] > n * P  # the end cap: solid, body or layer by height
    flipped = np.array([c == "1" for c in orientation])[unit]
    ly = np.where(flipped, H - centres[:, 1], centres[:, 1])
    x0, x1, y0, y1 = spec.cavity
    cavity = (lx > x0) & (lx < x1) & (ly > y0) & (ly < y1) & ~cap
    if centres.shape[1] == 3:
        z = centres[:, 2]
        cavity &= (z > spec.side_wall) & (z < spec.width - spec.side_wall)
    label = np.where(ly > H - spec.layer, LAYER, BODY)
    label = np.where(cavity, CAVITY, label)
    if spec.slit is not None:
        sx0, _, _, sy1 = spec.slit
        label = np.where((lx > sx0) & (ly < sy1) & ~cap, SLIT, label)
    if passage > 0:  # the wall between cavity i and cavity i + 1, at mid-height and mid-width
        between = ((lx > x1) & (unit < n - 1)) | ((lx < x0) & (unit > 0))
        through = between & ~cap & (centres[:, 0] > 0) & (np.abs(centres[:, 1] - H / 2) < passage / 2)
        if centres.shape[1] == 3:
            through &= np.abs(centres[:, 2] - spec.width / 2) < passage / 2
        label = np.where(through, CAVITY, label)
    outside = (centres[:, 1] < 0) | (centres[:, 1] > H)
    if centres.shape[1] == 3:
        outside |= (centres[:, 2] < 0) | (centres[:, 2] > spec.width)
    label = np.where(outside, VOID, label)
    if base is not None:
        label = np.where(centres[:, 0] < 0, BASE, label)
    return label


def assemble(spec: UnitSpec, orientation: str, dim: int = 2, half: bool = False, passage: float = 0.0,
             base: BaseBlock | None = None) -> ActuatorMesh:
    """Mesh an actuator of ``len(orientation)`` units.

    Parameters
    ----------
    spec : UnitSpec
        The articulating unit.
    orientation : str
        The design, base first: one digit per unit, 1 = turned 180 degrees.
    dim : {2, 3}
        2 = plane-strain longitudinal section with filled cavities; 3 = solid with empty
        cavities.
    half : bool
        3D only: mesh the half 0 <= z <= width / 2; the model then holds u_z = 0 on the
        mid-plane (``symmetry_points``). The actuator is symmetric across its width, so this
        gives the same solution with half the unknowns.
    passage : float
        3D only: the diameter (mm) of an air passage through every wall between adjacent
        cavities (appendix D.1), meshed as a square channel of the same area at mid-height
        and mid-width (:func:`~pneumorph.geometry.features.check_passage`); 0 (default):
        closed cavities.
    base : BaseBlock, optional
        The base block (appendix D.2): a solid slab at ``-length <= x <= 0`` (region
        ``"base"``), clamped by its jaw faces instead of the face x = 0.

    Returns
    -------
    ActuatorMesh

    Examples
    --------
    >>> m = assemble(UnitSpec(), "01", dim=2)
    >>> m.cell_type, m.tracked.shape, sorted(m.regions)
    ('quad8', (2, 4), ['body', 'filler', 'layer'])
    >>> np.round(m.unit_centres(), 3).tolist()
    [[5.25, 4.5], [15.75, 7.5]]

    Raises
    ------
    GeometryError
        A bad ``dim`` or design, a passage in 2D or one that does not fit the walls.
    """
    import felupe as fem

    if dim not in (2, 3):
        raise GeometryError(f"dim must be 2 or 3, got {dim!r}")
    orientation = parse_orientation(orientation)
    if passage and dim != 3:
        raise GeometryError("a passage between cavities is a 3D feature: the 2D section would be cut in two")
    side = check_passage(spec, passage)
    n, P, H, W = len(orientation), spec.pitch, spec.height, spec.width
    h = spec.element_size
    xb_local, yb = section_breaks(spec)
    xb = [i * P + x for i in range(n) for x in xb_local] + [n * P + spec.end_cap]
    zb = [0.0, spec.side_wall, W / 2] if half else [0.0, spec.side_wall, W / 2, W - spec.side_wall, W]
    if side:
        yb += [H / 2 - side / 2, H / 2 + side / 2]
        zb += [W / 2 - side / 2] if half else [W / 2 - side / 2, W / 2 + side / 2]
    if base is not None:
        m = base.margin
        xb.append(-base.length)
        yb += [-m, H + m]
        zb += [-m] if half else [-m, W + m]
    xs, ys = grid_lines(xb, h), grid_lines(yb, h)
    grid = fem.Grid(xs, ys, grid_lines(zb, h)) if dim == 3 else fem.Grid(xs, ys)
    label = _label(spec, orientation, grid.points[grid.cells].mean(axis=1), side, base)
    solid = (label == BODY) | (label == LAYER) | (label == BASE)
    keep = solid | (label == CAVITY) if dim == 2 else solid
    cells, label = grid.cells[keep], label[keep]
    used = np.unique(cells)
    renumber = np.full(len(grid.points), -1)
    renumber[used] = np.arange(len(used))
    linear = fem.Mesh(grid.points[used], renumber[cells], grid.cell_type)
    mesh = linear.add_midpoints_edges() if spec.element_order == 2 else linear
    points = np.asarray(mesh.points, dtype=float)
    regions = {"body": np.flatnonzero(label == BODY), "layer": np.flatnonzero(label == LAYER)}
    if dim == 2:
        regions["filler"] = np.flatnonzero(label == CAVITY)
    if base is not None:
        regions["base"] = np.flatnonzero(label == BASE)

    tol = 1e-6
    x0, x1, y0, y1 = spec.cavity
    cavity_points = np.zeros(len(points), dtype=bool)
    tracked = np.zeros((n, 4), dtype=np.int64)
    for i, o in enumerate(orientation):
        cy0, cy1 = (y0, y1) if o == "0" else (H - y1, H - y0)
        inside = (
            (points[:, 0] > i * P + x0 - tol)
            & (points[:, 0] < i * P + x1 + tol)
            & (points[:, 1] > cy0 - tol)
            & (points[:, 1] < cy1 + tol)
        )
        if dim == 3:
            inside &= (points[:, 2] > spec.side_wall - tol) & (points[:, 2] < W - spec.side_wall + tol)
        cavity_points |= inside
        corners = [(i * P + x0, cy0), (i * P + x1, cy0), (i * P + x1, cy1), (i * P + x0, cy1)]
        for k, (cx, cy) in enumerate(corners):
            d = (points[:, 0] - cx) ** 2 + (points[:, 1] - cy) ** 2
            if dim == 3:
                d = d + (points[:, 2] - W / 2) ** 2
            tracked[i, k] = int(np.argmin(d))
            if d[tracked[i, k]] > tol**2:  # pragma: no cover - the grid has these lines
                raise GeometryError(f"no mesh point at cavity vertex {k} of unit {i}")
    if side:  # the passages' walls are loaded by the pressure too
        for i in range(n - 1):
            inside = ((points[:, 0] > i * P + x1 - tol) & (points[:, 0] < (i + 1) * P + x0 + tol)
                      & (np.abs(points[:, 1] - H / 2) < side / 2 + tol))
            if dim == 3:
                inside &= np.abs(points[:, 2] - W / 2) < side / 2 + tol
            cavity_points |= inside
    if base is None:
        clamped = np.isclose(points[:, 0], 0.0)
    else:  # the jaws of the clamp hold the block's bottom and top faces
        jaws = np.isclose(points[:, 1], -base.margin) | np.isclose(points[:, 1], H + base.margin)
        clamped = jaws & (points[:, 0] < tol)
    on_end = np.isclose(points[:, 0], n * P + spec.end_cap)
    if dim == 3:
        on_end &= np.isclose(points[:, 2], W / 2)
    end_points = np.flatnonzero(on_end)
    end_points = end_points[np.argsort(points[end_points, 1])]
    return ActuatorMesh(
        points=points,
        cells=np.asarray(mesh.cells, dtype=np.int64),
        cell_type=mesh.cell_type,
        regions=regions,
        cavity_points=cavity_points,
        tracked=tracked,
        end_points=end_points,
        base_points=clamped,
        orientation=orientation,
        spec=spec,
        symmetry_points=np.isclose(points[:, 2], W / 2) if (dim == 3 and half) else None,
    )


__all__ = ["BASE", "BODY", "CAVITY", "LAYER", "SLIT", "VOID", "ActuatorMesh", "assemble", "grid_lines"]

"""Assemble an actuator mesh from a unit (or a unit library) and a design.

One structured grid whose lines fall on every interface of every unit in either
orientation; each cell is labelled (body, stiff layer, cavity, slit) from its unit's
section, mirrored for orientation 1; the units of a mixed design (a design over a
:class:`~pneumorph.geometry.library.UnitLibrary`) follow each other with their own pitch
and section, on the cross-section lines that all units of a library share, so the mesh
conforms at every interface; cavity cells become the filler of the 2D
reduced-order model (section 5.2) and are removed in 3D; slit cells are removed. The
linear grid is then made quadratic (quad8 in 2D, hex20 in 3D) so that all materials share
one set of points.

The result is plain data (:class:`ActuatorMesh`): the model builders turn it into FElupe
regions and fields. Its named point sets (cavity walls, tracked vertices, clamped points, end
face) are found by :mod:`pneumorph.geometry.nodesets`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import GeometryError
from pneumorph.geometry.alphabet import Design, library_design
from pneumorph.geometry.features import BaseBlock, check_passage
from pneumorph.geometry.grid import grid_lines, section_breaks, width_breaks
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.nodesets import cavity_box as cavity_box
from pneumorph.geometry.nodesets import cavity_points, clamped_points, end_face_points, tracked_points
from pneumorph.geometry.unit import UnitSpec

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
FloatArray = NDArray[np.float64]

BODY, LAYER, CAVITY, SLIT, BASE, VOID = 0, 1, 2, 3, 4, 5
#: The bottom walls of another material (:attr:`UnitSpec.bottom_material`): ``BOTTOM + i`` for
#: the i-th of :func:`bottom_materials`, in region ``"bottom:<material>"``.
BOTTOM = 6


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
        Cell indices of ``"body"``, ``"layer"``, ``"bottom:<material>"`` for each bottom-wall
        material of the library (:func:`bottom_materials`), in 2D ``"filler"`` (the cavities),
        and ``"base"`` (the base block) if there is one.
    cavity_points : ndarray of bool, shape (p,)
        Points on the cavity walls, passages included (and, in 2D, inside the filler).
    tracked : ndarray, shape (n, 4)
        Per unit, the points at the cavity's four vertices (Fig 4.4; mid-width in 3D).
    end_points : ndarray
        Points of the free end face in the section plane, ordered by height.
    base_points : ndarray of bool, shape (p,)
        The clamped points: the base face x = 0, or the jaw faces of the base block.
    orientation : str
        ``0``/``1`` per unit, base first.
    spec : UnitSpec
        The unit (of a mixed design: the library's first unit, whose cross-section,
        width, height and element size all its units share).
    symmetry_points : ndarray of bool, shape (p,)
        3D half models: points on the mid-plane z = width / 2, where u_z = 0.
    units : tuple of UnitSpec
        The unit of every unit, base first (empty: every unit is ``spec``).
    design : str
        The design's canonical text (:mod:`pneumorph.geometry.alphabet`): the 0/1 string
        for one unit type, else the library's symbols (empty: ``orientation``).
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
    units: tuple[UnitSpec, ...] = ()
    design: str = ""

    @property
    def dim(self) -> int:
        return int(self.points.shape[1])

    @property
    def n_units(self) -> int:
        return len(self.orientation)

    @property
    def unit_specs(self) -> tuple[UnitSpec, ...]:
        """The unit of every unit, base first."""
        return self.units or (self.spec,) * self.n_units

    @property
    def unit_bounds(self) -> FloatArray:
        """Where each unit starts along the actuator, and where the last one ends: shape (n + 1,).

        >>> assemble(UnitSpec(), "01").unit_bounds.tolist()
        [0.0, 10.5, 21.0]
        """
        return unit_starts(self.unit_specs)

    @property
    def length(self) -> float:
        return float(self.unit_bounds[-1]) + self.spec.end_cap

    @property
    def axes(self) -> int:
        """The coordinates a response of this mesh keeps: 3 (x, y, z) for a 3D mesh of the full width, else 2.

        A half model holds its unit centres and tip on the mid-plane (u_z = 0 there), a 2D
        section has no z; the full width lets a sideways unit move them out of the plane.

        >>> assemble(UnitSpec(), "01", dim=3, half=True).axes, assemble(UnitSpec(), "01", dim=3).axes
        (2, 3)
        """
        return 3 if self.dim == 3 and self.symmetry_points is None else 2

    def unit_centres(self, displacement: FloatArray | None = None, axes: int = 2) -> FloatArray:
        """Mean of each unit's four tracked points: (x, y), shape (n, 2), or with ``axes=3`` (x, y, z)."""
        x = self.points if displacement is None else self.points + displacement
        return x[self.tracked][..., :axes].mean(axis=1)

    def submesh(self, region: str) -> tuple[FloatArray, IntArray]:
        """Points (all of them, shared) and the cells of one region."""
        return self.points, self.cells[self.regions[region]]


def unit_starts(units: Sequence[UnitSpec]) -> FloatArray:
    """Where each unit starts along the actuator, and where the last one ends (mm).

    Exact sums (``math.fsum``): for units of one pitch ``P`` they are ``i * P`` to the last bit.

    >>> unit_starts([UnitSpec(), UnitSpec(pitch=7.0, end_wall=1.5), UnitSpec()]).tolist()
    [0.0, 10.5, 17.5, 28.0]
    """
    pitches = [u.pitch for u in units]
    return np.array([math.fsum(pitches[:i]) for i in range(len(pitches) + 1)], dtype=float)


def bottom_materials(units: Iterable[UnitSpec]) -> tuple[str, ...]:
    """The materials of the units' bottom walls other than the body's, sorted: one region each.

    >>> bottom_materials([UnitSpec(), UnitSpec(bottom_material="smooth_sil_950")])
    ('smooth_sil_950',)
    """
    return tuple(sorted({u.bottom_material for u in units if u.bottom_material}))


def _label(units: Sequence[UnitSpec], orientation: str, starts: FloatArray, centres: FloatArray,
           passage: float = 0.0, base: BaseBlock | None = None, bottoms: Sequence[str] = ()) -> IntArray:
    """Label of each linear cell from its centroid: BODY, LAYER, CAVITY, SLIT, BASE, VOID or BOTTOM + i.

    Each cell belongs to the unit whose span holds its centroid (the end cap: to no unit,
    solid); ``units`` share height and width. ``passage`` is the side of the square channels
    between adjacent cavities (labelled CAVITY); cells outside the actuator's section (beside
    a base block with a margin) are VOID. The bottom wall of a unit with a ``bottom_material``
    (the i-th of ``bottoms``) is BOTTOM + i.
    """
    n, ref = len(orientation), units[0]
    H, W = ref.height, ref.width

    def per_unit(values: Iterable[float]) -> FloatArray:
        return np.asarray(list(values))

    cx = centres[:, 0]
    unit = np.searchsorted(starts[1:n], cx, side="right")  # 0 .. n - 1; the base block and the cap clip
    lx = cx - starts[unit]
    cap = cx > starts[n]  # the end cap: solid, body or layer by height
    flipped = np.array([c == "1" for c in orientation])[unit]
    ly = np.where(flipped, H - centres[:, 1], centres[:, 1])
    box = per_unit(c for u in units for c in u.cavity).reshape(n, 4)[unit]
    x0, x1, y0, y1 = box.T
    filled = np.array([u.solid for u in units], dtype=bool)[unit]
    cavity = (lx > x0) & (lx < x1) & (ly > y0) & (ly < y1) & ~cap & ~filled
    label = np.where(ly > H - per_unit(u.top_layer for u in units)[unit], LAYER, BODY)
    if centres.shape[1] == 3:  # across the width, turned over too (z -> W - z): a sideways unit's layer
        lz = np.where(flipped, W - centres[:, 2], centres[:, 2])
        z0, z1 = per_unit(c for u in units for c in u.cavity_z).reshape(n, 2)[unit].T
        cavity &= (lz > z0) & (lz < z1)
        label = np.where(lz > W - per_unit(u.side_layer for u in units)[unit], LAYER, label)
    if bottoms:  # the wall under the cavity, the unit's whole length and width, of its own material
        which = per_unit(bottoms.index(u.bottom_material) if u.bottom_material else -1 for u in units)[unit]
        wall = per_unit(u.wall for u in units)[unit]
        label = np.where((which >= 0) & (label == BODY) & (ly < wall) & ~cap, BOTTOM + which, label)
    label = np.where(cavity, CAVITY, label)
    if any(u.slit is not None for u in units):
        slit = np.array([u.slit is not None for u in units], dtype=bool)[unit]
        sx0 = per_unit(u.pitch - u.slit_width for u in units)[unit]
        sy1 = per_unit(u.slit_depth for u in units)[unit]
        label = np.where(slit & (lx > sx0) & (ly < sy1) & ~cap, SLIT, label)
    if passage > 0:  # the wall between cavity i and cavity i + 1, at mid-height and mid-width
        between = ((lx > x1) & (unit < n - 1)) | ((lx < x0) & (unit > 0))
        through = between & ~cap & (cx > 0) & (np.abs(centres[:, 1] - H / 2) < passage / 2)
        if centres.shape[1] == 3:
            through &= np.abs(centres[:, 2] - W / 2) < passage / 2
        label = np.where(through, CAVITY, label)
    outside = (centres[:, 1] < 0) | (centres[:, 1] > H)
    if centres.shape[1] == 3:
        outside |= (centres[:, 2] < 0) | (centres[:, 2] > W)
    label = np.where(outside, VOID, label)
    if base is not None:
        label = np.where(cx < 0, BASE, label)
    return label


def assemble(spec: UnitSpec | UnitLibrary, orientation: str | Design | Iterable[int], dim: int = 2,
             half: bool = False, passage: float = 0.0, base: BaseBlock | None = None) -> ActuatorMesh:
    """Mesh an actuator of ``len(orientation)`` units.

    Parameters
    ----------
    spec : UnitSpec or UnitLibrary
        The articulating unit, or a library of unit types for a mixed design.
    orientation : str or Design
        The design, base first: one digit per unit, 1 = turned 180 degrees; over a library
        also its symbols, upper case = turned (:func:`~pneumorph.geometry.alphabet.parse_design`).
    dim : {2, 3}
        2 = plane-strain longitudinal section with filled cavities; 3 = solid with empty
        cavities.
    half : bool
        3D only: mesh the half 0 <= z <= width / 2; the model then holds u_z = 0 on the
        mid-plane (``symmetry_points``): the same solution with half the unknowns for planar
        units; a design with a sideways unit (``layer_side``) has no such symmetry.
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

    A mixed design over the built-in library: a bending unit turned over, a short one,
    a near-rigid one (no filler in it):

    >>> from pneumorph.geometry.library import builtin_library
    >>> m = assemble(builtin_library(), "Asr", dim=2)
    >>> m.design, m.orientation, m.unit_bounds.tolist(), m.length
    ('Asr', '100', [0.0, 10.5, 17.5, 28.0], 28.0)

    Raises
    ------
    GeometryError
        A bad ``dim`` or design, a passage in 2D or one that does not fit the walls (or
        meets a solid unit), a sideways unit (``layer_side``) in 2D or in a half model.
    OrientationError
        A design that is not one over ``spec``'s symbols (0/1 for one unit).
    """
    if dim not in (2, 3):
        raise GeometryError(f"dim must be 2 or 3, got {dim!r}")
    library, design = library_design(spec, orientation)
    orientation = design.orientation
    if passage and dim != 3:
        raise GeometryError("a passage between cavities is a 3D feature: the 2D section would be cut in two")
    units = design.units(library)
    _check_sideways(units, design.text, dim, half)
    ref = library[library.default]  # the cross-section, mesh size and end cap all units share
    side = _passage_side(units, passage)
    starts = unit_starts(units)
    grid, bottoms = _grid(library, units, starts, dim, half, side, base), bottom_materials(library.units)
    label = _label(units, orientation, starts, grid.points[grid.cells].mean(axis=1), side, base, bottoms)
    mesh, label = _kept_cells(grid, label, dim, ref.element_order)
    points = np.asarray(mesh.points, dtype=float)
    return ActuatorMesh(
        points=points, cells=np.asarray(mesh.cells, dtype=np.int64), cell_type=mesh.cell_type,
        regions=_regions(label, dim, base, bottoms),
        cavity_points=cavity_points(points, ref, units, orientation, starts, dim, side),
        tracked=tracked_points(points, ref, units, orientation, starts, dim),
        end_points=end_face_points(points, ref, starts, dim), base_points=clamped_points(points, ref.height, base),
        orientation=orientation, spec=ref, units=units, design=design.text,
        symmetry_points=np.isclose(points[:, 2], ref.width / 2) if (dim == 3 and half) else None,
    )


def _check_sideways(units: Sequence[UnitSpec], text: str, dim: int, half: bool) -> None:
    """Refuse a sideways unit (``layer_side``) in a 2D section or a half model: it bends out of their plane.

    Raises
    ------
    GeometryError
        Naming the design and what to mesh instead.
    """
    if not any(u.layer_side for u in units):
        return
    if dim == 2:
        raise GeometryError(f"design {text!r} has a sideways unit (layer_side): it bends out of the 2D section's "
                            "plane; mesh it in 3D")
    if half:
        raise GeometryError(f"design {text!r} has a sideways unit (layer_side): it is not symmetric across the width; "
                            "mesh the full width (half=False)")


def _passage_side(units: Sequence[UnitSpec], passage: float) -> float:
    """The side (mm) of the square channel of a passage of diameter ``passage`` (0: none), checked in every unit.

    Raises
    ------
    GeometryError
        The passage does not fit a unit's walls, or meets a solid unit.
    """
    side = 0.0
    for unit in dict.fromkeys(units):
        side = check_passage(unit, passage)
    return side


def _grid(library: UnitLibrary, units: Sequence[UnitSpec], starts: FloatArray, dim: int, half: bool, side: float,
          base: BaseBlock | None) -> Any:
    """The structured linear grid (FElupe's ``Grid``) with a line on every interface.

    Parameters
    ----------
    library : UnitLibrary
        Its units' section lines cross every unit (the mesh conforms at every interface).
    units : sequence of UnitSpec
        The design's units, base first, starting at ``starts`` (:func:`unit_starts`).
    dim : {2, 3}
    half : bool
        3D: the half width only.
    side : float
        The side of the square passages between cavities (0: none).
    base : BaseBlock, optional
        The base block's lines (behind x = 0, and its margin).
    """
    import felupe as fem

    ref = library[library.default]
    n, H, W = len(units), ref.height, ref.width
    h = ref.element_size
    xb = [float(starts[i]) + x for i, unit in enumerate(units) for x in section_breaks(unit)[0]]
    xb.append(float(starts[n]) + ref.end_cap)
    yb = [y for unit in library.units for y in section_breaks(unit)[1]]
    zb = [z for unit in library.units for z in width_breaks(unit, half)]
    if side:
        yb += [H / 2 - side / 2, H / 2 + side / 2]
        zb += [W / 2 - side / 2] if half else [W / 2 - side / 2, W / 2 + side / 2]
    if base is not None:
        m = base.margin
        xb.append(-base.length)
        yb += [-m, H + m]
        zb += [-m] if half else [-m, W + m]
    xs, ys = grid_lines(xb, h), grid_lines(yb, h)
    return fem.Grid(xs, ys, grid_lines(zb, h)) if dim == 3 else fem.Grid(xs, ys)


def _kept_cells(grid: Any, label: IntArray, dim: int, order: int) -> tuple[Any, IntArray]:
    """The grid's cells of the actuator (a 2D section keeps its cavities) as a mesh of ``order``, and their labels.

    Points no kept cell uses are dropped; ``order`` 2 adds the midpoints of the edges
    (quad8, hex20).
    """
    import felupe as fem

    solid = (label == BODY) | (label == LAYER) | (label == BASE) | (label >= BOTTOM)
    keep = solid | (label == CAVITY) if dim == 2 else solid
    cells, label = grid.cells[keep], label[keep]
    used = np.unique(cells)
    renumber = np.full(len(grid.points), -1)
    renumber[used] = np.arange(len(used))
    linear = fem.Mesh(grid.points[used], renumber[cells], grid.cell_type)
    return (linear.add_midpoints_edges() if order == 2 else linear), label


def _regions(label: IntArray, dim: int, base: BaseBlock | None, bottoms: Sequence[str] = ()) -> dict[str, IntArray]:
    """The cells of each material region: body, layer, the bottom walls, the 2D filler, the base block.

    A bottom material of the library has its region even where the design has no unit of it
    (empty), so that every design of one library has the same regions.
    """
    regions = {"body": np.flatnonzero(label == BODY), "layer": np.flatnonzero(label == LAYER)}
    for i, material in enumerate(bottoms):
        regions[f"bottom:{material}"] = np.flatnonzero(label == BOTTOM + i)
    if dim == 2:
        regions["filler"] = np.flatnonzero(label == CAVITY)
    if base is not None:
        regions["base"] = np.flatnonzero(label == BASE)
    return regions


__all__ = ["BASE", "BODY", "BOTTOM", "CAVITY", "LAYER", "SLIT", "VOID", "ActuatorMesh", "assemble", "bottom_materials",
           "cavity_box", "grid_lines", "unit_starts"]

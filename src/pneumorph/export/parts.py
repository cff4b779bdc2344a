"""Watertight triangle meshes of an actuator's parts, for printing, CAD and the moulds.

An actuator of ``n`` units (:func:`pneumorph.geometry.assembly.assemble`) is made of three
kinds of part, all in the actuator's frame and in mm (x along the actuator from the clamped
base face x = 0, y across its height, z across its width):

``body``
    The Mold Star 15 body: the box ``length x height x width`` (``length = n pitch +
    end_cap``) minus the stiff layer's pieces, minus every unit's cavity (a closed internal
    void, ``side_wall`` short of both sides), minus the slits. A unit as built (``"0"``)
    has its layer on top (``height - layer <= y <= height``); a unit turned 180 degrees
    (``"1"``) has it at the bottom (``0 <= y <= layer``) and its cavity mirrored, so the
    body of a mixed design is a staggered bar.
``layer_1``, ``layer_2``, ...
    The Smooth-Sil 950 strip cut into pieces, base first: one piece per run of units with
    the same orientation (the whole strip, cut to the actuator's length, when all units face
    the same way), each ``layer`` thick and ``width`` wide; the last piece also covers the
    end cap. :func:`layer_pieces` lists their cut lengths and sides.
``base_block``
    A solid silicone slab glued to the clamped base face, through which the syringe is
    pushed into the first cavity (section 6.4.2: the thick slab keeps the air from escaping
    through the insertion). Its size is :class:`BaseBlock`'s; it is not part of the model,
    which clamps the face x = 0.

These are the regions of :func:`~pneumorph.geometry.assembly.assemble` (``"body"`` and
``"layer"``; the 3D mesh drops the cavity and slit cells): the tests check that the union
of the 3D mesh's body cells is this body, boolean for boolean.

The 1.5 mm holes punched between adjacent units after casting (section 6.4.1) are not in
the body: the model has closed cavities, and they are a step of the casting
(``docs/manufacturing.md``).

How the solids are built
    Every part is a union or difference of axis-aligned boxes whose corners are the unit's
    own dimensions, so the parts are built as exact boxes combined by manifold3d's booleans
    (:func:`box`, then one batch subtraction). The result is exact: its vertices are the
    boxes' corners (no meshing, no tessellation error), its volume is the analytic volume
    to rounding (about 1e-12 relative), it does not depend on the element size, it has a
    few hundred triangles instead of the hex mesh's tens of thousands, and manifold3d
    guarantees a closed, oriented 2-manifold even where faces of the cut boxes coincide.
    The alternative, the boundary faces of the hex20 mesh's regions, is exact too but ties
    the part to the mesh (element size, felupe) and needs its own stitching of the
    quadrilaterals into triangles and a separate watertightness repair for the layer
    pieces, which share nodes with the body.

STEP
    Not written. STEP is a boundary representation that needs a CAD kernel (OpenCASCADE,
    through CadQuery or build123d: a native wheel of about 100 MB, not available for
    every Python and platform the package supports); trimesh and manifold3d write meshes
    only. STL carries the same information for these parts, which are made of planar
    faces, and every CAD program imports it (as a mesh body, or converted to a solid).

Examples
--------
>>> from pneumorph.geometry.unit import UnitSpec
>>> parts = actuator_parts(UnitSpec(), "0110")
>>> sorted(parts)
['base_block', 'body', 'layer_1', 'layer_2', 'layer_3']
>>> all(m.is_watertight and m.is_volume for m in parts.values())
True
>>> float(parts["body"].volume), float(parts["layer_2"].volume)   # mm^3, exact
(4374.0, 945.0)
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pneumorph.errors import GeometryError, interrupts_kept
from pneumorph.geometry.features import BaseBlock, Box
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.geometry.unit import UnitSpec

if TYPE_CHECKING:  # pragma: no cover
    import manifold3d
    import trimesh

__all__ = [
    "BaseBlock",
    "LayerPiece",
    "actuator_parts",
    "actuator_solids",
    "box",
    "check_materials",
    "layer_pieces",
    "outline_solid",
    "to_manifold",
    "to_trimesh",
    "write_stl",
]

#: the base block the parts get unless told otherwise (frozen: safe as a default)
DEFAULT_BLOCK = BaseBlock()

# The 12 outward triangles of a box whose 8 corners are numbered by bits (x, y, z).
_BOX_FACES = np.array(
    [
        [0, 6, 2], [0, 4, 6],  # x = x0
        [1, 7, 5], [1, 3, 7],  # x = x1
        [0, 5, 4], [0, 1, 5],  # y = y0
        [2, 7, 3], [2, 6, 7],  # y = y1
        [0, 3, 1], [0, 2, 3],  # z = z0
        [4, 7, 6], [4, 5, 7],  # z = z1
    ],
    dtype=np.uint64,
)


@dataclass(frozen=True)
class LayerPiece:
    """One piece of the Smooth-Sil strip: a run of units facing the same way.

    Attributes
    ----------
    first, last : int
        The first and last unit it covers (0-based, base first, inclusive).
    side : {"top", "bottom"}
        ``"top"``: ``height - layer <= y <= height`` (units as built, ``"0"``);
        ``"bottom"``: ``0 <= y <= layer`` (units turned, ``"1"``).
    x0, x1 : float
        Its extent along the actuator, mm (the last piece includes the end cap).
    """

    first: int
    last: int
    side: str
    x0: float
    x1: float

    @property
    def length(self) -> float:
        """The length to cut from the strip, mm."""
        return self.x1 - self.x0

    def box(self, spec: UnitSpec) -> Box:
        """The piece ``(x0, x1, y0, y1, z0, z1)`` in the actuator's frame."""
        y0, y1 = (spec.height - spec.layer, spec.height) if self.side == "top" else (0.0, spec.layer)
        return (self.x0, self.x1, y0, y1, 0.0, spec.width)


def layer_pieces(spec: UnitSpec, orientation: str) -> list[LayerPiece]:
    """The pieces the Smooth-Sil strip is cut into, base first.

    Consecutive units with the same orientation share one piece: their layers lie on the
    same side, end to end. A design whose units all face the same way has one piece, the
    strip cut to the actuator's length.

    Parameters
    ----------
    spec : UnitSpec
    orientation : str
        The design, base first (``"0"`` layer on top, ``"1"`` at the bottom).

    Returns
    -------
    list of LayerPiece

    Examples
    --------
    >>> [(p.first, p.last, p.side, p.length) for p in layer_pieces(UnitSpec(), "00111")]
    [(0, 1, 'top', 21.0), (2, 4, 'bottom', 31.5)]
    >>> layer_pieces(UnitSpec(end_cap=2.0), "0")[0].length
    12.5
    >>> layer_pieces(UnitSpec(wall=3.0, layer=0.0), "01")   # no stiff layer: no pieces
    []
    """
    orientation = parse_orientation(orientation)
    n, P = len(orientation), spec.pitch
    pieces: list[LayerPiece] = []
    if spec.layer == 0:  # a unit without a stiff layer (an extending unit): no strip to cut
        return pieces
    start = 0
    for i in range(1, n + 1):
        if i == n or orientation[i] != orientation[start]:
            x1 = i * P + (spec.end_cap if i == n else 0.0)
            side = "top" if orientation[start] == "0" else "bottom"
            pieces.append(LayerPiece(first=start, last=i - 1, side=side, x0=start * P, x1=x1))
            start = i
    return pieces


def _cavity_boxes(spec: UnitSpec, orientation: str) -> list[Box]:
    """Each unit's cavity in the actuator's frame (mirrored in y for orientation 1); none for a solid unit
    (``solid = true``: its cavity is filled with the body material)."""
    if spec.solid:
        return []
    x0, x1, y0, y1 = spec.cavity
    H, W, P = spec.height, spec.width, spec.pitch
    out = []
    for i, o in enumerate(orientation):
        cy0, cy1 = (y0, y1) if o == "0" else (H - y1, H - y0)
        out.append((i * P + x0, i * P + x1, cy0, cy1, spec.side_wall, W - spec.side_wall))
    return out


def box(bounds: Iterable[float]) -> manifold3d.Manifold:
    """An axis-aligned box as a manifold3d solid whose corners are exactly ``bounds``.

    Parameters
    ----------
    bounds : (x0, x1, y0, y1, z0, z1)
        mm; ``x0 < x1`` and so on.

    Returns
    -------
    manifold3d.Manifold

    Examples
    --------
    >>> box((0.0, 1.0, 0.0, 2.0, 0.0, 0.5)).volume()
    1.0
    """
    x0, x1, y0, y1, z0, z1 = (float(b) for b in bounds)
    if not (x0 < x1 and y0 < y1 and z0 < z1):
        raise GeometryError(f"an empty box: x {x0:g}..{x1:g}, y {y0:g}..{y1:g}, z {z0:g}..{z1:g} mm")
    corners = np.array([[(x0, x1)[k & 1], (y0, y1)[(k >> 1) & 1], (z0, z1)[(k >> 2) & 1]] for k in range(8)])
    return to_manifold(corners, _BOX_FACES)


def to_manifold(vertices: np.ndarray, faces: np.ndarray) -> manifold3d.Manifold:
    """A manifold3d solid from a closed, outward-oriented triangle mesh.

    Raises
    ------
    GeometryError
        The triangles do not close an oriented volume.

    Examples
    --------
    >>> m = actuator_parts(UnitSpec(), "0")["body"]
    >>> round(to_manifold(m.vertices, m.faces).volume(), 6)
    1093.5
    """
    import manifold3d as m3

    v = np.array(np.asarray(vertices), dtype=np.float64, order="C")  # a plain array, not a subclass
    f = np.array(np.asarray(faces), dtype=np.uint64, order="C")
    if hasattr(m3, "Mesh64"):
        solid = m3.Manifold(m3.Mesh64(vert_properties=v, tri_verts=f))
    else:  # pragma: no cover - manifold3d < 3: single precision meshes
        solid = m3.Manifold(m3.Mesh(vert_properties=v.astype(np.float32), tri_verts=f.astype(np.uint32)))
    if solid.status() != m3.Error.NoError:
        raise GeometryError(f"the triangles do not close a volume (manifold3d: {solid.status()})")
    return solid


def to_trimesh(solid: manifold3d.Manifold) -> trimesh.Trimesh:
    """The triangle mesh of a manifold3d solid (shared vertices, outward normals).

    Examples
    --------
    >>> to_trimesh(box((0.0, 1.0, 0.0, 1.0, 0.0, 1.0))).is_watertight
    True
    """
    with interrupts_kept():  # trimesh swallows a Ctrl-C in its optional imports
        import trimesh

    mesh = solid.to_mesh64() if hasattr(solid, "to_mesh64") else solid.to_mesh()
    vertices = np.asarray(mesh.vert_properties, dtype=np.float64)[:, :3]
    faces = np.asarray(mesh.tri_verts, dtype=np.int64)
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


def outline_solid(spec: UnitSpec, orientation: str, z0: float, z1: float) -> manifold3d.Manifold:
    """The body without its cavities between two planes z = ``z0`` and z = ``z1``.

    The body's longitudinal section (the box minus the layer pieces and the slits),
    extruded across the width: what a mould's walls enclose.

    Examples
    --------
    >>> round(outline_solid(UnitSpec(), "01", 0.0, 15.0).volume(), 6)   # 2 x 10.5 x 9 x 15
    2835.0
    """
    import manifold3d as m3

    orientation = parse_orientation(orientation)
    n, P, H = len(orientation), spec.pitch, spec.height
    L = n * P + spec.end_cap
    out = 1.0  # cutters reach past the outer faces, so no cut face coincides with one
    cutters = []
    for piece in layer_pieces(spec, orientation):
        _, _, y0, y1, _, _ = piece.box(spec)
        ya, yb = (y0, H + out) if piece.side == "top" else (-out, y1)
        xa = -out if piece.first == 0 else piece.x0
        xb = L + out if piece.last == n - 1 else piece.x1
        cutters.append(box((xa, xb, ya, yb, z0 - out, z1 + out)))
    if spec.slit is not None:
        sx0, sx1, _, sy1 = spec.slit
        for i, o in enumerate(orientation):
            ya, yb = (-out, sy1) if o == "0" else (H - sy1, H + out)
            xb = i * P + sx1 if (i < n - 1 or spec.end_cap > 0) else L + out
            cutters.append(box((i * P + sx0, xb, ya, yb, z0 - out, z1 + out)))
    return m3.Manifold.batch_boolean([box((0.0, L, 0.0, H, z0, z1)), *cutters], m3.OpType.Subtract)


def check_materials(spec: UnitSpec, base_block: BaseBlock | None = DEFAULT_BLOCK) -> None:
    """Refuse parts of a material the material library does not know (the body's, the layer's, the block's).

    Raises
    ------
    UnknownMaterialError
        Naming the material and listing the known ones.

    Examples
    --------
    >>> check_materials(UnitSpec())
    >>> check_materials(UnitSpec(body_material="nonesuch"))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.errors.UnknownMaterialError: unknown material 'nonesuch'; known materials: ...
    """
    from pneumorph.materials.library import get

    for name in (spec.body_material, *([spec.layer_material] if spec.layer > 0 else []),
                 *([base_block.material] if base_block is not None else [])):
        get(name)


def check_buildable(spec: UnitSpec) -> None:
    """Refuse a unit whose parts these builders cannot make: a sideways unit (``layer_side``), whose stiff strip
    lies on a side face (the parts, strips and moulds here put it on the top or bottom face), and a unit with a
    bottom wall of another material (``bottom_material``).

    >>> check_buildable(UnitSpec(layer_side=True))
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: the parts and moulds of a sideways unit (layer_side: its stiff strip on a side
    face) are not built yet; export a planar unit
    """
    if spec.layer_side:
        raise GeometryError("the parts and moulds of a sideways unit (layer_side: its stiff strip on a side face) "
                            "are not built yet; export a planar unit")
    if spec.bottom_material:
        raise GeometryError(f"the parts and moulds of a unit with a bottom wall of {spec.bottom_material} "
                            "(bottom_material) are not built yet; export a unit of one body material")


def actuator_solids(
    spec: UnitSpec, orientation: str, base_block: BaseBlock | None = DEFAULT_BLOCK
) -> dict[str, manifold3d.Manifold]:
    """The actuator's parts as manifold3d solids (see :func:`actuator_parts`).

    Raises
    ------
    UnknownMaterialError
        A part of a material the library does not know (:func:`check_materials`).
    GeometryError
        A unit these builders cannot make (:func:`check_buildable`).
    """
    import manifold3d as m3

    check_buildable(spec)
    check_materials(spec, base_block)
    orientation = parse_orientation(orientation)
    cavities = [box(b) for b in _cavity_boxes(spec, orientation)]
    body = m3.Manifold.batch_boolean([outline_solid(spec, orientation, 0.0, spec.width), *cavities],
                                     m3.OpType.Subtract)
    solids = {"body": body}
    pieces = layer_pieces(spec, orientation)
    digits = len(str(len(pieces)))
    for k, piece in enumerate(pieces, start=1):
        solids[f"layer_{k:0{digits}d}"] = box(piece.box(spec))
    if base_block is not None:
        solids["base_block"] = box(base_block.box(spec))
    return solids


def actuator_parts(
    spec: UnitSpec, orientation: str, base_block: BaseBlock | None = DEFAULT_BLOCK
) -> dict[str, trimesh.Trimesh]:
    """Watertight meshes of the body, the layer pieces and the base block.

    Parameters
    ----------
    spec : UnitSpec
        The articulating unit.
    orientation : str
        The design, base first (e.g. ``"001111010001001"``).
    base_block : BaseBlock or None
        The block at the base (None: no block).

    Returns
    -------
    dict of str to trimesh.Trimesh
        ``"body"``, ``"layer_1"``... (zero-padded when there are ten or more, base first;
        :func:`layer_pieces` gives their sides and lengths) and ``"base_block"``, in the
        actuator's frame, mm. Each mesh is watertight with outward normals.

    Raises
    ------
    OrientationError
        A design that is not a string of 0/1.

    Examples
    --------
    >>> parts = actuator_parts(UnitSpec(), "001111010001001")
    >>> len(parts), float(parts["body"].volume)   # 15 x (10.5 x 9 x 15 - 4.5 x 6 x 12)
    (10, 16402.5)
    """
    return {name: to_trimesh(solid) for name, solid in actuator_solids(spec, orientation, base_block).items()}


def write_stl(parts: Mapping[str, trimesh.Trimesh], folder: str | Path) -> list[Path]:
    """Write one binary STL per part, ``<folder>/<name>.stl``, each atomically.

    STL has no units: the coordinates are mm. The folder is created if needed.

    Parameters
    ----------
    parts : mapping of str to trimesh.Trimesh
        E.g. :func:`actuator_parts`'s result.
    folder : str or Path

    Returns
    -------
    list of Path
        The files written, in the order of ``parts``.

    Raises
    ------
    GeometryError
        A part name that is not a plain file name.
    OutputPathError
        The folder cannot be created or written.

    Examples
    --------
    >>> import tempfile, trimesh
    >>> paths = write_stl(actuator_parts(UnitSpec(), "01"), tempfile.mkdtemp())
    >>> [p.name for p in paths]
    ['body.stl', 'layer_1.stl', 'layer_2.stl', 'base_block.stl']
    >>> round(float(trimesh.load_mesh(paths[0]).volume), 3)
    2187.0
    """
    from pneumorph.io.files import atomic_write_bytes, check_writable_dir

    folder = check_writable_dir(folder, "STL folder")
    for name in parts:
        if not name or Path(name).name != name or name in (".", ".."):
            raise GeometryError(f"part name {name!r} is not a plain file name")
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, mesh in parts.items():
        data = mesh.export(file_type="stl")
        assert isinstance(data, bytes)  # binary STL
        written.append(atomic_write_bytes(folder / f"{name}.stl", data))
    return written

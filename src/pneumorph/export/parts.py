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
    end cap. :func:`~pneumorph.export.strips.layer_pieces` lists their cut lengths and
    faces. Over a unit library (a mixed design) a sideways unit's piece lies on a side face.
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
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pneumorph.errors import GeometryError, interrupts_kept
from pneumorph.export.strips import LayerPiece, layer_pieces
from pneumorph.geometry.alphabet import Design, library_design
from pneumorph.geometry.assembly import cavity_box, unit_starts
from pneumorph.geometry.features import BaseBlock, Box
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.limits import check_manufacturable
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


def cavity_boxes(spec: UnitSpec | UnitLibrary, design: str | Design) -> list[Box]:
    """Each unit's cavity in the actuator's frame (turned over as the unit is); none for a solid unit
    (``solid = true``: its cavity is filled with the body material)."""
    library, units, orientation = _units(spec, design)
    starts, H = unit_starts(units), library[library.default].height
    return [cavity_box(u, o, float(starts[i]), H)
            for i, (u, o) in enumerate(zip(units, orientation, strict=True)) if not u.solid]


def _units(spec: UnitSpec | UnitLibrary, design: str | Design) -> tuple[UnitLibrary, tuple[UnitSpec, ...], str]:
    """The library, every unit's type and the orientation of a design (0/1 for one unit)."""
    library, parsed = library_design(spec, design)
    return library, parsed.units(library), parsed.orientation


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


def outline_solid(spec: UnitSpec | UnitLibrary, design: str | Design, z0: float, z1: float,
                  keep: tuple[str, ...] = ()) -> manifold3d.Manifold:
    """The body without its cavities between two planes z = ``z0`` and z = ``z1``.

    The bar minus the layer pieces and the slits; for planar units, the body's longitudinal
    section extruded across the width: what a mould's walls enclose. ``keep``: the faces whose
    strips are not cut out (``"left"``, ``"right"``: the sideways units' footprint across the
    width, as a mould's plinth or its side sheet sees it).

    Examples
    --------
    >>> round(outline_solid(UnitSpec(), "01", 0.0, 15.0).volume(), 6)   # 2 x 10.5 x 9 x 15
    2835.0
    """
    import manifold3d as m3

    library, units, orientation = _units(spec, design)
    ref = library[library.default]
    starts, H = unit_starts(units), ref.height
    n, L = len(units), float(starts[-1]) + ref.end_cap
    out = 1.0  # cutters reach past the outer faces, so no cut face coincides with one
    cutters = [box(p.cutter(ref, n, z0, z1, out)) for p in layer_pieces(library, design) if p.side not in keep]
    for i, (u, o) in enumerate(zip(units, orientation, strict=True)):
        if u.slit is not None:
            sx0, sx1, _, sy1 = u.slit
            ya, yb = (-out, sy1) if o == "0" else (H - sy1, H + out)
            xb = float(starts[i]) + sx1 if (i < n - 1 or ref.end_cap > 0) else L + out
            cutters.append(box((float(starts[i]) + sx0, xb, ya, yb, z0 - out, z1 + out)))
    return m3.Manifold.batch_boolean([box((0.0, L, 0.0, H, z0, z1)), *cutters], m3.OpType.Subtract)


def check_materials(spec: UnitSpec | UnitLibrary, base_block: BaseBlock | None = DEFAULT_BLOCK,
                    design: str | Design | None = None) -> None:
    """Refuse parts of a material the material library does not know (the body's, the layer's, the block's).

    Over a library, of every type (or of those ``design`` uses).

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
    from pneumorph.materials.library.builtin import get

    for unit in _types(spec, design):
        for name in (unit.body_material, *([unit.layer_material] if unit.layer > 0 else [])):
            get(name)
    if base_block is not None:
        get(base_block.material)


def check_buildable(spec: UnitSpec | UnitLibrary, design: str | Design | None = None) -> None:
    """Refuse a unit whose parts these builders cannot make: one a mould cannot cast
    (:func:`~pneumorph.geometry.limits.check_manufacturable`: a wall, layer, cavity or slit too thin, a unit
    too large), or one with a bottom wall of another material (``bottom_material``). Over a library, every
    type (or those ``design`` uses).

    >>> check_buildable(UnitSpec(bottom_material="smooth_sil_950"))
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: the parts and moulds of a unit with a bottom wall of smooth_sil_950
    (bottom_material) are not built yet; export a unit of one body material
    """
    for unit in _types(spec, design):
        check_manufacturable(unit, f"unit {unit.name!r}:" if unit.name != "unit" else "unit")
        if unit.bottom_material:
            raise GeometryError(f"the parts and moulds of a unit with a bottom wall of {unit.bottom_material} "
                                "(bottom_material) are not built yet; export a unit of one body material")


def _types(spec: UnitSpec | UnitLibrary, design: str | Design | None) -> tuple[UnitSpec, ...]:
    """The unit types of ``spec`` (a library's: all, or those ``design`` uses)."""
    if isinstance(spec, UnitSpec):
        return (spec,)
    return spec.units if design is None else tuple(dict.fromkeys(_units(spec, design)[1]))


def actuator_solids(
    spec: UnitSpec | UnitLibrary, design: str | Design, base_block: BaseBlock | None = DEFAULT_BLOCK
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

    library, _, _ = _units(spec, design)  # the design checked first
    check_buildable(library, design)
    check_materials(library, base_block, design)
    ref = library[library.default]  # the section all units share
    cavities = [box(b) for b in cavity_boxes(library, design)]
    body = m3.Manifold.batch_boolean([outline_solid(library, design, 0.0, ref.width), *cavities],
                                     m3.OpType.Subtract)
    solids = {"body": body}
    pieces = layer_pieces(library, design)
    digits = len(str(len(pieces)))
    for k, piece in enumerate(pieces, start=1):
        solids[f"layer_{k:0{digits}d}"] = box(piece.box(ref))
    if base_block is not None:
        solids["base_block"] = box(base_block.box(ref))
    return solids


def actuator_parts(
    spec: UnitSpec | UnitLibrary, design: str | Design, base_block: BaseBlock | None = DEFAULT_BLOCK
) -> dict[str, trimesh.Trimesh]:
    """Watertight meshes of the body, the layer pieces and the base block.

    Parameters
    ----------
    spec : UnitSpec or UnitLibrary
        The articulating unit, or a library of unit types (they share the section).
    design : str
        The design, base first (e.g. ``"001111010001001"``; over a library its symbols).
    base_block : BaseBlock or None
        The block at the base (None: no block).

    Returns
    -------
    dict of str to trimesh.Trimesh
        ``"body"``, ``"layer_1"``... (zero-padded when there are ten or more, base first;
        :func:`~pneumorph.export.strips.layer_pieces` gives their faces and lengths) and
        ``"base_block"``, in the actuator's frame, mm. Each mesh is watertight with outward
        normals.

    Raises
    ------
    OrientationError
        A design that is not one over the unit's (0/1) or the library's symbols.

    Examples
    --------
    >>> parts = actuator_parts(UnitSpec(), "001111010001001")
    >>> len(parts), float(parts["body"].volume)   # 15 x (10.5 x 9 x 15 - 4.5 x 6 x 12)
    (10, 16402.5)

    A sideways unit's strip lies on a side face:

    >>> from pneumorph.geometry.library import builtin_library
    >>> parts = actuator_parts(builtin_library("spatial"), "alL")
    >>> sorted(parts), float(parts["layer_2"].volume)   # 10.5 x 12 x 3
    (['base_block', 'body', 'layer_1', 'layer_2', 'layer_3'], 378.0)
    """
    return {name: to_trimesh(solid) for name, solid in actuator_solids(spec, design, base_block).items()}


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

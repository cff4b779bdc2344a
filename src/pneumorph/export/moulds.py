"""The casting mould of the Mold Star body, as printable parts that are checked to fit.

How the body is cast
    The body's cavities are closed voids, and a rigid core cannot be pulled out of a closed
    void. The body is therefore cast in two pieces in one pour, as Pneu-nets are, and glued
    together with Sil-Poxy (the dissertation glues its sections the same way, section
    6.4.1):

    ``open_body``
        The body above the plane z = ``side_wall`` (its thickness ``width - side_wall``):
        every cavity opens through that face, where a core stood.
    ``side_sheet``
        The rest, the ``side_wall`` thick slab of the body's outline, which closes the
        cavities when glued on. Before gluing, the 1.5 mm holes between adjacent units
        (section 6.4.1) are punched through the end walls from the open side.

    Glued back in place the two pieces are the body exactly (:class:`MouldCheck`
    ``reassembly_error``). The mould lies on its side: z (the actuator's width) is up, the
    pull direction, and every part is in the actuator's frame (mm), so the mould's pocket
    is the body itself, not a copy of it.

The parts (:func:`casting_mould`)
    ``base_plate``
        ``plate`` thick, under everything; its top is the cavities' open face (z =
        ``side_wall``). It holds a square pocket for each core's tenon and a blind hole
        for each pin.
    ``side_walls``
        One frame from the base plate to the lid, ``wall`` wide around the pockets: the
        body's pocket (its outline, staggered where the units turn, with the layer pieces
        and the slits as walls) through its full height, and beside it a ``side_wall`` deep
        blind pocket for the side sheet, so that both pieces fill from the same pour and
        are pressed flat by the same lid. It lifts off upwards: the pocket is a prism along
        z, so it has no undercut.
    ``core_01``, ``core_02``, ...
        One per cavity, its exact box (or, with a draft, tapered towards its tip) standing
        on a square tenon that drops into the base plate's pocket.
    ``lid``
        The plate that closes the open end (section 6.4.1: the mould is overfilled and a
        plate pressed on forces the excess out; the pressed face is the flattest). It has
        the pour opening, a ``pour_diameter`` hole over the first unit, and a
        ``vent_diameter`` hole over the last unit, for each pocket: pour through one,
        the air and the excess leave through the other.
    ``pin_1`` ... ``pin_4``
        Alignment pins (3 mm dowels by default) at the corners, through the side walls
        into blind holes of the base plate and of the lid.

Clearance and draft
    ``clearance`` is the gap between mating printed parts only: pins in their holes
    (radially and at both ends) and the core tenons in their pockets. The faces that touch
    the silicone are exact (no clearance), so the cast is the body and nothing else: the
    tenon is set back from the core's root face by more than the clearance, so the gap
    around it is closed off by the core and cannot fill. ``draft`` tapers the cores, the
    only parts pulled out of cured silicone that grips them on four sides: the root is the
    exact cavity and each side face leans in by ``draft`` degrees towards the tip, so a
    drafted cavity is smaller than designed (:class:`MouldCheck` ``cavity_volume_change``);
    the outline walls are not drafted (the soft Mold Star 15 strips from straight walls,
    and a draft there would change the walls the model was designed with; Appendix E:
    0.1 mm matters). The default draft is 0: the cast is the designed body exactly.

The checks (:class:`MouldCheck`, run by :func:`casting_mould`)
    - every part is one closed, oriented volume (watertight);
    - no two parts overlap: every pairwise intersection volume is below the tolerance;
    - the mould's empty space inside its outer box is the cast (the open body and the
      side sheet in their pockets), plus the pour and vent openings, plus the clearance
      gaps around the pins and tenons, boolean for boolean; the gaps do not touch the cast
      (minimum distance > 0), so no silicone reaches them;
    - the two cast pieces glued back together are the body (draft 0) or the body with the
      drafted cavities.

Examples
--------
>>> from pneumorph.geometry.unit import UnitSpec
>>> mould = casting_mould(UnitSpec(), "01")
>>> sorted(mould.parts)
['base_plate', 'core_1', 'core_2', 'lid', 'pin_1', 'pin_2', 'pin_3', 'pin_4', 'side_walls']
>>> c = mould.check
>>> c.max_overlap < 1e-6, c.cavity_error < 1e-6, c.reassembly_error < 1e-6, c.gap_distance > 0.1
(True, True, True, True)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from pneumorph.errors import GeometryError
from pneumorph.export.mouldlayout import UnitCasting, unit_castings
from pneumorph.export.mouldparts import CUTTER_OVERRUN, Mould, MouldCheck, MouldSpec, check_fit, hole_centres
from pneumorph.export.parts import (
    actuator_solids,
    box,
    cavity_boxes,
    check_buildable,
    outline_solid,
    to_trimesh,
)
from pneumorph.geometry.alphabet import Design, library_design
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec

if TYPE_CHECKING:  # pragma: no cover
    import manifold3d

__all__ = ["Mould", "MouldCheck", "MouldSpec", "casting_mould"]


def _cylinder(cx: float, cy: float, z0: float, z1: float, radius: float, segments: int) -> manifold3d.Manifold:
    import manifold3d as m3

    return m3.Manifold.cylinder(z1 - z0, radius, -1.0, segments).translate((cx, cy, z0))


def _core(cavity: tuple[float, ...], tip_inset: float, tenon_inset: float, tenon_depth: float) -> manifold3d.Manifold:
    """The core of one cavity: the cavity (tapered by ``tip_inset`` at its tip) on a tenon."""
    import manifold3d as m3

    x0, x1, y0, y1, z0, z1 = cavity
    if tip_inset > 0:
        d = tip_inset
        points = [(x, y, z0) for x in (x0, x1) for y in (y0, y1)]
        points += [(x, y, z1) for x in (x0 + d, x1 - d) for y in (y0 + d, y1 - d)]
        body = m3.Manifold.hull_points(np.array(points, dtype=float))
    else:
        body = box(cavity)
    t = tenon_inset
    tenon = box((x0 + t, x1 - t, y0 + t, y1 - t, z0 - tenon_depth, z0 + (z1 - z0) / 2))
    return body + tenon


def casting_mould(spec: UnitSpec | UnitLibrary, orientation: str | Design, mould: MouldSpec | None = None,
                  check: bool = True) -> Mould:
    """Build the casting mould of the body and check that its parts fit.

    Parameters
    ----------
    spec : UnitSpec or UnitLibrary
        The articulating unit, or a library of unit types (a mixed design; a sideways unit
        turned over stands on a plinth: :mod:`pneumorph.export.mouldlayout`).
    orientation : str or Design
        The design, base first (0/1, or over the library's symbols), or the design as parsed
        (:func:`~pneumorph.geometry.alphabet.parse_design`).
    mould : MouldSpec, optional
        Clearance, draft and sizes (default :class:`MouldSpec`'s).
    check : bool
        Measure the assembly (:class:`MouldCheck`) and refuse a mould that fails; False
        skips the booleans (the ``check`` field is then all NaN).

    Returns
    -------
    Mould

    Raises
    ------
    GeometryError
        Settings that do not fit the unit (a clearance as wide as the tenon's setback, a
        draft that eats the cores, holes that do not fit on a unit's face), or a mould that
        fails a check: overlapping parts, a part that is not watertight, an empty space
        that is not the cast.

    Examples
    --------
    >>> m = casting_mould(UnitSpec(), "0", MouldSpec(draft=1.0))
    >>> round(m.check.cavity_volume_change, 2)   # mm^3: the drafted core leaves more silicone
    25.69
    >>> casting_mould(UnitSpec(), "0", MouldSpec(clearance=1.2, wall=8.0))
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: mould clearance 1.2 mm is not smaller than the core tenon's setback 1.125
    mm (a quarter of the cavity's smaller side, 4.5 mm): silicone would run into the tenon pockets
    """
    mould = MouldSpec() if mould is None else mould
    library, parsed = library_design(spec, orientation)
    spec = library if not library.is_single else library[library.default]
    check_buildable(spec, parsed)
    inset, tip = check_fit(spec, parsed, mould)  # the same checks as MouldSpec.check
    holes = hole_centres(spec, parsed, mould)
    castings = unit_castings(spec, parsed)
    ref = library[library.default]
    n = len(castings)
    s, W, H = ref.side_wall, ref.width, ref.height
    L = castings[-1].x1
    w, t = mould.wall, mould.plate
    dy = H + w  # the side sheet's pocket beside the body's, in y
    sheet_offset = (0.0, dy, W - s)
    Y = 2 * H + w  # both pockets
    outer = (-w, L + w, -w, Y + w, s - t, W + t)
    cores, pockets = _cores(spec, parsed, mould, inset, tip)
    pins, pin_holes = _pins(mould, L, Y, s, W)
    hole_cutters, openings = _holes(holes, mould, dy, W, outer[5])
    plate = _plate(outer, s, [box((c.x0, c.x1, 0.0, H, s, c.split)) for c in castings if c.plinth])
    solids = _plates(spec, parsed, outer, dy, pockets, pin_holes, hole_cutters, plate)
    digits = len(str(n))
    solids.update({f"core_{k:0{digits}d}": core for k, core in enumerate(cores, start=1)})
    solids.update({f"pin_{k}": pin for k, pin in enumerate(pins, start=1)})
    cast, opening, in_place = _cast(spec, parsed, cores, sheet_offset, openings, castings)
    result = (_checked(spec, parsed, solids, cast, opening, [pins, pin_holes, pockets, cores], plate,
                       in_place, outer) if check else _unchecked())
    return Mould(parts={name: to_trimesh(solid) for name, solid in solids.items()},
                 cast={name: to_trimesh(solid) for name, solid in cast.items()}, openings=to_trimesh(opening),
                 sheet_offset=sheet_offset, explode=_explode(solids, W + t), outer=outer, check=result, spec=mould,
                 unit=spec, orientation=parsed.text if not library.is_single else parsed.orientation)


def _cores(spec: UnitSpec | UnitLibrary, orientation: str | Design, mould: MouldSpec, inset: list[float],
           tip: list[float]) -> tuple[list[manifold3d.Manifold], list[manifold3d.Manifold]]:
    """The cores (exact cavities on tenons) and the tenons' pockets in the base plate (or its plinths).

    Parameters
    ----------
    inset, tip : list of float
        Per cavity: the tenon's setback from its sides and the core tip's inset (:func:`check_fit`).
    """
    c, td = mould.clearance, mould.tenon_depth
    cavities = cavity_boxes(spec, orientation)
    cores = [_core(cav, tp, i, td) for cav, tp, i in zip(cavities, tip, inset, strict=True)]
    # each core's root is its cavity's open face: the side wall's, or a plinth's top
    pockets = [box((a + i - c, b - i + c, p + i - c, q - i + c, z - td - c, z + CUTTER_OVERRUN))
               for (a, b, p, q, z, _), i in zip(cavities, inset, strict=True)]
    return cores, pockets


def _pins(mould: MouldSpec, L: float, Y: float, s: float,
          W: float) -> tuple[list[manifold3d.Manifold], list[manifold3d.Manifold]]:
    """The alignment pins at the corners of a mould ``L`` by ``Y`` inside, and their holes through walls and plates."""
    w, c, seg = mould.wall, mould.clearance, mould.segments
    r = mould.pin_diameter / 2
    pin_xy = [(x, y) for x in (-w / 2, L + w / 2) for y in (-w / 2, Y + w / 2)]
    pins = [_cylinder(x, y, s - mould.pin_depth, W + mould.pin_depth, r, seg) for x, y in pin_xy]
    pin_holes = [_cylinder(x, y, s - mould.pin_depth - c, W + mould.pin_depth + c, r + c, seg) for x, y in pin_xy]
    return pins, pin_holes


def _holes(holes: list[tuple[str, float, float, float]], mould: MouldSpec, dy: float, W: float,
           top: float) -> tuple[list[manifold3d.Manifold], list[manifold3d.Manifold]]:
    """The pour and vent holes through the lid (from ``W`` to ``top``) over both pockets: cutters and openings."""
    hole_cutters, openings = [], []
    for _, x, y, radius in holes:
        for oy in (0.0, dy):
            hole_cutters.append(_cylinder(x, y + oy, W - CUTTER_OVERRUN, top + CUTTER_OVERRUN, radius, mould.segments))
            openings.append(_cylinder(x, y + oy, W, top, radius, mould.segments))
    return hole_cutters, openings


def _plate(outer: tuple[float, ...], top: float, plinths: list[manifold3d.Manifold]) -> manifold3d.Manifold:
    """The base plate before its pockets and pin holes: the mould's footprint up to z = ``top`` (the side wall's
    face) and the ``plinths`` on it (under turned-over sideways units, :mod:`pneumorph.export.mouldlayout`)."""
    import manifold3d as m3

    X0, X1, Y0, Y1, Z0, _ = outer
    plate = box((X0, X1, Y0, Y1, Z0, top))
    return m3.Manifold.batch_boolean([plate, *plinths], m3.OpType.Add) if plinths else plate


def _plates(spec: UnitSpec | UnitLibrary, orientation: str | Design, outer: tuple[float, ...], dy: float,
            pockets: list[manifold3d.Manifold], pin_holes: list[manifold3d.Manifold],
            hole_cutters: list[manifold3d.Manifold], plate: manifold3d.Manifold) -> dict[str, manifold3d.Manifold]:
    """The base plate (``plate``, :func:`_plate`, less the tenon pockets), the side walls (the body's and the sheet's
    pockets) and the lid (holes)."""
    import manifold3d as m3

    ref = _section(spec)
    s, W = ref.side_wall, ref.width
    X0, X1, Y0, Y1, _, Z1 = outer
    # the body's pocket over the plinths too (their strips are cast elsewhere); the side sheet's across every unit
    body_pocket = outline_solid(spec, orientation, s - CUTTER_OVERRUN, W + CUTTER_OVERRUN, keep=("left",))
    sheet_pocket = outline_solid(spec, orientation, W - s, W + CUTTER_OVERRUN,
                                 keep=("left", "right")).translate((0.0, dy, 0.0))
    return {
        "base_plate": m3.Manifold.batch_boolean([plate, *pockets, *pin_holes], m3.OpType.Subtract),
        "side_walls": m3.Manifold.batch_boolean([box((X0, X1, Y0, Y1, s, W)), body_pocket, sheet_pocket,
                                                 *pin_holes], m3.OpType.Subtract),
        "lid": m3.Manifold.batch_boolean([box((X0, X1, Y0, Y1, W, Z1)), *hole_cutters, *pin_holes],
                                         m3.OpType.Subtract),
    }


def _cast(spec: UnitSpec | UnitLibrary, orientation: str | Design, cores: list[manifold3d.Manifold],
          sheet_offset: tuple[float, ...], openings: list[manifold3d.Manifold],
          castings: list[UnitCasting]) -> tuple[dict[str, manifold3d.Manifold], manifold3d.Manifold, Any]:
    """What is cast: the open body (around the cores) and the side sheet at its pocket; the holes' openings; the
    sheet's pieces in their places on the body (each at its unit's depth, :mod:`pneumorph.export.mouldlayout`)."""
    import manifold3d as m3

    ref = _section(spec)
    s, W, H = ref.side_wall, ref.width, ref.height
    sheet = outline_solid(spec, orientation, 0.0, s, keep=("left", "right"))
    raised = [c for c in castings if c.bottom > 0]
    in_place, above = sheet, [outline_solid(spec, orientation, s, W), *cores]
    if raised:  # the pieces under turned-over sideways units lie on their strips, not on z = 0
        out = CUTTER_OVERRUN
        spans = [box((c.x0, c.x1, -out, H + out, -out, s + out)) for c in raised]
        moved = [(sheet ^ span).translate((0.0, 0.0, c.bottom)) for span, c in zip(spans, raised, strict=True)]
        flat = m3.Manifold.batch_boolean([sheet, *spans], m3.OpType.Subtract)
        in_place = m3.Manifold.batch_boolean([flat, *moved], m3.OpType.Add)
        above.extend(moved)
    open_body = m3.Manifold.batch_boolean(above, m3.OpType.Subtract)
    cast = {"open_body": open_body, "side_sheet": sheet.translate(sheet_offset)}
    return cast, m3.Manifold.batch_boolean(openings, m3.OpType.Add), in_place


def _section(spec: UnitSpec | UnitLibrary) -> UnitSpec:
    """The unit whose section every unit of the design shares (a library's default type)."""
    return spec[spec.default] if isinstance(spec, UnitLibrary) else spec


def _explode(solids: dict[str, Any], e: float) -> dict[str, tuple[float, float, float]]:
    """The exploded view's offsets: each layer of the assembly (and the cast) one mould height ``e`` apart."""
    explode = {"base_plate": (0.0, 0.0, -e), "side_walls": (0.0, 0.0, 2 * e), "lid": (0.0, 0.0, 3 * e),
               "cast": (0.0, 0.0, e)}
    explode.update({name: (0.0, 0.0, 0.0) for name in solids if name.startswith("core_")})
    explode.update({name: (0.0, 0.0, e) for name in solids if name.startswith("pin_")})
    return explode


def _unchecked() -> MouldCheck:
    """The check of a mould not measured: every field NaN (no parts, no pairs)."""
    nan = float("nan")
    return MouldCheck({}, nan, 0, nan, nan, nan, nan, nan, nan, nan, nan)


def _checked(spec: UnitSpec | UnitLibrary, orientation: str | Design, solids: dict[str, Any], cast: dict[str, Any],
             opening: Any, parts: list[list[manifold3d.Manifold]], plate: Any, in_place: Any,
             outer: tuple[float, ...]) -> MouldCheck:
    """The measured assembly (:func:`_measure`).

    ``parts`` are the pins, their holes, the tenon pockets and the cores, whose clearance gaps
    are measured too (the pockets' within ``plate``, :func:`_plate`). ``in_place``: the sheet's
    pieces on the body.

    Raises
    ------
    GeometryError
        A mould that fails a check (:func:`_failure`).
    """
    import manifold3d as m3

    pins, pin_holes, pockets, cores = parts
    X0, X1, Y0, Y1, _, _ = outer
    W = _section(spec).width
    gaps = [hole - pin for hole, pin in zip(pin_holes, pins, strict=False)]
    gaps += [(pocket ^ plate) - core for pocket, core in zip(pockets, cores, strict=False)]
    body = actuator_solids(spec, orientation, base_block=None)["body"]
    # the cores above their roots (the side wall's face, or a plinth's top): the cavities as cast
    roots = [c[4] for c in cavity_boxes(spec, orientation)]
    core_tops = m3.Manifold.batch_boolean([core ^ box((X0, X1, Y0, Y1, z, W)) for core, z in zip(cores, roots,
                                                                                                   strict=True)],
                                          m3.OpType.Add) if cores else m3.Manifold()
    as_cast = outline_solid(spec, orientation, 0.0, W) - core_tops
    result = _measure(solids, cast, opening, m3.Manifold.batch_boolean(gaps, m3.OpType.Add), body, as_cast,
                      in_place, outer)
    if not result.ok:
        raise GeometryError(_failure(result))
    return result


def _bounds_overlap(a: manifold3d.Manifold, b: manifold3d.Manifold) -> bool:
    (ax0, ay0, az0, ax1, ay1, az1), (bx0, by0, bz0, bx1, by1, bz1) = a.bounding_box(), b.bounding_box()
    return ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1 and az0 < bz1 and bz0 < az1


def _xor_volume(a: manifold3d.Manifold, b: manifold3d.Manifold) -> float:
    return (a - b).volume() + (b - a).volume()


def _measure(solids: dict[str, Any], cast: dict[str, Any], opening: Any, gaps: Any, body: Any, as_cast: Any,
             in_place: Any, outer: tuple[float, ...]) -> MouldCheck:
    """The checks of :class:`MouldCheck`, on manifold3d solids."""
    import manifold3d as m3

    outer_box = box(outer)
    tolerance = 1e-9 * outer_box.volume()
    watertight = {}
    for name, solid in solids.items():
        shells = solid.decompose()
        watertight[name] = (solid.status() == m3.Error.NoError and len(shells) == 1 and solid.volume() > 0)
    names = list(solids)
    max_overlap, pairs = 0.0, 0
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if _bounds_overlap(solids[a], solids[b]):
                pairs += 1
                max_overlap = max(max_overlap, (solids[a] ^ solids[b]).volume())
    empty = m3.Manifold.batch_boolean([outer_box, *solids.values()], m3.OpType.Subtract)
    cast_all = cast["open_body"] + cast["side_sheet"]
    expected = m3.Manifold.batch_boolean([cast_all, opening, gaps], m3.OpType.Add)
    reach = 10.0  # mm: min_gap reports at most this
    gap_distance = gaps.min_gap(cast_all + opening, reach) if not gaps.is_empty() else reach
    back = cast["open_body"] + in_place
    return MouldCheck(
        watertight=watertight,
        max_overlap=max_overlap,
        overlap_pairs=pairs,
        cavity_error=_xor_volume(empty, expected),
        cast_volume=cast_all.volume(),
        openings_volume=opening.volume(),
        gaps_volume=gaps.volume(),
        gap_distance=gap_distance,
        reassembly_error=_xor_volume(back, as_cast),
        cavity_volume_change=as_cast.volume() - body.volume(),
        tolerance=tolerance,
    )


def _failure(c: MouldCheck) -> str:
    problems = []
    bad = [name for name, ok in c.watertight.items() if not ok]
    if bad:
        problems.append(f"part(s) {', '.join(bad)} are not one closed volume")
    if c.max_overlap > c.tolerance:
        problems.append(f"parts overlap by up to {c.max_overlap:.3g} mm^3")
    if c.cavity_error > c.tolerance:
        problems.append(f"the empty space differs from the cast by {c.cavity_error:.3g} mm^3")
    if c.gap_distance <= 0:
        problems.append("a clearance gap touches the cast (silicone would leak into it)")
    if c.reassembly_error > c.tolerance:
        problems.append(f"the cast pieces differ from the body by {c.reassembly_error:.3g} mm^3")
    return "the mould fails its checks: " + "; ".join(problems)

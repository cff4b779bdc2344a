"""The casting mould's records: its settings (:class:`MouldSpec`), the checks that its parts fit
(:class:`MouldCheck`) and the mould itself (:class:`Mould`); how it is built and checked:
:mod:`pneumorph.export.moulds`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from pneumorph.errors import GeometryError
from pneumorph.export.mouldlayout import pour_face, unit_castings
from pneumorph.export.parts import cavity_boxes
from pneumorph.geometry.alphabet import Design, library_design
from pneumorph.geometry.assembly import unit_starts
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec

if TYPE_CHECKING:  # pragma: no cover
    import trimesh


CUTTER_OVERRUN = 1.0  # how far cutters reach past the faces they open, mm


@dataclass(frozen=True)
class MouldSpec:
    """Settings of the casting mould (mm and degrees).

    Parameters
    ----------
    clearance : float
        Gap between mating printed parts: each pin and its holes (radius and ends), each
        core's tenon and its pocket (default 0.2 mm, for FDM or resin prints; 0 for
        machined parts fitted by hand). The silicone-facing faces have none.
    draft : float
        Taper of the cavity cores, degrees (default 0: exact cavities; 0.5-1 eases pulling
        the cured body off the cores, at the cost of cavities up to ``depth x tan(draft)``
        narrower per side at their closed end).
    wall : float
        Width of the mould's walls around and between the pockets (default 6 mm).
    plate : float
        Thickness of the base plate and of the lid (default 5 mm).
    pin_diameter : float
        Alignment pins (default 3 mm, a standard dowel).
    pin_depth : float
        How far each pin reaches into the base plate and into the lid (default 3 mm).
    pour_diameter, vent_diameter : float
        The holes in the lid over the first and the last unit (default 4 and 2 mm).
    segments : int
        Sides of the polygons of the pins and the round holes (default 32).

    Raises
    ------
    GeometryError
        A negative clearance or draft, a draft of 45 degrees or more, a non-positive size,
        pins whose holes do not fit in the wall or the plates; the message names the
        parameter.

    Examples
    --------
    >>> MouldSpec().clearance, MouldSpec().draft
    (0.2, 0.0)
    >>> MouldSpec(clearance=2.0)
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: mould clearance 2 mm is too large: a pin hole of 3 + 2 x 2 mm leaves less
    than 0.5 mm of the 6 mm wall on each side (clearance, pin_diameter, wall)
    """

    clearance: float = 0.2
    draft: float = 0.0
    wall: float = 6.0
    plate: float = 5.0
    pin_diameter: float = 3.0
    pin_depth: float = 3.0
    pour_diameter: float = 4.0
    vent_diameter: float = 2.0
    segments: int = 32

    def __post_init__(self) -> None:
        for key in ("clearance", "draft", "wall", "plate", "pin_diameter", "pin_depth", "pour_diameter",
                    "vent_diameter"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise GeometryError(f"mould {key} must be a finite number, got {value!r}")
        if self.clearance < 0:
            raise GeometryError(f"mould clearance must be >= 0 mm, got {self.clearance:g} mm")
        if not 0 <= self.draft < 45:
            raise GeometryError(f"mould draft must be >= 0 and < 45 degrees, got {self.draft:g}")
        for key in ("wall", "plate", "pin_diameter", "pin_depth", "pour_diameter", "vent_diameter"):
            if getattr(self, key) <= 0:
                raise GeometryError(f"mould {key} must be > 0 mm, got {getattr(self, key):g} mm")
        if isinstance(self.segments, bool) or not isinstance(self.segments, int) or not 8 <= self.segments <= 256:
            raise GeometryError(f"mould segments must be a whole number from 8 to 256, got {self.segments!r}")
        rim = (self.wall - self.pin_diameter - 2 * self.clearance) / 2
        if rim < 0.5:
            raise GeometryError(
                f"mould clearance {self.clearance:g} mm is too large: a pin hole of {self.pin_diameter:g} + 2 x "
                f"{self.clearance:g} mm leaves less than 0.5 mm of the {self.wall:g} mm wall on each side "
                "(clearance, pin_diameter, wall)"
            )
        if self.pin_depth + self.clearance > self.plate - 0.5:
            raise GeometryError(
                f"mould pin_depth {self.pin_depth:g} mm + clearance {self.clearance:g} mm leaves less than 0.5 mm of "
                f"the {self.plate:g} mm plate under the pin holes (pin_depth, clearance, plate)"
            )

    @property
    def tenon_depth(self) -> float:
        """How deep each core's tenon sits in the base plate: half the plate, mm."""
        return self.plate / 2

    def check(self, spec: UnitSpec | UnitLibrary, orientation: str | Design) -> None:
        """Refuse settings that do not fit this unit and design, before anything is built.

        Raises
        ------
        GeometryError
            A clearance as wide as the core tenon's setback (a quarter of the cavity's
            smaller side), a draft that narrows the cores' tips by more than that, pour or
            vent holes that do not fit on the first or last unit's face; the message names
            the parameter.

        Examples
        --------
        >>> MouldSpec(draft=8.0).check(UnitSpec(), "01")
        Traceback (most recent call last):
        ...
        pneumorph.errors.GeometryError: mould draft 8 degrees narrows each side of the 12 mm deep cores by
        1.69 mm, more than a quarter of the cavity's smaller side (4.5 mm); use at most 5.36 degrees
        """
        check_fit(spec, orientation, self)
        self.check_design(spec, orientation)

    def check_design(self, spec: UnitSpec | UnitLibrary, orientation: str | Design) -> None:
        """Refuse a design no mould of these settings can cast: no unit's face on z = width free of its strip for
        the pour and vent holes (or holes that do not fit on it), or side-sheet pieces of different thicknesses.

        Raises
        ------
        GeometryError
        """
        hole_centres(spec, orientation, self)
        unit_castings(spec, orientation)  # the side sheet's pieces all as thick


@dataclass(frozen=True)
class MouldCheck:
    """What :func:`casting_mould` measured on the assembled mould (volumes in mm^3).

    Attributes
    ----------
    watertight : dict of str to bool
        Each part: one closed, oriented volume.
    max_overlap : float
        The largest intersection volume of two parts.
    overlap_pairs : int
        How many pairs of parts were intersected (those whose bounding boxes overlap).
    cavity_error : float
        Volume of the symmetric difference between the mould's empty space (inside its
        outer box) and the cast + openings + clearance gaps.
    cast_volume, openings_volume, gaps_volume : float
        The cast pieces, the pour and vent holes, the clearance gaps.
    gap_distance : float
        The smallest distance from a clearance gap to the cast or its openings, mm
        (positive: the gaps are closed off; at most 10, the search length).
    reassembly_error : float
        Volume of the symmetric difference between the two cast pieces glued back and the
        body as cast: the designed body with the cores' shapes as cavities (the designed
        body itself when the draft is 0).
    cavity_volume_change : float
        The body as cast minus the designed body, mm^3: what the cores' draft adds to the
        silicone (0 without draft).
    tolerance : float
        The volume below which a difference counts as none.
    """

    watertight: dict[str, bool]
    max_overlap: float
    overlap_pairs: int
    cavity_error: float
    cast_volume: float
    openings_volume: float
    gaps_volume: float
    gap_distance: float
    reassembly_error: float
    cavity_volume_change: float
    tolerance: float

    @property
    def ok(self) -> bool:
        """All checks passed."""
        return (all(self.watertight.values()) and self.max_overlap <= self.tolerance
                and self.cavity_error <= self.tolerance and self.reassembly_error <= self.tolerance
                and self.gap_distance > 0)

    def to_dict(self) -> dict[str, Any]:
        """Plain values, for JSON."""
        return {
            "ok": self.ok,
            "watertight": dict(self.watertight),
            "max_overlap_mm3": self.max_overlap,
            "overlap_pairs": self.overlap_pairs,
            "cavity_error_mm3": self.cavity_error,
            "cast_volume_mm3": self.cast_volume,
            "openings_volume_mm3": self.openings_volume,
            "gaps_volume_mm3": self.gaps_volume,
            "gap_distance_mm": self.gap_distance,
            "reassembly_error_mm3": self.reassembly_error,
            "cavity_volume_change_mm3": self.cavity_volume_change,
            "tolerance_mm3": self.tolerance,
        }


@dataclass(frozen=True)
class Mould:
    """A casting mould: printable parts in their assembled places, and what they cast.

    Attributes
    ----------
    parts : dict of str to trimesh.Trimesh
        The printable parts (see the module's description), in the actuator's frame, mm.
    cast : dict of str to trimesh.Trimesh
        ``"open_body"`` and ``"side_sheet"``: the silicone as it lies in the mould (the
        sheet in its own pocket, moved by ``sheet_offset`` from its place on the body).
    openings : trimesh.Trimesh
        The pour and vent holes through the lid.
    sheet_offset : (float, float, float)
        Where the side sheet is cast relative to its place on the body, mm.
    explode : dict of str to (float, float, float)
        How far to move each part (and ``"cast"``, the cast pieces) in an exploded view, mm.
    outer : (float, float, float, float, float, float)
        The mould's outer box ``(x0, x1, y0, y1, z0, z1)``.
    check : MouldCheck
    spec : MouldSpec
    unit : UnitSpec or UnitLibrary
        The unit, or the library of the design's unit types.
    orientation : str
        The design (0/1, or over the library's symbols).
    """

    parts: dict[str, trimesh.Trimesh]
    cast: dict[str, trimesh.Trimesh]
    openings: trimesh.Trimesh
    sheet_offset: tuple[float, float, float]
    explode: dict[str, tuple[float, float, float]]
    outer: tuple[float, float, float, float, float, float]
    check: MouldCheck
    spec: MouldSpec = field(repr=False)
    unit: UnitSpec | UnitLibrary = field(repr=False)
    orientation: str = ""


def hole_centres(spec: UnitSpec | UnitLibrary, design: str | Design,
                  mould: MouldSpec) -> list[tuple[str, float, float, float]]:
    """The pour and vent holes of the body's pocket: (name, x, y, radius), checked to fit.

    Over the first and the last unit whose face on z = width is the body's (not a sideways
    unit's strip: :func:`~pneumorph.export.mouldlayout.pour_face`).
    """
    library, parsed = library_design(spec, design)
    units, orientation = parsed.units(library), parsed.orientation
    H = library[library.default].height
    starts = unit_starts(units)
    free = [i for i, (u, o) in enumerate(zip(units, orientation, strict=True)) if pour_face(u, o, H) is not None]
    if not free:
        raise GeometryError("no unit's face on z = width is free of its strip for the mould's pour and vent holes "
                            "(every unit is sideways with its strip on that face); turn one over")
    out = []
    for name, unit, frac, diameter in (("pour_diameter", free[0], 0.3, mould.pour_diameter),
                                       ("vent_diameter", free[-1], 0.75, mould.vent_diameter)):
        u, r = units[unit], diameter / 2
        span = u.pitch - u.slit_width  # the unit's top face along x, without its slit
        face = pour_face(u, orientation[unit], H)
        assert face is not None
        y0, y1 = face
        lo = float(starts[unit])
        x, hi = lo + frac * span, lo + span
        if x - r < lo or x + r > hi or 2 * r > (y1 - y0):
            raise GeometryError(
                f"mould {name} {diameter:g} mm does not fit on the top face of unit {unit + 1} "
                f"({span:g} x {y1 - y0:g} mm, the hole centred {x - lo:g} mm from its start); make it smaller"
            )
        out.append((name, x, (y0 + y1) / 2, r))
    (_, xa, ya, ra), (_, xb, yb, rb) = out
    if math.hypot(xa - xb, ya - yb) < ra + rb + 0.5:
        raise GeometryError(
            f"mould pour_diameter {mould.pour_diameter:g} mm and vent_diameter {mould.vent_diameter:g} mm: the two "
            f"holes over the single unit are less than 0.5 mm apart; make them smaller"
        )
    return out


def check_fit(spec: UnitSpec | UnitLibrary, design: str | Design,
               mould: MouldSpec) -> tuple[list[float], list[float]]:
    """Per cavity: the tenon's inset (a quarter of the cavity's smaller side across z) and the core's tip inset
    (its depth times the draft's tangent), checked against the clearance and the cavity."""
    insets, tips = [], []
    for x0, x1, y0, y1, z0, z1 in cavity_boxes(spec, design):
        smaller = min(x1 - x0, y1 - y0)
        inset = smaller / 4
        if mould.clearance >= inset:
            raise GeometryError(
                f"mould clearance {mould.clearance:g} mm is not smaller than the core tenon's setback {inset:g} mm "
                f"(a quarter of the cavity's smaller side, {smaller:g} mm): silicone would run into the tenon pockets"
            )
        depth = z1 - z0
        tip = depth * math.tan(math.radians(mould.draft))
        if tip > smaller / 4:
            raise GeometryError(
                f"mould draft {mould.draft:g} degrees narrows each side of the {depth:g} mm deep cores by {tip:.3g} "
                f"mm, more than a quarter of the cavity's smaller side ({smaller:g} mm); use at most "
                f"{math.degrees(math.atan(smaller / 4 / depth)):.3g} degrees"
            )
        insets.append(inset)
        tips.append(tip)
    return insets, tips

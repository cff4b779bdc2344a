"""Where each unit of a design is split between the two cast pieces, and what stands under it in the mould.

The mould (:mod:`pneumorph.export.moulds`) casts the body on its side, its cavities open
towards the base plate, in two pieces: the *open body* above a plane and a thin *side sheet*
below it that closes the cavities. For a planar unit, or a sideways unit whose strip lies on
the far side (``l``, the strip on z = width), that plane is the side wall's face z =
``side_wall``: the sheet is the body below it. A sideways unit turned over (``L``) has its
strip on z = 0, then its wall and its cavity: its cavity opens at z = ``layer + wall``, so
its core stands on a *plinth* of the base plate, from z = ``side_wall`` up to there, and its
piece of the sheet is its wall, z = ``layer`` to ``layer + wall``. Every piece of the sheet is
cast in one flat slab (so they must all be as thick), then cut where the pieces change depth
and glued each onto its units before the strips.

Examples
--------
>>> from pneumorph.geometry.library import builtin_library
>>> [(c.x0, c.bottom, c.split, c.plinth) for c in unit_castings(builtin_library("spatial"), "alL")]
[(0.0, 0.0, 1.5, False), (10.5, 0.0, 1.5, False), (21.0, 3.0, 4.5, True)]
"""

from __future__ import annotations

from dataclasses import dataclass

from pneumorph.errors import GeometryError
from pneumorph.geometry.alphabet import Design, library_design
from pneumorph.geometry.assembly import unit_starts
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec


@dataclass(frozen=True)
class UnitCasting:
    """How one unit is cast.

    Attributes
    ----------
    x0, x1 : float
        The unit's extent along the actuator, mm (the last unit's includes the end cap).
    bottom : float
        The lowest z of its body, mm (0; a turned-over sideways unit's strip thickness).
    split : float
        The plane between the open body and the side sheet over this unit, mm.
    plinth : bool
        Its core stands on a plinth of the base plate (``split`` above the side wall's face).
    """

    x0: float
    x1: float
    bottom: float
    split: float
    plinth: bool

    @property
    def sheet(self) -> float:
        """The thickness of its piece of the side sheet, mm."""
        return self.split - self.bottom


def unit_castings(spec: UnitSpec | UnitLibrary, design: str | Design) -> list[UnitCasting]:
    """How each unit of ``design`` is cast, base first (module docstring).

    Raises
    ------
    GeometryError
        Sheet pieces of different thicknesses (the sheet is cast as one flat slab): a turned-over
        sideways unit whose wall is not as thick as the section's side wall.
    """
    library, parsed = library_design(spec, design)
    units, orientation = parsed.units(library), parsed.orientation
    ref = library[library.default]
    starts = unit_starts(units)
    out = []
    for i, (u, o) in enumerate(zip(units, orientation, strict=True)):
        x1 = float(starts[i + 1]) + (ref.end_cap if i == len(units) - 1 else 0.0)
        if u.layer_side and o == "1":  # the strip on z = 0, then the wall: the cavity opens above both
            bottom, split = u.layer, u.layer + u.wall
        else:
            bottom, split = 0.0, ref.side_wall
        out.append(UnitCasting(float(starts[i]), x1, bottom, split, split > ref.side_wall))
    thick = {round(c.sheet, 9) for c in out}
    if len(thick) > 1:
        raise GeometryError(f"the side sheet's pieces would be {' and '.join(f'{t:g}' for t in sorted(thick))} mm "
                            "thick, and the mould casts the sheet as one flat slab: give the turned-over sideways "
                            "units a wall as thick as the side wall")
    return out


def pour_face(unit: UnitSpec, orientation: str, height: float) -> tuple[float, float] | None:
    """The y range of a unit's face on z = width that the pour and vent holes may open onto, or None where the
    strip covers it (a sideways unit as built: its strip lies on that face).

    >>> pour_face(UnitSpec(), "0", 12.0), pour_face(UnitSpec(), "1", 12.0)
    ((0.0, 9.0), (3.0, 12.0))
    """
    if unit.layer_side:
        return None if orientation == "0" else (0.0, height)
    if unit.layer <= 0:
        return (0.0, height)
    return (0.0, height - unit.layer) if orientation == "0" else (unit.layer, height)


__all__ = ["UnitCasting", "pour_face", "unit_castings"]

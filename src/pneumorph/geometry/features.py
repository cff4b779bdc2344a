"""Features of a physical actuator that the design models leave out (appendix D).

- :class:`BaseBlock` - the silicone slab glued to the base face, through which the syringe
  enters and by which the test rig clamps the actuator (D.2, section 6.4.2).
- :func:`passage_side` and :func:`check_passage` - the air passages between adjacent
  cavities (D.1: 1.5 mm holes punched through each wall between cavities, section 6.4.1).

The design models clamp the base face x = 0 and close every cavity; ``assemble(...,
passage=..., base=...)`` (:mod:`pneumorph.geometry.assembly`) meshes these features, so that
the sensitivity studies can measure what leaving them out costs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pneumorph.errors import GeometryError
from pneumorph.geometry.limits import MAX_LENGTH_MM
from pneumorph.geometry.unit import UnitSpec

#: an axis-aligned box ``(x0, x1, y0, y1, z0, z1)`` in mm
Box = tuple[float, float, float, float, float, float]

#: the holes punched between adjacent cavities of the physical actuators (section 6.4.1), mm
PHYSICAL_PASSAGE = 1.5


def check_length(name: str, value: float, positive: bool) -> None:
    """Refuse a length that is not a finite number (> 0, or >= 0 if not ``positive``), in mm."""
    ok = not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
    if not ok or (value <= 0 if positive else value < 0):
        raise GeometryError(f"{name} must be a finite number {'> 0' if positive else '>= 0'} mm, got {value!r}")
    if value > MAX_LENGTH_MM:  # the limit of every length of a unit: the mesh grows with it
        raise GeometryError(f"{name} of {value:g} mm is more than {MAX_LENGTH_MM:g} mm (MAX_LENGTH_MM, "
                            "pneumorph.geometry.limits)")


@dataclass(frozen=True)
class BaseBlock:
    """The solid silicone block glued to the base face of the actuator.

    The syringe that inflates the actuator is pushed through it into the first cavity;
    the thick slab keeps the air from escaping around the needle (section 6.4.2), and the
    test rig's clamp grips it. The design models leave it out and clamp the face x = 0;
    meshed (``assemble(..., base=BaseBlock())``), it is held by the clamp's jaws instead:
    its faces at the bottom and top of its section (y = -margin and y = height + margin)
    are fixed over its whole length, and the face x = 0 is free to deform with it.

    Parameters
    ----------
    length : float
        Thickness along the actuator, mm (default 10: about one unit's pitch, enough to
        grip in a clamp and seal around an 18 gauge needle).
    margin : float
        How far it overhangs the actuator's section on each side (y and z), mm (default 0:
        the block has the actuator's ``height x width`` section).
    material : str
        Library name of its silicone (default ``mold_star_15``, the body's).

    Raises
    ------
    GeometryError
        A non-positive length, a negative margin or a blank material name.

    Examples
    --------
    >>> BaseBlock().box(UnitSpec())
    (-10.0, 0.0, 0.0, 12.0, 0.0, 15.0)
    >>> BaseBlock(length=-1.0)
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: base block length must be a finite number > 0 mm, got -1.0
    """

    length: float = 10.0
    margin: float = 0.0
    material: str = "mold_star_15"

    def __post_init__(self) -> None:
        check_length("base block length", self.length, positive=True)
        check_length("base block margin", self.margin, positive=False)
        if not isinstance(self.material, str) or not self.material.strip():
            raise GeometryError(f"base block material must be a non-empty text, got {self.material!r}")

    def box(self, spec: UnitSpec) -> Box:
        """The block ``(x0, x1, y0, y1, z0, z1)`` beside the base face of an actuator of ``spec``."""
        m = float(self.margin)
        return (-float(self.length), 0.0, 0.0 - m, spec.height + m, 0.0 - m, spec.width + m)

    def to_dict(self) -> dict[str, float | str]:
        """Its parameters, for provenance and fingerprints."""
        return {"length": float(self.length), "margin": float(self.margin), "material": self.material}


def passage_side(diameter: float) -> float:
    """Side of the square channel with the area of a round hole of ``diameter`` (mm).

    The structured mesh removes a square column of cells; the same cross-section as the
    punched hole keeps the air path's area, which is what the wall between cavities loses.

    >>> round(passage_side(1.5), 4)
    1.3293
    """
    return diameter * math.sqrt(math.pi) / 2


def check_passage(spec: UnitSpec, diameter: float) -> float:
    """The square side of a passage of ``diameter`` through ``spec``'s walls; refuses one that does not fit.

    The passage runs along the actuator at mid-height and mid-width, through the walls
    between adjacent cavities. Mid-height lies in the common height of two cavities facing
    either way (orientation 0: ``wall .. wall + cavity_height``, orientation 1 mirrored),
    which is ``cavity_height - layer`` high; the passage must fit in it, and across the
    cavity's width (of a sideways unit: the common width of its cavities facing either way,
    ``width - 2 side_wall - 2 layer``), and it cannot run through a slit (that would open the cavities to the
    outside).

    Raises
    ------
    GeometryError
        A negative or non-finite diameter, or a passage that does not fit.

    Examples
    --------
    >>> round(check_passage(UnitSpec(), 1.5), 4)
    1.3293
    >>> check_passage(UnitSpec(), 4.0)
    Traceback (most recent call last):
    ...
    pneumorph.errors.GeometryError: a passage of 4 mm (a 3.54 mm square channel) is wider than the walls
    between cavities allow: at most 3.385 mm for this unit (the common height of two cavities facing either
    way, cavity_height 6 mm - layer 3 mm, and the cavity's width)
    """
    check_length("passage diameter", diameter, positive=False)
    if diameter == 0:
        return 0.0
    if spec.slit is not None:
        raise GeometryError("a passage cannot run through a unit with a slit: it would open the cavities to the "
                            "outside")
    if spec.solid:
        raise GeometryError(f"a passage cannot run through the solid unit {spec.name!r}: it has no cavity to join")
    side = passage_side(diameter)
    # a sideways unit's cavities facing either way share the width less both side layers
    room = min(spec.cavity_height - spec.top_layer, spec.width - 2 * spec.side_wall - 2 * spec.side_layer)
    if side >= room:
        most = room * 2 / math.sqrt(math.pi)
        where = (f"height of two cavities facing either way, cavity_height {spec.cavity_height:g} mm - layer "
                 f"{spec.layer:g} mm, and the cavity's width" if not spec.layer_side else
                 f"width of two cavities facing either way, width {spec.width:g} mm - 2 side walls - 2 x side layer "
                 f"{spec.layer:g} mm, and the cavity's height")
        raise GeometryError(
            f"a passage of {diameter:g} mm (a {side:.3g} mm square channel) is wider than the walls between cavities "
            f"allow: at most {most:.4g} mm for this unit (the common {where})")
    return side


__all__ = ["PHYSICAL_PASSAGE", "BaseBlock", "Box", "check_length", "check_passage", "passage_side"]

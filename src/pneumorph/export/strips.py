"""The stiff strips of a design: the Smooth-Sil strip cut into pieces, and what they cut from the body.

A unit's stiff layer lies on one face of the bar (:class:`~pneumorph.geometry.unit.UnitSpec`):
the top for a planar unit as built (``y = height``), the bottom turned over; the right side
for a sideways unit as built (``z = width``, looking from the base to the tip with y up), the
left side turned over. Consecutive units whose layers lie on the same face, of the same
thickness and material, share one piece, end to end; the last piece also covers the end cap.
These are the ``"layer"`` cells of :func:`~pneumorph.geometry.assembly.assemble`, unit by
unit (the tests compare them boolean for boolean).

Examples
--------
>>> from pneumorph.geometry.library import builtin_library
>>> [(p.first, p.last, p.side, p.length) for p in layer_pieces(builtin_library("spatial"), "aalLA")]
[(0, 1, 'top', 21.0), (2, 2, 'right', 10.5), (3, 3, 'left', 10.5), (4, 4, 'bottom', 10.5)]
"""

from __future__ import annotations

from dataclasses import dataclass

from pneumorph.geometry.alphabet import Design, library_design
from pneumorph.geometry.assembly import unit_starts
from pneumorph.geometry.features import Box
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec

#: the faces a strip lies on, and whether they lie across the height (y) or the width (z)
SIDES = {"top": "y", "bottom": "y", "right": "z", "left": "z"}


@dataclass(frozen=True)
class LayerPiece:
    """One piece of the stiff strip: a run of units whose layers lie on the same face.

    Attributes
    ----------
    first, last : int
        The first and last unit it covers (0-based, base first, inclusive).
    side : {"top", "bottom", "right", "left"}
        ``"top"``: ``height - thickness <= y <= height`` (planar units as built, ``"0"``);
        ``"bottom"``: ``0 <= y <= thickness`` (turned, ``"1"``); ``"right"``:
        ``width - thickness <= z <= width`` (sideways units as built); ``"left"``:
        ``0 <= z <= thickness`` (sideways, turned).
    x0, x1 : float
        Its extent along the actuator, mm (the last piece includes the end cap).
    thickness : float
        mm.
    material : str
        Its library material.
    """

    first: int
    last: int
    side: str
    x0: float
    x1: float
    thickness: float
    material: str

    @property
    def length(self) -> float:
        """The length to cut from the strip, mm."""
        return self.x1 - self.x0

    def box(self, spec: UnitSpec) -> Box:
        """The piece ``(x0, x1, y0, y1, z0, z1)`` in the actuator's frame (``spec``: the section's height, width)."""
        H, W, t = spec.height, spec.width, self.thickness
        y0, y1 = {"top": (H - t, H), "bottom": (0.0, t)}.get(self.side, (0.0, H))
        z0, z1 = {"right": (W - t, W), "left": (0.0, t)}.get(self.side, (0.0, W))
        return (self.x0, self.x1, y0, y1, z0, z1)

    def cutter(self, spec: UnitSpec, n: int, z0: float, z1: float, out: float) -> Box:
        """What the piece cuts from the body between the planes z = ``z0``, ``z1``: its box, reaching ``out``
        past the outer faces it lies on (and past the ends at the actuator's ends), so no cut face coincides
        with one."""
        x0, x1, y0, y1, pz0, pz1 = self.box(spec)
        xa = -out if self.first == 0 else x0
        xb = x1 + out if self.last == n - 1 else x1
        if SIDES[self.side] == "y":
            ya, yb = (y0, y1 + out) if self.side == "top" else (y0 - out, y1)
            return (xa, xb, ya, yb, z0 - out, z1 + out)
        za, zb = (pz0, z1 + out) if self.side == "right" else (z0 - out, pz1)
        return (xa, xb, y0 - out, y1 + out, za, zb)


def layer_pieces(spec: UnitSpec | UnitLibrary, design: str | Design) -> list[LayerPiece]:
    """The pieces the stiff strip is cut into, base first.

    Consecutive units whose layers lie on the same face (of the same thickness and material)
    share one piece: a design whose units all face the same way has one piece, the strip cut
    to the actuator's length. Units without a layer (extending) have none.

    Parameters
    ----------
    spec : UnitSpec or UnitLibrary
        The unit (designs of 0/1), or a library of unit types.
    design : str
        The design, base first (``"0"`` layer on top, ``"1"`` at the bottom; over a library
        its symbols, upper case turned over).

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
    library, parsed = library_design(spec, design)
    units, orientation = parsed.units(library), parsed.orientation
    starts, cap = unit_starts(units), library[library.default].end_cap
    faces = [_face(u, o) for u, o in zip(units, orientation, strict=True)]
    n, pieces, start = len(units), [], 0
    for i in range(1, n + 1):
        if i == n or faces[i] != faces[start]:
            face = faces[start]
            if face is not None:
                side, thickness, material = face
                x1 = float(starts[i]) + (cap if i == n else 0.0)
                pieces.append(LayerPiece(start, i - 1, side, float(starts[start]), x1, thickness, material))
            start = i
    return pieces


def _face(unit: UnitSpec, o: str) -> tuple[str, float, str] | None:
    """The face a unit's layer lies on in orientation ``o``, its thickness and material (None: no layer)."""
    if unit.side_layer > 0:
        return ("right" if o == "0" else "left", unit.side_layer, unit.layer_material)
    if unit.top_layer > 0:
        return ("top" if o == "0" else "bottom", unit.top_layer, unit.layer_material)
    return None


__all__ = ["SIDES", "LayerPiece", "layer_pieces"]

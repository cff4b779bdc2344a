"""What a unit may be: its lengths up to :data:`MAX_LENGTH_MM` and its name up to
:data:`MAX_NAME_CHARS` characters (:func:`check_lengths`), and the one refusal of a unit or a
mesh past pneumorph's limits (:class:`MeshLimitError`).

A unit that passes :class:`~pneumorph.geometry.unit.UnitSpec`'s own checks can still cost
without bound: a pitch of 10 m at a 1.5 mm element size is a mesh of millions of nodes,
whose solve grows by hundreds of MB a second until the machine runs out. The rule is the
one every entry point uses (the bench's upload, :func:`pneumorph.models.factory.make_model`
behind the command line and design configs): every length of a unit is at most
:data:`MAX_LENGTH_MM` (here), and the mesh it implies is counted before meshing
(:mod:`pneumorph.geometry.meshsize`).

A unit a user describes must also be one a mould can cast (:func:`check_manufacturable`):
walls and the stiff layer at least :data:`MIN_WALL_MM`, cavities and slits at least
:data:`MIN_FEATURE_MM`, pitch, width and height at most :data:`MAX_UNIT_MM` (the sources of
the numbers beside them). Unit files, unit libraries, the bench's uploads (and so the
exports of them) and the unit optimisation's bounds are checked; units made inside an
analysis (a tolerance's perturbed walls) are not.
"""

from __future__ import annotations

from typing import Any

from pneumorph.errors import GeometryError

MAX_LENGTH_MM = 1000.0
"""Largest length of any part of a unit (pitch, width, walls, cavity, layer, slit, element size), mm."""
MAX_NAME_CHARS = 200
"""Longest name of a unit (characters)."""
#: the lengths of a :class:`~pneumorph.geometry.unit.UnitSpec` (mm) that :func:`check_lengths` checks
UNIT_LENGTHS = (
    "pitch",
    "width",
    "wall",
    "side_wall",
    "end_wall",
    "layer",
    "cavity_height",
    "slit_width",
    "slit_depth",
    "end_cap",
    "element_size",
)


#: thinnest wall, side wall, end wall and stiff layer a unit may have (mm): the thinnest silicone parts the
#: dissertation cast and handled are the 1 mm Mold Star 15 and Smooth-Sil strips cast in 3D-printed moulds
#: (Ellis 2020, Appendix B.2, steps 8-10, parts C and D: within +-0.05 mm, the printed moulds' tolerance); its
#: unit walls are 1.5 mm, the thinnest that held 45 kPa for long (section 4.2). At 1 mm the printed mould's
#: +-0.1 mm (Appendix E) is a tenth of the wall.
MIN_WALL_MM = 1.0
#: smallest cavity (height, length) and slit (width, depth) a unit may have (mm): a core or blade of the mould
#: (three-dimensionally printed, +-0.1 mm, Appendix E) that stands and comes out of the cured silicone; the
#: dissertation's smallest are the 1.5 mm holes punched between units (section 6.4.1) and the 4 mm cavity of
#: the short-pitch unit (section 8.3.1)
MIN_FEATURE_MM = 1.0
#: largest pitch, width and height of one unit (mm): a unit's mould part printed in one piece on a common
#: fused-deposition printer's bed (about 250 x 210 mm; the dissertation's moulds were printed so, Appendix B)
MAX_UNIT_MM = 250.0
#: where the manufacturing limits come from, for the messages
LIMITS_SOURCE = "pneumorph.geometry.limits: moulded silicone, Ellis 2020 Appendix B.2 and E"


class MeshLimitError(GeometryError):
    """A unit whose dimensions or mesh exceed the limits of :mod:`pneumorph.geometry.limits`.

    The message states the estimate (nodes, elements, memory) and the limit.
    """


def check_lengths(spec: object) -> None:
    """Refuse a unit with any length above :data:`MAX_LENGTH_MM`.

    Raises
    ------
    MeshLimitError
        Naming the length, its value and the limit.

    Examples
    --------
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> check_lengths(UnitSpec())
    >>> check_lengths(UnitSpec(pitch=1e4))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.geometry.limits.MeshLimitError: unit pitch 1e+04 mm is above the limit MAX_LENGTH_MM = 1000 mm...
    """
    for key in UNIT_LENGTHS:
        value = getattr(spec, key)
        if value > MAX_LENGTH_MM:
            raise MeshLimitError(f"unit {key} {value:.4g} mm is above the limit MAX_LENGTH_MM = {MAX_LENGTH_MM:g} mm "
                                 "(pneumorph.geometry.limits)")


class ManufacturingError(GeometryError):
    """A unit that cannot be moulded: a wall, layer or feature thinner than :data:`MIN_WALL_MM` or
    :data:`MIN_FEATURE_MM`, or a unit larger than :data:`MAX_UNIT_MM`; the message names the part,
    its size and the limit."""


def check_manufacturable(spec: Any, where: str = "unit") -> None:
    """Refuse a unit that cannot be cast in a printed mould (see the limits above, and their sources).

    A zero stiff layer (an extending unit), no slit and no end cap are no parts, and pass.

    Raises
    ------
    ManufacturingError
        Naming the part, its size and the limit, e.g. ``unit wall 1e-06 mm is thinner than ...``.

    Examples
    --------
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> check_manufacturable(UnitSpec())
    >>> check_manufacturable(UnitSpec(wall=3.0, layer=0.0, pitch=7.0, end_wall=1.5))
    >>> check_manufacturable(UnitSpec(wall=1e-6))  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    pneumorph.geometry.limits.ManufacturingError: unit wall 1e-06 mm is thinner than the thinnest wall a mould
    casts, MIN_WALL_MM = 1 mm (pneumorph.geometry.limits: moulded silicone, Ellis 2020 Appendix B.2 and E)
    """
    parts: list[tuple[str, float, str]] = [(k, float(getattr(spec, k)), "wall") for k in
                                           ("wall", "side_wall", "end_wall", "layer")]
    parts += [("cavity_height", float(spec.cavity_height), "feature"),
              ("cavity length", float(spec.cavity_length), "feature"),
              ("slit_width", float(spec.slit_width), "feature"),
              ("slit_depth", float(spec.slit_depth), "feature")]
    for name, value, kind in parts:
        optional = name in ("layer", "slit_width", "slit_depth")
        if optional and value == 0.0:
            continue
        if kind == "wall" and value < MIN_WALL_MM:
            raise ManufacturingError(f"{where} {name} {value:.4g} mm is thinner than the thinnest wall a mould casts, "
                                     f"MIN_WALL_MM = {MIN_WALL_MM:g} mm ({LIMITS_SOURCE})")
        if kind == "feature" and value < MIN_FEATURE_MM:
            raise ManufacturingError(f"{where} {name} {value:.4g} mm is smaller than the smallest cavity or slit a "
                                     f"mould casts, MIN_FEATURE_MM = {MIN_FEATURE_MM:g} mm ({LIMITS_SOURCE})")
    for name in ("pitch", "width", "height"):
        value = float(getattr(spec, name))
        if value > MAX_UNIT_MM:
            raise ManufacturingError(f"{where} {name} {value:.4g} mm is larger than a unit's mould part printed in one "
                                     f"piece, MAX_UNIT_MM = {MAX_UNIT_MM:g} mm ({LIMITS_SOURCE})")


__all__ = ["LIMITS_SOURCE", "MAX_LENGTH_MM", "MAX_NAME_CHARS", "MAX_UNIT_MM", "MIN_FEATURE_MM", "MIN_WALL_MM",
           "UNIT_LENGTHS", "ManufacturingError", "MeshLimitError", "check_lengths", "check_manufacturable"]

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
"""

from __future__ import annotations

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


__all__ = ["MAX_LENGTH_MM", "MAX_NAME_CHARS", "UNIT_LENGTHS", "MeshLimitError", "check_lengths"]

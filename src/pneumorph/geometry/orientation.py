"""Orientation vectors: which way each articulating unit faces.

A design is a sequence of unit orientations, 0 or 1, where 1 is the unit turned 180 degrees
about the actuator's long axis (section 4.4). At the edges (CLI, files, the evaluation
cache) a design is written as a string of digits, base first: ``"010011..."``.
"""

from __future__ import annotations

from collections.abc import Iterable

from pneumorph.checks import MAX_UNITS
from pneumorph.errors import OrientationError


def parse_orientation(design: str | Iterable[int], n_units: int | None = None) -> str:
    """Validate a design and return it as a string of ``0``/``1`` digits.

    Parameters
    ----------
    design : str or iterable of int
        ``"0101..."`` (spaces, commas and underscores are ignored) or a sequence of 0/1.
    n_units : int, optional
        The required length.

    Returns
    -------
    str

    Raises
    ------
    OrientationError
        Empty, other characters than 0/1, or the wrong length.

    Examples
    --------
    >>> parse_orientation("0101 1")
    '01011'
    >>> parse_orientation([1, 0, 1], n_units=3)
    '101'
    """
    if isinstance(design, str):
        text = "".join(ch for ch in design if ch not in " ,_\t")
    else:
        try:
            text = "".join(str(int(v)) for v in design)
        except (TypeError, ValueError):
            raise OrientationError(f"orientation must be a sequence of 0/1, got {design!r}") from None
    if not text:
        raise OrientationError("the orientation vector is empty; give one digit 0/1 per unit, e.g. '010011'")
    bad = sorted(set(text) - {"0", "1"})
    if bad:
        raise OrientationError(
            f"orientation {design!r} contains {', '.join(repr(b) for b in bad)}; only the digits 0 and 1 "
            "are allowed (0 = unit as built, 1 = unit turned 180 degrees about the long axis)"
        )
    if len(text) > MAX_UNITS:
        raise OrientationError(f"the design has {len(text)} units; at most {MAX_UNITS} (limit MAX_UNITS)")
    if n_units is not None and len(text) != n_units:
        raise OrientationError(f"orientation {text!r} has {len(text)} units, expected {n_units}")
    return text


def mirror(design: str) -> str:
    """The design with every unit inverted; its shape is the mirror image (y -> -y).

    Examples
    --------
    >>> mirror("0011")
    '1100'
    """
    return parse_orientation(design).translate(str.maketrans("01", "10"))

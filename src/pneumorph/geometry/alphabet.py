"""Designs over a unit library's alphabet: which type each unit is, and which way it faces.

Notation (base first, one character per unit; spaces, commas and underscores are ignored):

- a symbol of the library in lower case (``a``, ``e``, ...) is a unit of that type as built
  (orientation 0); in upper case (``A``, ``E``, ...) the unit turned 180 degrees about the
  long axis (orientation 1);
- the digits ``0`` and ``1`` are a unit of the library's first type (its default) in
  orientation 0 and 1, so every 0/1 design is a design over any library whose first type is
  the default unit, with the same meaning there.

The canonical text of a design (:attr:`Design.text`, what caches, files and responses keep)
is the 0/1 string for a one-type library (:meth:`~pneumorph.geometry.library.UnitLibrary.single`),
so a one-type design is written as its 0/1 string, and the letters otherwise.

Examples
--------
>>> from pneumorph.geometry.library import builtin_library
>>> d = parse_design("aaEr s", builtin_library())
>>> d.text, d.symbols, d.orientation
('aaErs', 'aaers', '00100')
>>> parse_design("0110", builtin_library()).text
'aAAa'
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from pneumorph.checks import MAX_UNITS
from pneumorph.errors import OrientationError
from pneumorph.geometry.library import SEPARATORS, UnitLibrary
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.geometry.unit import UnitSpec


@dataclass(frozen=True)
class Design:
    """A parsed design: the type symbol and the orientation of every unit, base first.

    Attributes
    ----------
    symbols : str
        The library symbol of each unit (lower case).
    orientation : str
        ``0``/``1`` per unit: 1 = turned 180 degrees about the long axis.
    text : str
        The canonical text (module docstring): 0/1 digits for a one-type library.

    Examples
    --------
    >>> from pneumorph.geometry.library import builtin_library
    >>> d = parse_design("aEs", builtin_library())
    >>> d.n_units, [u.name for u in d.units(builtin_library())]
    (3, ['unit', 'extending', 'short'])
    >>> d.mirror().text
    'AeS'
    """

    symbols: str
    orientation: str
    text: str

    @property
    def n_units(self) -> int:
        return len(self.symbols)

    def units(self, library: UnitLibrary) -> tuple[UnitSpec, ...]:
        """The unit spec of every unit, base first."""
        return tuple(library[s] for s in self.symbols)

    def mirror(self) -> Design:
        """Every unit turned over: the mirror image (y -> -y) of the actuator's shape."""
        flipped = self.orientation.translate(str.maketrans("01", "10"))
        return Design(self.symbols, flipped, _text(self.symbols, flipped, self.text.isdigit()))

    def __str__(self) -> str:
        return self.text


def _text(symbols: str, orientation: str, digits: bool) -> str:
    if digits:
        return orientation
    return "".join(s if o == "0" else s.upper() for s, o in zip(symbols, orientation, strict=True))


def _allowed(library: UnitLibrary) -> str:
    types = ", ".join(f"{s}/{s.upper()} ({m})" for s, m in zip(library.symbols, library.modes, strict=True))
    return (f"{types}, and 0/1 for {library.default} (lower case or 0: the unit as built; upper case or 1: turned "
            "180 degrees about the long axis)")


def parse_design(design: str | Iterable[int] | Design, library: UnitLibrary, n_units: int | None = None) -> Design:
    """Validate a design over ``library``'s symbols (module docstring) and return it parsed.

    Parameters
    ----------
    design : str, iterable of int, or Design
        ``"aAes..."``, or ``"0101..."`` (the library's first type), or a sequence of 0/1.
    library : UnitLibrary
        The alphabet.
    n_units : int, optional
        The required length.

    Returns
    -------
    Design

    Raises
    ------
    OrientationError
        Empty, too long or the wrong length; characters that are no symbol of the library
        (the message names them and lists the allowed ones). A 0/1 design (any design
        without letters, for a one-type library) is checked by
        :func:`~pneumorph.geometry.orientation.parse_orientation`, with its messages.

    Examples
    --------
    >>> from pneumorph.geometry.library import UnitLibrary, builtin_library
    >>> parse_design("0101 1", UnitLibrary.single()).text
    '01011'
    >>> parse_design("aAa", UnitLibrary.single()).text   # one type: the 0/1 text
    '010'
    >>> parse_design("aXe", builtin_library())
    Traceback (most recent call last):
    ...
    pneumorph.errors.OrientationError: design 'aXe' contains 'X', which is no symbol of the unit library 'builtin';
    allowed: a/A (bending), e/E (extending), r/R (near-rigid), s/S (short-pitch), and 0/1 for a (lower case or 0:
    the unit as built; upper case or 1: turned 180 degrees about the long axis)
    """
    digits = library.is_single
    if isinstance(design, Design):  # parsed once: checked against this library, not read again
        return _checked(design, library, n_units)
    if not isinstance(design, str):
        orientation = parse_orientation(design, n_units)
        return Design(library.default * len(orientation), orientation, _text(library.default * len(orientation),
                                                                              orientation, digits))
    text = "".join(ch for ch in design if ch not in SEPARATORS)
    if set(text) <= {"0", "1"} or (digits and not any(ch.isalpha() for ch in text)):  # the 0/1 checks and messages
        orientation = parse_orientation(design, n_units)
        symbols = library.default * len(orientation)
        return Design(symbols, orientation, _text(symbols, orientation, digits))
    bad = sorted({ch for ch in text if ch not in "01" and ch.lower() not in library.symbols})
    if bad:
        which = ", ".join(repr(b) for b in bad)
        raise OrientationError(
            f"design {design!r} contains {which}, which {'is' if len(bad) == 1 else 'are'} no symbol of the unit "
            f"library {library.name!r}; allowed: {_allowed(library)}")
    if len(text) > MAX_UNITS:
        raise OrientationError(f"the design has {len(text)} units; at most {MAX_UNITS} (limit MAX_UNITS)")
    if n_units is not None and len(text) != n_units:
        raise OrientationError(f"design {text!r} has {len(text)} units, expected {n_units}")
    symbols = "".join(library.default if ch in "01" else ch.lower() for ch in text)
    orientation = "".join(ch if ch in "01" else ("1" if ch.isupper() else "0") for ch in text)
    return Design(symbols, orientation, _text(symbols, orientation, digits))


def _checked(design: Design, library: UnitLibrary, n_units: int | None) -> Design:
    """An already parsed design, checked over ``library``: its symbols are the library's and its length is right."""
    bad = sorted(set(design.symbols) - set(library.symbols))
    if bad:
        which = ", ".join(repr(b) for b in bad)
        raise OrientationError(f"design {design.text!r} uses {which}, which {'is' if len(bad) == 1 else 'are'} no "
                               f"symbol of the unit library {library.name!r}; allowed: {_allowed(library)}")
    if n_units is not None and design.n_units != n_units:
        raise OrientationError(f"design {design.text!r} has {design.n_units} units, expected {n_units}")
    if design.text.isdigit() != library.is_single:  # the canonical text of this library
        return Design(design.symbols, design.orientation, _text(design.symbols, design.orientation, library.is_single))
    return design


def library_design(spec: UnitSpec | UnitLibrary, design: str | Iterable[int] | Design) -> tuple[UnitLibrary, Design]:
    """The library of ``spec`` (a unit: its one-type library) and ``design`` parsed over it (:func:`parse_design`).

    >>> library, design = library_design(UnitSpec(), "0110")
    >>> library.is_single, [u.name for u in design.units(library)][:2]
    (True, ['unit', 'unit'])
    """
    library = spec if isinstance(spec, UnitLibrary) else UnitLibrary.single(spec)
    return library, parse_design(design, library)


__all__ = ["Design", "library_design", "parse_design"]

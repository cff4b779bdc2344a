"""Unit libraries: the types of articulating unit a design may use, each named by a symbol.

A library maps one-character symbols (lower-case letters ``a``-``z``) to unit specs
(:class:`~pneumorph.geometry.unit.UnitSpec`); a design over it is a string of those symbols
(:mod:`pneumorph.geometry.alphabet`): lower case for a unit as built, upper case for a unit
turned 180 degrees about the long axis. The digits 0 and 1 are a unit of the library's
first type in orientation 0 or 1, so the designs of the one-unit library
(:meth:`UnitLibrary.single`) are 0/1 strings.

The library file (TOML; ``docs/unit-library.md``)::

    [library]
    name = "my units"                 # optional
    description = "..."               # optional

    [[units]]
    symbol = "a"                      # one lower-case letter, unique
    mode = "bending"                  # optional label (the deformation mode)
    unit = {}                         # the unit's parameters (mm), defaults for those left out

    [[units]]
    symbol = "s"
    unit = "short.toml"               # or a unit file with a [unit] table, relative to this file

All units of a library are meshed as one tensor grid, so they must share its cross-section
(:func:`check_joinable`): the same height, width and side walls, element size and order, end
cap, body material and stiff-layer material, and the same lines across the height.

Examples
--------
>>> lib = builtin_library()
>>> lib.symbols, lib.default
(('a', 'e', 'r', 's'), 'a')
>>> lib["s"].pitch, lib["a"] == UnitSpec()
(7.0, True)
"""

from __future__ import annotations

import string
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.errors import GeometryError, UnitLibraryError
from pneumorph.geometry.grid import cross_section_lines
from pneumorph.geometry.limits import check_manufacturable
from pneumorph.geometry.unit import UnitSpec
from pneumorph.io.provenance import digest

#: the characters a unit type may be named by
SYMBOLS = string.ascii_lowercase
#: characters a design may contain besides symbols: ignored separators
SEPARATORS = " ,_\t"
#: the keys of a library file, of its [library] table and of each [[units]] entry
FILE_KEYS = ("library", "units")
LIBRARY_KEYS = ("name", "description")
ENTRY_KEYS = ("symbol", "mode", "unit")
#: the unit parameters two units of one library must share, beside their cross-section lines
SHARED_FIELDS = ("element_order", "element_size", "width", "side_wall", "end_cap", "body_material")


def check_symbol(symbol: object, where: str = "unit library") -> str:
    """A unit type's symbol: one lower-case letter ``a``-``z``, else a :class:`UnitLibraryError`.

    Digits are the orientation of the first type (``0``/``1``), upper case is a unit turned
    over, and spaces, commas and underscores separate groups in a design: none can be a symbol.

    Examples
    --------
    >>> check_symbol("e")
    'e'
    >>> check_symbol("1")
    Traceback (most recent call last):
    ...
    pneumorph.errors.UnitLibraryError: unit library: symbol '1' is a digit; the digits 0 and 1 write the
    orientation of the library's first unit type, so symbols are the lower-case letters a-z
    """
    if not isinstance(symbol, str) or len(symbol) != 1:
        raise UnitLibraryError(f"{where}: a symbol must be one character (a lower-case letter a-z), got {symbol!r}")
    if symbol.isdigit():
        raise UnitLibraryError(
            f"{where}: symbol {symbol!r} is a digit; the digits 0 and 1 write the orientation of the library's first "
            "unit type, so symbols are the lower-case letters a-z")
    if symbol in string.ascii_uppercase:
        raise UnitLibraryError(
            f"{where}: symbol {symbol!r} is upper case; upper case writes a unit turned 180 degrees (orientation 1), "
            f"so name the type by {symbol.lower()!r}")
    if symbol not in SYMBOLS:
        raise UnitLibraryError(f"{where}: symbol {symbol!r} is not allowed; symbols are the lower-case letters a-z")
    return symbol


def check_joinable(units: Mapping[str, UnitSpec], where: str = "unit library") -> None:
    """Refuse units that cannot follow each other in one conforming mesh.

    The actuator is one tensor grid: every unit's lines across the height (both orientations)
    and the width must be the same, and so must the parameters of :data:`SHARED_FIELDS` and
    the stiff layer's material (of the units that have one). Then the faces between units
    carry the same nodes, and every unit is meshed as it would be alone.

    Raises
    ------
    UnitLibraryError
        Naming the two symbols and what differs.

    Examples
    --------
    >>> check_joinable({"a": UnitSpec(), "s": UnitSpec(pitch=7.0, end_wall=1.5)})
    >>> check_joinable({"a": UnitSpec(), "t": UnitSpec(cavity_height=5.0)})
    Traceback (most recent call last):
    ...
    pneumorph.errors.UnitLibraryError: unit library: units 'a' and 't' cannot be joined: their heights differ
    (12 mm and 11 mm); the units of a library share one cross-section
    """
    items = list(units.items())
    if len(items) < 2:
        return
    first, ref = items[0]
    ref_y, ref_z = cross_section_lines(ref)
    layered = [(s, u) for s, u in items if u.layer > 0]
    for symbol, unit in items[1:]:
        pair = f"{where}: units {first!r} and {symbol!r} cannot be joined"
        if unit.height != ref.height:
            raise UnitLibraryError(f"{pair}: their heights differ ({ref.height:g} mm and {unit.height:g} mm); "
                                   "the units of a library share one cross-section")
        for key in SHARED_FIELDS:
            a, b = getattr(ref, key), getattr(unit, key)
            if a != b:
                raise UnitLibraryError(f"{pair}: their {key} differ ({a!r} and {b!r}); the units of a library share "
                                       "one mesh and one body material")
        y, z = cross_section_lines(unit)
        for axis, mine, theirs in (("height (y)", ref_y, y), ("width (z)", ref_z, z)):
            if len(mine) != len(theirs) or not np.allclose(mine, theirs, rtol=0.0, atol=1e-9):
                raise UnitLibraryError(
                    f"{pair}: their grid lines across the {axis} differ ({_lines(mine)} and {_lines(theirs)} mm), "
                    "so the faces between them would not share nodes; move the walls, cavity or layer of one onto "
                    "the other's lines (both orientations count)")
    if layered:
        (s0, u0), *rest = layered
        for symbol, unit in rest:
            if unit.layer_material != u0.layer_material:
                raise UnitLibraryError(
                    f"{where}: units {s0!r} and {symbol!r} cannot be joined: their stiff layers are of different "
                    f"materials ({u0.layer_material!r} and {unit.layer_material!r}); the models give the layer one "
                    "material")


def _lines(values: Any) -> str:
    return ", ".join(f"{v:g}" for v in values)


@dataclass(frozen=True)
class UnitLibrary:
    """Unit types by symbol: the alphabet of the designs that mix them.

    Parameters
    ----------
    symbols : tuple of str
        One lower-case letter per type, in the file's order; the first is the library's
        default type, which the digits 0/1 of a design stand for.
    units : tuple of UnitSpec
        The unit of each symbol.
    modes : tuple of str
        A label per type (its deformation mode); empty: the unit's name.
    name, description, source : str
        What the library is called, says of itself, and where it was read from.

    Raises
    ------
    UnitLibraryError
        No units, a bad or repeated symbol, or units that cannot be joined (:func:`check_joinable`).

    Examples
    --------
    >>> lib = UnitLibrary(("a", "r"), (UnitSpec(), UnitSpec(solid=True, name="rigid")))
    >>> lib["r"].solid, "r" in lib, len(lib), lib.modes
    (True, True, 2, ('unit', 'rigid'))
    >>> UnitLibrary(("a", "a"), (UnitSpec(), UnitSpec()))
    Traceback (most recent call last):
    ...
    pneumorph.errors.UnitLibraryError: unit library: symbol 'a' is given twice (units 1 and 2); every unit type needs
    its own symbol
    """

    symbols: tuple[str, ...]
    units: tuple[UnitSpec, ...]
    modes: tuple[str, ...] = ()
    name: str = "library"
    description: str = ""
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        where = self.source or "unit library"
        object.__setattr__(self, "symbols", tuple(self.symbols))
        object.__setattr__(self, "units", tuple(self.units))
        if not self.symbols:
            raise UnitLibraryError(f"{where}: the library has no units; give at least one [[units]] entry")
        if len(self.units) != len(self.symbols):
            raise UnitLibraryError(f"{where}: {len(self.symbols)} symbols for {len(self.units)} units")
        seen: dict[str, int] = {}
        for i, (symbol, unit) in enumerate(zip(self.symbols, self.units, strict=True), 1):
            check_symbol(symbol, where)
            if symbol in seen:
                raise UnitLibraryError(f"{where}: symbol {symbol!r} is given twice (units {seen[symbol]} and {i}); "
                                       "every unit type needs its own symbol")
            seen[symbol] = i
            if not isinstance(unit, UnitSpec):
                raise UnitLibraryError(f"{where}: unit {symbol!r} must be a UnitSpec, got {type(unit).__name__}")
        modes = tuple(self.modes) or tuple(u.name for u in self.units)
        if len(modes) != len(self.units) or not all(isinstance(m, str) for m in modes):
            raise UnitLibraryError(f"{where}: give one mode label (text) per unit, got {self.modes!r}")
        object.__setattr__(self, "modes", tuple(m or u.name for m, u in zip(modes, self.units, strict=True)))
        for key in ("name", "description"):
            if not isinstance(getattr(self, key), str):
                raise UnitLibraryError(f"{where}: library {key} must be a text, got {getattr(self, key)!r}")
        check_joinable(dict(zip(self.symbols, self.units, strict=True)), where)

    # -- mapping -------------------------------------------------------------------------
    def __getitem__(self, symbol: str) -> UnitSpec:
        try:
            return self.units[self.symbols.index(symbol)]
        except ValueError:
            raise UnitLibraryError(f"no unit {symbol!r} in {self.name!r}; its symbols: "
                                   f"{', '.join(self.symbols)}") from None

    def __contains__(self, symbol: object) -> bool:
        return symbol in self.symbols

    def __iter__(self) -> Iterator[str]:
        return iter(self.symbols)

    def __len__(self) -> int:
        return len(self.symbols)

    @property
    def default(self) -> str:
        """The first symbol: the type that the digits 0/1 of a design stand for."""
        return self.symbols[0]

    @property
    def symmetric(self) -> tuple[str, ...]:
        """The symbols of the types whose turned-over unit is the same body (:attr:`UnitSpec.symmetric`).

        They have one orientation: one letter in designs, one set of windows in chain tables.

        >>> builtin_library().symmetric
        ('e',)
        """
        return tuple(s for s, u in zip(self.symbols, self.units, strict=True) if u.symmetric)

    @property
    def alphabet(self) -> tuple[str, ...]:
        """The symbols designs over several types are written in; empty for one type (0/1 designs).

        >>> builtin_library().alphabet, UnitLibrary.single().alphabet
        (('a', 'e', 'r', 's'), ())
        """
        return () if self.is_single else self.symbols

    @property
    def symmetric_types(self) -> tuple[int, ...]:
        """Indices in :attr:`alphabet` of the :attr:`symmetric` types (empty for one type).

        >>> builtin_library().symmetric_types
        (1,)
        """
        return tuple(self.alphabet.index(t) for t in self.symmetric) if self.alphabet else ()

    @property
    def is_single(self) -> bool:
        """One type only: its designs are written as 0/1 digits."""
        return len(self.symbols) == 1

    # -- construction ----------------------------------------------------------------------
    @classmethod
    def single(cls, spec: UnitSpec | None = None, symbol: str = "a") -> UnitLibrary:
        """The library of one unit type: the designs of one-type actuators (0/1 strings).

        >>> UnitLibrary.single().is_single
        True
        """
        return cls((symbol,), (spec if spec is not None else UnitSpec(),), name="single")

    def to_dict(self) -> dict[str, Any]:
        """The library for provenance and fingerprints: name and every unit's description.

        >>> UnitLibrary.single().to_dict()["units"][0]["symbol"]
        'a'
        """
        return {"name": self.name, "description": self.description,
                "units": [{"symbol": s, "mode": m, "unit": u.to_dict()}
                          for s, m, u in zip(self.symbols, self.modes, self.units, strict=True)]}

    def fingerprint(self) -> str:
        """A short hash of :meth:`to_dict` (the units' parameters decide it, not the file's path).

        >>> len(builtin_library().fingerprint())
        16
        """
        return digest(self.to_dict())

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "unit library", base: Path | None = None) -> UnitLibrary:
        """Build from the tables of a library file; ``base`` is the folder unit files are relative to.

        Raises
        ------
        UnitLibraryError
            Unknown keys (listing the known ones), a missing or bad symbol, a unit that does
            not validate (naming its symbol), or any error of the class itself.

        Examples
        --------
        >>> UnitLibrary.from_dict({"units": [{"symbol": "a", "unit": {}}, {"symbol": "r", "unit": {"solid": True}}]})[
        ...     "r"].solid
        True
        >>> UnitLibrary.from_dict({"units": [{"symbol": "a", "unit": {"pich": 7.0}}]})
        Traceback (most recent call last):
        ...
        pneumorph.errors.UnitLibraryError: unit library: unit 'a' (entry 1): unknown unit parameter(s) pich;
        known: ...
        """
        _check_keys(data, FILE_KEYS, source, "the file")
        head = data.get("library", {})
        if not isinstance(head, Mapping):
            raise UnitLibraryError(f"{source}: [library] must be a table with {', '.join(LIBRARY_KEYS)}")
        _check_keys(head, LIBRARY_KEYS, source, "[library]")
        entries = data.get("units")
        if not isinstance(entries, list) or not entries:
            raise UnitLibraryError(f"{source}: expected [[units]] entries, each with a symbol and a unit")
        symbols, units, modes = [], [], []
        for i, entry in enumerate(entries, 1):
            if not isinstance(entry, Mapping):
                raise UnitLibraryError(f"{source}: [[units]] entry {i} must be a table, got {entry!r}")
            _check_keys(entry, ENTRY_KEYS, source, f"[[units]] entry {i}")
            if "symbol" not in entry:
                raise UnitLibraryError(f"{source}: [[units]] entry {i} has no symbol")
            symbol = check_symbol(entry["symbol"], f"{source}: [[units]] entry {i}")
            mode = entry.get("mode", "")
            if not isinstance(mode, str):
                raise UnitLibraryError(f"{source}: unit {symbol!r} (entry {i}): mode must be a text, got {mode!r}")
            symbols.append(symbol)
            units.append(_entry_unit(entry.get("unit", {}), f"{source}: unit {symbol!r} (entry {i})", base))
            modes.append(mode)
        return cls(tuple(symbols), tuple(units), tuple(modes), name=head.get("name", "library"),
                   description=head.get("description", ""), source=source)

    @classmethod
    def from_toml(cls, path: str | Path) -> UnitLibrary:
        """Read a library file (module docstring); unit files named in it are relative to it.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> d = pathlib.Path(tempfile.mkdtemp())
        >>> _ = (d / "short.toml").write_text("[unit]\\npitch = 7.0\\nend_wall = 1.5\\n")
        >>> text = '[[units]]\\nsymbol = "a"\\n[[units]]\\nsymbol = "s"\\nunit = "short.toml"\\n'
        >>> _ = (d / "lib.toml").write_text(text)
        >>> UnitLibrary.from_toml(d / "lib.toml")["s"].cavity_length
        4.0
        """
        from pneumorph.io.files import read_toml

        p = Path(path)
        return cls.from_dict(read_toml(p, "unit library", UnitLibraryError), source=str(p), base=p.parent)


def _check_keys(table: Mapping[str, Any], known: tuple[str, ...], source: str, where: str) -> None:
    unknown = sorted(set(table) - set(known))
    if unknown:
        raise UnitLibraryError(f"{source}: unknown key(s) {', '.join(unknown)} in {where}; known: {', '.join(known)}")


def _entry_unit(value: Any, where: str, base: Path | None) -> UnitSpec:
    """The unit of an entry: an inline table of parameters or the path of a unit file."""
    try:
        if isinstance(value, str):
            path = Path(value)
            if not path.is_absolute() and base is not None:
                path = base / path
            return UnitSpec.from_toml(path)
        if isinstance(value, Mapping):
            spec = UnitSpec.from_dict(dict(value), source=where)
            check_manufacturable(spec, f"{where}: unit")
            return spec
    except UnitLibraryError:
        raise
    except GeometryError as exc:
        message = str(exc)
        raise UnitLibraryError(message if message.startswith(where) else f"{where}: {message}") from None
    raise UnitLibraryError(f"{where}: unit must be a table of parameters or the path of a unit file, got {value!r}")


#: The libraries that ship with pneumorph, by the name a setting gives (``--library builtin``), and their data files
BUILTIN_LIBRARIES: dict[str, str] = {"builtin": "units.toml", "spatial": "spatial.toml", "modes": "modes.toml"}


def builtin_library(name: str = "builtin") -> UnitLibrary:
    """A library that ships with pneumorph (:data:`BUILTIN_LIBRARIES`, in ``geometry/data``).

    ``"builtin"`` (``units.toml``, planar): ``a`` the bending unit (the default
    :class:`UnitSpec`), ``e`` an extending unit, ``r`` a near-rigid one and ``s`` a
    short-pitch one. ``"spatial"`` (``spatial.toml``): ``a`` and ``l``, a sideways unit
    (``layer_side``) that bends out of the plane of ``a``. ``"modes"`` (``modes.toml``):
    ``a``, ``b`` a bimodal unit, ``m`` a low-bending one and ``p`` the bimodal unit with the
    composite as cast (``bottom_material``) (``docs/unit-library.md``).

    Raises
    ------
    UnitLibraryError
        ``name`` is no built-in library (the message lists them).

    Examples
    --------
    >>> [f"{s}: {m}" for s, m in zip(builtin_library().symbols, builtin_library().modes)]
    ['a: bending', 'e: extending', 'r: near-rigid', 's: short-pitch']
    >>> builtin_library("spatial").symbols, builtin_library("spatial")["l"].layer_side
    (('a', 'l'), True)
    >>> builtin_library("modes").modes
    ('bending', 'bimodal', 'low-bending', 'bimodal, paper')
    >>> builtin_library("planar")
    Traceback (most recent call last):
    ...
    pneumorph.errors.UnitLibraryError: no built-in unit library 'planar'; the built-in ones: builtin, spatial, modes
    """
    if name not in BUILTIN_LIBRARIES:
        raise UnitLibraryError(f"no built-in unit library {name!r}; the built-in ones: {', '.join(BUILTIN_LIBRARIES)}")
    text = resources.files("pneumorph.geometry").joinpath(f"data/{BUILTIN_LIBRARIES[name]}").read_text("utf-8")
    where = "built-in unit library" if name == "builtin" else f"built-in unit library {name!r}"
    return UnitLibrary.from_dict(tomllib.loads(text), source=where)


__all__ = ["BUILTIN_LIBRARIES", "SYMBOLS", "UnitLibrary", "builtin_library", "check_joinable", "check_symbol"]

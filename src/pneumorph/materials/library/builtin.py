"""The material library: the dissertation's silicones, composites, paper and filler law.

The data live in ``data/materials.toml`` (shipped with the package) with every number as
printed in its source and its unit, convention and source named; users add materials from
their own TOML files with the same schema (:func:`register_toml`, :func:`load_library`).
This module turns them into immutable :class:`Material` objects in the internal units
(MPa, tonne/mm^3, 1/K, mm) - the conversion happens in one place, :func:`to_internal`.

Examples
--------
>>> from pneumorph.materials.library import builtin as library
>>> ms15 = library.get("Mold Star 15")
>>> ms15.name, round(ms15.shear_modulus, 4), ms15.bulk_modulus.value
('mold_star_15', 0.1314, 0.119)
>>> ms15.density.value, ms15.density.printed, ms15.density.printed_unit
(1.139e-09, 1139, 'kg/m^3')
>>> library.get("ecoflex-0030").assumed
('bulk_modulus',)
"""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

from pneumorph.errors import MaterialDataError, UnknownMaterialError
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.materials.library.material import (
    BUILTIN_ORIGIN,
    Library,
    Material,
    Quantity,
    normalise,
)
from pneumorph.materials.library.schema import load_library, parse_library
from pneumorph.materials.library.units import INTERNAL_UNITS, UNITS, to_internal

__all__ = [
    "INTERNAL_UNITS",
    "UNITS",
    "Library",
    "Material",
    "Quantity",
    "builtin",
    "clear_registered",
    "eq_5_2",
    "filler_names",
    "get",
    "get_filler",
    "load_library",
    "names",
    "normalise",
    "parse_library",
    "register_toml",
    "to_internal",
]


_builtin: Library | None = None
_registered: list[Library] = []


def builtin() -> Library:
    """The library shipped with pneumorph (read once, then cached)."""
    global _builtin
    if _builtin is None:
        text = resources.files("pneumorph.materials").joinpath("data/materials.toml").read_text("utf-8")
        _builtin = parse_library(tomllib.loads(text), BUILTIN_ORIGIN)
    return _builtin


def _libraries() -> list[Library]:
    """Registered user libraries (latest first), then the built-in one."""
    return [*reversed(_registered), builtin()]


def names() -> tuple[str, ...]:
    """Canonical names of every available material (built-in first, then registered).

    Examples
    --------
    >>> "mold_star_15" in names()
    True
    """
    seen: list[str] = []
    for lib in reversed(_libraries()):
        seen.extend(n for n in lib.names() if n not in seen)
    return tuple(seen)


def get(name: str) -> Material:
    """The material called ``name`` (case, spaces, hyphens and dots do not matter).

    Registered user materials take precedence over built-in ones of the same name (only
    possible with ``register_toml(..., replace=True)``).

    Raises
    ------
    UnknownMaterialError
        If no library holds the name; the message lists the known ones.

    Examples
    --------
    >>> get("mold-star-15") is get("Mold Star 15")
    True
    """
    for lib in _libraries():
        found = lib.find(name)
        if found is not None:
            return found
    raise UnknownMaterialError(name, names())


def filler_names() -> tuple[str, ...]:
    """Names of every available filler law."""
    seen: list[str] = []
    for lib in reversed(_libraries()):
        seen.extend(n for n in lib.filler_names() if n not in seen)
    return tuple(seen)


def get_filler(name: str = "ellis2020_eq5_2") -> FillerLaw:
    """The filler law called ``name`` (default: Eq 5.2 of the dissertation).

    Examples
    --------
    >>> round(float(get_filler().modulus(0.0)), 4)
    0.0643
    """
    for lib in _libraries():
        if normalise(name) in lib.filler_names():
            return lib.filler(name)
    raise UnknownMaterialError(name, filler_names())


def eq_5_2() -> FillerLaw:
    """The dissertation's filler law, Eq 5.2, from the built-in library.

    Examples
    --------
    >>> law = eq_5_2()
    >>> law.coefficients, [x * 1e3 for x in law.pressure_range]
    ((0.0643, -1.82, 12.4), [0.0, 45.0])
    """
    return get_filler("ellis2020_eq5_2")


def register_toml(path: str | Path, replace: bool = False) -> Library:
    """Add the materials and fillers of a user TOML file to the library.

    Parameters
    ----------
    path : str or Path
        A file with the schema of ``data/materials.toml``.
    replace : bool
        Allow entries whose names (or aliases) are already taken; the new ones then take
        precedence. Without it, a clash raises :class:`MaterialDataError`.

    Returns
    -------
    Library
        The file's contents.
    """
    lib = load_library(path)
    if not replace:
        for m in lib.materials:
            for alias in (m.name, m.display_name, *m.aliases):
                for other in _libraries():
                    clash = other.find(alias)
                    if clash is not None:
                        raise MaterialDataError(
                            f"{lib.path}: [materials.{m.name}]: name {alias!r} is already used by "
                            f"{clash.name!r} from {other.path}; rename it or pass replace=True"
                        )
        for f in lib.fillers:
            if f.name in filler_names():
                raise MaterialDataError(
                    f"{lib.path}: [fillers.{f.name}]: name already used; rename it or pass replace=True"
                )
    _registered.append(lib)
    return lib


def clear_registered() -> None:
    """Forget every registered user file (the built-in library stays)."""
    _registered.clear()

"""The design space of the unit optimisation: which dimensions vary, between which bounds.

A :class:`DesignSpace` is a base unit (:class:`~pneumorph.geometry.unit.UnitSpec`, the
built-in unit by default) and a few of its lengths, each between two bounds (mm), rounded
to a resolution (0.1 mm by default: what a mould can hold, and the same candidate is then
the same cache entry). The pitch stays that of the base unit unless it is made a
variable, so an optimised unit fits actuators of the base unit's length.

:meth:`DesignSpace.check` builds the unit at every corner of the box and meshes it, before
any solve: every constraint of a unit on these lengths (walls that leave a cavity, a slit
above the layer, an element size that fits) is linear in them, so a box whose corners all
mesh meshes everywhere.

Examples
--------
>>> space = DesignSpace.default()
>>> space.names
('cavity_height', 'end_wall', 'wall', 'layer')
>>> space.unit([6.0, 3.0, 1.5, 3.0]) == UnitSpec(name="unitopt")
True
>>> parse_variable("wall=1:2.5")
Variable(name='wall', low=1.0, high=2.5)
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import GeometryError, SettingsError
from pneumorph.geometry.limits import check_manufacturable
from pneumorph.geometry.unit import UnitSpec

FloatArray = NDArray[np.float64]

#: the unit dimensions the optimisation may vary (mm), in the order of :meth:`DesignSpace.default`'s
VARIABLES = ("cavity_height", "end_wall", "wall", "layer", "side_wall", "pitch")

#: the default box (mm): around the built-in unit (6, 3, 1.5, 3), within what meshes at the built-in
#: 10.5 mm pitch (a cavity at least 2.5 mm long) and what the geometry study screened (section History of
#: docs/unit-geometry.md: cavities 4.5-12 mm high, end walls 1.5-3 mm)
DEFAULT_BOUNDS: dict[str, tuple[float, float]] = {
    "cavity_height": (3.0, 9.0),
    "end_wall": (1.5, 4.0),
    "wall": (1.0, 2.5),
    "layer": (1.5, 4.5),
}


@dataclass(frozen=True)
class Variable:
    """One varied dimension of the unit: a :class:`UnitSpec` length between two bounds (mm).

    Raises
    ------
    SettingsError
        An unknown dimension (the message lists the known ones), bounds that are not finite
        or not ``0 < low < high``.
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        if self.name not in VARIABLES:
            raise SettingsError(f"unknown unit variable {self.name!r}; known: {', '.join(VARIABLES)}")
        for bound in (self.low, self.high):
            if isinstance(bound, bool) or not isinstance(bound, (int, float)) or not math.isfinite(bound):
                raise SettingsError(f"the bounds of {self.name} must be finite numbers of mm, got {bound!r}")
        object.__setattr__(self, "low", float(self.low))
        object.__setattr__(self, "high", float(self.high))
        if not 0.0 < self.low < self.high:
            raise SettingsError(f"the bounds of {self.name} must satisfy 0 < low < high, got {self.low:g}:"
                                f"{self.high:g} mm")


def parse_variable(text: str) -> Variable:
    """A variable from ``NAME=LOW:HIGH`` (mm), as the command line writes it.

    Raises
    ------
    SettingsError
        Not of that form, an unknown name, or bad bounds.

    Examples
    --------
    >>> parse_variable("end_wall=2:3.5").high
    3.5
    >>> parse_variable("height=1:2")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: unknown unit variable 'height'; known: cavity_height, end_wall, wall,
        layer, side_wall, pitch
    """
    name, eq, bounds = str(text).partition("=")
    low, colon, high = bounds.partition(":")
    if not eq or not colon:
        raise SettingsError(f"a unit variable is written NAME=LOW:HIGH (mm), e.g. wall=1:2.5; got {text!r}")
    try:
        lo, hi = float(low), float(high)
    except ValueError:
        raise SettingsError(f"the bounds of {name.strip()} must be numbers of mm, got {bounds!r}") from None
    return Variable(name.strip(), lo, hi)


@dataclass(frozen=True)
class DesignSpace:
    """A base unit and the dimensions that vary (see the module docstring).

    Parameters
    ----------
    variables : sequence of Variable
        At least one, each name once.
    base : UnitSpec
        The unit whose other dimensions, materials and mesh size every candidate keeps.
    resolution : float
        Candidates' dimensions are rounded to this (mm; 0 keeps them as they are).

    Raises
    ------
    SettingsError
        No variable, a name given twice, a resolution that is negative or not finite.
    """

    variables: tuple[Variable, ...]
    base: UnitSpec = field(default_factory=lambda: UnitSpec(name="unitopt"))
    resolution: float = 0.1

    def __post_init__(self) -> None:
        object.__setattr__(self, "variables", tuple(self.variables))
        if not self.variables:
            raise SettingsError("the unit optimisation needs at least one variable")
        names = [v.name for v in self.variables]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise SettingsError(f"unit variable(s) given twice: {', '.join(twice)}")
        if not isinstance(self.base, UnitSpec):
            raise SettingsError(f"the base unit must be a UnitSpec, got {type(self.base).__name__}")
        r = self.resolution
        if isinstance(r, bool) or not isinstance(r, (int, float)) or not math.isfinite(r) or r < 0:
            raise SettingsError(f"the resolution must be a finite number of mm >= 0, got {r!r}")

    @classmethod
    def default(cls, base: UnitSpec | None = None) -> DesignSpace:
        """The four variables of :data:`DEFAULT_BOUNDS` around ``base`` (the built-in unit)."""
        return cls(tuple(Variable(n, *b) for n, b in DEFAULT_BOUNDS.items()),
                   base if base is not None else UnitSpec(name="unitopt"))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(v.name for v in self.variables)

    @property
    def lower(self) -> FloatArray:
        return np.array([v.low for v in self.variables])

    @property
    def upper(self) -> FloatArray:
        return np.array([v.high for v in self.variables])

    def snap(self, x: Sequence[float] | FloatArray) -> FloatArray:
        """``x`` clipped to the bounds and rounded to the resolution (staying inside the bounds).

        >>> DesignSpace.default().snap([6.04, 0.0, 1.55, 9.0]).tolist()
        [6.0, 1.5, 1.6, 4.5]
        """
        v = np.clip(np.asarray(x, dtype=float), self.lower, self.upper)
        if self.resolution > 0:
            r = self.resolution
            snapped = np.round(np.round(v / r) * r, 6)
            inside = (snapped >= self.lower - 1e-9) & (snapped <= self.upper + 1e-9)
            v = np.where(inside, snapped, v)
        return np.asarray(v, dtype=float)

    def values(self, x: Sequence[float] | FloatArray) -> dict[str, float]:
        """The candidate's dimensions by name (snapped)."""
        return {n: float(value) for n, value in zip(self.names, self.snap(x), strict=True)}

    def unit(self, x: Sequence[float] | FloatArray, name: str | None = None) -> UnitSpec:
        """The base unit with the candidate's dimensions (snapped).

        Raises
        ------
        GeometryError
            The dimensions make no unit (see :class:`UnitSpec`).
        """
        changes: dict[str, Any] = dict(self.values(x))
        if name is not None:
            changes["name"] = name
        return replace(self.base, **changes)

    def base_point(self) -> FloatArray:
        """The base unit's values of the variables (may lie outside the bounds)."""
        return np.array([float(getattr(self.base, n)) for n in self.names])

    def check(self) -> None:
        """Build and mesh (3D, one unit) the unit at every corner of the box; nothing is solved. Every corner must
        be a unit a mould casts (:func:`~pneumorph.geometry.limits.check_manufacturable`): the box's units then
        are too (walls, layer and cavity grow or shrink along each variable).

        Raises
        ------
        GeometryError
            A corner that makes no unit, is not manufacturable or does not mesh, naming the corner.

        Examples
        --------
        >>> DesignSpace((Variable("end_wall", 2.0, 5.5),)).check()
        Traceback (most recent call last):
        ...
        pneumorph.errors.GeometryError: the bounds do not always make a unit: at end_wall=5.5 mm: the walls
            leave no cavity: pitch 10.5 mm - 2 x end wall 5.5 mm - slit 0.0 mm = -0.5 mm
        """
        from pneumorph.geometry.assembly import assemble

        for corner in itertools.product(*[(v.low, v.high) for v in self.variables]):
            where = ", ".join(f"{n}={value:g}" for n, value in zip(self.names, corner, strict=True))
            try:
                corner_values: dict[str, Any] = dict(zip(self.names, corner, strict=True))
                spec = replace(self.base, **corner_values)
                check_manufacturable(spec)
                assemble(spec, "0", dim=3, half=True)
            except GeometryError as exc:
                raise GeometryError(f"the bounds do not always make a unit: at {where} mm: {exc}") from None

    def to_dict(self) -> dict[str, object]:
        return {"variables": {v.name: [v.low, v.high] for v in self.variables}, "resolution": self.resolution,
                "base": self.base.to_dict()}


__all__ = ["DEFAULT_BOUNDS", "VARIABLES", "DesignSpace", "Variable", "parse_variable"]

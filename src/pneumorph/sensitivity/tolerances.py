"""Mould tolerances (appendix E.2): the unit's thicknesses perturbed within a tolerance class.

The dissertation varied three thicknesses of Fig E.4 by +-0.1 mm (FDM-printed moulds) and
+-0.02 mm (machined aluminium moulds): the side walls, the Mold Star wall and the Smooth-Sil
layer. In :class:`~pneumorph.geometry.unit.UnitSpec` these are ``side_wall``, ``wall`` (the
Mold Star walls on both sides of the cavity) and ``layer``. A :class:`Tolerance` draws
seeded random offsets (uniform within the class), the one-at-a-time extremes the
dissertation ran, and the corners of the box; :func:`perturbed` applies offsets to a unit.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import product

import numpy as np
from numpy.typing import NDArray

from pneumorph import checks
from pneumorph.errors import SettingsError
from pneumorph.geometry.unit import UnitSpec

FloatArray = NDArray[np.float64]

#: Fig E.4: the sides, the Mold Star wall, the Smooth-Sil layer
FIELDS = ("side_wall", "wall", "layer")
#: the tolerance classes of appendix E.2 (mm): FDM-printed and machined moulds
PRINTED, MACHINED = 0.1, 0.02


@dataclass(frozen=True)
class Tolerance:
    """A tolerance class: every thickness in ``fields`` within ``+-tolerance`` mm.

    Examples
    --------
    >>> t = Tolerance(0.1)
    >>> t.samples(2, seed=0).shape, t.extremes().tolist()[:2]
    ((2, 3), [[-0.1, 0.0, 0.0], [0.1, 0.0, 0.0]])
    >>> Tolerance(-0.1)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: tolerance must be a finite number >= 0 and <= 1 (mm), got -0.1
    """

    tolerance: float = PRINTED
    fields: tuple[str, ...] = FIELDS

    def __post_init__(self) -> None:
        object.__setattr__(self, "tolerance", checks.real(self.tolerance, "tolerance", 0.0, 1.0, unit="mm"))
        if not self.fields or len(set(self.fields)) != len(self.fields):
            raise SettingsError(f"tolerance fields must be distinct unit thicknesses, got {self.fields!r}")
        lengths = {"side_wall", "wall", "end_wall", "layer", "cavity_height", "width", "pitch", "end_cap"}
        unknown = [f for f in self.fields if f not in lengths]
        if unknown:
            raise SettingsError(f"unknown unit thickness(es) {', '.join(unknown)}; known: {', '.join(sorted(lengths))}")

    def samples(self, n: int, seed: int) -> FloatArray:
        """``n`` offsets (n, fields), each uniform in ``[-t, t]``, from a seeded generator."""
        n = checks.integer(n, "samples", 1, 100_000)
        rng = np.random.default_rng(checks.integer(seed, "seed", 0, 2**32 - 1))
        return rng.uniform(-self.tolerance, self.tolerance, size=(n, len(self.fields)))

    def extremes(self) -> FloatArray:
        """One thickness at a time at ``-t`` then ``+t`` (appendix E.2), shape (2 fields, fields)."""
        m = len(self.fields)
        out = np.zeros((2 * m, m))
        for i in range(m):
            out[2 * i, i], out[2 * i + 1, i] = -self.tolerance, self.tolerance
        return out

    def corners(self) -> FloatArray:
        """Every combination of ``-t`` and ``+t``, shape (2^fields, fields)."""
        return np.array(list(product((-self.tolerance, self.tolerance), repeat=len(self.fields))), dtype=float)


def perturbed(unit: UnitSpec, fields: tuple[str, ...], offsets: FloatArray) -> UnitSpec:
    """``unit`` with ``offsets`` (mm) added to its ``fields``.

    Raises
    ------
    GeometryError
        A thickness the offsets make impossible (the unit's own checks).

    Examples
    --------
    >>> perturbed(UnitSpec(), FIELDS, np.array([0.1, -0.1, 0.05])).layer
    3.05
    """
    values = {f: round(float(getattr(unit, f)) + float(d), 12) for f, d in zip(fields, offsets, strict=True)}
    return replace(unit, **values)


__all__ = ["FIELDS", "MACHINED", "PRINTED", "Tolerance", "perturbed"]

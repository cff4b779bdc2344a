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
from typing import Any

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

    def check(self, unit: UnitSpec) -> None:
        """Refuse a tolerance as large as one of the unit's thicknesses it varies.

        >>> Tolerance(0.9).check(UnitSpec(side_wall=0.5))
        Traceback (most recent call last):
        ...
        pneumorph.errors.SettingsError: the tolerance +-0.9 mm is not smaller than the unit's side_wall (0.5 mm): a
        mould within it could leave no side_wall; give a smaller tolerance (--tolerance)
        """
        for f in self.fields:
            value = float(getattr(unit, f))
            if f == "layer" and value == 0.0:
                continue  # a unit without a layer has none to vary
            if self.tolerance >= value:
                raise SettingsError(f"the tolerance +-{self.tolerance:g} mm is not smaller than the unit's {f} "
                                    f"({value:g} mm): a mould within it could leave no {f}; give a smaller "
                                    "tolerance (--tolerance)")

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


def _grid_shape(unit: UnitSpec) -> tuple[int, int]:
    """Points and cells of a 2-unit half 3D mesh with both orientations: the grid's topology."""
    from pneumorph.geometry.assembly import assemble

    mesh = assemble(unit, "01", dim=3, half=True)
    return len(mesh.points), len(mesh.cells)


def matched_element_size(unit: UnitSpec, tolerance: Tolerance, steps: int = 40) -> float:
    """The smallest element size (>= the unit's) that meshes every unit of the tolerance box alike.

    The mesh has a grid line at every interface and at most ``element_size`` between lines,
    so a thickness that grows past a multiple of the element size gains a layer of
    elements across the whole actuator: a change of mesh as large as the tolerance's own
    effect (the built-in unit's walls are exactly one 1.5 mm element; at 1.6 mm they would
    be two). Meshing every case with the same cell counts isolates the geometry, as the
    dissertation's mesh update did (appendix C.4). The counts are monotone in each
    segment's length, which is affine in the offsets, so checking the corners of the box
    checks every unit in it.

    Raises
    ------
    GeometryError
        No element size up to ``1 + steps / 100`` times the unit's keeps the topology.

    Examples
    --------
    >>> matched_element_size(UnitSpec(), Tolerance(0.1))   # wall 1.4 + layer 3.1: a 1.7 mm segment
    1.71
    """
    from pneumorph.errors import GeometryError

    tolerance.check(unit)
    corners = [perturbed(unit, tolerance.fields, c) for c in tolerance.corners()]
    for k in range(steps + 1):
        size = round(unit.element_size * (1 + k / 100), 6)
        shapes = {_grid_shape(replace(u, element_size=size)) for u in [replace(unit, element_size=size), *corners]}
        if len(shapes) == 1:
            return size
    raise GeometryError(f"no element size from {unit.element_size:g} to {unit.element_size * (1 + steps / 100):g} mm "
                        f"meshes every unit within +-{tolerance.tolerance:g} mm alike; give the unit a smaller "
                        "tolerance or an element size that is not a divisor of its thicknesses")


def box_units(unit: UnitSpec, tolerance: Tolerance, offsets: Any) -> tuple[UnitSpec, list[UnitSpec]]:
    """The nominal ``unit`` at :func:`matched_element_size`, and it moved to each row of ``offsets``.

    Every unit of a tolerance study, a table or a robustness check is built here, so all share
    the nominal mesh's cell counts.

    Examples
    --------
    >>> nominal, (thin,) = box_units(UnitSpec(), Tolerance(0.1), [[-0.1, 0.0, 0.0]])
    >>> nominal.element_size, thin.side_wall, thin.element_size
    (1.71, 1.4, 1.71)
    """
    nominal = replace(unit, element_size=matched_element_size(unit, tolerance))
    return nominal, [perturbed(nominal, tolerance.fields, np.asarray(o, dtype=float)) for o in offsets]


def corner_label(offsets: Any) -> str:
    """``"corner - + +"``: which end of each thickness a corner of the tolerance box takes.

    >>> corner_label([-0.1, 0.1, 0.1])
    'corner - + +'
    """
    return "corner " + " ".join("-" if v < 0 else "+" for v in offsets)


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
    values: dict[str, Any] = {f: round(float(getattr(unit, f)) + float(d), 12)
                              for f, d in zip(fields, offsets, strict=True)}
    return replace(unit, **values)


__all__ = ["FIELDS", "MACHINED", "PRINTED", "Tolerance", "box_units", "corner_label", "matched_element_size",
           "perturbed"]

"""Mesh convergence: a design solved at several element sizes, its observed order and limit.

The 3D model meshes the unit with a grid line at every interface of its walls, layer and
cavity and at most ``element_size`` between lines, so refining by a factor does not divide
every cell by it. A mesh is therefore measured by its *representative cell size*
``h = (V / N)^(1/3)`` (``V`` the meshed volume, ``N`` its cells; Roache, "Quantification of
uncertainty in computational fluid dynamics", Annu. Rev. Fluid Mech. 29, 1997; Celik et
al., J. Fluids Eng. 130, 078001, 2008), not by the nominal element size.

For a quantity ``f`` (tip position, curl, the Eq 4.1 error of a target) on three meshes
``h1 > h2 > h3`` that converges monotonically, :func:`converge` fits ``f(h) = f* + C h^p``
through the three values: the *observed order* ``p`` solves

    (f2 - f1) / (f3 - f2) = (h1^p - h2^p) / (h2^p - h3^p)

(monotone in ``p``, solved by bracketing), and ``f*`` is the Richardson extrapolation. The
estimated error of the finest value is the grid convergence index
``GCI = Fs |f3 - f2| / ((h2 / h3)^p - 1)`` with the safety factor ``Fs = 1.25`` (three
meshes); from two meshes and an order known from elsewhere (a short actuator's study),
the same with ``Fs = 3``. Oscillating values have no order: the estimate is then the
spread of the values, said as such.

Examples
--------
>>> c = converge([1.5, 1.0, 0.75], [2 + 3 * 1.5**2, 2 + 3 * 1.0**2, 2 + 3 * 0.75**2])
>>> round(c.order, 6), round(c.extrapolated, 6)
(2.0, 2.0)
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from pneumorph.errors import SettingsError

#: Roache's factors of safety on the Richardson error: three meshes with an observed order,
#: and two meshes with an order assumed from another study
SAFETY_THREE, SAFETY_TWO = 1.25, 3.0
#: the bracket of observed orders searched (quadratic elements: 2-4 where the solution is smooth)
ORDER_RANGE = (0.05, 12.0)


@dataclass(frozen=True)
class Convergence:
    """One quantity over a sequence of meshes, coarse to fine.

    Attributes
    ----------
    sizes, values : tuple of float
        Representative cell sizes (mm) and the quantity on each mesh.
    order : float or None
        Observed (or, from two meshes, assumed) order of convergence; None when the values
        oscillate or the order lies outside :data:`ORDER_RANGE`.
    extrapolated : float or None
        The Richardson estimate of the value on an infinitely fine mesh.
    error : float
        Estimated error of the finest value (grid convergence index, absolute, same unit
        as the values); without an order, the spread of the values.
    method : str
        ``"three meshes"``, ``"two meshes, assumed order"``, ``"oscillating"`` or ``"one mesh"``.
    """

    sizes: tuple[float, ...]
    values: tuple[float, ...]
    order: float | None
    extrapolated: float | None
    error: float
    method: str

    def to_dict(self) -> dict[str, Any]:
        return {"sizes_mm": list(self.sizes), "values": list(self.values), "order": self.order,
                "extrapolated": self.extrapolated, "error": self.error, "method": self.method}


def _order(h: Sequence[float], f: Sequence[float]) -> float | None:
    """The order ``p`` through three values, or None (oscillating or outside the bracket)."""
    from scipy.optimize import brentq

    e21, e32 = f[1] - f[0], f[2] - f[1]
    if e32 == 0.0 or e21 == 0.0 or (e21 > 0) != (e32 > 0):
        return None
    ratio = e21 / e32

    def gap(p: float) -> float:
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - ratio

    lo, hi = ORDER_RANGE
    if gap(lo) * gap(hi) > 0:
        return None
    return float(brentq(gap, lo, hi, xtol=1e-12))


def converge(sizes: Sequence[float], values: Sequence[float], order: float | None = None) -> Convergence:
    """Observed order, Richardson limit and error estimate of a quantity over meshes.

    Parameters
    ----------
    sizes : sequence of float
        Representative cell sizes, strictly decreasing (coarse to fine).
    values : sequence of float
        The quantity on each mesh (all finite).
    order : float, optional
        With two meshes: the order to assume (e.g. observed on a short actuator). With
        three or more it is ignored: the order is observed on the three finest.

    Examples
    --------
    >>> c = converge([1.5, 1.0], [5.5, 5.0], order=2.0)   # f = 4 + h^2, order assumed
    >>> round(c.extrapolated, 6), round(c.error, 6), c.method
    (4.6, 1.2, 'two meshes, assumed order')
    >>> converge([1.5, 1.0, 0.75], [1.0, 2.0, 1.5]).method
    'oscillating'
    """
    h = [float(s) for s in sizes]
    f = [float(v) for v in values]
    if len(h) != len(f) or not h:
        raise SettingsError(f"{len(h)} mesh sizes for {len(f)} values")
    if any(b >= a for a, b in itertools.pairwise(h)) or min(h) <= 0:
        raise SettingsError(f"mesh sizes must decrease from coarse to fine, got {h}")
    if not all(math.isfinite(v) for v in f):
        raise SettingsError(f"the values must be finite, got {f}")
    sizes_t, values_t = tuple(h), tuple(f)
    if len(h) == 1:
        return Convergence(sizes_t, values_t, None, None, math.nan, "one mesh")
    if len(h) >= 3:
        h3, f3 = h[-3:], f[-3:]
        p = _order(h3, f3)
        if p is None:
            return Convergence(sizes_t, values_t, None, None, max(f3) - min(f3), "oscillating")
        r = h3[1] / h3[2]
        gain = (f3[2] - f3[1]) / (r**p - 1)
        return Convergence(sizes_t, values_t, p, f3[2] + gain, SAFETY_THREE * abs(gain), "three meshes")
    if order is None or not order > 0:
        return Convergence(sizes_t, values_t, None, None, abs(f[1] - f[0]), "two meshes, no order")
    r = h[0] / h[1]
    gain = (f[1] - f[0]) / (r**order - 1)
    return Convergence(sizes_t, values_t, float(order), f[1] + gain, SAFETY_TWO * abs(gain),
                       "two meshes, assumed order")


def representative_size(mesh: Any) -> float:
    """``(V / N)^(1/3)`` (3D; ``(A / N)^(1/2)`` in 2D) of a meshed actuator, mm.

    The volume is that of the cells' corner boxes (the meshes are structured grids of
    axis-aligned cells before deformation).

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> coarse = representative_size(assemble(UnitSpec(element_size=3.0), "0", dim=3, half=True))
    >>> fine = representative_size(assemble(UnitSpec(element_size=1.5), "0", dim=3, half=True))
    >>> 1.3 < coarse / fine < 2.5
    True
    """
    points = np.asarray(mesh.points, dtype=float)
    dim = points.shape[1]
    corners = points[np.asarray(mesh.cells)[:, : 2**dim]]
    extent = corners.max(axis=1) - corners.min(axis=1)
    volume = float(np.prod(extent, axis=1).sum())
    return (volume / len(mesh.cells)) ** (1.0 / dim)


@dataclass(frozen=True)
class MeshPoint:
    """One design solved on one mesh.

    Attributes
    ----------
    design : str
    element_size : float
        The nominal element size (mm, the unit's ``element_size``).
    cell_size : float
        The representative cell size (mm, :func:`representative_size`).
    cells, dofs : int
        Cells of the mesh and unknowns of the model.
    tip : tuple of float or None
        Tip position (x, y) at the last level, mm (its pressure is ``tip_pressure_kpa`` in ``extra``).
    curl : float or None
        End-face rotation at the last level, degrees.
    value : float or None
        The objective at its best level (Eq 4.1 in mm for a profile); ``pressure_kpa`` that level.
    wall_time_s : float
    failure : str or None
    """

    design: str
    element_size: float
    cell_size: float
    cells: int
    dofs: int
    tip: tuple[float, float] | None
    curl: float | None
    value: float | None
    pressure_kpa: float | None
    wall_time_s: float
    failure: str | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.failure is None

    def to_dict(self) -> dict[str, Any]:
        return {"design": self.design, "element_size_mm": self.element_size, "cell_size_mm": self.cell_size,
                "cells": self.cells, "dofs": self.dofs, "tip_mm": None if self.tip is None else list(self.tip),
                "curl_deg": self.curl, "value": self.value, "pressure_kpa": self.pressure_kpa,
                "wall_time_s": self.wall_time_s, "failure": self.failure, **self.extra}


@dataclass(frozen=True)
class MeshStudy:
    """Every design of a study on every mesh, and the convergence of each quantity.

    Attributes
    ----------
    points : tuple of MeshPoint
        Design by design, coarse to fine.
    objective : str
        The objective's label (what ``value`` measures).
    order : float or None
        The order assumed for designs solved on two meshes only (observed on a short
        actuator on nested meshes), if given.
    """

    points: tuple[MeshPoint, ...]
    objective: str
    order: float | None = None

    @property
    def designs(self) -> list[str]:
        return list(dict.fromkeys(p.design for p in self.points))

    def of(self, design: str) -> list[MeshPoint]:
        """The converged points of one design, coarse to fine."""
        return sorted((p for p in self.points if p.design == design and p.ok), key=lambda p: -p.cell_size)

    def convergence(self, design: str, quantity: str) -> Convergence | None:
        """The :class:`Convergence` of ``quantity`` (``"tip_x"``, ``"tip_y"``, ``"curl"``, ``"value"``)."""
        pts = self.of(design)
        values = [_quantity(p, quantity) for p in pts]
        if not pts or any(v is None for v in values):
            return None
        return converge([p.cell_size for p in pts], [float(v) for v in values if v is not None], self.order)

    def to_dict(self) -> dict[str, Any]:
        quantities = ("tip_x", "tip_y", "curl", "value")
        return {
            "objective": self.objective,
            "assumed_order": self.order,
            "points": [p.to_dict() for p in self.points],
            "convergence": {d: {q: (c.to_dict() if (c := self.convergence(d, q)) is not None else None)
                                for q in quantities} for d in self.designs},
        }


def _quantity(point: MeshPoint, name: str) -> float | None:
    if name == "tip_x":
        return None if point.tip is None else point.tip[0]
    if name == "tip_y":
        return None if point.tip is None else point.tip[1]
    if name == "curl":
        return point.curl
    if name == "value":
        return point.value
    raise SettingsError(f"unknown quantity {name!r}; known: tip_x, tip_y, curl, value")


def check_refinement(model: Any, sizes: Iterable[float], parallel: int = 1,
                     memory: int | None = None) -> dict[float, tuple[int, int]]:
    """Refuse, before any solve, element sizes whose solves would not fit in memory.

    The mesh is counted from the unit's grid, cavities included (an upper bound;
    :func:`pneumorph.geometry.meshsize.check_mesh`): 6.9 GB estimated for the 15-unit actuator
    at 1.0 mm, which peaked at 6.0 GB. Over a unit library, of an actuator of its largest unit type
    (a design may be all of it: a sideways unit meshed across the whole width, a longer pitch); with
    the model's base block. ``parallel`` solves run at once (the workers).

    Returns
    -------
    dict
        Nodes and estimated bytes of one solve per size.

    Raises
    ------
    MeshLimitError
        One line: the size, its nodes and estimated memory, and what is available.
    UnitLibraryError
        A unit library whose units no longer join at a size (their grid lines differ).

    Examples
    --------
    >>> from pneumorph.models.fe import Full3D
    >>> check_refinement(Full3D(15), [1.0], memory=8 * 10**9)
    {1.0: (91322, 6894416781)}
    >>> from pneumorph.geometry.library import builtin_library
    >>> spatial = Full3D(15, library=builtin_library("spatial"))  # its sideways unit 'l': the whole width
    >>> check_refinement(spatial, [0.75], memory=10**12)
    {0.75: (292933, 32055697783)}
    """
    from pneumorph.geometry.limits import MeshLimitError
    from pneumorph.geometry.meshsize import available_memory, check_mesh

    free = available_memory() if memory is None else int(memory)
    out = {}
    mixed = bool(getattr(model, "mixed", False))
    types = list(zip(model.library.symbols, model.library.units, strict=True)) if mixed else [("", model.unit)]
    for h in sorted(set(float(s) for s in sizes)):
        if mixed:  # every unit of the library at h must still join (a UnitLibraryError)
            refined(model, h)
        largest = (0, 0)
        for symbol, spec in types:
            try:
                estimate = check_mesh(replace(spec, element_size=h), model.n_units, model.dim,
                                      getattr(model, "half", True), memory=free, parallel=parallel,
                                      advice="choose a larger element size", base=getattr(model, "base_block", None))
            except MeshLimitError as exc:
                which = f", unit type '{symbol}' ({spec.name})" if mixed else ""
                raise MeshLimitError(f"element size {h:g} mm{which}: {exc}") from None
            largest = max(largest, (estimate.nodes, estimate.bytes))
        out[h] = largest
    return out


def refined(model: Any, element_size: float) -> Any:
    """``model`` with its unit (or every unit of its library) meshed at ``element_size`` mm."""
    unit = replace(model.unit, element_size=element_size)
    if model.mixed:
        library = replace(model.library, units=tuple(replace(u, element_size=element_size)
                                                      for u in model.library.units))
        return model.variant(unit=unit, library=library)
    return model.variant(unit=unit)


def mesh_points(model: Any, designs: Iterable[str], sizes: Iterable[float],
                measure: Callable[[Any], tuple[float, int | None]], evaluator: Any,
                on_point: Callable[[MeshPoint], None] | None = None) -> list[MeshPoint]:
    """Solve every design at every element size through ``evaluator`` (cached: a rerun resumes).

    Parameters
    ----------
    model : FEModel
        The model at its default mesh; each size is :func:`refined` from it.
    designs : iterable of str
    sizes : iterable of float
        Element sizes (mm), any order.
    measure : callable
        ``measure(response) -> (value, level)``: the quantity compared besides tip and curl
        and the level it is taken at (a design objective at its best level, e.g.
        ``lambda r: (s := score(r, objective)).value, s.level`` with
        :func:`pneumorph.design.objectives.fitness.score`).
    evaluator : Evaluator
        Solves the ``(model, design)`` cases (``iter_cases``).
    on_point : callable, optional
        Called with each :class:`MeshPoint` as it arrives (progress).
    """
    designs = list(designs)
    models = {h: refined(model, h) for h in sorted(set(float(s) for s in sizes), reverse=True)}
    meshes = {h: _mesh_size(m, designs[0]) for h, m in models.items()}
    cases = [(h, d) for h in models for d in designs]
    out: list[MeshPoint] = []
    for i, outcome in evaluator.iter_cases([(models[h], d) for h, d in cases]):
        h, design = cases[i]
        cells, size = meshes[h]
        r = outcome.response
        meta = {} if r is None else dict(r.metadata)
        if outcome.ok and r is not None:
            value, level = measure(r)
            level = int(level) if level is not None else len(r.pressures) - 1
            point = MeshPoint(design, h, size, cells, int(meta.get("dofs", 0)),
                              (float(r.tip[-1, 0]), float(r.tip[-1, 1])), float(r.curl[-1]), float(value),
                              float(r.pressures[level] * 1e3), float(outcome.wall_time),
                              extra={"precision": meta.get("precision"),
                                     "tip_pressure_kpa": float(r.pressures[-1] * 1e3)})
        else:
            point = MeshPoint(design, h, size, cells, int(meta.get("dofs", 0)), None, None, None, None,
                              float(outcome.wall_time), outcome.failure or "did not converge")
        out.append(point)
        if on_point is not None:
            on_point(point)
    return out


def _mesh_size(model: Any, design: str) -> tuple[int, float]:
    """Cells and representative size of ``model``'s mesh (the same for every design of it)."""
    mesh = model.mesh(design)
    return len(mesh.cells), representative_size(mesh)


__all__ = ["ORDER_RANGE", "SAFETY_THREE", "SAFETY_TWO", "Convergence", "MeshPoint", "MeshStudy", "check_refinement",
           "converge", "mesh_points", "refined", "representative_size"]

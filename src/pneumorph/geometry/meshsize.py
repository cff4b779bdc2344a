"""The size of the mesh a unit implies, checked before meshing.

The structured grid of an actuator of ``units`` units is counted from the grid's breaks
without building it (:func:`estimate_mesh`) and has at most :data:`MAX_NODES_2D` or
:data:`MAX_NODES_3D` nodes where the bench builds it, and a solve that fits in the memory
available on the command line (:func:`check_mesh`). A refusal
(:class:`~pneumorph.geometry.limits.MeshLimitError`) states the estimate.

The estimate is exact for the grid of :func:`pneumorph.geometry.assembly.assemble` (lines
through every break, no gap wider than the element size, the end cap and a base block
included) and an upper bound of the mesh (cavity cells are counted); the peak memory of one
solve is estimated from the nodes by :func:`solve_memory`, a law fitted to measured 3D
solves (a direct solver's fill grows faster than the nodes).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pneumorph.geometry.limits import MeshLimitError, check_lengths

if TYPE_CHECKING:
    from pneumorph.geometry.features import BaseBlock
    from pneumorph.geometry.unit import UnitSpec

MAX_NODES_3D = 60_000
"""Largest 3D mesh (nodes of the half model) the bench builds: about 3 x the built-in actuator, 4 GB (the command
line's limit is the memory available instead, :func:`check_mesh`)."""

MAX_NODES_2D = 200_000
"""Largest 2D mesh (nodes) the bench builds: about 70 x the built-in actuator, 2 GB."""

BASE_BYTES = 150_000_000
"""Memory of a solving process before its mesh: Python, NumPy, SciPy, FElupe (0.15 GB: a 2D solve of 2,747 nodes)."""

BYTES_3D = 1_640.0
"""Peak memory of a 3D solve (hex20, direct solver) is ``BASE_BYTES + BYTES_3D * nodes**(4/3)`` bytes: the built-in
actuator (21,252 nodes estimated, 19,512 meshed) peaks at 1.12 GB (estimated 1.12 GB), at a 1.0 mm element size (91,322
estimated) at 6.0 GB (estimated 6.9 GB; :mod:`pneumorph.sensitivity.mesh`)."""

BYTES_PER_NODE_2D = 10_000
"""Peak memory of a 2D solve per node (quad8), an upper bound: the built-in actuator's 2,747 nodes add little."""


@dataclass(frozen=True)
class MeshEstimate:
    """The size of an actuator's structured mesh, counted before it is built.

    Attributes
    ----------
    cells : (int, int, int)
        Grid cells along x (the whole actuator), y and z (1 in 2D).
    elements : int
        Cells of the grid (an upper bound of the elements: cavity cells are counted).
    nodes : int
        Nodes of the grid: corners, and with quadratic elements (hex20, quad8) the mid-edge nodes.
    bytes : int
        Estimated peak memory of one solve.
    dim : int
    """

    cells: tuple[int, int, int]
    elements: int
    nodes: int
    bytes: int
    dim: int

    def describe(self) -> str:
        """One line: nodes, elements and memory.

        Examples
        --------
        >>> MeshEstimate((10, 4, 1), 40, 189, 151_890_000, 2).describe()
        'about 189 nodes, 40 elements, 0.15 GB for one solve'
        >>> MeshEstimate((10, 4, 1), 40, 189, 123_456_000_000, 2).describe()
        'about 189 nodes, 40 elements, 123 GB for one solve'
        """
        gb = self.bytes / 1e9
        size = f"{gb:.2f}" if gb < 1 else f"{gb:.1f}" if gb < 100 else f"{gb:,.0f}"
        return f"about {self.nodes:,} nodes, {self.elements:,} elements, {size} GB for one solve"


def cells_between(breaks: Iterable[float], size: float) -> int:
    """Grid cells through ``breaks`` with no gap wider than ``size``, counted without building the lines.

    The count of :func:`pneumorph.geometry.grid.grid_lines` minus one (breaks closer than
    1e-6 mm merged), in constant memory however long the gaps.

    Examples
    --------
    >>> cells_between([0.0, 1.5, 4.5], 1.5)
    3
    >>> cells_between([0.0, 1e9], 1.5)
    666666667
    """
    b = sorted({round(float(x), 6) for x in breaks})
    return sum(max(1, math.ceil((hi - lo) / size - 1e-9)) for lo, hi in itertools.pairwise(b))


def estimate_mesh(spec: UnitSpec, units: int, dim: int, half: bool = True,
                  base: BaseBlock | None = None) -> MeshEstimate:
    """The mesh of ``units`` units of ``spec`` in ``dim`` dimensions, counted from the grid's breaks.

    Parameters
    ----------
    spec : UnitSpec
    units : int
        Units along the actuator.
    dim : {2, 3}
    half : bool
        3D: the half model across the width (the models' default); a sideways unit
        (``layer_side``) is always counted whole, as its models mesh it.
    base : BaseBlock, optional
        A meshed base block (appendix D.2) before the base face, with its margin (the
        sensitivity studies' variant, a config's ``[model.base_block]``).

    Examples
    --------
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> e = estimate_mesh(UnitSpec(), 15, 3)
    >>> e.cells, e.elements, e.nodes  # the mesh itself: 3,480 elements, 19,512 nodes (no cavity cells)
    ((105, 8, 5), 4200, 21252)
    >>> estimate_mesh(UnitSpec(pitch=500.0), 15, 3).describe()
    'about 1,007,157 nodes, 200,400 elements, 166 GB for one solve'
    >>> from pneumorph.geometry.features import BaseBlock
    >>> estimate_mesh(UnitSpec(), 15, 3, base=BaseBlock(length=1000.0)).describe()  # 7 times as long
    'about 155,466 nodes, 30,880 elements, 13.9 GB for one solve'
    >>> estimate_mesh(UnitSpec(cavity_height=9.0, layer_side=True), 15, 3).nodes  # sideways: the full width
    39757
    """
    from pneumorph.geometry.grid import section_breaks, width_breaks

    half = half and not spec.layer_side
    h = spec.element_size
    xb, yb = section_breaks(spec)
    zb = width_breaks(spec, half)
    nx = int(units) * cells_between(xb, h) + (cells_between([0.0, spec.end_cap], h) if spec.end_cap > 0 else 0)
    ny = cells_between(yb, h)
    nz = cells_between(zb, h) if dim == 3 else 1
    cells, elements, nodes = (nx, ny, nz), nx * ny * nz, grid_nodes(nx, ny, nz, dim, spec.element_order)
    if base is not None:  # the block before the base face, with its margin's cells (the face it shares counted twice)
        m = float(base.margin)
        bx = cells_between([-float(base.length), 0.0], h)
        by = cells_between([*yb, -m, spec.height + m], h)
        bz = cells_between([*zb, -m] if half else [*zb, -m, spec.width + m], h) if dim == 3 else 1
        cells, elements = (nx + bx, by, bz), elements + bx * by * bz
        nodes += grid_nodes(bx, by, bz, dim, spec.element_order)
    return MeshEstimate(cells, elements, nodes, solve_memory(nodes, dim), dim)


def grid_nodes(nx: int, ny: int, nz: int, dim: int, order: int) -> int:
    """Nodes of a structured grid of ``nx x ny (x nz)`` cells: corners, and mid-edge nodes if ``order`` is 2.

    >>> grid_nodes(1, 1, 1, 3, 2), grid_nodes(2, 1, 1, 2, 1)  # one hex20; two quad4
    (20, 6)
    """
    if dim == 3:
        nodes = (nx + 1) * (ny + 1) * (nz + 1)
        if order == 2:  # a mid-node on every edge of the grid
            nodes += nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz
        return nodes
    nodes = (nx + 1) * (ny + 1)
    if order == 2:
        nodes += nx * (ny + 1) + (nx + 1) * ny
    return nodes


def solve_memory(nodes: int, dim: int) -> int:
    """Estimated peak memory (bytes) of one FE solve on a mesh of ``nodes`` nodes.

    3D: ``BASE_BYTES + BYTES_3D * nodes**(4/3)`` (:data:`BYTES_3D`); 2D:
    ``BASE_BYTES + BYTES_PER_NODE_2D * nodes``.

    Examples
    --------
    >>> round(solve_memory(21_252, 3) / 1e9, 2), round(solve_memory(MAX_NODES_3D, 3) / 1e9, 1)
    (1.12, 4.0)
    >>> round(solve_memory(2_747, 2) / 1e9, 2)
    0.18
    """
    if dim == 3:
        return int(BASE_BYTES + BYTES_3D * float(nodes) ** (4 / 3))
    return int(BASE_BYTES + BYTES_PER_NODE_2D * nodes)


def available_memory() -> int:
    """Bytes of memory available to a new solve now (``MemAvailable``; else the physical memory).

    >>> available_memory() > 0
    True
    """
    import os

    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return int(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))


def check_mesh(spec: UnitSpec, units: int, dim: int, half: bool = True, memory: int | None = None,
               parallel: int = 1, advice: str | None = None, base: BaseBlock | None = None) -> MeshEstimate:
    """Refuse a unit too large or too finely meshed for an actuator of ``units`` units, before meshing.

    Parameters
    ----------
    spec : UnitSpec
    units, dim, half
        As for :func:`estimate_mesh`.
    memory : int, optional
        Bytes the solves may use (the command line: :func:`available_memory`). The mesh is
        refused when ``parallel`` solves of it are estimated to need more. Without it, the
        fixed limits :data:`MAX_NODES_3D` and :data:`MAX_NODES_2D` (the bench's: a server
        never starts a solve that large, whatever the machine has free).
    parallel : int
        Solves of this mesh that may run at once.
    advice : str, optional
        What a refusal tells the user to change (default: the unit or the actuator's length).
    base : BaseBlock, optional
        A meshed base block, counted with the actuator (:func:`estimate_mesh`).

    Returns
    -------
    MeshEstimate
        The estimate of a unit within the limits.

    Raises
    ------
    MeshLimitError
        A length above :data:`MAX_LENGTH_MM`, or a mesh past the limit; the message states
        the estimate.

    Examples
    --------
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> check_mesh(UnitSpec(), 15, 3).nodes <= MAX_NODES_3D
    True
    >>> check_mesh(UnitSpec(element_size=1.0), 15, 3, memory=8 * 10**9).nodes   # refined: fits in 8 GB
    91322
    >>> check_mesh(UnitSpec(pitch=400.0), 15, 3)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.geometry.limits.MeshLimitError: a 3D actuator of 15 units of this unit is a mesh of about 805,152
    nodes, ...GB for one solve; the limit is 60,000 nodes...
    >>> check_mesh(UnitSpec(element_size=1.0), 15, 3, memory=4 * 10**9)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.geometry.limits.MeshLimitError: a 3D actuator of 15 units of this unit is a mesh of about 91,322
    nodes, ... 6.9 GB for one solve; 4.0 GB are available...
    >>> from pneumorph.geometry.features import BaseBlock
    >>> check_mesh(UnitSpec(), 15, 3, memory=8 * 10**9, base=BaseBlock(length=1000.0))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.geometry.limits.MeshLimitError: a 3D actuator of 15 units of this unit with a base block of 1000 mm
    is a mesh of about 155,466 nodes, 30,880 elements, 13.9 GB for one solve; 8.0 GB are available: ...
    """
    check_lengths(spec)
    estimate = estimate_mesh(spec, units, dim, half, base)
    block = "" if base is None else f" with a base block of {float(base.length):g} mm"
    what = f"a {dim}D actuator of {units} units of this unit{block} is a mesh of {estimate.describe()}"
    fewer = ", or solve fewer at once" if advice is None else " or fewer workers"
    advice = advice or ("make the unit smaller, its element_size larger or the actuator shorter"
                        + ("" if base is None else ", or the base block shorter"))
    if memory is not None:
        if estimate.bytes * parallel > memory:
            at_once = f" x {parallel} at once" if parallel > 1 else ""
            raise MeshLimitError(f"{what}{at_once}; {memory / 1e9:.1f} GB are available: {advice}"
                                 + (fewer if parallel > 1 else ""))
        return estimate
    limit, name = (MAX_NODES_3D, "MAX_NODES_3D") if dim == 3 else (MAX_NODES_2D, "MAX_NODES_2D")
    if estimate.nodes > limit:
        raise MeshLimitError(f"{what}; the limit is {limit:,} nodes ({name}, pneumorph.geometry.limits): {advice}")
    return estimate


__all__ = ["BASE_BYTES", "BYTES_3D", "BYTES_PER_NODE_2D", "MAX_NODES_2D", "MAX_NODES_3D", "MeshEstimate",
           "available_memory", "cells_between", "check_mesh", "estimate_mesh", "grid_nodes",
           "solve_memory"]

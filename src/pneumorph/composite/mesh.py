"""Mapped quad mesh of a crimped-paper composite coupon (plain numpy, no FElupe).

The coupon is a silicone strip of length ``L0`` and thickness ``T`` (plane strain, unit
depth). The paper strain limiter is a triangular wave through the middle of it. The mesh
is structured: its middle node row follows the wave exactly, with a node at every peak
and valley, and the rows above and below blend linearly from the wave to the flat top
and bottom surfaces. The paper is the chain of two-node line cells on that middle row,
so it shares its nodes with the matrix: tied to it, without contact, like rebar
elements whose layer coincides with element edges.

The wave is placed symmetric about the middle of the coupon (a peak at ``L0/2``), so
both paper ends lie at the same height and the straightened paper lies along the line
between them.

Examples
--------
>>> from pneumorph.composite.crimp import Crimp
>>> m = coupon_mesh(Crimp.from_ratio(0.2, 1.5, 176.25), thickness=5.0, per_flute=2, rows=1)
>>> m.points.shape, m.quads.shape, m.lines.shape
((285, 2), (188, 4), (94, 2))
>>> round(float(m.paper_length), 3)  # L0 * 2 s / lambda for a crimp over the whole length
225.71
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pneumorph.composite.crimp import Crimp
from pneumorph.errors import CrimpError

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class CouponMesh:
    """Nodes and cells of a composite coupon.

    Attributes
    ----------
    points : ndarray, shape (n, 2)
        Node coordinates (mm): ``x`` along the coupon from 0 to ``L0``, ``y`` through
        the thickness from ``-T/2`` to ``T/2``.
    quads : ndarray, shape (m, 4)
        Matrix cells (counter-clockwise 4-node quadrilaterals).
    lines : ndarray, shape (k, 2)
        Paper cells (2-node line elements along the middle node row).
    grid : ndarray, shape (2 rows + 1, columns)
        Node numbers by row (bottom to top) and column (``x`` increasing).
    paper : ndarray
        Node numbers of the paper, from ``x = 0`` to ``x = L0`` (``grid[rows]``).
    top : ndarray
        Node numbers of the top surface, ``x`` increasing (``grid[-1]``).
    kinks : ndarray
        ``x`` of the peaks and valleys inside the coupon.
    """

    points: FloatArray
    quads: IntArray
    lines: IntArray
    grid: IntArray
    kinks: FloatArray

    @property
    def paper(self) -> IntArray:
        """Paper nodes, ``x`` increasing."""
        return self.grid[self.grid.shape[0] // 2]

    @property
    def top(self) -> IntArray:
        """Top-surface nodes, ``x`` increasing."""
        return self.grid[-1]

    @property
    def paper_length(self) -> float:
        """Length of the paper along the wave (mm)."""
        p = self.points[self.paper]
        return float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))


def wave_height(crimp: Crimp, x: FloatArray) -> FloatArray:
    """Height of the paper at ``x`` for the wave centred on the coupon (a peak at ``L0/2``).

    Examples
    --------
    >>> c = Crimp(1.5, 6.0, 60.0)
    >>> [float(v) for v in wave_height(c, np.array([30.0, 33.0, 27.0, 31.5]))]
    [1.5, -1.5, -1.5, 0.0]
    """
    shift = crimp.length / 2.0 - crimp.wavelength / 4.0
    return np.asarray(crimp.y(np.asarray(x, dtype=float) - shift), dtype=float)


def _columns(crimp: Crimp, per_flute: int) -> tuple[FloatArray, FloatArray]:
    """Column ``x`` positions: every kink, each flute split into ``per_flute`` cells."""
    half = crimp.wavelength / 2.0
    centre = crimp.length / 2.0
    k = np.arange(-math.ceil(centre / half) - 1, math.ceil(centre / half) + 2)
    kinks = centre + k * half
    tol = 1e-9 * crimp.length
    kinks = kinks[(kinks > tol) & (kinks < crimp.length - tol)]
    edges = np.concatenate([[0.0], kinks, [crimp.length]])
    xs = [0.0]
    for a, b in itertools.pairwise(edges):
        n = max(1, math.ceil((b - a) / half * per_flute - 1e-6))
        xs.extend(np.linspace(a, b, n + 1)[1:])
    return np.asarray(xs, dtype=np.float64), np.asarray(kinks, dtype=np.float64)


def coupon_mesh(crimp: Crimp, thickness: float = 5.0, per_flute: int = 4, rows: int = 4) -> CouponMesh:
    """Structured mesh of a coupon whose middle node row follows the crimp.

    Parameters
    ----------
    crimp : Crimp
        Amplitude, wavelength and crimped length ``L0``.
    thickness : float
        Coupon thickness ``T`` (mm); the paper (``|y| <= A``) must lie inside it.
    per_flute : int
        Cells along each flute (half wavelength); partial flutes at the ends get
        proportionally fewer.
    rows : int
        Cell rows between the paper and each surface.

    Returns
    -------
    CouponMesh

    Raises
    ------
    CrimpError
        Thickness not larger than ``2 A``, or fewer than one cell per flute or row.
    """
    t = float(thickness)
    if not (math.isfinite(t) and t > 2.0 * crimp.amplitude):
        raise CrimpError(
            f"the coupon thickness must exceed the crimp height 2A = {2 * crimp.amplitude:g} mm "
            f"so that the paper lies inside the matrix, got {thickness!r} mm"
        )
    if int(per_flute) < 1 or int(rows) < 1:
        raise CrimpError(f"per_flute and rows must be at least 1, got {per_flute} and {rows}")
    per_flute, rows = int(per_flute), int(rows)
    xs, kinks = _columns(crimp, per_flute)
    ym = wave_height(crimp, xs)
    frac = np.arange(rows + 1) / rows
    lower = -t / 2 + np.outer(frac, ym + t / 2)
    upper = ym + np.outer(frac, t / 2 - ym)
    ys = np.vstack([lower, upper[1:]])
    nrow, ncol = ys.shape
    points = np.column_stack([np.broadcast_to(xs, ys.shape).ravel(), ys.ravel()])
    grid = np.arange(nrow * ncol).reshape(nrow, ncol)
    quads = np.column_stack(
        [grid[:-1, :-1].ravel(), grid[:-1, 1:].ravel(), grid[1:, 1:].ravel(), grid[1:, :-1].ravel()]
    )
    paper = grid[rows]
    lines = np.column_stack([paper[:-1], paper[1:]])
    return CouponMesh(points=points, quads=quads, lines=lines, grid=grid, kinks=kinks)

"""Layered geometry of the bimodal Slow Pneu-net actuator (section 3.3, Appendix B.2).

Longitudinal section (x along the actuator, y across its height, z across its width; the
base at x = 0 is clamped, the free end at x = length)::

    y = height  +------------------------------------------------------+
                |  Smooth-Sil 950 strip (``strip``)                     |
                +------------------------------------------------------+
                |  top wall (Mold Star 15, ``top_wall``)                |
                |  +-------+   +-------+          +-------+   +         |
                |  | void  |   | void  |   ...    | void  |   |  body   |
                |  | open  |   |       |          |       |   | (17.5)  |
                +--+-------+---+-------+----------+-------+---+---------+
                |  seal: 1 mm Mold Star 15 strip closing the voids      |
                +------------------------------------------------------+
                |  bilinear composite (``bilinear``, 5 mm)              |
    y = 0       +------------------------------------------------------+

The Mold Star 15 body (157.5 x 15 x 17.5 mm, 15 voids, closed at the free end by an assumed
``end_cap`` beyond the last void's end wall) is cast with its voids open on the underside; a
1 mm Mold Star 15 strip seals them and is the interface to the bilinear composite glued below
it, so the Ecoflex of the composite never sees the pressure; a
Smooth-Sil 950 strip is glued on top (section 3.3.2, Appendix B.2 steps 9-12). Along x a
void is ``end_wall | void | end_wall``, so neighbouring voids are ``2 end_wall`` apart.
In z each void stops ``side_wall`` short of both sides.

Every dimension is a parameter; :data:`ASSUMED` names those the dissertation does not give
and why the default was chosen.

Examples
--------
>>> s = BimodalSpec()
>>> s.voids * s.pitch, s.length, s.height, s.void   # 15 voids of 10.5 mm and the 4.5 mm end cap
(157.5, 162.0, 25.5, (1.5, 9.0, 6.0, 22.0))
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.checks import MAX_UNITS, MIN_ELEMENT_FRACTION
from pneumorph.errors import GeometryError
from pneumorph.geometry.assembly import grid_lines

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
FloatArray = NDArray[np.float64]

#: Cell labels of the layered grid.
BILINEAR, SEAL, BODY, STRIP, VOID = 0, 1, 2, 3, 4
LABELS = {BILINEAR: "bilinear", SEAL: "seal", BODY: "body", STRIP: "strip", VOID: "void"}

#: Dimensions the dissertation does not give, with the reason for the default.
ASSUMED: dict[str, str] = {
    "top_wall": "1.5 mm: not given for the bimodal body; the walls of the dissertation's actuator "
    "(section 4.2, Fig 4.1) are all 1.5 mm, and the body 'shares its dimensions' with it",
    "end_wall": "1.5 mm: as top_wall (voids 7.5 mm long at the 10.5 mm pitch, 3 mm walls between voids)",
    "side_wall": "1.5 mm: as top_wall",
    "void_open_bottom": "the voids run from the seal strip to the top wall (16 mm high): Appendix B.2 "
    "step 9 glues the 1 mm strip 'to the underside of the main centre section to seal the open voids'",
    "strip": "2 mm: Appendix B.2 step 10 glues 'a 2 mm strip of Smooth-Sil', the legend of Fig B.4 "
    "says '1 mm thick strip of Smooth-Sil'; the procedure's value is used",
    "strip_width": "the Smooth-Sil strip, seal and composite span the full 15 mm width "
    "(step 11 cuts the composite 15 mm wide; the strips' widths are not given)",
    "tip_point": "the tracked tip (red dot, Fig 3.11; its position is not given) is the mid-point of "
    "the end face's chord on the mid-plane, between its bottom and top corners: the centre of the "
    "end section as a beam sees it, unaffected by the bulging of the end wall over the last void",
    "end_cap": "4.5 mm: extra solid beyond the last void, so that the free end wall is 6 mm (end_wall + "
    "end_cap) and the actuator 162 mm long (the voids keep the 10.5 mm pitch of section 3.3.1's 157.5 mm). "
    "Not given: the dissertation describes the inlet end (a thick slab on the base unit that the needle "
    "pierces, section 3.3.2, Appendix B.2 step 13) but not the free end. In this model a 1.5 mm free end "
    "wall balloons (about 29 kPa) before any crimp ratio crosses and a 3 mm one before CR 0.25 and 0.3 do; "
    "the cast actuators all reversed and were inflated until rupture (section 3.3.4), so their end bore "
    "the pressure of the reversal: 6 mm is the thinnest end of those run (1.5, 3, 4.5, 6 mm) with which "
    "all three crimp ratios cross within the default ramp (9 V0), as the casts did; with 4.5 mm CR 0.3 "
    "crosses only past it (39.9 kPa at 9.67 V0) and its ramp stops at the next step",
    "holes": "the 1.5 mm holes joining neighbouring voids (section 6.x) are not modelled: every "
    "void carries the same pressure, as after a slow quasi-static ramp",
}

_LENGTHS = (
    "pitch",
    "width",
    "body_height",
    "top_wall",
    "end_wall",
    "side_wall",
    "seal",
    "strip",
    "bilinear",
    "element_size",
)


@dataclass(frozen=True)
class BimodalSpec:
    """Dimensions (mm) of the bimodal actuator and its mesh size.

    Parameters
    ----------
    voids : int
        Number of voids (15; the length is ``voids * pitch + end_cap``).
    pitch : float
        Length per void (10.5 mm: 15 voids = 157.5 mm, section 3.3.1).
    width : float
        15 mm (section 3.3.1).
    body_height : float
        Height of the Mold Star 15 body, 17.5 mm (section 3.3.1).
    top_wall, end_wall, side_wall : float
        Wall thicknesses of the body (assumed 1.5 mm, see :data:`ASSUMED`).
    seal : float
        The Mold Star 15 strip sealing the voids, 1 mm (section 3.3.2).
    strip : float
        The Smooth-Sil 950 strip on top (assumed 2 mm, see :data:`ASSUMED`).
    bilinear : float
        The bilinear composite, 5 mm (section 3.3.1).
    end_cap : float
        Extra solid beyond the last void's end wall (assumed 4.5 mm, a 6 mm free end wall that lets
        the actuator reverse, see :data:`ASSUMED`; 0 leaves the 1.5 mm end wall alone).
    element_size : float
        Target edge length of the hexahedra (the grid also has a line on every interface).

    Raises
    ------
    GeometryError
        Non-positive sizes, fewer than one void, walls that leave no void.
    """

    voids: int = 15
    pitch: float = 10.5
    width: float = 15.0
    body_height: float = 17.5
    top_wall: float = 1.5
    end_wall: float = 1.5
    side_wall: float = 1.5
    seal: float = 1.0
    strip: float = 2.0
    bilinear: float = 5.0
    end_cap: float = 4.5
    element_size: float = 1.5

    def __post_init__(self) -> None:
        if isinstance(self.voids, bool) or not isinstance(self.voids, (int, np.integer)) or not (
                1 <= self.voids <= MAX_UNITS):
            raise GeometryError(f"the actuator needs 1 to {MAX_UNITS} voids (limit MAX_UNITS), "
                                f"got voids={self.voids!r}")
        for key in _LENGTHS:
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise GeometryError(f"{key} must be a positive, finite number of mm, got {value!r}")
        if isinstance(self.end_cap, bool) or not isinstance(self.end_cap, (int, float)) or not math.isfinite(
                self.end_cap) or self.end_cap < 0:
            raise GeometryError(f"end_cap must be >= 0 mm, got {self.end_cap!r}")
        thinnest = min(getattr(self, key) for key in _LENGTHS if key != "element_size")
        if self.element_size < MIN_ELEMENT_FRACTION * thinnest:
            raise GeometryError(
                f"element_size {self.element_size:g} mm is below {MIN_ELEMENT_FRACTION:g} x the thinnest layer "
                f"({thinnest:g} mm), the limit MIN_ELEMENT_FRACTION: the mesh would not fit in memory")
        if self.pitch - 2 * self.end_wall <= 0:
            raise GeometryError(
                f"the end walls leave no void: pitch {self.pitch} mm - 2 x end wall {self.end_wall} mm <= 0"
            )
        if self.width - 2 * self.side_wall <= 0:
            raise GeometryError(f"the side walls leave no void: 2 x {self.side_wall} mm >= width {self.width} mm")
        if self.body_height - self.top_wall <= 0:
            raise GeometryError(
                f"the top wall ({self.top_wall} mm) leaves no void in a body {self.body_height} mm high"
            )

    # -- derived dimensions ---------------------------------------------------------------
    @property
    def length(self) -> float:
        return self.voids * self.pitch + self.end_cap

    @property
    def height(self) -> float:
        """Whole stack: bilinear + seal + body + strip."""
        return self.bilinear + self.seal + self.body_height + self.strip

    @property
    def interfaces(self) -> tuple[float, float, float, float, float]:
        """Heights y of: seal bottom, body bottom, void top, strip bottom, top surface."""
        y0 = self.bilinear
        y1 = y0 + self.seal
        y3 = y1 + self.body_height
        return (y0, y1, y3 - self.top_wall, y3, y3 + self.strip)

    @property
    def void(self) -> tuple[float, float, float, float]:
        """The first void ``(x0, x1, y0, y1)``; void ``i`` is shifted by ``i * pitch``."""
        _, y1, y2, _, _ = self.interfaces
        return (self.end_wall, self.pitch - self.end_wall, y1, y2)

    @property
    def void_volume(self) -> float:
        """Volume of one void (mm^3)."""
        x0, x1, y0, y1 = self.void
        return (x1 - x0) * (y1 - y0) * (self.width - 2 * self.side_wall)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class BimodalMesh:
    """The labelled hexahedral grid of a bimodal actuator (plain data).

    Attributes
    ----------
    points : ndarray, shape (p, 3)
    cells : ndarray, shape (c, 20) or (c, 8)
        ``hexahedron20`` (default) or ``hexahedron`` cells in FElupe's ordering; void cells
        are removed.
    cell_type : str
    label : ndarray, shape (c,)
        Per cell, BILINEAR, SEAL, BODY or STRIP.
    void_points : ndarray of bool
        Points on the void walls (where the pressure acts).
    base_points : ndarray of bool
        Points of the clamped base face x = 0.
    symmetry_points : ndarray of bool or None
        Half models: points on the mid-plane z = width / 2 (u_z = 0 there).
    tip : ndarray, shape (2,)
        The bottom and top corners of the end face on the mid-plane; the tracked tip is
        their mid-point.
    section_points : ndarray
        Points of the mid-plane (z = width / 2) outline of the end face, ordered by height.
    station : ndarray, shape (2,)
        Bottom and top points of the mid-plane at the centre of the last wall between two
        voids, x = (voids - 1) pitch (the base section for a single void): a second tracked
        point, one void short of the tip, away from the free end wall.
    spec : BimodalSpec
    """

    points: FloatArray
    cells: IntArray
    cell_type: str
    label: IntArray
    void_points: BoolArray
    base_points: BoolArray
    symmetry_points: BoolArray | None
    tip: IntArray
    section_points: IntArray
    spec: BimodalSpec
    station: IntArray | None = None


def _label(spec: BimodalSpec, centres: FloatArray) -> IntArray:
    y0, y1, _, y3, _ = spec.interfaces
    x, y, z = centres[:, 0], centres[:, 1], centres[:, 2]
    lx = x - np.clip(np.floor(x / spec.pitch), 0, spec.voids - 1) * spec.pitch
    label = np.select([y < y0, y < y1, y < y3], [BILINEAR, SEAL, BODY], STRIP)
    vx0, vx1, vy0, vy1 = spec.void
    void = (lx > vx0) & (lx < vx1) & (y > vy0) & (y < vy1)
    void &= (z > spec.side_wall) & (z < spec.width - spec.side_wall) & (x < spec.voids * spec.pitch)
    return np.where(void, VOID, label).astype(np.int64)


def _lines(spec: BimodalSpec, half: bool) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The grid lines in x, y and z: a line on every interface and void wall, no gap wider than the element."""
    P, W, h = spec.pitch, spec.width, spec.element_size
    vx0, vx1, _, _ = spec.void
    xb = [i * P + x for i in range(spec.voids) for x in (0.0, vx0, vx1)] + [spec.voids * P, spec.length]
    zb = [0.0, spec.side_wall, W / 2] if half else [0.0, spec.side_wall, W / 2, W - spec.side_wall, W]
    return grid_lines(xb, h), grid_lines([0.0, *spec.interfaces], h), grid_lines(zb, h)


def node_count(spec: BimodalSpec, half: bool = True, quadratic: bool = True) -> int:
    """The nodes of :func:`mesh_actuator`'s mesh, counted from its grid lines without meshing.

    The grid's nodes (:func:`~pneumorph.geometry.meshsize.grid_nodes`) less those no cell keeps: inside each
    void, the grid points strictly within it and, for 20-node cells, the edges through its inside (a half model's
    void reaches the mid-plane z = width / 2, whose points within the void go too).

    Examples
    --------
    >>> node_count(BimodalSpec(voids=15, element_size=2.5))  # the mesh of the plan's measured ramps
    16291
    >>> node_count(BimodalSpec(voids=2, element_size=3.0), half=False, quadratic=False)
    1032
    """
    from pneumorph.geometry.meshsize import grid_nodes

    xs, ys, zs = _lines(spec, half)
    vx0, vx1, vy0, vy1 = spec.void
    z1 = spec.width / 2 if half else spec.width - spec.side_wall

    def inside(lines: FloatArray, lo: float, hi: float) -> int:
        return int(np.count_nonzero((lines > lo + 1e-6) & (lines < hi - 1e-6)))

    # lines strictly inside the first void (every void meshes alike), and its cells along each axis
    mx, my, mz = inside(xs, vx0, vx1), inside(ys, vy0, vy1), inside(zs, spec.side_wall, z1)
    ax, ay, az = mx + 1, my + 1, mz + 1
    mz += 1 if half else 0  # the mid-plane's points within the void: no cell on its other side
    gone = mx * my * mz + (ax * my * mz + mx * ay * mz + mx * my * az if quadratic else 0)
    grid = grid_nodes(len(xs) - 1, len(ys) - 1, len(zs) - 1, 3, 2 if quadratic else 1)
    return grid - spec.voids * gone


def mesh_actuator(spec: BimodalSpec, half: bool = True, quadratic: bool = True) -> BimodalMesh:
    """Mesh the actuator as a structured hexahedral grid with a line on every interface.

    Parameters
    ----------
    spec : BimodalSpec
    half : bool
        Mesh 0 <= z <= width / 2 only (the actuator is symmetric across its width).
    quadratic : bool
        20-node hexahedra (default) or linear 8-node ones.

    Returns
    -------
    BimodalMesh

    Examples
    --------
    >>> m = mesh_actuator(BimodalSpec(voids=2, element_size=3.0))
    >>> m.cell_type, sorted(set(m.label.tolist()))
    ('hexahedron20', [0, 1, 2, 3])
    """
    import felupe as fem

    P, W = spec.pitch, spec.width
    vx0, vx1, _, _ = spec.void
    grid = fem.Grid(*_lines(spec, half))
    label = _label(spec, grid.points[grid.cells].mean(axis=1))
    keep = label != VOID
    cells, label = grid.cells[keep], label[keep]
    used = np.unique(cells)
    renumber = np.full(len(grid.points), -1)
    renumber[used] = np.arange(len(used))
    mesh = fem.Mesh(grid.points[used], renumber[cells], grid.cell_type)
    if quadratic:
        mesh = mesh.add_midpoints_edges()
    points = np.asarray(mesh.points, dtype=float)

    tol = 1e-6
    lx = points[:, 0] - np.clip(np.floor(points[:, 0] / P), 0, spec.voids - 1) * P
    # points on the void walls: inside (or on) a void box; x = i P is never a void wall
    _, _, vy0, vy1 = spec.void
    on_void = (
        (points[:, 0] < spec.voids * P + tol)
        & (lx > vx0 - tol) & (lx < vx1 + tol)
        & (points[:, 1] > vy0 - tol) & (points[:, 1] < vy1 + tol)
        & (points[:, 2] > spec.side_wall - tol) & (points[:, 2] < W - spec.side_wall + tol)
    )
    # a point at x = i P + vx1 of void i-1 has lx = vx1 - P ... handled by the clip above;
    # the last void's end wall point x = voids P gives lx = P (outside), as it should
    end = np.isclose(points[:, 0], spec.length)
    mid = np.isclose(points[:, 2], W / 2)
    section = np.flatnonzero(end & mid)
    section = section[np.argsort(points[section, 1])]
    tip = section[[0, -1]]
    xs_ = (spec.voids - 1) * P
    st = np.flatnonzero(np.isclose(points[:, 0], xs_) & mid)
    st = st[np.argsort(points[st, 1])][[0, -1]]
    return BimodalMesh(
        points=points,
        cells=np.asarray(mesh.cells, dtype=np.int64),
        cell_type=mesh.cell_type,
        label=label.astype(np.int64),
        void_points=on_void,
        base_points=np.isclose(points[:, 0], 0.0),
        symmetry_points=mid if half else None,
        tip=tip,
        section_points=section,
        spec=spec,
        station=st,
    )


def cell_volumes(mesh: BimodalMesh) -> dict[str, float]:
    """Volume (mm^3) of each layer's cells, from the axis-aligned box of every cell.

    Examples
    --------
    >>> v = cell_volumes(mesh_actuator(BimodalSpec(voids=1, element_size=3.0), half=False))
    >>> round(v["bilinear"], 6)   # (10.5 + 4.5) x 5 x 15
    1125.0
    """
    x = mesh.points[mesh.cells]
    size = x.max(axis=1) - x.min(axis=1)
    vol = np.prod(size, axis=1)
    return {name: float(vol[mesh.label == code].sum()) for code, name in LABELS.items() if code != VOID}

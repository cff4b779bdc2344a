"""Paths: targets of any shape, ordered points from the base to the free end (a hook, a letter, a spiral).

A profile (:mod:`pneumorph.design.objectives.profiles`) is a graph ``y = f(x)``; the actuator curls
past 300 degrees, so the shapes it makes best are not graphs. A :class:`PathTarget` is a
polyline through points ``(x, y)`` or ``(x, y, z)`` in mm, given in order from the base to the
free end, in the frame of :attr:`~pneumorph.models.response.Response.centres`: x along the
undeformed axis from the base face, y up from the actuator's bottom face (the built-in unit's
undeformed centres lie at 4.5 or 7.5 mm, its axis at 6 mm), z across from the mid-plane. It is
matched by the unit centres as the model reports them, with no shift to their undeformed
heights.

The correspondence (``docs/shapes.md``): centre ``i`` of ``n`` has its *stretch* of the path,
the part within ``window * S`` of arc length of its place ``(i - 1/2) S / n`` (``S`` the path's
length: the centres spread along the path as along the actuator), and its term is the squared
distance to the nearest point of that stretch. The value is

.. math:: V = \\sqrt{\\sum_i d(c_i, P_i)^2}

in mm, the sum of squares of Eq 4.1, and ``V / sqrt(n)`` the RMS per centre. A design whose
centres lie on the path, each within its stretch, has ``V = 0``. Each term is the distance
to a fixed set, 1-Lipschitz in its centre, so ``V`` is 1-Lipschitz in the stacked centres:
a model whose every centre is within ``e`` of another's changes ``V`` by at most ``e sqrt(n)``
(the chain's bound, :mod:`pneumorph.design.certified.bounds`). The stretches keep the order along the
path: a centre near the base is not matched to the end of a hook that curls back past it.

Presets (:data:`PATH_PRESETS`) are drawn for the actuator they are asked of: their length
is a multiple of its undeformed length ``L``, their arcs of radius fractions of it.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.design.objectives.profiles import MAX_CURVE_POINTS, Sense, target_points
from pneumorph.errors import TargetExpressionError

FloatArray = NDArray[np.float64]

PATH_WINDOW = 0.15
"""Half the stretch of the path each centre is matched within, as a share of the path's length."""

MAX_PATH_POINTS = MAX_CURVE_POINTS
"""Most points accepted for a path."""

MIN_PATH_MM = 1.0
"""Shortest path accepted (mm): a path must go somewhere."""

_CHUNK = 1 << 16
"""Points whose distances to a stretch are computed at once (memory: about 1 kB per point and segment)."""


def path_points(points: ArrayLike, where: str = "a path") -> FloatArray:
    """Points as a checked (m, 3) array of finite mm values, repeated neighbours dropped (a 2-column path at z = 0).

    Raises
    ------
    TargetExpressionError
        Not a list of [x, y] or [x, y, z] numbers, fewer than 2 or more than :data:`MAX_PATH_POINTS`
        points, values that are not finite or beyond :data:`~pneumorph.design.objectives.profiles.MAX_TARGET_MM`
        (the checks of a drawn curve's points),
        or a path shorter than :data:`MIN_PATH_MM` (all its points at one place).

    Examples
    --------
    >>> path_points([[0, 0], [10, 0], [10, 0], [10, 5]]).tolist()
    [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 5.0, 0.0]]
    >>> path_points([[1, 1], [1, 1]])
    Traceback (most recent call last):
    ...
    pneumorph.errors.TargetExpressionError: a path's points all lie within 1 mm of each other (its length is 0
    mm); give points along the shape, from the base to the free end
    """
    p = target_points(points, (2, 3), where)
    if p.shape[1] == 2:
        p = np.column_stack([p, np.zeros(len(p))])
    keep = np.r_[True, np.any(np.diff(p, axis=0) != 0.0, axis=1)]
    p = p[keep]
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) if len(p) > 1 else 0.0
    if length < MIN_PATH_MM:
        raise TargetExpressionError(f"a path's points all lie within {MIN_PATH_MM:g} mm of each other (its length "
                                    f"is {length:.3g} mm); give points along the shape, from the base to the free "
                                    "end")
    return p


@functools.lru_cache(maxsize=64)
def _stretches(points: tuple[tuple[float, ...], ...], window: float,
               n: int) -> tuple[tuple[FloatArray, ...], tuple[FloatArray, ...]]:
    """Each of ``n`` centres' stretch of the polyline ``points`` as segments: their starts and ends, (s_i, 3) each."""
    p = np.asarray(points, dtype=float)
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    arc = np.r_[0.0, np.cumsum(steps)]
    total = float(arc[-1])

    def at(s: float) -> FloatArray:
        j = int(np.clip(np.searchsorted(arc, s, side="right") - 1, 0, len(steps) - 1))
        t = (s - arc[j]) / steps[j] if steps[j] > 0 else 0.0
        return np.asarray(p[j] + min(max(t, 0.0), 1.0) * (p[j + 1] - p[j]), dtype=float)

    starts: list[FloatArray] = []
    ends: list[FloatArray] = []
    for i in range(n):
        place = (i + 0.5) / n * total
        lo, hi = max(place - window * total, 0.0), min(place + window * total, total)
        inner = np.flatnonzero((arc > lo) & (arc < hi))  # the path's own points inside the stretch
        knots = np.vstack([at(lo), p[inner], at(hi)])
        starts.append(knots[:-1])
        ends.append(knots[1:])
    for array in (*starts, *ends):
        array.setflags(write=False)
    return tuple(starts), tuple(ends)


def _segment_distance2(q: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Squared distance of points ``q`` (m, 3) to the nearest of the segments ``a``-``b`` (s, 3), shape (m,).

    Written out per coordinate (no einsum: the segments are few, the points many), and in the plane where the
    points and the segments all lie at z = 0.
    """
    out = np.empty(len(q))
    d = b - a
    dd = (d * d).sum(axis=1)
    inv = np.where(dd > 0.0, 1.0 / np.where(dd > 0.0, dd, 1.0), 0.0)
    axes = 2 if not (np.any(a[:, 2]) or np.any(b[:, 2]) or np.any(q[:, 2])) else 3
    step = max(1, _CHUNK // max(len(a), 1))
    for lo in range(0, len(q), step):
        rel = [q[lo:lo + step, j, None] - a[None, :, j] for j in range(axes)]  # (c, s) each
        t = rel[0] * d[:, 0]
        for j in range(1, axes):
            t += rel[j] * d[:, j]
        t *= inv
        np.clip(t, 0.0, 1.0, out=t)
        total = None
        for j in range(axes):
            e = rel[j]
            e -= t * d[:, j]
            e *= e
            total = e if total is None else total + e
        assert total is not None
        out[lo:lo + step] = total.min(axis=1)
    return out


@dataclass(frozen=True)
class PathTarget:
    """A path the unit centres should lie along, in order (minimised; mm).

    Attributes
    ----------
    points : tuple of (x, y, z)
        The polyline's points (mm; z = 0 for a path in the plane), from the base to the free
        end. With ``relative``, in units of the actuator length ``L``.
    name : str
        A short label ("path", or a preset's name).
    window : float
        Each centre's stretch is within ``window`` times the path's length of its place
        (:data:`PATH_WINDOW`).
    relative : bool
        The points are fractions of ``L`` (a preset drawn for any actuator).
    length : float or None
        ``L`` (mm) of a relative path; None takes the actuator's undeformed length.

    Examples
    --------
    Three centres along a straight path of 30 mm, each at its place, then 1 mm off it:

    >>> t = path_target([[0, 0], [30, 0]])
    >>> c = np.array([[5.0, 0.0], [15.0, 0.0], [25.0, 0.0]])
    >>> float(t.error(c)), float(t.error(c + [0.0, 1.0])), t.rms(c + [0.0, 1.0]).item()
    (0.0, 1.7320508075688772, 1.0)
    """

    points: tuple[tuple[float, ...], ...]
    name: str = "path"
    window: float = PATH_WINDOW
    relative: bool = False
    length: float | None = None
    sense: Sense = field(default="min", init=False)
    unit: str = field(default="mm", init=False)
    point: None = field(default=None, init=False)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.window) and 0.0 < self.window <= 1.0):
            raise TargetExpressionError(f"a path's window is a share of its length in (0, 1], got {self.window!r}")

    def at(self, length: float, height: float) -> PathTarget:
        """The path in mm for an actuator ``length`` mm long whose undeformed axis lies ``height`` mm up (a relative
        path scaled by ``L``, its own ``length`` if given, and started on the axis; a path in mm as it is).

        >>> preset_path("hook").at(100.0, 6.0).points[0]
        (0.0, 6.0, 0.0)
        """
        if not self.relative:
            return self
        scale = self.length if self.length is not None else length
        p = np.asarray(self.points, dtype=float) * scale + np.array([0.0, height, 0.0])
        return PathTarget(tuple(tuple(float(v) for v in row) for row in p), self.name, self.window)

    def polyline(self) -> FloatArray:
        """The path's points (m, 3), mm."""
        self._absolute()
        return np.asarray(self.points, dtype=float)

    def arc_length(self) -> float:
        """The path's length (mm)."""
        return float(np.linalg.norm(np.diff(self.polyline(), axis=0), axis=1).sum())

    def _absolute(self) -> None:
        if self.relative:
            raise ValueError("a relative path is placed on an actuator first: PathTarget.at(length, height)")

    @property
    def spatial(self) -> bool:
        """True for a path that leaves the plane z = 0."""
        return bool(np.any(np.asarray(self.points, dtype=float)[:, 2] != 0.0))

    def stretches(self, n: int) -> tuple[tuple[FloatArray, ...], tuple[FloatArray, ...]]:
        """The stretch of each of ``n`` centres as segments: their starts and ends, (s_i, 3) each."""
        self._absolute()
        return _stretches(self.points, float(self.window), int(n))

    def term(self, i: int, n: int, centre: ArrayLike) -> FloatArray:
        """Centre ``i``'s term (0-based, of ``n``): its squared distance to its stretch, shape ``centre.shape[:-1]``.

        ``centre`` holds points ``(..., 2)`` (z = 0) or ``(..., 3)`` (z from the mid-plane).
        """
        q = np.asarray(centre, dtype=float)
        shape = q.shape[:-1]
        flat = q.reshape(-1, q.shape[-1])
        if flat.shape[1] == 2:
            flat = np.column_stack([flat, np.zeros(len(flat))])
        a, b = self.stretches(n)
        return _segment_distance2(flat, a[i], b[i]).reshape(shape)

    def distance_to(self, i: int, n: int, centre: ArrayLike) -> FloatArray:
        """Centre ``i``'s distance to its stretch (mm)."""
        return np.sqrt(self.term(i, n, centre))

    def terms(self, centres: ArrayLike) -> FloatArray:
        """Every centre's term, shape ``centres.shape[:-1]`` (centres ``(..., n, 2 or 3)``)."""
        c = np.asarray(centres, dtype=float)
        n = c.shape[-2]
        return np.stack([self.term(i, n, c[..., i, :]) for i in range(n)], axis=-1)

    def error(self, centres: ArrayLike) -> FloatArray:
        """The value ``V`` (mm) of centres ``(..., n, 2 or 3)``, shape ``centres.shape[:-2]``."""
        return np.sqrt(self.terms(centres).sum(axis=-1))

    def rms(self, centres: ArrayLike) -> FloatArray:
        """The RMS distance per centre (mm): ``V / sqrt(n)``."""
        c = np.asarray(centres, dtype=float)
        return self.error(c) / np.sqrt(c.shape[-2])

    def nearest(self, centres: ArrayLike) -> FloatArray:
        """Each centre's nearest point of its stretch, ``(n, 3)`` for centres ``(n, 2 or 3)`` (for figures)."""
        c = np.asarray(centres, dtype=float)
        if c.shape[-1] == 2:
            c = np.column_stack([c, np.zeros(len(c))])
        a, b = self.stretches(len(c))
        out = np.empty_like(c)
        for i, q in enumerate(c):
            d = b[i] - a[i]
            dd = np.einsum("sj,sj->s", d, d)
            t = np.clip(np.einsum("sj,sj->s", q - a[i], d) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
            foot = a[i] + t[:, None] * d
            out[i] = foot[np.argmin(np.linalg.norm(foot - q, axis=1))]
        return out

    @property
    def label(self) -> str:
        what = "a preset drawn for the actuator" if self.relative else f"through {len(self.points)} points"
        return f"{self.name}: path {what}" + (" in space" if self.spatial else "")

    @property
    def display(self) -> str:
        return f"path {self.name}"


def path_target(points: ArrayLike, name: str = "path", window: float = PATH_WINDOW,
                where: str = "a path") -> PathTarget:
    """A path target through ``points`` ``[[x, y], ...]`` or ``[[x, y, z], ...]`` (mm), from the base to the free end.

    Raises
    ------
    TargetExpressionError
        Points :func:`path_points` refuses.

    Examples
    --------
    >>> t = path_target([[0, 0], [50, 0], [50, 50]])
    >>> t.label, t.arc_length()
    ('path: path through 3 points', 100.0)
    """
    p = path_points(points, where)
    return PathTarget(tuple(tuple(float(v) for v in row) for row in p), name, window)


def read_path(file: str | Path) -> PathTarget:
    """A path from a CSV or TXT file: two or three columns of mm (x, y[, z]), one point a line, from the base on.

    Commas, semicolons, tabs or spaces separate the columns; a first line that is not numbers
    (a header) and lines starting with ``#`` are skipped.

    Raises
    ------
    TargetExpressionError
        A file that cannot be read, or whose rows are not two or three numbers each.
    """
    import io

    from pneumorph.io.reading import MAX_SETTINGS_BYTES, read_text_file

    text = read_text_file(file, "path file", TargetExpressionError, limit=MAX_SETTINGS_BYTES)
    rows: list[list[float]] = []
    header_allowed = True
    for number, line in enumerate(io.StringIO(text), 1):  # a line at a time: stopped at MAX_PATH_POINTS
        if len(rows) >= MAX_PATH_POINTS:
            raise TargetExpressionError(f"{file}: more than MAX_PATH_POINTS = {MAX_PATH_POINTS} points "
                                        "(pneumorph.design.objectives.paths); thin the path out")
        fields = line.replace(",", " ").replace(";", " ").split()
        if not fields or fields[0].startswith("#"):
            continue
        try:
            values = [float(f) for f in fields]
        except ValueError:
            if header_allowed:  # only the first line may be a header
                header_allowed = False
                continue
            raise TargetExpressionError(f"{file}: line {number} is not numbers: {line.strip()[:60]!r}; a path file "
                                        "holds x, y (and z) in mm, one point a line") from None
        header_allowed = False
        if len(values) not in (2, 3) or (rows and len(values) != len(rows[0])):
            raise TargetExpressionError(f"{file}: line {number} has {len(values)} numbers; every line holds 2 "
                                        "(x, y) or every line 3 (x, y, z), in mm")
        rows.append(values)
    if not rows:
        raise TargetExpressionError(f"{file}: no points; a path file holds x, y (and z) in mm, one point a line")
    return path_target(rows, Path(file).stem or "path", where=f"the path in {file}")


# -- presets ---------------------------------------------------------------------------------------------------------
def _arc(start: FloatArray, heading: float, radius: float, turn: float, steps: int = 24) -> FloatArray:
    """Points of a circular arc in the plane from ``start`` at ``heading`` (rad), turning ``turn`` rad (positive:
    counter-clockwise) on ``radius``; the start left out."""
    sign = 1.0 if turn >= 0 else -1.0
    centre = start + sign * radius * np.array([-np.sin(heading), np.cos(heading)])
    phis = heading - sign * np.pi / 2 + np.linspace(0.0, turn, steps + 1)[1:]
    return centre + radius * np.column_stack([np.cos(phis), np.sin(phis)])


def _chain(pieces: list[tuple[str, float, float]], start: tuple[float, float] = (0.0, 0.0)) -> FloatArray:
    """A planar path from straight pieces ``("line", length, 0)`` and arcs ``("arc", radius, turn)``."""
    pts = [np.asarray(start, dtype=float)]
    heading = 0.0
    for kind, a, b in pieces:
        if kind == "line":
            pts.append(pts[-1] + a * np.array([np.cos(heading), np.sin(heading)]))
        else:
            pts.extend(_arc(pts[-1], heading, a, b))
            heading += b
    return np.vstack(pts)


def _unit_length(points: FloatArray) -> FloatArray:
    """Points scaled to a path of length 1."""
    return points / float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def _letter_l() -> FloatArray:
    # SPADA's L: 80 mm straight, a quarter arc, 30 mm straight; the arc's radius the actuator's tightest curl (about
    # 0.19 of the centres' line at 45 kPa) where SPADA's is 20 mm of 141
    return _unit_length(_chain([("line", 0.51, 0.0), ("arc", 0.19, np.pi / 2), ("line", 0.19, 0.0)]))


def _letter_s() -> FloatArray:
    # two arcs of one radius turning opposite ways (SPADA's S: three-quarter turns of radius 25 mm, which the
    # actuator's length holds only at a radius it cannot curl; here 160 degrees each)
    return _unit_length(_chain([("arc", 1.0, np.radians(160.0)), ("arc", 1.0, -np.radians(160.0))]))


def _letter_r() -> FloatArray:
    # a stem, the bowl (a half turn) and the leg kicking out on twice the bowl's radius (SPADA's R: 20 and 40 mm)
    return _unit_length(_chain([("line", 0.25, 0.0), ("arc", 0.19, np.pi), ("arc", 0.38, -np.pi / 4)]))


def _hook() -> FloatArray:
    # a J: a straight shank, then 200 degrees on the tightest curl
    return _unit_length(_chain([("line", 0.34, 0.0), ("arc", 0.19, np.radians(200.0))]))


def _spiral() -> FloatArray:
    # r = a - b theta about a centre above the base, wound inwards over 252 degrees, the radius falling by a third
    theta = np.linspace(0.0, 1.4 * np.pi, 121)
    r = 0.3 - 0.025 * theta
    return _unit_length(np.column_stack([r * np.sin(theta), 0.3 - r * np.cos(theta)]))


def _coil() -> FloatArray:
    # a right-handed helix of one and a half turns about an axis along x (radius a tenth of its length)
    turns, radius = 1.5, 0.1
    t = np.linspace(0.0, 2 * np.pi * turns, 121)
    rise = np.sqrt(max(1.0 - (2 * np.pi * turns * radius) ** 2, 0.0)) / t[-1]
    return _unit_length(np.column_stack([rise * t, radius * (1 - np.cos(t)), -radius * np.sin(t)]))


#: Preset paths by name, each as points in units of the actuator length L (a path of length about L).
PATH_PRESETS: dict[str, Callable[[], FloatArray]] = {
    "letter-l": _letter_l, "letter-s": _letter_s, "letter-r": _letter_r, "hook": _hook, "spiral": _spiral,
    "coil": _coil,
}

#: How much longer than the undeformed actuator a preset is drawn by default: the line through the unit centres
#: lengthens as the cavities inflate (1.17 L at 45 kPa, 1.04 L at 27 kPa, by the 3D chain for any design).
PRESET_SCALE = 1.15


def preset_path(name: str, scale: float = PRESET_SCALE, length: float | None = None) -> PathTarget:
    """The preset path ``name`` (:data:`PATH_PRESETS`), ``scale`` times the actuator length ``L`` long.

    Examples
    --------
    >>> t = preset_path("letter-l")
    >>> round(t.at(100.0, 6.0).arc_length(), 6), t.label
    (115.0, 'letter-l: path a preset drawn for the actuator')
    """
    key = name.strip().lower()
    if key not in PATH_PRESETS:
        raise TargetExpressionError(f"unknown path preset {name!r}; known: {', '.join(PATH_PRESETS)}")
    if not (np.isfinite(scale) and 0.0 < scale <= 100.0):
        raise TargetExpressionError(f"a preset path's scale is a positive multiple of the actuator length, got "
                                    f"{scale!r}")
    p = PATH_PRESETS[key]() * scale
    if p.shape[1] == 2:
        p = np.column_stack([p, np.zeros(len(p))])
    return PathTarget(tuple(tuple(float(v) for v in row) for row in p), key, relative=True, length=length)


__all__ = [
    "MAX_PATH_POINTS",
    "MIN_PATH_MM",
    "PATH_PRESETS",
    "PATH_WINDOW",
    "PRESET_SCALE",
    "PathTarget",
    "path_points",
    "path_target",
    "preset_path",
    "read_path",
]

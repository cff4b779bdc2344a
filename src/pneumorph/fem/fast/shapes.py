"""Rigid obstacles' geometry: a plane (:class:`Plane`), a cylinder (:class:`Cylinder`, a circle in 2D) and a
sphere (:class:`Sphere`), each giving every point ``x`` a signed gap ``g(x)`` (negative: inside), the outward
normal ``n = dg/dx`` and the curvature ``H = dn/dx`` (None for a plane); their tables (``[[model.obstacle]]``)
read and checked (:func:`obstacle_from_dict`), and whether one starts inside a body (:func:`start_inside`).

The penalty that holds a body's surface out of them is :mod:`~pneumorph.fem.fast.contact`'s.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pneumorph import checks
from pneumorph.errors import SettingsError

FloatArray = NDArray[np.float64]


def _vector(value: Any, name: str, dim: int) -> tuple[float, ...]:
    """``value`` as ``dim`` finite numbers (SettingsError otherwise)."""
    try:
        v = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise SettingsError(f"{name} must be {dim} numbers, got {value!r}") from None
    if v.size != dim or not np.all(np.isfinite(v)):
        raise SettingsError(f"{name} must be {dim} finite numbers, got {value!r}")
    return tuple(float(c) for c in v)


def _unit(value: Any, name: str, dim: int) -> tuple[float, ...]:
    v = np.asarray(_vector(value, name, dim))
    norm = float(np.linalg.norm(v))
    if norm == 0.0:
        raise SettingsError(f"{name} must not be zero, got {value!r}")
    return tuple(float(c) for c in v / norm)


@dataclass(frozen=True)
class Obstacle:
    """A rigid obstacle (use :class:`Plane`, :class:`Cylinder` or :class:`Sphere`)."""

    kind: ClassVar[str] = ""

    def kinematics(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray | None]:
        """Gaps (m,), outward unit normals (m, d) and curvatures ``dn/dx`` (m, d, d; None: flat) at points (m, d)."""
        raise NotImplementedError  # pragma: no cover

    def to_dict(self) -> dict[str, Any]:
        """The obstacle as a TOML/JSON table (``[[model.obstacle]]``)."""
        out: dict[str, Any] = {"kind": self.kind}
        for key, value in vars(self).items():
            if value != ():  # (a circle has no axis)
                out[key] = [float(v) for v in value] if isinstance(value, tuple) else float(value)
        return out


@dataclass(frozen=True)
class Plane(Obstacle):
    """A rigid half-space: the body stays on the side ``normal`` points to, from the plane through ``point``.

    >>> gap, n, H = Plane((10.0, 0.0), (-1.0, 0.0)).kinematics(np.array([[12.0, 1.0], [9.0, 5.0]]))
    >>> gap.tolist(), n[0].tolist(), H is None
    ([-2.0, 1.0], [-1.0, 0.0], True)
    """

    kind: ClassVar[str] = "plane"
    point: tuple[float, ...]
    normal: tuple[float, ...]

    def kinematics(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray | None]:
        n = np.asarray(self.normal)
        return (x - np.asarray(self.point)) @ n, np.broadcast_to(n, x.shape), None


def _round(dx: FloatArray, radius: float, axis: FloatArray | None) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Gap, normal and curvature of a circle, sphere (``axis`` None) or cylinder from ``dx = x - centre``."""
    d = dx.shape[1]
    if axis is not None:
        dx = dx - np.outer(dx @ axis, axis)
    dist = np.maximum(np.linalg.norm(dx, axis=1), 1e-12 * radius)
    n = dx / dist[:, None]
    projector = np.eye(d) if axis is None else np.eye(d) - np.outer(axis, axis)
    H = (projector[None] - n[:, :, None] * n[:, None, :]) / dist[:, None, None]
    return dist - radius, n, H


@dataclass(frozen=True)
class Cylinder(Obstacle):
    """A rigid cylinder of ``radius`` about the line through ``centre`` along ``axis`` (a circle in 2D: no axis).

    >>> gap, n, H = Cylinder((0.0, 0.0, 0.0), 2.0, (0.0, 0.0, 1.0)).kinematics(np.array([[3.0, 0.0, 7.0]]))
    >>> gap.tolist(), n.tolist(), H[0].diagonal().round(4).tolist()
    ([1.0], [[1.0, 0.0, 0.0]], [0.0, 0.3333, 0.0])
    """

    kind: ClassVar[str] = "cylinder"
    centre: tuple[float, ...]
    radius: float
    axis: tuple[float, ...] = ()

    def kinematics(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray | None]:
        axis = np.asarray(self.axis) if len(self.axis) == 3 else None
        return _round(x - np.asarray(self.centre), self.radius, axis)


@dataclass(frozen=True)
class Sphere(Obstacle):
    """A rigid sphere (a circle in 2D) of ``radius`` about ``centre``.

    >>> gap, n, H = Sphere((0.0, 0.0), 1.0).kinematics(np.array([[0.0, 0.5]]))
    >>> gap.tolist(), n.tolist()
    ([-0.5], [[0.0, 1.0]])
    """

    kind: ClassVar[str] = "sphere"
    centre: tuple[float, ...]
    radius: float

    def kinematics(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray | None]:
        return _round(x - np.asarray(self.centre), self.radius, None)


KINDS: dict[str, type[Obstacle]] = {"plane": Plane, "cylinder": Cylinder, "sphere": Sphere}


def obstacle_from_dict(table: Mapping[str, Any], dim: int, where: str = "obstacle") -> Obstacle:
    """An obstacle from its table (``kind`` and its geometry, mm), checked.

    Raises
    ------
    SettingsError
        An unknown kind or key, a point of the wrong size or not finite, a zero normal or
        axis, a radius <= 0, a friction < 0 or above :data:`~pneumorph.checks.MAX_FRICTION` (the table's
        ``friction`` is checked here and kept by the caller: the geometry does not hold it).

    Examples
    --------
    >>> obstacle_from_dict({"kind": "plane", "point": [150, 0], "normal": [-2, 0]}, 2)
    Plane(point=(150.0, 0.0), normal=(-1.0, 0.0))
    >>> obstacle_from_dict({"kind": "cylinder", "centre": [0, 0], "radius": 0}, 2)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: obstacle radius must be a finite number > 0 (mm), got 0
    """
    if not isinstance(table, Mapping):
        raise SettingsError(f"{where} must be a table (kind, and its geometry), got {table!r}")
    kind = table.get("kind")
    if kind not in KINDS:
        raise SettingsError(f"{where} kind must be one of {', '.join(KINDS)}, got {kind!r}")
    keys = {"plane": ["point", "normal"], "cylinder": ["centre", "radius", "axis"], "sphere": ["centre", "radius"]}
    allowed = [*keys[kind], "kind", "friction"]
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise SettingsError(f"{where}: unknown key(s) {', '.join(unknown)} of a {kind}; known: {', '.join(allowed)}")
    checks.real(table.get("friction", 0.0), f"{where} friction", 0.0, checks.MAX_FRICTION, limit="MAX_FRICTION")
    missing = [k for k in keys[kind] if k not in table and not (k == "axis" and dim == 2)]
    if missing:
        raise SettingsError(f"{where}: a {kind} needs {', '.join(missing)}")
    if kind == "plane":
        return Plane(_vector(table["point"], f"{where} point", dim),
                     _unit(table["normal"], f"{where} normal", dim))
    radius = checks.real(table["radius"], f"{where} radius", 0.0, low_open=True, unit="mm")
    centre = _vector(table["centre"], f"{where} centre", dim)
    if kind == "sphere":
        return Sphere(centre, radius)
    if dim == 2:
        if "axis" in table:
            raise SettingsError(f"{where}: a cylinder in 2D is a circle about the section's normal; give no axis")
        return Cylinder(centre, radius)
    return Cylinder(centre, radius, _unit(table["axis"], f"{where} axis", 3))


def start_inside(obstacles: Sequence[Obstacle], x: FloatArray) -> str | None:
    """Why an obstacle cannot start where it is (a point ``x`` (p, d) of the body inside it), or None.

    >>> start_inside([Sphere((0.0, 0.0), 1.0)], np.array([[3.0, 0.0], [0.5, 0.0]]))
    'obstacle 1 (sphere) starts inside the actuator: its point (0.5, 0) mm lies 0.5 mm inside it'
    """
    for i, obstacle in enumerate(obstacles):
        gap = obstacle.kinematics(x)[0]
        worst = int(np.argmin(gap))
        if gap[worst] < -1e-9:  # (a wall through a surface point touches it)
            where = ", ".join(f"{v:g}" for v in x[worst])
            return (f"obstacle {i + 1} ({obstacle.kind}) starts inside the actuator: its point ({where}) mm lies "
                    f"{-gap[worst]:.3g} mm inside it")
    return None


__all__ = ["KINDS", "Cylinder", "Obstacle", "Plane", "Sphere", "obstacle_from_dict", "start_inside"]

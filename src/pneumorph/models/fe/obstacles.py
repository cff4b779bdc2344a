"""Rigid obstacles in the FE models: ``[[model.obstacle]]`` tables, the contact items of a mesh, the forces out.

An obstacle (:mod:`pneumorph.fem.fast.shapes`: a plane, a cylinder - a circle in 2D - or a sphere,
frictionless or with Coulomb ``friction``) touches the actuator's outer surface nodes, or with
``on = "end"`` the nodes of its free end face only (a load cell against the tip: :func:`blocked_wall`).
Every reported level records, per obstacle, the force the actuator exerts on it (N), the nodes in contact and the
contact length (2D, mm) or area (3D, mm^2), the clearance (the least gap of the nodes it may touch, mm; <= 0 in
contact), and the reaction of the clamped base on the actuator
(N): with no gravity it equals the sum of the obstacles' forces, since the cavity pressure is
internal. The 2D section's forces per mm of depth are multiplied by the unit's width; a 3D half
model's by two (their z components vanish by symmetry).

The penalty is :func:`~pneumorph.fem.fast.contact.penalty_stiffness` of the body silicone's shear
modulus and the unit's element size: a contact pressure ``p_c`` lets the surface into the obstacle
by about ``p_c / (10 mu)`` of an element (about 1 % of an element at ``p_c = mu / 10``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from pneumorph import checks
from pneumorph.errors import SettingsError
from pneumorph.fem.fast.contact import RigidContact, penalty_stiffness, surface_points
from pneumorph.fem.fast.shapes import Cylinder, Obstacle, Plane, Sphere, obstacle_from_dict, start_inside
from pneumorph.geometry.assembly import ActuatorMesh
from pneumorph.models.response import FloatArray

#: the gap over which the penalty sets in, over the element size
#: (:func:`~pneumorph.fem.fast.contact.penalty_gap`)
SMOOTHING = 0.02
#: the deepest a Newton step may carry a node into an obstacle from outside, over the element size
#: (:meth:`~pneumorph.fem.fast.contact.RigidContact.step_fraction`)
REACH = 0.1
#: the farthest a Newton step may move a node of a body with obstacles, over the element size
#: (:meth:`~pneumorph.fem.fast.contact.RigidContact.step_fraction`)
STRIDE = 1.0
#: where an obstacle may touch: the whole outer surface, or the free end face only
TOUCHES = ("surface", "end")


@dataclass(frozen=True)
class ModelObstacle:
    """An obstacle of a model, the nodes it may touch (``on``: ``"surface"`` or ``"end"``) and Coulomb's
    friction coefficient on it."""

    obstacle: Obstacle
    on: str = "surface"
    friction: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        out = self.obstacle.to_dict()
        if self.on != "surface":  # absent by default
            out["on"] = self.on
        if self.friction > 0.0:  # likewise
            out["friction"] = self.friction
        return out


def check_obstacles(obstacles: Sequence[Any] | None, dim: int,
                    where: str = "[[model.obstacle]]") -> tuple[ModelObstacle, ...]:
    """The obstacles of a model, from tables (``kind``, its geometry in mm, ``on``) or :class:`ModelObstacle`.

    Raises
    ------
    SettingsError
        A table that is no valid obstacle (:func:`~pneumorph.fem.fast.shapes.obstacle_from_dict`), an
        unknown ``on``, or a ``friction`` outside 0 to :data:`~pneumorph.checks.MAX_FRICTION`.

    Examples
    --------
    >>> [o.obstacle.kind for o in check_obstacles([{"kind": "cylinder", "centre": [60, 20], "radius": 5}], 2)]
    ['cylinder']
    >>> check_obstacles([{"kind": "sphere", "centre": [60, 20], "radius": -1}], 2)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: [[model.obstacle]] 1 radius must be a finite number > 0 (mm), got -1
    >>> check_obstacles([{"kind": "plane", "point": [150, 0], "normal": [-1, 0], "friction": 20}], 2)
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: [[model.obstacle]] 1 friction must be ... <= 10 (limit MAX_FRICTION), got 20
    """
    if obstacles is None:
        return ()
    if not isinstance(obstacles, (list, tuple)):
        raise SettingsError(f"{where} must be a list of obstacle tables, got {obstacles!r}")
    out = []
    for i, entry in enumerate(obstacles):
        name = f"{where} {i + 1}"
        if isinstance(entry, ModelObstacle):  # (a table's friction is checked with its geometry)
            item = entry
            checks.real(item.friction, f"{name} friction", 0.0, checks.MAX_FRICTION, limit="MAX_FRICTION")
        elif isinstance(entry, Mapping):
            on = entry.get("on", "surface")
            if on not in TOUCHES:
                raise SettingsError(f"{name} on must be one of {', '.join(TOUCHES)}, got {on!r}")
            obstacle = obstacle_from_dict({k: v for k, v in entry.items() if k != "on"}, dim, name)
            item = ModelObstacle(obstacle, on, float(entry.get("friction", 0.0)))
        else:
            raise SettingsError(f"{name} must be a table (kind, and its geometry), got {entry!r}")
        out.append(item)
    return tuple(out)


def _symmetric(obstacle: Obstacle, z0: float) -> bool:
    """Whether ``obstacle`` is its own mirror image about the plane ``z = z0``."""
    if isinstance(obstacle, Plane):
        return bool(obstacle.normal[2] == 0.0)
    assert isinstance(obstacle, (Cylinder, Sphere))
    centre = obstacle.centre
    axis = obstacle.axis if isinstance(obstacle, Cylinder) else ()
    if len(axis) == 3 and abs(axis[2]) == 1.0:  # a cylinder across the width
        return True
    return bool(np.isclose(centre[2], z0) and (len(axis) != 3 or axis[2] == 0.0))


def contact_items(obstacles: Sequence[ModelObstacle], mesh: ActuatorMesh, shear_modulus: float) -> list[RigidContact]:
    """The contact items of a meshed actuator, refused where an obstacle starts inside it.

    Raises
    ------
    SettingsError
        A surface node lies inside an obstacle before any load, or on a 3D half model an obstacle is not
        symmetric about the mid-plane ``z = width / 2``.
    """
    if not obstacles:
        return []
    z0 = mesh.spec.width / 2
    for i, o in enumerate(obstacles):
        if mesh.symmetry_points is not None and not _symmetric(o.obstacle, z0):
            raise SettingsError(f"obstacle {i + 1} is not symmetric about the half model's mid-plane z = {z0:g} mm; "
                                "solve the full width (half = false)")
    excluded = mesh.cavity_points.copy()
    if mesh.symmetry_points is not None:
        excluded |= mesh.symmetry_points
    faces, nodes = surface_points(mesh.cells, mesh.cell_type, excluded)
    end_x = mesh.points[mesh.end_points[0], 0]
    on_end = np.isclose(mesh.points[:, 0], end_x)
    end_faces = faces[np.all(on_end[faces], axis=1)]
    k = penalty_stiffness(shear_modulus, mesh.spec.element_size, mesh.dim)
    smoothing = SMOOTHING * mesh.spec.element_size
    items = [RigidContact(o.obstacle, np.unique(end_faces) if o.on == "end" else nodes, k,
                          end_faces if o.on == "end" else faces, smoothing, o.friction,
                          REACH * mesh.spec.element_size, STRIDE * mesh.spec.element_size) for o in obstacles]
    for item in items:
        item.commit(mesh.points)  # friction's anchors: where the nodes start
    problem = start_inside([o.obstacle for o in obstacles], mesh.points)  # any point: an obstacle in a cavity too
    if problem is not None:
        raise SettingsError(problem)
    return items


class ContactRecord:
    """The forces and contact of every reported level, for a response's metadata (``metadata["contact"]``).

    Parameters
    ----------
    obstacles : sequence of ModelObstacle
    mesh : ActuatorMesh
    contacts : list of RigidContact
        The items of :func:`contact_items` in the solved body.
    half : bool
        A 3D half model (forces doubled, their z components zero).
    """

    def __init__(self, obstacles: Sequence[ModelObstacle], mesh: ActuatorMesh, contacts: list[RigidContact],
                 half: bool) -> None:
        self.obstacles = list(obstacles)
        self.mesh = mesh
        self.contacts = contacts
        self.base = np.flatnonzero(mesh.base_points)
        # 2D: per mm of depth times the width; a half model: twice its half
        self.scale = np.full(mesh.dim, mesh.spec.width if mesh.dim == 2 else 2.0 if half else 1.0)
        if half:
            self.scale[2] = 0.0
        self.levels: list[dict[str, Any]] = []

    def record(self, k: int, pressure: float, system: Any, displacement: FloatArray) -> None:
        """Level ``k`` at ``pressure`` (MPa), the fast ``system``'s state ``displacement`` (p, d)."""
        x = self.mesh.points + displacement
        residual = system.residual(displacement.ravel())[0].reshape(-1, self.mesh.dim)
        reaction = residual[self.base].sum(axis=0) * self.scale
        entries = []
        for contact in self.contacts:
            report = contact.report(x)
            entries.append({"force_n": (report["force"] * self.scale).tolist(),
                            "force_magnitude_n": float(np.linalg.norm(report["force"] * self.scale)),
                            "nodes_in_contact": report["nodes"].tolist(),
                            "node_forces_n": (report["node_forces"] * self.scale).tolist(),
                            "node_pressures_kpa": (report["node_pressures"] * 1e3).tolist(),
                            "clearance_mm": float(contact.obstacle.kinematics(x[contact.points])[0].min()),
                            "contact_length_mm" if self.mesh.dim == 2 else "contact_area_mm2":
                                report["measure"] * (2.0 if self.mesh.dim == 3 and self.scale[2] == 0.0 else 1.0)})
        self.levels[k:] = [{"pressure_kpa": pressure * 1e3, "base_reaction_n": reaction.tolist(),
                            "obstacles": entries}]

    def metadata(self) -> dict[str, Any]:
        """What a response's metadata keeps: the obstacles, the penalty and every level."""
        return {"obstacles": [o.to_dict() for o in self.obstacles],
                "penalty": self.contacts[0].stiffness if self.contacts else None,
                "force_units": "N (2D: per mm of depth times the unit's width)",
                "levels": self.levels}


def check_reach(model: Any, design: Any) -> None:
    """Refuse an obstacle of ``model`` (an :class:`~pneumorph.models.fe.base.FEModel`) that starts inside the
    meshed ``design``, before any solve (:func:`contact_items`'s :class:`SettingsError`)."""
    if model.obstacles:
        contact_items(model.obstacles, model.mesh(design), model.body.shear_modulus)


def blocked_obstacle(model: Any, design: Any) -> dict[str, Any]:
    """The blocking wall of ``design`` on ``model`` (:func:`blocked_wall`): the free tip's motion is that of the
    model's first pressure level, solved without obstacles (one level).

    Returns the obstacle's table (``on = "end"``), 3D points on a 3D model.
    """
    steps = model.ramp.steps
    ramp = replace(model.ramp, pressure=model.ramp.pressure / steps.increments, steps=replace(steps, increments=1))
    solution = model.variant(ramp_spec=ramp, obstacles=()).solve(design)
    response, mesh = solution.response, solution.mesh
    axes = len(response.reference_tip)
    ends = mesh.points[mesh.end_points]
    wall = blocked_wall(response.reference_tip, response.tip[0], ends[:, :axes])
    if mesh.dim == 3 and axes == 2:  # a half model: the wall across the width
        wall["point"] = [*wall["point"], float(ends[0, 2])]
        wall["normal"] = [*wall["normal"], 0.0]
    return wall


def parse_obstacle(text: str) -> dict[str, Any]:
    """An obstacle table from its one-line form ``KIND:key=v,v;key=v`` (numbers, mm).

    Raises
    ------
    SettingsError
        No ``KIND:``, a part without ``=``, a key given twice, a value that is no list of numbers; the
        table itself is checked by :func:`check_obstacles`.

    Examples
    --------
    >>> parse_obstacle("plane:point=150,0;normal=-1,0")
    {'kind': 'plane', 'point': [150.0, 0.0], 'normal': [-1.0, 0.0]}
    >>> parse_obstacle("cylinder:centre=38,22;radius=4;on=end")
    {'kind': 'cylinder', 'centre': [38.0, 22.0], 'radius': 4.0, 'on': 'end'}
    """
    kind, sep, rest = str(text).strip().partition(":")
    if not sep or not kind:
        raise SettingsError(f"an obstacle is KIND:key=value;... (plane:point=150,0;normal=-1,0, "
                            f"cylinder:centre=38,22;radius=4, sphere:...), got {text!r}")
    table: dict[str, Any] = {"kind": kind.strip()}
    for part in filter(None, (p.strip() for p in rest.split(";"))):
        key, eq, value = part.partition("=")
        if not eq or not key.strip():
            raise SettingsError(f"obstacle {text!r}: {part!r} is no key=value")
        key = key.strip()
        if key in table:  # a second value would silently replace the first
            raise SettingsError(f"obstacle {text!r}: {key} is given twice")
        if key == "on":
            table[key] = value.strip()
            continue
        try:
            numbers = [float(v) for v in value.split(",")]
        except ValueError:
            raise SettingsError(f"obstacle {text!r}: {key} must be numbers, got {value!r}") from None
        table[key] = numbers[0] if key in ("radius", "friction") and len(numbers) == 1 else numbers
    return table


def blocked_wall(tip0: FloatArray, tip1: FloatArray, end_points: FloatArray) -> dict[str, Any]:
    """The wall of a blocked-force test: a plane normal to the free tip's motion ``tip1 - tip0`` (its first
    level), through the end face's point farthest along it, touching the end face only.

    Examples
    --------
    >>> wall = blocked_wall(np.array([10.0, 5.0]), np.array([9.9, 6.0]), np.array([[10.0, 0.0], [10.0, 10.0]]))
    >>> wall["kind"], [round(v, 3) for v in wall["normal"]], wall["point"], wall["on"]
    ('plane', [0.1, -0.995], [10.0, 10.0], 'end')
    """
    motion = np.asarray(tip1, dtype=float) - np.asarray(tip0, dtype=float)
    norm = float(np.linalg.norm(motion))
    if not norm > 0.0:
        raise SettingsError("the free tip does not move at the first level: no direction for a blocking wall")
    d = motion / norm
    ends = np.asarray(end_points, dtype=float)
    farthest = ends[int(np.argmax(ends @ d))]
    return {"kind": "plane", "point": farthest.tolist(), "normal": (-d).tolist(), "on": "end"}


__all__ = ["REACH", "SMOOTHING", "STRIDE", "TOUCHES", "ContactRecord", "ModelObstacle", "blocked_obstacle",
           "blocked_wall", "check_obstacles", "check_reach", "contact_items", "parse_obstacle"]

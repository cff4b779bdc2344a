"""Frictionless contact of a body's outer surface nodes with rigid obstacles, for the fast assembler.

An obstacle is a rigid plane (:class:`Plane`), cylinder (:class:`Cylinder`, a circle in 2D) or
sphere (:class:`Sphere`) that does not move. Its geometry gives every point ``x`` a signed gap
``g(x)`` (negative: the point is inside the obstacle), the outward normal ``n = dg/dx`` and the
curvature ``H = dn/dx`` (None for a plane). A node-to-rigid-surface penalty holds the surface
nodes out of it, as FElupe's ``ContactRigidPlane``/``ContactRigidCylinder`` do (their normal part):
a node in contact (``g < 0``) adds

    r = k g n                      to the residual,
    K = k (n (x) n + g H)          to its own d x d block of the tangent,

so the obstacle pushes it with ``-k g n``; the force on the obstacle is the sum of ``k g n``. A node couples
with itself only: a :class:`RigidContact` is one more owner of :class:`~pneumorph.fem.fast.assembler.FastSystem`.

The penalty ``k`` (:func:`penalty_stiffness`) is :data:`PENALTY` times the shear modulus times the element size to
the power ``d - 2``: a node carrying a contact pressure ``p_c`` over its share ``h^(d-1)`` of the surface penetrates
``g = h p_c / (PENALTY mu)``, a fraction ``p_c / (PENALTY mu)`` of an element. Coulomb friction adds a tangential
penalty (:data:`TANGENTIAL` times ``k``) with return-mapped sliding (:mod:`~pneumorph.fem.fast.friction`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from pneumorph import checks
from pneumorph.errors import SettingsError
from pneumorph.fem.fast.friction import coulomb, slip

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: the penalty over the shear modulus (2D) or over shear modulus x element size (3D): 100 let in a tenth as much and
#: moved a blocked force by 1.4 % at most, but a hard press cost twice the time (docs/grasping.md)
PENALTY = 10.0

#: the tangential penalty of friction over the normal one (FElupe's default): a sticking node creeps by
#: ``mu f_n / k_t``, ten times its penetration at ``mu = 1``; a stiffer one (1) failed a 3D ramp whose
#: symmetrised sliding tangents then stalled Newton (:mod:`.friction`)
TANGENTIAL = 0.1

#: every cell type's faces, as local nodes: the corners first (in order around the face), then the
#: edges' middle nodes of a quadratic cell (VTK numbering, as FElupe's meshes)
FACES: dict[str, list[list[int]]] = {
    "quad": [[0, 1], [1, 2], [2, 3], [3, 0]],
    "quad8": [[0, 1, 4], [1, 2, 5], [2, 3, 6], [3, 0, 7]],
    "hexahedron": [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]],
    "hexahedron20": [[0, 3, 2, 1, 11, 10, 9, 8], [4, 5, 6, 7, 12, 13, 14, 15], [0, 1, 5, 4, 8, 17, 12, 16],
                     [1, 2, 6, 5, 9, 18, 13, 17], [2, 3, 7, 6, 10, 19, 14, 18], [3, 0, 4, 7, 11, 16, 15, 19]],
}

#: each face node's share of its face, by the face's node count: a line's ends; a quadratic line's (Simpson's
#: weights); a quad's corners; a quadratic quad's corners and middle nodes (half a corner's on each edge)
SHARES: dict[int, FloatArray] = {2: np.full(2, 0.5), 3: np.array([1 / 6, 1 / 6, 2 / 3]), 4: np.full(4, 0.25),
                                 8: np.r_[np.full(4, 1 / 12), np.full(4, 1 / 6)]}


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
        axis, a radius <= 0, a friction < 0 (the table's ``friction`` is checked here and kept by the
        caller: the geometry does not hold it).

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
    friction = table.get("friction", 0.0)
    if not (isinstance(friction, (int, float)) and not isinstance(friction, bool) and math.isfinite(friction)
            and friction >= 0.0):
        raise SettingsError(f"{where} friction must be a finite number >= 0, got {friction!r}")
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


def penalty_stiffness(shear_modulus: float, element_size: float, dim: int, factor: float = PENALTY) -> float:
    """The contact penalty: ``factor`` times the shear modulus (MPa) times the element size (mm) to ``dim - 2``.

    In N/mm per mm of depth in 2D (plane strain), N/mm in 3D.

    >>> penalty_stiffness(0.03, 1.5, 2), round(penalty_stiffness(0.03, 1.5, 3), 6)
    (0.3, 0.45)
    """
    return float(factor * shear_modulus * element_size ** (dim - 2))


def penalty_gap(gap: FloatArray, smoothing: float = 0.0) -> tuple[FloatArray, FloatArray]:
    """The penalised gap ``phi(g)`` and its slope: ``g`` below ``-s``, 0 above ``s``, ``-(g - s)^2 / (4 s)``
    between (``s``: ``smoothing``; 0: ``min(g, 0)``).

    The quadratic blend makes the contact force continuously differentiable in the gap, so a node that
    touches and leaves between Newton iterations does not make the tangent jump (which stalled
    a 2D actuator curling round a cylinder at a residual of 1e-3); a node within ``s`` of the surface
    feels at most ``k s / 4``.

    >>> phi, slope = penalty_gap(np.array([-1.0, -0.1, 0.0, 0.1, 1.0]), 0.1)
    >>> phi.round(3).tolist(), slope.round(3).tolist()
    ([-1.0, -0.1, -0.025, 0.0, 0.0], [1.0, 1.0, 0.5, 0.0, 0.0])
    """
    if smoothing <= 0.0:
        return np.minimum(gap, 0.0), (gap < 0.0).astype(float)
    s = smoothing
    blend = np.abs(gap) < s
    phi = np.where(gap <= -s, gap, np.where(blend, -((gap - s) ** 2) / (4 * s), 0.0))
    slope = np.where(gap <= -s, 1.0, np.where(blend, -(gap - s) / (2 * s), 0.0))
    return phi, slope


def surface_faces(cells: IntArray, cell_type: str) -> IntArray:
    """The faces (edges in 2D) that belong to one cell only, as node lists (f, k), corners first.

    >>> import felupe as fem
    >>> mesh = fem.Rectangle(n=3)
    >>> surface_faces(mesh.cells, "quad").shape
    (8, 2)
    """
    table = np.asarray(FACES[cell_type])
    corners = 2 if cell_type in ("quad", "quad8") else 4
    faces = np.asarray(cells)[:, table].reshape(-1, table.shape[1])
    key = np.sort(faces[:, :corners], axis=1)
    _, index, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    return np.asarray(faces[np.sort(index[counts == 1])], dtype=np.int64)


def face_measures(faces: IntArray, x: FloatArray) -> FloatArray:
    """Length (2D: through the middle node of a quadratic edge) or area (3D: of the corners' quad) of every face."""
    p = x[faces]
    if x.shape[1] == 2:
        if faces.shape[1] == 3:
            return np.asarray(np.linalg.norm(p[:, 2] - p[:, 0], axis=1) + np.linalg.norm(p[:, 1] - p[:, 2], axis=1))
        return np.asarray(np.linalg.norm(p[:, 1] - p[:, 0], axis=1))
    return np.asarray(0.5 * np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1))


@dataclass
class RigidContact:
    """One obstacle against some nodes of a body: an owner of the fast assembler.

    Parameters
    ----------
    obstacle : Obstacle
    points : ndarray of int
        The nodes that may touch it (the body's outer surface nodes).
    stiffness : float
        The penalty (:func:`penalty_stiffness`).
    faces : ndarray of int, optional
        The surface faces, for the contact length (2D) or area (3D) in :meth:`report`.
    smoothing : float
        The gap (mm) over which the penalty sets in (:func:`penalty_gap`; 0: at once).
    friction : float
        Coulomb's coefficient (:mod:`.friction`; 0: frictionless), with :data:`TANGENTIAL` times the
        penalty as the tangential stiffness; its anchors are kept by :meth:`commit` after each converged state.
    reach : float
        The deepest (mm) a Newton step may carry a node into the obstacle from outside the penalty's full
        stiffness (:meth:`step_fraction`; 0: no limit).
    stride : float
        The farthest (mm) a Newton step may move any node of the body (:meth:`step_fraction`; 0: no limit).

    Once a state is committed (:meth:`commit`), the tangent's curvature term ``k phi H`` (a negative stiffness
    across the normal) takes the smaller of the node's penalised gap and the converged one, as FElupe's
    ``curvature="converged"``: an overshooting trial state made a finger's tangent indefinite (steps of 10-150 mm).

    Examples
    --------
    A node 0.25 mm inside a wall is pushed back with ``k g`` along its normal:

    >>> contact = RigidContact(Plane((1.0, 0.0), (-1.0, 0.0)), np.array([0, 1]), 10.0)
    >>> X = np.array([[0.0, 0.0], [1.25, 0.0]])
    >>> force, active = contact.forces(X)
    >>> (force + 0.0).tolist(), active.tolist()
    ([[0.0, 0.0], [2.5, 0.0]], [False, True])
    """

    obstacle: Obstacle
    points: IntArray
    stiffness: float
    faces: IntArray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    smoothing: float = 0.0
    friction: float = 0.0
    reach: float = 0.0
    stride: float = 0.0
    #: the friction anchors of the last converged state (None: every node where it is)
    anchors: FloatArray | None = None
    #: the penalised gaps of the last converged state (None: no bound on the curvature's term)
    converged: FloatArray | None = None
    # the assembler's owner data: one "cell" per node
    cells: IntArray = field(init=False)
    take: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    scatter: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    edofs: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, dtype=np.int64)
        self.cells = self.points[:, None]

    def evaluate(self, x: FloatArray, symmetric: bool = False) -> tuple[FloatArray, FloatArray, NDArray[np.bool_],
                                                                        FloatArray, NDArray[np.bool_]]:
        """At the positions ``x`` of all the body's points (p, d): the force on the obstacle at every node
        ``k phi(g) n`` (:func:`penalty_gap`) plus its friction (:mod:`.friction`), (m, d); their blocks
        ``k (phi'(g) n (x) n + phi(g) H)`` plus friction's, (m, d, d; ``symmetric``: for a symmetric tangent,
        :func:`~pneumorph.fem.fast.friction.coulomb`'s ``coupled`` off); which nodes the obstacle pushes
        (``phi < 0``); the anchors a commit at ``x`` keeps (m, d); and which nodes slide (m,)."""
        xs = x[self.points]
        gap, n, H = self.obstacle.kinematics(xs)
        phi, slope = penalty_gap(gap, self.smoothing)
        force = self.stiffness * phi[:, None] * n
        K = self.stiffness * slope[:, None, None] * n[:, :, None] * n[:, None, :]
        if H is not None:  # the curvature's term, at most the last converged state's (see the class notes)
            bound = phi if self.converged is None else np.maximum(phi, self.converged)
            K += self.stiffness * bound[:, None, None] * H
        active = phi < 0.0
        anchors = xs.copy()  # out of contact: where a node is
        sliding = np.zeros(len(xs), dtype=bool)
        if self.friction > 0.0 and np.any(active):
            a = np.flatnonzero(active)
            reference = xs[a] if self.anchors is None else self.anchors[a]
            e, E = slip(xs[a] - reference, n[a], None if H is None else H[a])
            ft, Kt, kept = coulomb(e, E, -self.stiffness * phi[a], self.stiffness * slope[a], n[a], self.friction,
                                   TANGENTIAL * self.stiffness, coupled=not symmetric)
            force[a] += ft
            K[a] += Kt
            anchors[a] = xs[a] - kept
            sliding[a] = np.any(kept != e, axis=1)  # (a return-mapped slip is shorter)
        return force, K, active, anchors, sliding

    def forces(self, x: FloatArray) -> tuple[FloatArray, NDArray[np.bool_]]:
        """The force on the obstacle at every node (m, d) and which nodes it pushes (:meth:`evaluate`)."""
        force, _, active, _, _ = self.evaluate(x)
        return force, active

    def states(self, x: FloatArray) -> NDArray[np.int8]:
        """Every node's contact state at ``x`` (all the body's points): 0 free, 1 pressed (sticking), 2 sliding.

        >>> contact = RigidContact(Plane((1.0, 0.0), (-1.0, 0.0)), np.array([0, 1]), 10.0, friction=0.5)
        >>> contact.commit(np.array([[0.0, 0.0], [1.25, 0.0]]))  # (0, 1): free, sticking; then 3 N > 0.5 x 2.5 N
        >>> contact.states(np.array([[0.0, 0.0], [1.25, 3.0]])).tolist()
        [0, 2]
        """
        _, _, active, _, sliding = self.evaluate(x)
        return np.asarray(active.astype(np.int8) + sliding, dtype=np.int8)

    def residual(self, x: FloatArray) -> FloatArray:
        """The nodes' contributions to the residual, (m, d) (the force on the obstacle)."""
        return self.evaluate(x)[0]

    def tangent(self, x: FloatArray, symmetric: bool = False) -> FloatArray:
        """The nodes' d x d blocks (zero out of contact), (m, d, d) (:meth:`evaluate`)."""
        return self.evaluate(x, symmetric)[1]

    def step_fraction(self, x: FloatArray, dx: FloatArray, motion: float = 0.0) -> float:
        """The fraction of a step ``dx`` from ``x`` (all the body's points, (p, d)) that carries no node from
        outside the penalty's full stiffness (a gap above ``-smoothing``) deeper than ``reach`` into the obstacle,
        and moves no node farther than ``stride`` or ``motion`` (mm), whichever is larger.

        A Newton step sees no contact stiffness at the nodes still outside: it could carry one a substep's motion
        into the obstacle, whose penalty then inverts the elements next to it. Scaled to land it ``reach`` inside
        (a straight path's gap, linear between its ends), the next step sees it in contact. The stride bounds a
        step along a nearly singular tangent: a finger's tip sliding on a wall, held only by its bending.

        >>> contact = RigidContact(Plane((1.0, 0.0), (-1.0, 0.0)), np.array([0, 1]), 10.0, reach=0.1)
        >>> x = np.array([[0.0, 0.0], [0.5, 0.0]])
        >>> round(contact.step_fraction(x, np.array([[0.0, 0.0], [1.1, 0.0]])), 6)  # 0.6 of its 1.1 mm reach 0.1 mm in
        0.545455
        >>> contact.step_fraction(x, np.array([[0.0, 0.0], [0.55, 0.0]]))  # 0.05 mm in: all of it
        1.0
        >>> far = RigidContact(Plane((9.0, 0.0), (-1.0, 0.0)), np.array([0, 1]), 10.0, stride=0.5)
        >>> far.step_fraction(x, np.array([[2.0, 0.0], [0.0, 0.0]]), motion=1.0)  # 2 mm: the substep moves 1 mm
        0.5
        """
        fraction = 1.0
        if self.stride > 0.0:
            farthest = float(np.max(np.linalg.norm(dx, axis=1), initial=0.0))
            fraction = min(1.0, max(self.stride, motion) / farthest) if farthest > 0.0 else 1.0
        if self.reach <= 0.0:
            return fraction
        xs = x[self.points]
        g0 = self.obstacle.kinematics(xs)[0]
        g1 = self.obstacle.kinematics(xs + dx[self.points])[0]
        deep = (g0 > -max(self.smoothing, 0.5 * self.reach)) & (g1 < -self.reach)
        if not np.any(deep):
            return fraction
        return min(fraction, float(np.min((g0[deep] + self.reach) / (g0[deep] - g1[deep]))))

    def _tributary(self, measures: FloatArray, share: FloatArray, touching: NDArray[np.bool_]) -> FloatArray:
        """Every point's share of the faces in contact (those whose corners all touch), or of all its faces
        where none of its faces is: the area (length in 2D) its contact force acts on."""
        corners = 2 if self.faces.shape[1] <= 3 else 4
        full = np.all(touching[self.faces[:, :corners]], axis=1)
        out, anywhere = np.zeros(len(touching)), np.zeros(len(touching))
        np.add.at(out, self.faces[full], measures[full, None] * share[None, :])
        np.add.at(anywhere, self.faces, measures[:, None] * share[None, :])
        return np.where(out > 0.0, out, anywhere)

    def commit(self, x: FloatArray) -> None:
        """Keep the friction anchors and the penalised gaps of the converged state ``x`` (positions of all the
        body's points)."""
        self.anchors = self.evaluate(x)[3]
        self.converged = penalty_gap(self.obstacle.kinematics(x[self.points])[0], self.smoothing)[0]

    def report(self, x: FloatArray) -> dict[str, Any]:
        """The force on the obstacle (summed, per unit depth in 2D), the nodes in contact and theirs, the contact
        length (2D) or area (3D): the nodes' shares of their faces (:data:`SHARES`), summed over those in contact,
        and each node's contact pressure: its force over its share of the faces in contact (MPa)."""
        force, active = self.forces(x)
        touching = np.zeros(x.shape[0], dtype=bool)
        touching[self.points[active]] = True
        measure = 0.0
        pressures = np.zeros(int(active.sum()))
        if len(self.faces):
            share = SHARES[self.faces.shape[1]]
            faces = face_measures(self.faces, x)
            measure = float(np.sum(faces * (touching[self.faces] @ share)))
            pressures = np.linalg.norm(force[active], axis=1) / self._tributary(faces, share, touching)[
                self.points[active]]
        return {"force": force.sum(axis=0), "nodes": self.points[active], "node_forces": force[active],
                "measure": measure, "node_pressures": pressures}


def surface_points(cells: IntArray, cell_type: str, excluded: NDArray[np.bool_] | None = None) -> tuple[IntArray,
                                                                                                         IntArray]:
    """The outer surface's faces and nodes: faces of one cell, without those whose corners all lie in ``excluded``
    (the cavity walls, a plane of symmetry).

    >>> import felupe as fem
    >>> mesh = fem.Rectangle(n=3)
    >>> faces, nodes = surface_points(mesh.cells, "quad")
    >>> len(faces), nodes.tolist()
    (8, [0, 1, 2, 3, 5, 6, 7, 8])
    """
    faces = surface_faces(cells, cell_type)
    if excluded is not None:
        corners = 2 if faces.shape[1] <= 3 else 4
        faces = faces[~np.all(excluded[faces[:, :corners]], axis=1)]
    return faces, np.unique(faces)


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


__all__ = ["FACES", "KINDS", "PENALTY", "SHARES", "TANGENTIAL", "Cylinder", "Obstacle", "Plane", "RigidContact",
           "Sphere", "face_measures", "obstacle_from_dict", "penalty_gap", "penalty_stiffness", "start_inside",
           "surface_faces", "surface_points"]

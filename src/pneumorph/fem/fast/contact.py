"""Contact of a body's outer surface nodes with rigid obstacles, for the fast assembler.

An obstacle (:mod:`~pneumorph.fem.fast.shapes`: a plane, cylinder or sphere that does not move) gives every
point ``x`` a signed gap ``g(x)`` (negative: the point is inside the obstacle), the outward normal
``n = dg/dx`` and the curvature ``H = dn/dx`` (None for a plane). A node-to-rigid-surface penalty holds the surface
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

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.fast.friction import coulomb, slip
from pneumorph.fem.fast.shapes import Obstacle

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
    d = np.where(blend, gap - s, 0.0)  # squared only in the blend (a gap past 1e154 mm would overflow)
    phi = np.where(gap <= -s, gap, np.where(blend, -(d * d) / (4 * s), 0.0))
    slope = np.where(gap <= -s, 1.0, np.where(blend, -d / (2 * s), 0.0))
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

    >>> from pneumorph.fem.fast.shapes import Plane
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

        >>> from pneumorph.fem.fast.shapes import Plane
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

        >>> from pneumorph.fem.fast.shapes import Plane
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


def contact_fraction(system: Any, u: FloatArray, step: FloatArray, motion: float = 0.0) -> float:
    """The fraction of a Newton ``step`` (over the active dofs) from ``u`` that carries no surface node deep into
    an obstacle it was not pressing on, nor any node farther than the obstacles' stride or ``motion`` (mm)
    (:meth:`RigidContact.step_fraction`; 1 without obstacles)."""
    contacts = getattr(system, "contacts", ())
    if not contacts:
        return 1.0
    x = system.points + u.reshape(system.points.shape)
    dx = node_steps(system, step)
    return min(c.step_fraction(x, dx, motion) for c in contacts)


def node_steps(system: Any, step: FloatArray) -> FloatArray:
    """A ``step`` over the active dofs as each node's displacement increment, one row a node (0 where prescribed)."""
    du = np.zeros(system.points.size)
    du[system.dof1] = step
    return du.reshape(system.points.shape)


def contacts_changed(system: Any, u: FloatArray, u_new: FloatArray, sliding: bool = False) -> bool:
    """Whether some surface node touches an obstacle at ``u_new`` (all dofs) and not at ``u``, or the reverse
    (``sliding``: or sticks at one and slides at the other,
    :meth:`RigidContact.states`)."""
    d = system.points.shape[1]
    x, x_new = system.points + u.reshape(-1, d), system.points + u_new.reshape(-1, d)
    if sliding:
        return any(np.any(c.states(x) != c.states(x_new)) for c in getattr(system, "contacts", ()))
    return any(np.any(c.forces(x)[1] != c.forces(x_new)[1]) for c in getattr(system, "contacts", ()))




__all__ = ["FACES", "PENALTY", "SHARES", "TANGENTIAL", "RigidContact", "contact_fraction", "contacts_changed",
           "face_measures", "node_steps", "penalty_gap", "penalty_stiffness", "surface_faces", "surface_points"]

"""Coulomb friction of surface nodes on a rigid obstacle: a penalty stick and a return-mapped slip.

The formulation of FElupe's rigid contacts (``ContactRigidBase``). The state is each node's anchor:
where it sticks on the obstacle since the last converged state. For a node in contact that has
moved by ``w = x - anchor``, the elastic slip ``e`` is ``w`` projected on the obstacle's tangent
plane, ``P w`` with ``P = I - n n``. Its derivative over ``x`` is ``E = P - (n . w) H - n (x) H w``,
with the curvature ``H`` of :mod:`~pneumorph.fem.fast.contact`. The trial tangential force
``k_t e`` sticks while it is within ``mu`` times the normal force ``f_n``. Beyond that the node
slides, with the force ``mu f_n t`` along ``t = e / |e|`` and the consistent tangent
``mu (f_n (I - t t) / |e| E - k phi' t (x) n)``. The anchor moves with a sliding node, and it is
reset where a node leaves contact. Anchors are only committed after a converged substep
(:meth:`~pneumorph.fem.fast.contact.RigidContact.commit`), so a cut-back starts again from the
last converged state.

The sliding tangent is not symmetric, nor is a sticking node's on a curved obstacle. The 3D
assembler factorises a symmetric tangent (its upper triangle): there a sliding node's block
without its coupling to the normal force is symmetrised into it, and the rest of the block is
kept apart (``FastSystem.remainder``), for Newton steps solved
by GMRES on the whole tangent with the symmetric factorisation as its preconditioner
(:func:`~pneumorph.fem.linear.corrected`). A 3-unit 3D finger pressed on a cylinder with
friction 0.5 took 290 Newton iterations and 7 cut-backs with the symmetric tangent alone,
its fresh steps cycling while nodes switched between sticking and sliding and in and out of
contact; with a line search that asks every fresh step to lower the residual
(:data:`~pneumorph.fem.fast.newton.FRICTION_GROWTH`) 118 and 1, with the whole tangent too 99
and 1 (85 and none frictionless).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def slip(w: FloatArray, n: FloatArray, H: FloatArray | None) -> tuple[FloatArray, FloatArray]:
    """The tangential part ``e`` (m, d) of the motions ``w`` since the anchors and its derivative ``E`` (m, d, d).

    >>> e, E = slip(np.array([[1.0, 2.0]]), np.array([[0.0, 1.0]]), None)
    >>> e.tolist(), E[0].tolist()
    ([[1.0, 0.0]], [[1.0, 0.0], [0.0, 0.0]])
    """
    d = w.shape[1]
    P = np.eye(d)[None] - n[:, :, None] * n[:, None, :]
    e = np.einsum("aij,aj->ai", P, w)
    E = P.copy()
    if H is not None:
        nw = np.einsum("ai,ai->a", n, w)
        E -= nw[:, None, None] * H + n[:, :, None] * np.einsum("aij,aj->ai", H, w)[:, None, :]
    return e, E


def coulomb(e: FloatArray, E: FloatArray, normal_force: FloatArray, normal_slope: FloatArray, n: FloatArray,
            friction: float, stiffness: float, coupled: bool = True) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Tangential forces (m, d), their tangent blocks (m, d, d) and the slips kept (m, d) of nodes in contact.

    ``normal_force``: ``f_n = -k phi`` (>= 0); ``normal_slope``: ``k phi'`` (>= 0), the rate at which
    ``f_n`` falls as the gap opens; ``stiffness``: the tangential penalty ``k_t``; ``coupled``: a sliding
    node's tangent keeps its coupling ``- mu k phi' t (x) n`` to the normal force (False: left out, for a
    symmetric tangent).

    Examples
    --------
    A node pressed with 1 N moved 0.1 mm sideways: it sticks under ``k_t = 5`` (0.5 N <= 0.6 N) and
    slides at 0.6 N under ``k_t = 10``:

    >>> n = np.array([[0.0, 1.0]])
    >>> e, E = slip(np.array([[0.1, 0.0]]), n, None)
    >>> coulomb(e, E, np.array([1.0]), np.array([10.0]), n, 0.6, 5.0)[0].round(6).tolist()
    [[0.5, 0.0]]
    >>> force, _, kept = coulomb(e, E, np.array([1.0]), np.array([10.0]), n, 0.6, 10.0)
    >>> force.round(6).tolist(), kept.round(6).tolist()
    ([[0.6, 0.0]], [[0.06, 0.0]])
    """
    trial = stiffness * e
    size = np.linalg.norm(trial, axis=1)
    limit = friction * normal_force
    slide = size > limit + np.sqrt(np.finfo(float).eps) * np.maximum(limit, 1.0)
    force, K, kept = trial.copy(), stiffness * E, e.copy()
    if np.any(slide):
        t = trial[slide] / size[slide, None]
        d = e.shape[1]
        force[slide] = limit[slide, None] * t
        kept[slide] = e[slide] * (limit[slide] / size[slide])[:, None]
        ratio = (np.eye(d)[None] - t[:, :, None] * t[:, None, :]) / np.linalg.norm(e[slide], axis=1)[:, None, None]
        K[slide] = friction * normal_force[slide, None, None] * ratio @ E[slide]
        if coupled:
            K[slide] -= friction * normal_slope[slide, None, None] * t[:, :, None] * n[slide][:, None, :]
    return force, K, kept


__all__ = ["coulomb", "slip"]

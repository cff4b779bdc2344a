"""The identification's linearised problem: a model's shape as nodes that move linearly with the
parameters (:class:`LinearisedScan`), the least-squares system of the correlation distances and its
step in a trust region, the covariance and correlations of the parameters, and what cannot be
told apart (:func:`confounded`); the driver: :mod:`pneumorph.identify.fit`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import lsq_linear
from scipy.spatial import cKDTree

from pneumorph.correlation.align import Transform, small_rotation
from pneumorph.correlation.compare import ModelShape, resample

FloatArray = NDArray[np.float64]

#: pairs of parameters correlated beyond this cannot be told apart
MAX_CORRELATION = 0.95

#: the smallest eigenvalue of the parameters' correlation matrix below which J^T J is near-singular
MIN_EIGENVALUE = 1e-3


# -- the shape of a model as nodes that move linearly with the parameters ----------------------
@dataclass(frozen=True)
class LinearisedScan:
    """One scan's model shape at the current parameters and its node sensitivities.

    3D: ``nodes`` are the surface nodes (normals kept from the base solve); 2D: the outline's
    segment end points, two rows per segment.
    """

    dim: int
    nodes: FloatArray
    derivatives: FloatArray  # (free, nodes, dim)
    normals: FloatArray

    def at(self, step: FloatArray) -> FloatArray:
        return self.nodes + np.tensordot(step, self.derivatives, axes=1) if len(step) else self.nodes

    def match(self, x: FloatArray, step: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Per point: its signed distance to the shape and the distance's derivative by the free parameters."""
        nodes = self.at(step)
        if self.dim == 3:
            _, i = cKDTree(nodes).query(x)
            n = self.normals[i]
            r = ((x - nodes[i]) * n).sum(axis=1)
            dq = self.derivatives[:, i, :]  # (free, points, 3)
            return r, -(dq * n[None]).sum(axis=2).T
        segments = nodes.reshape(-1, 2, 2)
        samples, segment = resample(segments)
        _, k = cKDTree(samples).query(x)
        s = segment[k]
        a, b = segments[s, 0], segments[s, 1]
        d = b - a
        length2 = np.maximum((d**2).sum(axis=1), 1e-300)
        t = np.clip(((x - a) * d).sum(axis=1) / length2, 0.0, 1.0)
        q = a + t[:, None] * d
        n = np.c_[-d[:, 1], d[:, 0]] / np.sqrt(length2)[:, None]
        r = ((x - q) * n).sum(axis=1)
        if not len(self.derivatives):
            return r, np.zeros((len(x), 0))
        D = self.derivatives.reshape(len(self.derivatives), -1, 2, 2)
        dq = (1 - t)[None, :, None] * D[:, s, 0] + t[None, :, None] * D[:, s, 1]
        return r, -(dq * n[None]).sum(axis=2).T


def shape_nodes(shape: ModelShape, dim: int) -> tuple[FloatArray, FloatArray]:
    if dim == 3:
        return shape.surface, shape.normals
    return shape.outline.reshape(-1, 2), np.empty((0, 2))


def _align_columns(x: FloatArray, r_normals: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The columns of a small rigid motion about the points' centre (as ``plane_step``), and that centre."""
    centre = x.mean(axis=0)
    p = x - centre
    if x.shape[1] == 2:
        rot = (np.c_[-p[:, 1], p[:, 0]] * r_normals).sum(axis=1)[:, None]
    else:
        rot = np.cross(p, r_normals)
    return np.hstack([rot, r_normals]), centre


def _normals_of(lin: LinearisedScan, x: FloatArray, step: FloatArray) -> FloatArray:
    """The unit normals the residuals of ``x`` are measured along (for the alignment columns)."""
    nodes = lin.at(step)
    if lin.dim == 3:
        _, i = cKDTree(nodes).query(x)
        return lin.normals[i]
    segments = nodes.reshape(-1, 2, 2)
    samples, segment = resample(segments)
    _, k = cKDTree(samples).query(x)
    d = segments[segment[k], 1] - segments[segment[k], 0]
    return np.c_[-d[:, 1], d[:, 0]] / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)


@dataclass
class LinearisedState:
    """The linearised problem's unknowns: the parameter step and each scan's alignment."""

    step: FloatArray
    transforms: list[Transform]


def linearised_system(lins: Sequence[LinearisedScan], points: Sequence[FloatArray], state: LinearisedState,
                      scale: FloatArray) -> tuple[FloatArray, FloatArray, list[FloatArray]]:
    """Residuals, the Jacobian (free parameters in units of ``scale``, then each scan's motion), centres."""
    blocks, rows, centres = [], [], []
    motion = [3 + 3 if lin.dim == 3 else 1 + 2 for lin in lins]
    for s, (lin, p) in enumerate(zip(lins, points, strict=True)):
        x = state.transforms[s](p)
        r, dtheta = lin.match(x, state.step)
        align, centre = _align_columns(x, _normals_of(lin, x, state.step))
        a = np.zeros((len(x), len(state.step) + sum(motion)))
        a[:, :len(state.step)] = dtheta * scale
        start = len(state.step) + sum(motion[:s])
        a[:, start:start + motion[s]] = align
        blocks.append(a)
        rows.append(r)
        centres.append(centre)
    return np.concatenate(rows), np.vstack(blocks), centres


def solve_linearised(lins: Sequence[LinearisedScan], points: Sequence[FloatArray], transforms: list[Transform],
                      lower: FloatArray, upper: FloatArray, scale: FloatArray, max_steps: int = 60
                      ) -> tuple[LinearisedState, FloatArray, FloatArray]:
    """Gauss-Newton on the linearised shapes from a zero step: (state, residuals, Jacobian) at its end."""
    state = LinearisedState(np.zeros(len(scale)), list(transforms))
    for _ in range(max_steps):
        r, a, centres = linearised_system(lins, points, state, scale)
        k = len(scale)
        lo = np.r_[(lower - state.step) / scale, np.full(a.shape[1] - k, -np.inf)]
        hi = np.r_[(upper - state.step) / scale, np.full(a.shape[1] - k, np.inf)]
        z = lsq_linear(a, -r, bounds=(lo, hi), method="bvls" if a.shape[1] < 40 else "trf").x
        state.step = np.clip(state.step + z[:k] * scale, lower, upper)
        offset = k
        for s, lin in enumerate(lins):
            n_rot = 3 if lin.dim == 3 else 1
            omega, move = z[offset:offset + n_rot], z[offset + n_rot:offset + n_rot + lin.dim]
            offset += n_rot + lin.dim
            rotation = small_rotation(omega)
            c = centres[s]
            state.transforms[s] = state.transforms[s].then(Transform(rotation, c + move - rotation @ c))
        if np.max(np.abs(z), initial=0.0) < 1e-9:
            break
    r, a, _ = linearised_system(lins, points, state, scale)
    return state, r, a


def scaled_covariance(r: FloatArray, a: FloatArray, k: int) -> tuple[FloatArray, float]:
    """The covariance of the first ``k`` (scaled) unknowns, ``s^2 (J^T J)^-1``, and ``s``."""
    dof = max(len(r) - a.shape[1], 1)
    sigma = float(np.sqrt(r @ r / dof))
    normal = a.T @ a
    try:
        inverse = np.linalg.pinv(normal, rcond=1e-13, hermitian=True)
    except np.linalg.LinAlgError:  # pragma: no cover - pinv of a symmetric matrix converges
        inverse = np.full_like(normal, np.nan)
    return np.asarray(sigma**2 * inverse[:k, :k], dtype=float), sigma


def correlation_of(cov: FloatArray) -> FloatArray:
    d = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    return np.asarray(cov / np.outer(d, d), dtype=float)


def confounded(names: Sequence[str], cov_scaled: FloatArray, column_norms: FloatArray) -> dict[str, str]:
    """The parameters to fix, each with why: the scans do not move with it, or cannot tell it from another.

    ``cov_scaled`` is the covariance of the parameters in units of their plausible change
    (:data:`~pneumorph.identify.parameters.SPANS`), ``column_norms`` the norms of their
    Jacobian columns. Greedy: a parameter without effect first; then, while a pair is
    correlated beyond :data:`MAX_CORRELATION` or the correlation matrix is near-singular,
    the least determined parameter of the worst pair (or of the weakest direction). A
    parameter that is merely loosely determined (its standard error above its plausible change) stays fitted: fixing it
    would bias the others.

    Examples
    --------
    >>> cov = np.array([[1.0, 1.08, 0.0], [1.08, 1.2, 0.0], [0.0, 0.0, 1.0]]) * 1e-4
    >>> confounded(["a", "b", "c"], cov, np.ones(3))
    {'b': 'cannot be told apart from a (correlation 0.986)'}
    >>> confounded(["a", "b", "c"], np.diag([1e-4, 4.0, 1e-4]), np.array([1.0, 1.0, 0.0]))
    {'c': 'the scans do not depend on it'}
    """
    out: dict[str, str] = {}
    names = list(names)
    keep = list(range(len(names)))
    top = float(np.max(column_norms, initial=0.0))
    for i in list(keep):
        if column_norms[i] <= 1e-9 * max(top, 1e-300):
            out[names[i]] = "the scans do not depend on it"
            keep.remove(i)
    while keep:
        sub = cov_scaled[np.ix_(keep, keep)]
        se = np.sqrt(np.maximum(np.diag(sub), 0.0))
        if len(keep) < 2:
            break
        corr = correlation_of(sub)
        off = np.abs(corr - np.eye(len(keep)))
        i, j = (int(v) for v in np.unravel_index(int(np.argmax(off)), off.shape))
        worst = float(off[i, j])
        eigenvalues, vectors = np.linalg.eigh(corr)
        if worst > MAX_CORRELATION:
            drop = i if se[i] >= se[j] else j
            other = j if drop == i else i
            out[names[keep[drop]]] = (f"cannot be told apart from {names[keep[other]]} (correlation "
                                      f"{corr[i, j]:.3g})")
        elif eigenvalues[0] < MIN_EIGENVALUE:
            weights = np.abs(vectors[:, 0])
            drop = int(np.argmax(weights * se))
            partners = [names[keep[m]] for m in np.argsort(-weights) if m != drop and weights[m] > 0.2]
            out[names[keep[drop]]] = (f"cannot be told apart from a combination of {', '.join(partners)} (J^T J "
                                      f"near-singular: smallest correlation eigenvalue {eigenvalues[0]:.2g})")
        else:
            break
        del keep[drop]
    return out

#: pairs of parameters correlated beyond this cannot be told apart

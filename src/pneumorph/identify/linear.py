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

#: a combination of the parameters whose standard error exceeds this many plausible changes
#: (:data:`~pneumorph.identify.parameters.SPANS`) is not determined by the scans
MAX_DIRECTION_ERROR = 1.0
#: nor, for each eigenvalue of the correlation form of ``J^T J`` (normalised by its diagonal) below this, the
#: weakest combination: parameters whose columns point alike to within it (a correlation of 0.999 for a pair)
#: are told apart by less than the forward differences' own error, so the linearisation rather than the noise
#: would decide the step. The form is blind to the columns' sizes: a parameter that moves the scans strongly
#: (the wall) does not make the others look undetermined
MIN_EIGENVALUE = 1e-3
#: a parameter whose Jacobian column (alignment taken out) is below this fraction of the largest moves no scan
NO_EFFECT = 1e-4
#: a parameter that moves by more than this many of its plausible changes per plausible change of an
#: undetermined combination is not identified (its value is where that combination was held)
MAX_SHARE = 0.25


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
                      lower: FloatArray, upper: FloatArray, scale: FloatArray, hold: FloatArray | None = None,
                      max_steps: int = 60) -> tuple[LinearisedState, FloatArray, FloatArray]:
    """Gauss-Newton on the linearised shapes from a zero step: (state, residuals, Jacobian) at its end.

    ``hold`` (free parameters x combinations, in units of ``scale``, orthonormal columns): combinations the
    step keeps at zero (stiff rows ``w hold^T z = 0`` beside the scans' rows; residuals and Jacobian are
    returned without them).
    """
    state = LinearisedState(np.zeros(len(scale)), list(transforms))
    k = len(scale)
    held = np.zeros((k, 0)) if hold is None else hold
    for _ in range(max_steps):
        r, a, centres = linearised_system(lins, points, state, scale)
        lo = np.r_[(lower - state.step) / scale, np.full(a.shape[1] - k, -np.inf)]
        hi = np.r_[(upper - state.step) / scale, np.full(a.shape[1] - k, np.inf)]
        w = 1e3 * max(float(np.linalg.norm(a[:, :k], axis=0).max(initial=0.0)), 1.0)
        rows = np.zeros((held.shape[1], a.shape[1]))
        rows[:, :k] = w * held.T
        z = lsq_linear(np.vstack([a, rows]), -np.r_[r, w * held.T @ (state.step / scale)], bounds=(lo, hi),
                       method="bvls" if a.shape[1] < 40 else "trf").x
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


def correlation_of(cov: FloatArray) -> FloatArray:
    d = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    return np.asarray(cov / np.outer(d, d), dtype=float)


def project_out(a: FloatArray, k: int) -> FloatArray:
    """The first ``k`` columns of ``a`` with their parts along the other (alignment) columns removed.

    >>> project_out(np.array([[1.0, 1.0], [1.0, 0.0]]), 1).ravel().tolist()
    [0.0, 1.0]
    """
    q, _ = np.linalg.qr(a[:, k:])
    return a[:, :k] - q @ (q.T @ a[:, :k])


@dataclass(frozen=True)
class Directions:
    """The combinations of the parameters the scans determine, and those they do not.

    The eigenvectors of ``J^T J`` (``J``: the residuals' derivatives by the parameters in units of their
    plausible changes ``spans``, the alignment taken out), each a combination of parameters;
    its standard error is ``sigma / sqrt(eigenvalue)`` plausible changes.

    Attributes
    ----------
    names, spans : the parameters and their plausible changes
    eigenvalues : ndarray, shape (k,)
        Of ``J^T J`` along each combination.
    vectors : ndarray, shape (k, k)
        The combinations as columns (unit length, in plausible changes).
    held : ndarray of bool, shape (k,)
        The combinations the scans do not determine (the fit keeps them where they were).
    sigma : float
        The residual's standard deviation, mm.
    points : int
        The scan points behind ``J``.

    Examples
    --------
    Two parameters that move the scans alike, and a third on its own:

    >>> j = np.array([[1.0, 1.0, 0.0], [1.0, 1.0001, 0.0], [0.0, 0.0, 2.0]]) * 100
    >>> d = directions(j.T @ j, 0.05, ("a", "b", "c"), np.array([0.05, 0.05, 0.1]), 3)
    >>> d.held.tolist(), d.combination(0)
    ([True, False, False], 'a +0.035 with b -0.035')
    >>> (d.shares().round(2).tolist(), d.standard_errors().round(6).tolist())
    ([0.71, 0.71, 0.0], [9e-06, 9e-06, 2.5e-05])
    """

    names: tuple[str, ...]
    spans: FloatArray
    eigenvalues: FloatArray
    vectors: FloatArray
    held: NDArray[np.bool_]
    sigma: float
    points: int

    def errors(self) -> FloatArray:
        """Each combination's standard error, in plausible changes."""
        return np.asarray(self.sigma / np.sqrt(np.maximum(self.eigenvalues, 1e-300)), dtype=float)

    def covariance(self) -> FloatArray:
        """The parameters' covariance in plausible changes, the held combinations fixed."""
        v = self.vectors[:, ~self.held]
        return np.asarray(self.sigma**2 * (v / np.maximum(self.eigenvalues[~self.held], 1e-300)) @ v.T, dtype=float)

    def standard_errors(self) -> FloatArray:
        """Each parameter's standard error in its own unit, the held combinations fixed."""
        return np.sqrt(np.maximum(np.diag(self.covariance()), 0.0)) * self.spans

    def shares(self) -> FloatArray:
        """How far each parameter moves per plausible change of the held combinations, in its plausible changes."""
        return np.asarray(np.sqrt((self.vectors[:, self.held] ** 2).sum(axis=1)), dtype=float)

    def combination(self, j: int) -> str:
        """Combination ``j`` in the parameters' units, one plausible change long (terms under 0.1 left out)."""
        v = self.vectors[:, j] * np.sign(self.vectors[np.argmax(np.abs(self.vectors[:, j])), j])
        return " with ".join(f"{n} {x * s:+.2g}" for n, x, s in zip(self.names, v, self.spans, strict=True)
                             if abs(x) >= 0.1)

    def scan_change(self, j: int) -> float:
        """The RMS change of the scans' residuals, mm, along one plausible change of combination ``j``."""
        return float(np.sqrt(max(self.eigenvalues[j], 0.0) / max(self.points, 1)))


def directions(normal: FloatArray, sigma: float, names: Sequence[str], spans: FloatArray, points: int,
               hold: FloatArray | None = None) -> Directions:
    """The combinations of ``normal`` (``J^T J`` in plausible changes, alignment taken out), weakest first:
    those whose standard error exceeds :data:`MAX_DIRECTION_ERROR` plausible changes are held, and as many of
    the weakest as the correlation form of ``normal`` has eigenvalues below :data:`MIN_EIGENVALUE` (columns
    too alike to tell apart), whichever are more; or ``hold`` (orthonormal columns) are.

    Examples
    --------
    A strong parameter beside two weak ones that the scans tell apart well: nothing held, though the
    weak combination's eigenvalue is 1e-5 of the largest.

    >>> j = np.array([[100.0, 0.0, 0.0], [0.0, 1.0, 0.5], [0.0, 0.0, 0.3]]) * 10
    >>> d = directions(j.T @ j, 0.05, ("wall", "a", "b"), np.array([0.1, 0.05, 0.05]), 3)
    >>> d.held.tolist(), float(d.eigenvalues[0] / d.eigenvalues[-1]) < 1e-4
    ([False, False, False], True)
    """
    if hold is None:
        eigenvalues, vectors = np.linalg.eigh(normal)
        errors = sigma / np.sqrt(np.maximum(eigenvalues, 1e-300))
        size = np.sqrt(np.maximum(np.diag(normal), 1e-300))
        alike = np.linalg.eigvalsh(normal / np.outer(size, size)) < MIN_EIGENVALUE
        held = np.arange(len(eigenvalues)) < max(int(np.sum(errors > MAX_DIRECTION_ERROR)), int(np.sum(alike)))
        return Directions(tuple(names), np.asarray(spans, float), eigenvalues, vectors, held, sigma, points)
    p = np.eye(len(normal)) - hold @ hold.T
    eigenvalues, vectors = np.linalg.eigh(p @ normal @ p)
    kept = vectors[:, hold.shape[1]:]  # the null space of p is the held combinations
    held_values = np.einsum("ij,ik,kj->j", hold, normal, hold)
    return Directions(tuple(names), np.asarray(spans, float), np.r_[held_values, eigenvalues[hold.shape[1]:]],
                      np.hstack([hold, kept]), np.r_[np.ones(hold.shape[1], bool), np.zeros(kept.shape[1], bool)],
                      sigma, points)


def residual_sigma(r: FloatArray, unknowns: int) -> float:
    """The residual's standard deviation with ``unknowns`` fitted.

    >>> residual_sigma(np.array([1.0, -1.0, 1.0, -1.0]), 2)
    1.4142135623730951
    """
    return float(np.sqrt(r @ r / max(len(r) - unknowns, 1)))

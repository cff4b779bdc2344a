"""Least-squares alignment of a scan to a model: rigid (or similarity) transforms in 2D or 3D.

For matched points the best transform is closed-form (Umeyama 1991, IEEE TPAMI 13(4),
376-380: the SVD of the cross-covariance, with the reflection removed). Unordered scan
points are matched to their nearest model points (a KD-tree) and the transform refined
until the matches stop changing: iterative closest points (Besl and McKay 1992, IEEE
TPAMI 14(2), 239-256). ICP finds the nearest local optimum, so it starts from every
alignment of the two clouds' principal axes (4 in 3D, 2 in 2D, up to the reflection) and
keeps the best.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class Transform:
    """``x -> scale * rotation @ x + translation``.

    Attributes
    ----------
    rotation : ndarray, shape (d, d)
        Proper rotation (determinant +1).
    translation : ndarray, shape (d,)
    scale : float
    """

    rotation: FloatArray
    translation: FloatArray
    scale: float = 1.0

    def __call__(self, points: ArrayLike) -> FloatArray:
        return self.scale * np.asarray(points, dtype=float) @ self.rotation.T + self.translation

    def then(self, other: Transform) -> Transform:
        """This transform followed by ``other``."""
        return Transform(other.rotation @ self.rotation, other.scale * other.rotation @ self.translation
                         + other.translation, other.scale * self.scale)

    @property
    def angle_deg(self) -> float:
        """The rotation angle, degrees."""
        d = self.rotation.shape[0]
        c = np.clip((np.trace(self.rotation) - (d - 2)) / 2.0, -1.0, 1.0)
        return float(np.degrees(np.arccos(c)))

    def to_dict(self) -> dict[str, object]:
        return {"rotation": self.rotation.tolist(), "translation_mm": self.translation.tolist(),
                "scale": self.scale, "angle_deg": self.angle_deg}


def fit_transform(source: ArrayLike, target: ArrayLike, scale: bool = False) -> Transform:
    """The transform that maps matched ``source`` points onto ``target`` in least squares.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> p = rng.normal(size=(20, 3))
    >>> c, s = np.cos(0.3), np.sin(0.3)
    >>> R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    >>> t = fit_transform(p, 2.0 * p @ R.T + [1, 2, 3], scale=True)
    >>> round(t.scale, 9), round(t.angle_deg, 6), np.round(t.translation, 9).tolist()
    (2.0, 17.188734, [1.0, 2.0, 3.0])
    """
    p, q = np.asarray(source, dtype=float), np.asarray(target, dtype=float)
    mp, mq = p.mean(axis=0), q.mean(axis=0)
    a, b = p - mp, q - mq
    u, sigma, vt = np.linalg.svd(b.T @ a / len(p))
    d = np.ones(p.shape[1])
    d[-1] = np.sign(np.linalg.det(u @ vt)) or 1.0
    rotation = u @ np.diag(d) @ vt
    s = float((sigma * d).sum() / (a**2).sum(axis=1).mean()) if scale else 1.0
    return Transform(rotation, mq - s * rotation @ mp, s)


@dataclass(frozen=True)
class Alignment:
    """The result of :func:`icp`.

    Attributes
    ----------
    transform : Transform
        Maps the scan onto the model.
    rms : float
        RMS distance of the aligned scan points to their nearest model points, mm.
    iterations : int
    """

    transform: Transform
    rms: float
    iterations: int


def _principal(points: FloatArray) -> FloatArray:
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    return vt


def starts(source: FloatArray, target: FloatArray) -> list[Transform]:
    """Transforms that put the source's principal axes on the target's, every sign with det +1."""
    ps, pt = _principal(source), _principal(target)
    d = source.shape[1]
    out = []
    for signs in product((1.0, -1.0), repeat=d):
        rotation = pt.T @ np.diag(signs) @ ps
        if np.linalg.det(rotation) > 0:
            out.append(Transform(rotation, target.mean(axis=0) - rotation @ source.mean(axis=0)))
    return out


def small_rotation(omega: FloatArray) -> FloatArray:
    """The rotation of a small rotation vector (3D, Rodrigues) or angle (2D)."""
    if omega.size == 1:
        c, s = np.cos(omega[0]), np.sin(omega[0])
        return np.array([[c, -s], [s, c]])
    angle = float(np.linalg.norm(omega))
    if angle < 1e-300:
        return np.eye(3)
    k = omega / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def plane_step(moved: FloatArray, targets: FloatArray, normals: FloatArray, scale: bool = False) -> Transform:
    """One linearised point-to-plane step (Chen and Medioni 1992): the small transform that
    minimises sum ((x_i' - q_i) . n_i)^2, so points may slide along the surface.
    """
    d = moved.shape[1]
    centre = moved.mean(axis=0)
    p = moved - centre
    if d == 2:
        rot = (np.c_[-p[:, 1], p[:, 0]] * normals).sum(axis=1)[:, None]
    else:
        rot = np.cross(p, normals)
    columns = [rot, normals] + ([(p * normals).sum(axis=1)[:, None]] if scale else [])
    A = np.hstack(columns)
    b = ((targets - moved) * normals).sum(axis=1)
    x, *_ = np.linalg.lstsq(A, b, rcond=None)
    k = rot.shape[1]
    R = small_rotation(x[:k])
    s = 1.0 + (x[-1] if scale else 0.0)
    t = x[k:k + d]
    return Transform(R, centre + t - s * R @ centre, s)


def icp(scan: ArrayLike, model: ArrayLike, scale: bool = False, max_iterations: int = 200,
        tolerance: float = 1e-10, initial: Transform | None = None, normals: ArrayLike | None = None) -> Alignment:
    """Align unordered ``scan`` points to ``model`` points (same dimension) by iterative closest points.

    Point-to-point steps from every start; then, if the model's unit ``normals`` are given,
    point-to-plane steps from the best, which let the scan slide along the surface to the
    exact fit instead of stopping where the nearest samples stop changing.

    Parameters
    ----------
    scan, model : array_like, shape (n, d) and (m, d)
    scale : bool
        Fit a scale too (a photo of unknown scale).
    max_iterations : int
    tolerance : float
        Stop when the mean squared distance changes by less than this, relatively.
    initial : Transform, optional
        Start here only, instead of every principal-axis alignment.
    normals : array_like, shape (m, d), optional
        Unit normals of the model at its points.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> model = np.c_[np.linspace(0, 100, 400), 10 * np.sin(np.linspace(0, 3, 400))]
    >>> c, s = np.cos(0.2), np.sin(0.2)
    >>> scan = (model[::3] - [5, 1]) @ np.array([[c, s], [-s, c]])
    >>> a = icp(scan, model)
    >>> round(a.transform.angle_deg, 3), a.rms < 1e-6
    (11.459, True)
    """
    p, q = np.asarray(scan, dtype=float), np.asarray(model, dtype=float)
    tree = cKDTree(q)

    def run(start: Transform, step: Any) -> Alignment:
        current, previous, it = start, np.inf, 0
        for it in range(1, max_iterations + 1):  # noqa: B007 - the count is reported after the loop
            moved = current(p)
            dist, index = tree.query(moved)
            mse = float(np.mean(dist**2))
            if np.isfinite(previous) and previous - mse <= tolerance * max(previous, 1e-300):
                break
            previous = mse
            current = current.then(step(moved, index))
        dist, _ = tree.query(current(p))
        return Alignment(current, float(np.sqrt(np.mean(dist**2))), it)

    def point(moved: FloatArray, index: IntArray) -> Transform:
        return fit_transform(moved, q[index], scale=scale)

    best: Alignment | None = None
    for start in ([initial] if initial is not None else starts(p, q)):
        found = run(start, point)
        if best is None or found.rms < best.rms:
            best = found
    assert best is not None
    if normals is not None:
        n = np.asarray(normals, dtype=float)
        refined = _refine(p, q, n, tree, best, scale, max_iterations)
        if refined.rms <= best.rms:
            best = refined
    return best


def _refine(p: FloatArray, q: FloatArray, n: FloatArray, tree: cKDTree, start: Alignment, scale: bool,
            max_iterations: int) -> Alignment:
    """Point-to-plane iterations from ``start`` until the transform stops changing."""
    current, it = start.transform, 0
    for it in range(1, max_iterations + 1):  # noqa: B007 - the count is reported after the loop
        moved = current(p)
        _, index = tree.query(moved)
        step = plane_step(moved, q[index], n[index], scale)
        current = current.then(step)
        if step.angle_deg < 1e-9 and np.linalg.norm(step.translation) < 1e-10 and abs(step.scale - 1) < 1e-12:
            break
    dist, _ = tree.query(current(p))
    return Alignment(current, float(np.sqrt(np.mean(dist**2))), start.iterations + it)

"""The volumetric term of a nearly incompressible solid on a dilatation of its own, per element.

A displacement element whose every quadrature point must keep its volume locks: a rubber with
a Poisson's ratio of 0.499 bends a fraction of what it should. The three-field (u-p-J)
formulation of Simo, Taylor and Pister (1985) keeps the isochoric energy at every point and
integrates the volumetric one on a dilatation ``theta`` and a pressure ``p`` of their own,
discontinuous between elements and condensed out element by element:

    Pi_vol = sum_e int_e U(theta) dV,    theta = Pi_e(J),    p = Pi_e(U'(theta)),

with ``U(theta) = 9/2 K (theta^(1/3) - 1)^2``, the volumetric term of the silicone's law (Eq 2.12)
and ``Pi_e`` the L2 projection onto the element's pressure space: linear (P1, ``1, X, Y, Z``)
for quadratic elements (hex20, quad8: the Q2/P1 pair, as commercial codes' hybrid quadratic
elements), constant (P0: the mean dilatation of Nagtegaal, Parks and Rice 1974) for linear
ones. With the element's mass matrix ``M = int N N^T dV`` of the pressure basis ``N`` and
``b_m = int N_m cof(F) grad N_a dV``:

* the residual adds ``p cof(F)`` to the stress at every point of the element;
* the tangent adds the geometric term ``p d cof(F) / dF`` at every point and the element's
  term ``sum_mn [M^-1 H M^-1]_mn b_m (x) b_n``, ``H = int N U''(theta) N^T dV``, inside the
  element's block: the sparsity pattern is the displacement form's.

For a deformation whose ``J`` lies in the pressure space (a homogeneous one) the energy is the
displacement form's. A material's free thermal stretch ``t``
(:class:`~pneumorph.fem.ogden.OgdenCompressible`) enters as ``theta`` of the elastic part
(``J / t^3``) and the factor ``1 / t^3`` of the element term; ``p cof(F)`` is the same.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

#: the bulk modulus over the initial shear modulus above which a silicone is integrated on the element's mean
#: dilatation by default: Poisson's ratio 0.45 (``K / mu = 2 (1 + nu) / (3 (1 - 2 nu))``)
MIXED_BULK_RATIO = 2.0 * 1.45 / (3.0 * 0.1)


def nearly_incompressible(bulk: float, shear: float) -> bool:
    """Whether a material of this bulk and (initial) shear modulus is integrated in the u-p-J form by default:
    ``K >= MIXED_BULK_RATIO * mu``, a Poisson's ratio of 0.45 or more.

    >>> nearly_incompressible(0.119, 0.131), nearly_incompressible(65.5, 0.131)   # Mold Star 15, and x550
    (False, True)
    """
    return bool(bulk >= MIXED_BULK_RATIO * shear)


def cofactor(F: FloatArray) -> FloatArray:
    """``cof(F) = det(F) F^-T`` of deformation gradients stored points last, (d, d, n), d = 2 or 3.

    >>> F = np.array([[2.0, 1.0], [0.0, 3.0]])[..., None]
    >>> cofactor(F)[..., 0].tolist()
    [[3.0, -0.0], [-1.0, 2.0]]
    """
    if F.shape[0] == 2:
        return np.stack([np.stack([F[1, 1], -F[1, 0]]), np.stack([-F[0, 1], F[0, 0]])])
    c = np.empty_like(F)
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            c[i, j] = F[i1, j1] * F[i2, j2] - F[i1, j2] * F[i2, j1]
    return c


def volumetric(theta: FloatArray, bulk: float) -> tuple[FloatArray, FloatArray]:
    """``U'(theta)`` (the pressure) and ``U''(theta)`` of ``U = 9/2 K (theta^(1/3) - 1)^2``.

    >>> p, dp = volumetric(np.array([1.0]), 10.0)
    >>> float(p[0]), float(dp[0])   # no pressure undeformed; U''(1) = K
    (0.0, 10.0)
    """
    s = np.cbrt(theta)
    return 3.0 * bulk * (s - 1.0) / (s * s), bulk * (2.0 - s) / s**5


@dataclass(frozen=True)
class PressureSpace:
    """The pressure (and dilatation) basis of every element at its quadrature points, and its inverse mass matrix.

    Attributes
    ----------
    N : ndarray, shape (c, q, m)
        ``1`` and, for a linear space, the reference coordinates about the element's centroid
        over its size.
    Minv : ndarray, shape (c, m, m)
        ``(int N N^T dV)^-1``.
    """

    N: FloatArray
    Minv: FloatArray

    def project(self, values: FloatArray, dV: FloatArray) -> FloatArray:
        """The L2 projection of point ``values`` (c, q) onto the space, at the points (c, q).

        >>> space = pressure_space(np.array([[[0.0], [1.0], [2.0]]]), np.ones((1, 3)), linear=True)
        >>> space.project(np.array([[1.0, 3.0, 5.0]]), np.ones((1, 3))).tolist()   # linear: itself
        [[1.0, 3.0, 5.0]]
        """
        coefficients = np.einsum("cmn,cqn,cq->cm", self.Minv, self.N, values * dV)
        return np.einsum("cqm,cm->cq", self.N, coefficients)

    def element_term(self, second: FloatArray, dV: FloatArray) -> FloatArray:
        """``M^-1 (int N U'' N^T dV) M^-1`` of every element from ``U''`` at the points (c, q): (c, m, m)."""
        H = np.einsum("cqm,cqn,cq->cmn", self.N, self.N, second * dV)
        return np.matmul(np.matmul(self.Minv, H), self.Minv)


def pressure_space(X: FloatArray, dV: FloatArray, linear: bool) -> PressureSpace:
    """The constant (P0) or linear (P1) pressure space of elements with quadrature points at ``X`` (c, q, d).

    >>> space = pressure_space(np.zeros((2, 4, 3)), np.full((2, 4), 0.25), linear=False)
    >>> space.N.shape, float(space.Minv[0, 0, 0])   # the mean: 1 / V
    ((2, 4, 1), 1.0)
    """
    volume = dV.sum(axis=1)
    basis = [np.ones(dV.shape)]
    if linear:
        centre = np.einsum("cqd,cq->cd", X, dV) / volume[:, None]
        size = volume ** (1.0 / X.shape[2])
        basis += list(np.moveaxis((X - centre[:, None]) / size[:, None, None], 2, 0))
    N = np.stack(basis, axis=2)
    return PressureSpace(N, np.linalg.inv(np.einsum("cqm,cqn,cq->cmn", N, N, dV)))


def geometric_blocks(cof: FloatArray, detF: FloatArray, p: FloatArray,
                     pairs: list[tuple[int, int]] | None = None) -> FloatArray:
    """``p d cof(F)_iJ / dF_kL = p (cof_iJ cof_kL - cof_iL cof_kJ) / det F`` at every point.

    Parameters
    ----------
    cof : ndarray, shape (d, d, n)
    detF : ndarray, shape (n,)
    p : ndarray, shape (n,)
    pairs : list of (int, int), optional
        Only the blocks of these component pairs ``(i, k)``, as ``(len(pairs), d, d, n)``
        (``[pair, J, L]``, the layout of :func:`~pneumorph.fem.fast.kernels.ogden_3d`'s); else
        the whole ``(d, d, d, d, n)`` ``[i, J, k, L]``.

    Examples
    --------
    >>> A = geometric_blocks(np.eye(2)[..., None], np.ones(1), np.ones(1))
    >>> A[0, 0, 1, 1, 0], A[0, 1, 1, 0, 0]   # d cof_00 / dF_11 = 1, d cof_01 / dF_10 = -1
    (np.float64(1.0), np.float64(-1.0))
    """
    w = p / detF
    if pairs is None:
        return w * (np.einsum("iJn,kLn->iJkLn", cof, cof) - np.einsum("iLn,kJn->iJkLn", cof, cof))
    out = np.empty((len(pairs), *cof.shape))
    for m, (i, k) in enumerate(pairs):
        out[m] = w * (cof[i][:, None] * cof[k][None, :] - cof[i][None, :] * cof[k][:, None])
    return out


__all__ = ["MIXED_BULK_RATIO", "PressureSpace", "cofactor", "geometric_blocks", "nearly_incompressible",
           "pressure_space", "volumetric"]

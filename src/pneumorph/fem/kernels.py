"""Plane-strain constitutive kernels with the quadrature points leading (fast assembly).

Each kernel maps in-plane deformation gradients ``F`` of shape ``(n, 2, 2)`` (``F33 = 1``)
to the in-plane first Piola-Kirchhoff stress ``P`` ``(n, 2, 2)`` and the in-plane block of
the tangent ``A_iJkL = dP_iJ / dF_kL`` ``(n, 2, 2, 2, 2)``, the same numbers as the 3D
materials evaluated at ``F = diag(F_2D, 1)``, without the 3x3 eigen-decompositions and the
``(3, 3, 3, 3)`` tensors nobody reads in plane strain.

* :func:`ogden_plane_strain` - the compressible Ogden model of
  :class:`pneumorph.fem.ogden.OgdenCompressible` (Eq 2.12), principal form with the
  closed-form 2x2 eigen-decomposition of ``C`` (the third stretch is 1).
* :func:`neo_hooke_plane_strain` - FElupe's ``NeoHookeCompressible``,
  ``W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.ogden import _power_divided_difference

FloatArray = NDArray[np.float64]


def _outer(a: FloatArray, b: FloatArray) -> FloatArray:
    """Pointwise ``a (x) b`` of (n, 2) vectors as (n, 2, 2)."""
    return a[:, :, None] * b[:, None, :]


def ogden_plane_strain(
    F: FloatArray, mu: Sequence[float], alpha: Sequence[float], bulk: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Stress and tangent of the compressible Ogden model (Eq 2.12) in plane strain.

    Parameters
    ----------
    F : ndarray, shape (n, 2, 2)
        In-plane deformation gradients (the out-of-plane stretch is 1).
    mu, alpha : sequence of float
        Ogden moduli (MPa, published Marc convention) and exponents.
    bulk : float
        Bulk modulus of ``9/2 K (J^(1/3) - 1)^2`` (MPa).

    Returns
    -------
    P : ndarray, shape (n, 2, 2)
    A : ndarray, shape (n, 2, 2, 2, 2)
    J : ndarray, shape (n,)
        ``det F``.

    Examples
    --------
    >>> import numpy as np
    >>> P, A, J = ogden_plane_strain(np.eye(2)[None], [0.1], [2.0], 10.0)
    >>> float(abs(P).max()), round(float(A[0, 0, 0, 0, 0]), 12)   # K + 4/3 G, G = 0.1
    (0.0, 10.133333333333)
    """
    mu_ = np.asarray(mu, dtype=float)
    alpha_ = np.asarray(alpha, dtype=float)
    F11, F12, F21, F22 = F[:, 0, 0], F[:, 0, 1], F[:, 1, 0], F[:, 1, 1]
    J = F11 * F22 - F12 * F21
    C11 = F11 * F11 + F21 * F21
    C22 = F12 * F12 + F22 * F22
    C12 = F11 * F12 + F21 * F22
    half = 0.5 * (C11 + C22)
    radius = np.hypot(0.5 * (C11 - C22), C12)
    c1 = half + radius
    c2 = (J * J) / c1  # det C / c1, accurate also when c2 << c1
    theta = 0.5 * np.arctan2(C12, 0.5 * (C11 - C22))
    cos, sin = np.cos(theta), np.sin(theta)
    N1 = np.stack([cos, sin], axis=1)
    N2 = np.stack([-sin, cos], axis=1)
    c = (c1, c2)
    # isochoric stretches lb_a^alpha_n = J^(-alpha_n/3) c_a^(alpha_n/2), lb_3 = J^(-alpha_n/3)
    Jn = [J ** (-a / 3.0) for a in alpha_]
    lb = [[Jn[n] * c1 ** (a / 2.0), Jn[n] * c2 ** (a / 2.0), Jn[n]] for n, a in enumerate(alpha_)]
    m = [(lb_n[0] + lb_n[1] + lb_n[2]) / 3.0 for lb_n in lb]
    h = 3.0 * bulk * (J ** (2.0 / 3.0) - J ** (1.0 / 3.0))  # J U'(J)
    beta = [sum(mu_[n] * (lb[n][a] - m[n]) for n in range(len(mu_))) + h for a in range(2)]
    S = [beta[a] / c[a] for a in range(2)]
    # d beta_a / d c_b = sum_n mu_n alpha_n / (2 c_b) [lb_a (d_ab - 1/3) - (lb_b - m)/3]
    #                    + K (2 J^(-1/3) - J^(-2/3)) J / (2 c_b)
    dh = bulk * (2.0 * J ** (-1.0 / 3.0) - J ** (-2.0 / 3.0)) * J
    diag = [[None, None], [None, None]]
    for a in range(2):
        for b in range(2):
            dbeta = dh / (2.0 * c[b])
            for n in range(len(mu_)):
                term = lb[n][a] * ((a == b) - 1.0 / 3.0) - (lb[n][b] - m[n]) / 3.0
                dbeta = dbeta + mu_[n] * alpha_[n] / (2.0 * c[b]) * term
            # 2 dS_a / dc_b
            diag[a][b] = 2.0 * (dbeta / c[a] - (a == b) * beta[a] / c[a] ** 2)
    common = sum(mu_[n] * m[n] for n in range(len(mu_))) - h
    dd = common / (c1 * c2)
    for n in range(len(mu_)):
        dd = dd + mu_[n] * Jn[n] * _power_divided_difference(c2, c1, alpha_[n] / 2.0 - 1.0)
    f1 = np.einsum("nij,nj->ni", F, N1)
    f2 = np.einsum("nij,nj->ni", F, N2)
    G11, G22 = _outer(f1, N1), _outer(f2, N2)
    Gs = _outer(f1, N2) + _outer(f2, N1)
    P = S[0][:, None, None] * G11 + S[1][:, None, None] * G22
    R1 = diag[0][0][:, None, None] * G11 + diag[0][1][:, None, None] * G22
    R2 = diag[1][0][:, None, None] * G11 + diag[1][1][:, None, None] * G22
    A = (
        G11[:, :, :, None, None] * R1[:, None, None]
        + G22[:, :, :, None, None] * R2[:, None, None]
        + (dd[:, None, None] * Gs)[:, :, :, None, None] * Gs[:, None, None]
    )
    S_mat = S[0][:, None, None] * _outer(N1, N1) + S[1][:, None, None] * _outer(N2, N2)
    A[:, 0, :, 0, :] += S_mat
    A[:, 1, :, 1, :] += S_mat
    return P, A, J


def neo_hooke_plane_strain(F: FloatArray, mu: float, lmbda: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Stress and tangent of FElupe's compressible neo-Hooke model in plane strain.

    ``P = mu (F - F^-T) + lambda ln J F^-T`` and
    ``A = mu I (x)_ik I + (mu - lambda ln J) F^-T (x)_il F^-T + lambda F^-T (x) F^-T``.

    Examples
    --------
    >>> import numpy as np
    >>> P, A, J = neo_hooke_plane_strain(np.eye(2)[None], 1.0, 2.0)
    >>> float(abs(P).max()), float(A[0, 0, 0, 0, 0]), float(A[0, 0, 1, 0, 1])   # lambda + 2 mu, mu
    (0.0, 4.0, 1.0)
    """
    F11, F12, F21, F22 = F[:, 0, 0], F[:, 0, 1], F[:, 1, 0], F[:, 1, 1]
    J = F11 * F22 - F12 * F21
    iFT = np.empty_like(F)  # F^-T = cof(F) / J
    iFT[:, 0, 0], iFT[:, 0, 1] = F22 / J, -F21 / J
    iFT[:, 1, 0], iFT[:, 1, 1] = -F12 / J, F11 / J
    lnJ = np.log(J)
    P = mu * F + (lmbda * lnJ - mu)[:, None, None] * iFT
    eye = np.eye(2)
    A = np.einsum("nil,nkj->nijkl", (mu - lmbda * lnJ)[:, None, None] * iFT, iFT)
    A += lmbda * iFT[:, :, :, None, None] * iFT[:, None, None, :, :]
    A += mu * np.einsum("ik,jl->ijkl", eye, eye)
    return P, A, J

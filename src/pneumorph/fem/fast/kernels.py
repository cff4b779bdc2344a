"""Constitutive kernels with the quadrature points last (plane strain and 3D).

Each kernel maps in-plane deformation gradients ``F`` of shape ``(2, 2, n)`` (``F33 = 1``)
to the in-plane first Piola-Kirchhoff stress ``P`` ``(2, 2, n)`` and the in-plane block of
the tangent ``A_iJkL = dP_iJ / dF_kL`` ``(2, 2, 2, 2, n)``, the same numbers as the 3D
materials evaluated at ``F = diag(F_2D, 1)``, without the 3x3 eigen-decompositions and the
``(3, 3, 3, 3)`` tensors nobody reads in plane strain. The points are the last, contiguous
axis, so that NumPy's elementwise loops run over long rows rather than 2x2 blocks.

* :func:`ogden_plane_strain` - the compressible Ogden model of
  :class:`pneumorph.fem.ogden.OgdenCompressible` (Eq 2.12), principal form with the
  closed-form 2x2 eigen-decomposition of ``C`` (the third stretch is 1).
* :func:`neo_hooke_plane_strain` - FElupe's ``NeoHookeCompressible``,
  ``W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2``.
* :func:`ogden_3d` - the one 3D Ogden kernel: the fast 3D assembly calls it directly and
  :class:`~pneumorph.fem.ogden.OgdenCompressible` adapts it to FElupe; with
  :func:`principal_3d`, the closed-form eigen-decomposition of ``C``.
* :func:`crimped_fibre_3d` - crimped fibres along a direction per point: slack until their
  crimp has straightened, then linear (the paper of the bilinear composite); added to a
  matrix kernel by :class:`pneumorph.fem.fibre.CrimpedFibreOgden`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

#: points per pass of the 3D kernels (:func:`principal_3d`, :func:`ogden_3d`): their tens of temporary rows of
#: this many numbers stay in the processor's cache. The same numbers as one pass (every operation is per point);
#: the 15-unit half model's tangent kernel (65,610 points) took 82 ms in passes of 4,096 against 112 ms in one.
POINT_CHUNK = 4096


def _in_chunks(compute: Callable[[slice], tuple[Any, ...]], n: int) -> tuple[Any, ...]:
    """``compute(points)`` of slices of :data:`POINT_CHUNK` of ``n`` points, its arrays (points last, or None)
    joined."""
    joined: list[Any] = []
    for start in range(0, n, POINT_CHUNK):
        points = slice(start, min(start + POINT_CHUNK, n))
        part = compute(points)
        if not joined:
            joined = [None if a is None else np.empty((*a.shape[:-1], n), dtype=a.dtype) for a in part]
        for whole, a in zip(joined, part, strict=True):
            if whole is not None:
                whole[..., points] = a
    return tuple(joined)


def _power_divided_difference(cb: FloatArray, ca: FloatArray, k: float) -> FloatArray:
    """``(cb^k - ca^k) / (cb - ca)``, exact also for ``cb == ca`` (limit ``k ca^(k-1)``).

    The divided differences ``(S_b - S_a) / (c_b - c_a)`` of the principal-frame tangent are
    divided differences of powers of ``c``; in closed form with ``expm1`` equal stretches
    (the undeformed state, uniaxial and equibiaxial states) are exact, without perturbing
    the eigenvalues.
    """
    x = np.log(cb / ca)
    small = np.abs(x) < 1e-13
    xs = np.where(small, 1.0, x)
    ratio = np.where(small, k, np.expm1(k * xs) / np.expm1(xs))
    return ca ** (k - 1.0) * ratio


def _outer(a: FloatArray, b: FloatArray) -> FloatArray:
    """Pointwise ``a (x) b`` of (2, n) vectors as (2, 2, n)."""
    return a[:, None] * b[None, :]


def ogden_plane_strain(
    F: FloatArray, mu: Sequence[float] | FloatArray, alpha: Sequence[float] | FloatArray, bulk: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Stress and tangent of the compressible Ogden model (Eq 2.12) in plane strain.

    Parameters
    ----------
    F : ndarray, shape (2, 2, n)
        In-plane deformation gradients (the out-of-plane stretch is 1).
    mu, alpha : sequence of float
        Ogden moduli (MPa, published Marc convention) and exponents.
    bulk : float
        Bulk modulus of ``9/2 K (J^(1/3) - 1)^2`` (MPa).

    Returns
    -------
    P : ndarray, shape (2, 2, n)
    A : ndarray, shape (2, 2, 2, 2, n)
    J : ndarray, shape (n,)
        ``det F``.

    Examples
    --------
    >>> import numpy as np
    >>> P, A, J = ogden_plane_strain(np.eye(2)[..., None], [0.1], [2.0], 10.0)
    >>> float(abs(P).max()), round(float(A[0, 0, 0, 0, 0]), 12)   # K + 4/3 G, G = 0.1
    (0.0, 10.133333333333)
    """
    mu_ = [float(v) for v in mu]
    alpha_ = [float(v) for v in alpha]
    terms = range(len(mu_))
    F11, F12, F21, F22 = F[0, 0], F[0, 1], F[1, 0], F[1, 1]
    J = F11 * F22 - F12 * F21
    C11 = F11 * F11 + F21 * F21
    C22 = F12 * F12 + F22 * F22
    C12 = F11 * F12 + F21 * F22
    half_diff = 0.5 * (C11 - C22)
    c1 = 0.5 * (C11 + C22) + np.hypot(half_diff, C12)
    c2 = (J * J) / c1  # det C / c1, accurate also when c2 << c1
    theta = 0.5 * np.arctan2(C12, half_diff)
    cos, sin = np.cos(theta), np.sin(theta)
    N1 = np.stack([cos, sin])
    N2 = np.stack([-sin, cos])
    c = (c1, c2)
    # isochoric stretches lb_a^alpha_n = J^(-alpha_n/3) c_a^(alpha_n/2), lb_3 = J^(-alpha_n/3)
    # (powers as exponentials of logarithms: several times faster than np.power)
    lnJ = np.log(J)
    ln1, ln2 = np.log(c1) - lnJ / 1.5, np.log(c2) - lnJ / 1.5  # ln of c_a J^(-2/3)
    Jn = [np.exp((-a / 3.0) * lnJ) for a in alpha_]
    lb = [(np.exp((0.5 * a) * ln1), np.exp((0.5 * a) * ln2), Jn[n]) for n, a in enumerate(alpha_)]
    m = [(lb_n[0] + lb_n[1] + lb_n[2]) / 3.0 for lb_n in lb]
    J13 = np.exp(lnJ / 3.0)
    h = 3.0 * bulk * J13 * (J13 - 1.0)  # J U'(J)
    beta = [sum(mu_[n] * (lb[n][a] - m[n]) for n in terms) + h for a in range(2)]
    S = [beta[a] / c[a] for a in range(2)]
    # d beta_a / d c_b = 1 / (2 c_b) {sum_n mu_n alpha_n [lb_a (d_ab - 1/3) - (lb_b - m)/3]
    #                                 + K (2 J^(-1/3) - J^(-2/3)) J}
    dh = bulk * (2.0 * J13 * J13 - J13)
    shared = [dh - sum(mu_[n] * alpha_[n] * (lb[n][b] - m[n]) for n in terms) / 3.0 for b in range(2)]
    diag = [[np.empty(0), np.empty(0)], [np.empty(0), np.empty(0)]]
    for a in range(2):
        own = sum(mu_[n] * alpha_[n] * lb[n][a] for n in terms)
        for b in range(2):
            dbeta = (shared[b] + own * ((a == b) - 1.0 / 3.0)) / (2.0 * c[b])
            # 2 dS_a / dc_b
            diag[a][b] = 2.0 * (dbeta - (a == b) * S[a]) / c[a]
    common = sum(mu_[n] * m[n] for n in terms) - h
    dd = common / (c1 * c2)
    for n in terms:
        dd = dd + mu_[n] * Jn[n] * _power_divided_difference(c2, c1, alpha_[n] / 2.0 - 1.0)
    f1 = np.stack([F11 * cos + F12 * sin, F21 * cos + F22 * sin])  # F N_1
    f2 = np.stack([F12 * cos - F11 * sin, F22 * cos - F21 * sin])  # F N_2
    G11, G22 = _outer(f1, N1), _outer(f2, N2)
    Gs = _outer(f1, N2) + _outer(f2, N1)
    P = S[0] * G11 + S[1] * G22
    R1 = diag[0][0] * G11 + diag[0][1] * G22
    R2 = diag[1][0] * G11 + diag[1][1] * G22
    A = G11[:, :, None, None] * R1 + G22[:, :, None, None] * R2 + (dd * Gs)[:, :, None, None] * Gs
    S_mat = S[0] * _outer(N1, N1) + S[1] * _outer(N2, N2)
    A[0, :, 0] += S_mat
    A[1, :, 1] += S_mat
    return P, A, J


def neo_hooke_plane_strain(F: FloatArray, mu: float, lmbda: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Stress and tangent of FElupe's compressible neo-Hooke model in plane strain.

    ``P = mu (F - F^-T) + lambda ln J F^-T`` and
    ``A = mu I (x)_ik I + (mu - lambda ln J) F^-T (x)_il F^-T + lambda F^-T (x) F^-T``.

    Examples
    --------
    >>> import numpy as np
    >>> P, A, J = neo_hooke_plane_strain(np.eye(2)[..., None], 1.0, 2.0)
    >>> float(abs(P).max()), float(A[0, 0, 0, 0, 0]), float(A[0, 1, 0, 1, 0])   # lambda + 2 mu, mu
    (0.0, 4.0, 1.0)
    """
    F11, F12, F21, F22 = F[0, 0], F[0, 1], F[1, 0], F[1, 1]
    J = F11 * F22 - F12 * F21
    iFT = np.stack([np.stack([F22, -F21]), np.stack([-F12, F11])]) / J  # F^-T = cof(F) / J
    lnJ = np.log(J)
    P = mu * F + (lmbda * lnJ - mu) * iFT
    # (mu - lambda ln J) F^-T_iL F^-T_kJ + lambda F^-T_iJ F^-T_kL + mu d_ik d_JL
    A = ((mu - lmbda * lnJ) * iFT)[:, None, None, :] * iFT.transpose(1, 0, 2)[None, :, :, None]
    A += lmbda * iFT[:, :, None, None] * iFT[None, None]
    for i in range(2):
        for j in range(2):
            A[i, j, i, j] += mu
    return P, A, J


#: relative eigenvalue gap below which :func:`principal_3d` uses LAPACK instead of the
#: closed form (whose eigenvectors lose accuracy as eps / gap)
_GAP = 1e-4


def principal_3d(F: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Eigenvalues ``c[a]`` ``(3, n)`` and eigenvectors ``N[a, J]`` ``(3, 3, n)`` of ``C = F^T F``.

    The costliest step of :func:`ogden_3d` (pass it there as ``principal`` to reuse
    it). Closed form where the eigenvalues are apart: the trigonometric solution of the
    characteristic cubic, eigenvectors of the extreme eigenvalues as the largest cross
    product of two rows of ``C - c I``, the middle one completing the right-handed
    basis. Points with a relative gap below ``1e-4`` (the undeformed state, uniaxial
    and equibiaxial states) go to LAPACK's ``eigh``, which is several times slower.
    Eigenvalues ascend.

    Examples
    --------
    >>> import numpy as np
    >>> c, N = principal_3d(np.diag([1.0, 1.2, 1.5])[..., None])
    >>> np.round(c[:, 0], 12).tolist(), np.round(abs(N[..., 0]), 12).tolist()
    ([1.0, 1.44, 2.25], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    """
    if F.shape[-1] > POINT_CHUNK:
        c_, N_ = _in_chunks(lambda points: principal_3d(F[..., points]), F.shape[-1])
        return c_, N_
    C11 = F[0, 0] * F[0, 0] + F[1, 0] * F[1, 0] + F[2, 0] * F[2, 0]
    C22 = F[0, 1] * F[0, 1] + F[1, 1] * F[1, 1] + F[2, 1] * F[2, 1]
    C33 = F[0, 2] * F[0, 2] + F[1, 2] * F[1, 2] + F[2, 2] * F[2, 2]
    C12 = F[0, 0] * F[0, 1] + F[1, 0] * F[1, 1] + F[2, 0] * F[2, 1]
    C13 = F[0, 0] * F[0, 2] + F[1, 0] * F[1, 2] + F[2, 0] * F[2, 2]
    C23 = F[0, 1] * F[0, 2] + F[1, 1] * F[1, 2] + F[2, 1] * F[2, 2]
    q = (C11 + C22 + C33) / 3.0
    B11, B22, B33 = C11 - q, C22 - q, C33 - q
    p2 = (B11 * B11 + B22 * B22 + B33 * B33 + 2.0 * (C12 * C12 + C13 * C13 + C23 * C23)) / 6.0
    p = np.sqrt(p2)
    with np.errstate(invalid="ignore", divide="ignore"):
        detB = B11 * (B22 * B33 - C23 * C23) - C12 * (C12 * B33 - C23 * C13) + C13 * (C12 * C23 - B22 * C13)
        r = np.clip(detB / (2.0 * p2 * p), -1.0, 1.0)
    phi = np.arccos(r) / 3.0
    hi = q + 2.0 * p * np.cos(phi)
    lo = q + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)
    mid = 3.0 * q - hi - lo

    def vector(lam: FloatArray) -> list[FloatArray]:  # (called where NaNs are expected)
        m11, m22, m33 = C11 - lam, C22 - lam, C33 - lam
        cands = [  # cross products of the rows of C - lam I: (1, 2), (1, 3), (2, 3)
            (C12 * C23 - C13 * m22, C13 * C12 - m11 * C23, m11 * m22 - C12 * C12),
            (C12 * m33 - C13 * C23, C13 * C13 - m11 * m33, m11 * C23 - C12 * C13),
            (m22 * m33 - C23 * C23, C23 * C13 - C12 * m33, C12 * C23 - m22 * C13),
        ]
        norms = [x * x + y * y + z * z for x, y, z in cands]
        first = (norms[0] >= norms[1]) & (norms[0] >= norms[2])
        second = ~first & (norms[1] >= norms[2])
        v = [np.where(first, cands[0][j], np.where(second, cands[1][j], cands[2][j])) for j in range(3)]
        scale = 1.0 / np.sqrt(np.where(first, norms[0], np.where(second, norms[1], norms[2])))
        return [vj * scale for vj in v]

    # equal eigenvalues give zero cross products: the NaNs go to LAPACK below
    with np.errstate(invalid="ignore", divide="ignore"):
        v_lo = vector(lo)
        v_hi = vector(hi)
        dot = v_hi[0] * v_lo[0] + v_hi[1] * v_lo[1] + v_hi[2] * v_lo[2]
        v_hi = [v_hi[j] - dot * v_lo[j] for j in range(3)]
        scale = 1.0 / np.sqrt(v_hi[0] * v_hi[0] + v_hi[1] * v_hi[1] + v_hi[2] * v_hi[2])
        v_hi = [vj * scale for vj in v_hi]
        v_mid = [
            v_hi[1] * v_lo[2] - v_hi[2] * v_lo[1],
            v_hi[2] * v_lo[0] - v_hi[0] * v_lo[2],
            v_hi[0] * v_lo[1] - v_hi[1] * v_lo[0],
        ]
    c = np.stack([lo, mid, hi])
    N = np.array([v_lo, v_mid, v_hi])
    close = ~((np.minimum(mid - lo, hi - mid) > _GAP * q) & np.all(np.isfinite(N), axis=(0, 1)))
    if np.any(close):
        Cc = np.stack(
            [np.stack([C11, C12, C13]), np.stack([C12, C22, C23]), np.stack([C13, C23, C33])]
        )[..., close]
        cc, Nc = np.linalg.eigh(np.moveaxis(Cc, -1, 0))  # (m, 3), (m, J, a)
        c[:, close] = cc.T
        N[..., close] = Nc.transpose(2, 1, 0)
    return c, N


def ogden_3d(
    F: FloatArray,
    mu: Sequence[float] | FloatArray,
    alpha: Sequence[float] | FloatArray,
    bulk: float,
    tangent: bool = True,
    principal: tuple[FloatArray, FloatArray] | None = None,
    pairs: Sequence[tuple[int, int]] | None = None,
) -> tuple[FloatArray, FloatArray | None, FloatArray]:
    """Stress and tangent of the compressible Ogden model (Eq 2.12), points last.

    The numbers of :class:`pneumorph.fem.ogden.OgdenCompressible` (principal form,
    divided differences exact at equal stretches) for deformation gradients stored as
    ``(3, 3, n)``, so that every step runs elementwise over long rows; only the
    eigenvectors of ``C`` come from a batched ``numpy.linalg.eigh``.

    Parameters
    ----------
    F : ndarray, shape (3, 3, n)
    mu, alpha : sequence of float
        Ogden moduli (MPa, published Marc convention) and exponents.
    bulk : float
        Bulk modulus of ``9/2 K (J^(1/3) - 1)^2`` (MPa).
    tangent : bool
        Compute the tangent (else ``A`` is None: a residual costs about half).
    principal : tuple of ndarray, optional
        :func:`principal_3d` of the same ``F``, if already computed.
    pairs : sequence of (int, int), optional
        Return only the blocks ``A[i, :, k, :]`` of these component pairs, as an array
        ``(len(pairs), 3, 3, n)`` (a symmetric tangent needs the pairs ``i <= k``).

    Returns
    -------
    P : ndarray, shape (3, 3, n)
    A : ndarray, shape (3, 3, 3, 3, n), or None
        ``dP_iJ / dF_kL``.
    J : ndarray, shape (n,)
        ``det F``.

    Examples
    --------
    >>> import numpy as np
    >>> P, A, J = ogden_3d(np.eye(3)[..., None], [0.1], [2.0], 10.0)
    >>> float(abs(P).max()), round(float(A[0, 0, 0, 0, 0]), 12), round(float(A[0, 1, 0, 1, 0]), 12)
    (0.0, 10.133333333333, 0.1)
    """
    if F.shape[-1] > POINT_CHUNK:
        return _ogden_passes(F, mu, alpha, bulk, tangent, principal, pairs)
    mu_, alpha_ = [float(v) for v in mu], [float(v) for v in alpha]
    terms = range(len(mu_))
    n = F.shape[-1]
    c_all, Nv = principal if principal is not None else principal_3d(F)  # Nv[a, J, p] = N_a,J
    c = [c_all[0], c_all[1], c_all[2]]
    J = (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1]) - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
         + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
    lnJ = np.log(J)
    lnc = [np.log(ca) - lnJ / 1.5 for ca in c]  # ln of c_a J^(-2/3)
    lb = [[np.exp((0.5 * a) * lnc[b]) for b in range(3)] for a in alpha_]  # lb[n][b]
    m = [(lb_n[0] + lb_n[1] + lb_n[2]) / 3.0 for lb_n in lb]
    J13 = np.exp(lnJ / 3.0)
    h = 3.0 * bulk * J13 * (J13 - 1.0)  # J U'(J)
    S = [(sum(mu_[k] * (lb[k][a] - m[k]) for k in terms) + h) / c[a] for a in range(3)]
    f = np.einsum("iJp,aJp->aip", F, Nv)  # f[a] = F N_a
    G = [[np.empty(0)] * 3 for _ in range(3)]  # G[a][b] = f_a (x) N_b
    for a in range(3):
        G[a][a] = f[a][:, None] * Nv[a][None, :]
    P = S[0] * G[0][0] + S[1] * G[1][1] + S[2] * G[2][2]
    if not tangent:
        return P, None, J
    Jn = [np.exp((-a / 3.0) * lnJ) for a in alpha_]  # J^(-alpha/3): the tangent's only (a residual skips them)
    for a, b in ((0, 1), (0, 2), (1, 2), (1, 0), (2, 0), (2, 1)):
        G[a][b] = f[a][:, None] * Nv[b][None, :]
    dh = bulk * (2.0 * J13 * J13 - J13)
    shared = [dh - sum(mu_[k] * alpha_[k] * (lb[k][b] - m[k]) for k in terms) / 3.0 for b in range(3)]
    diag = [[np.empty(0)] * 3 for _ in range(3)]
    for a in range(3):
        own = sum(mu_[k] * alpha_[k] * lb[k][a] for k in terms)
        for b in range(3):
            dbeta = (shared[b] + own * ((a == b) - 1.0 / 3.0)) / (2.0 * c[b])
            diag[a][b] = 2.0 * (dbeta - (a == b) * S[a]) / c[a]  # 2 dS_a / dc_b
    common = sum(mu_[k] * m[k] for k in terms) - h
    # A = sum_a G_aa (x) R_a + sum_(a<b) dd_ab Gs_ab (x) Gs_ab + d_ik S_JL, filled row by
    # row (iJ) of the 9 x 9 matrix: broadcasting whole (3, 3, 3, 3, n) blocks is far slower
    left, right = [], []
    for a in range(3):
        left.append(G[a][a])
        right.append(diag[a][0] * G[0][0] + diag[a][1] * G[1][1] + diag[a][2] * G[2][2])
    for a, b in ((0, 1), (0, 2), (1, 2)):
        dd = common / (c[a] * c[b])
        for k in terms:
            dd = dd + mu_[k] * Jn[k] * _power_divided_difference(c[b], c[a], alpha_[k] / 2.0 - 1.0)
        Gs = G[a][b] + G[b][a]
        left.append(Gs)
        right.append(dd * Gs)
    S_mat = S[0] * Nv[0][:, None] * Nv[0][None, :]
    for a in (1, 2):
        S_mat += S[a] * Nv[a][:, None] * Nv[a][None, :]
    if pairs is not None:  # only the blocks A[i, :, k, :] asked for, as [pair, J, L]
        Ab = np.empty((len(pairs), 3, 3, n))
        scratch = np.empty((3, n))
        for q, (i, k) in enumerate(pairs):
            for j in range(3):
                row = Ab[q, j]
                np.multiply(left[0][i, j], right[0][k], out=row)
                for L, R in zip(left[1:], right[1:], strict=False):
                    np.multiply(L[i, j], R[k], out=scratch)
                    row += scratch
                if i == k:
                    row += S_mat[j]
        return P, Ab, J
    A = np.empty((3, 3, 3, 3, n))
    for i in range(3):
        for j in range(3):
            row = A[i, j]
            np.multiply(left[0][i, j], right[0], out=row)
            for L, R in zip(left[1:], right[1:], strict=False):
                row += L[i, j] * R
            row[i] += S_mat[j]
    return P, A, J


def _ogden_passes(
    F: FloatArray, mu: Sequence[float] | FloatArray, alpha: Sequence[float] | FloatArray, bulk: float, tangent: bool,
    principal: tuple[FloatArray, FloatArray] | None, pairs: Sequence[tuple[int, int]] | None,
) -> tuple[FloatArray, FloatArray | None, FloatArray]:
    """:func:`ogden_3d` over passes of :data:`POINT_CHUNK` points (the same numbers)."""
    P, A, J = _in_chunks(lambda points: ogden_3d(
        F[..., points], mu, alpha, bulk, tangent,
        None if principal is None else (principal[0][:, points], principal[1][..., points]), pairs), F.shape[-1])
    return P, A, J


def crimp_blend(stretch: FloatArray, straight: float, blend: float) -> tuple[FloatArray, FloatArray]:
    """The slack-then-taut fibre stretch function ``g(x)``, ``x = stretch - straight``, and ``g'(x)``.

    ``g = 0`` for ``x <= -blend``, ``g = x`` for ``x >= blend`` and the quadratic
    ``(x + blend)^2 / (4 blend)`` between, which joins both with a continuous slope (so the
    tangent has no jump for Newton's method to trip on). ``g`` is exactly zero before the
    blend: a fibre whose crimp has not straightened carries nothing, also in compression.

    Examples
    --------
    >>> import numpy as np
    >>> g, dg = crimp_blend(np.array([1.0, 1.3, 1.5]), straight=1.3, blend=0.02)
    >>> np.round(g, 6).tolist(), dg.tolist()
    ([0.0, 0.005, 0.2], [0.0, 0.5, 1.0])
    """
    x = stretch - straight
    inside = (x + blend) / (2.0 * blend)
    g = np.where(x <= -blend, 0.0, np.where(x >= blend, x, 0.5 * (x + blend) * inside))
    dg = np.where(x <= -blend, 0.0, np.where(x >= blend, 1.0, inside))
    return g, dg


def crimped_fibre_3d(
    F: FloatArray,
    direction: FloatArray,
    straight: float,
    slope: float,
    blend: float,
    tangent: bool = True,
    pairs: Sequence[tuple[int, int]] | None = None,
    primary: float = 0.0,
) -> tuple[FloatArray, FloatArray | None]:
    """Stress and tangent of crimped fibres along unit vectors ``a`` (points last).

    The fibres' nominal stress (force per reference area across them) is
    ``s(l) = primary (l - 1) + slope g(l - straight)`` with ``l = |F a|`` their stretch and
    ``g`` :func:`crimp_blend`: ``primary`` per unit stretch (a crimp that resists being
    unfolded or folded further, a linear spring; 0 for an ideal crimp that carries nothing)
    until the crimp has straightened at the stretch ``straight``, then ``slope`` more per
    unit stretch. With ``f = F a``,

        P = s / l  f (x) a,
        A_iJkL = s / l  d_ik a_J a_L + (s' - s / l) / l^2  f_i a_J f_k a_L.

    Parameters
    ----------
    F : ndarray, shape (3, 3, n)
    direction : ndarray, shape (3, n)
        The fibres' unit vector in the reference configuration at every point.
    straight : float
        Stretch at which the crimp is straight (> 1 + blend).
    slope : float
        Nominal stress per unit stretch of the straight fibres (MPa).
    blend : float
        Half-width of the quadratic blend in stretch (> 0).
    tangent : bool
        Compute the tangent (else it is None).
    pairs : sequence of (int, int), optional
        Return only the blocks ``A[i, :, k, :]`` of these component pairs, as
        ``(len(pairs), 3, 3, n)`` (the layout of :func:`ogden_3d`'s).
    primary : float
        Nominal stress per unit stretch of the crimped fibres before they straighten (MPa).

    Returns
    -------
    P : ndarray, shape (3, 3, n)
    A : ndarray, shape (3, 3, 3, 3, n), the pairs' blocks, or None

    Examples
    --------
    >>> import numpy as np
    >>> a = np.array([[1.0], [0.0], [0.0]])
    >>> P, A = crimped_fibre_3d(np.diag([1.5, 1.0, 1.0])[..., None], a, 1.3, 100.0, 0.02)
    >>> round(float(P[0, 0, 0]), 9), round(float(A[0, 0, 0, 0, 0]), 9), float(abs(P[1:]).max())
    (20.0, 100.0, 0.0)
    """
    f = np.einsum("iJp,Jp->ip", F, direction)
    lam = np.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2])
    g, dg = crimp_blend(lam, straight, blend)
    over = (primary * (lam - 1.0) + slope * g) / lam  # s / l
    P = (over * f)[:, None] * direction[None, :]
    if not tangent:
        return P, None
    aa = direction[:, None] * direction[None, :]  # a_J a_L
    second = (primary + slope * dg - over) / (lam * lam)
    if pairs is not None:
        Ab = np.empty((len(pairs), 3, 3, F.shape[-1]))
        for q, (i, k) in enumerate(pairs):
            Ab[q] = (second * f[i] * f[k] + over * (i == k)) * aa
        return P, Ab
    A = (second * f)[:, None, None, None] * direction[None, :, None, None] * f[None, None, :, None] * direction
    for i in range(3):
        A[i, :, i, :] += over * aa
    return P, A

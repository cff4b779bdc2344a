"""Hand-coded compressible Ogden material for FElupe (spectral form, exact tangent).

The dissertation's silicone model (Eq 2.12) in the published (MSC Marc) convention,

    W = sum_n mu_n / alpha_n (lb1^a_n + lb2^a_n + lb3^a_n - 3) + 9/2 K (J^(1/3) - 1)^2,

with ``lb_a = J^(-1/3) l_a`` the isochoric principal stretches. Stress and tangent are
written in the principal frame of ``C = F^T F`` (Holzapfel 2000, Eq 6.196):

    S = sum_a S_a N_a N_a,     S_a = beta_a / c_a,   c_a = l_a^2,   beta_a = l_a dW/dl_a,
    CC = sum_ab 2 dS_a/dc_b N_a N_a N_b N_b
         + sum_(a != b) (S_b - S_a)/(c_b - c_a) (N_a N_b N_a N_b + N_a N_b N_b N_a).

The divided differences ``(S_b - S_a)/(c_b - c_a)`` are evaluated in closed form with
``expm1`` (they are divided differences of powers of ``c``), so equal stretches - the
undeformed state, uniaxial and equibiaxial states - are exact, without perturbing the
eigenvalues. It is about an order of magnitude cheaper than the automatic-differentiation
Ogden and gives the same stress and tangent to rounding.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def _power_divided_difference(cb: FloatArray, ca: FloatArray, k: float) -> FloatArray:
    """``(cb^k - ca^k) / (cb - ca)``, exact also for ``cb == ca`` (limit ``k ca^(k-1)``)."""
    x = np.log(cb / ca)
    small = np.abs(x) < 1e-13
    xs = np.where(small, 1.0, x)
    ratio = np.where(small, k, np.expm1(k * xs) / np.expm1(xs))
    return ca ** (k - 1.0) * ratio


class OgdenCompressible:
    """Compressible Ogden material (Eq 2.12) with hand-coded stress and tangent.

    It implements FElupe's constitutive-material protocol (``gradient``, ``hessian``), so
    it plugs into ``felupe.SolidBody`` like FElupe's own materials.

    Parameters
    ----------
    mu : sequence of float
        Moduli in the published Marc convention (MPa), e.g. Table A.4.
    alpha : sequence of float
        Exponents (non-zero).
    bulk : float
        Bulk modulus ``K`` of the volumetric term ``9/2 K (J^(1/3) - 1)^2`` (MPa).
    thermal_stretch : float
        ``theta = 1 + a dT``, the free thermal stretch of a uniform temperature change
        ``dT`` for a linear expansion coefficient ``a`` (default 1: none). The deformation
        splits as ``F = F_e theta``; the energy per reference volume is
        ``W(F) = theta^3 W_e(F / theta)``, so ``P = theta^2 P_e(F / theta)`` and
        ``A = theta A_e(F / theta)``: a free body expands by ``theta`` without stress.

    Examples
    --------
    >>> import numpy as np
    >>> umat = OgdenCompressible(mu=[1.0], alpha=[2.0], bulk=100.0)
    >>> F = np.eye(3).reshape(3, 3, 1, 1)
    >>> P, _ = umat.gradient([F, None])
    >>> float(abs(P).max())
    0.0
    """

    def __init__(self, mu: Sequence[float], alpha: Sequence[float], bulk: float, thermal_stretch: float = 1.0) -> None:
        self.mu = np.asarray(mu, dtype=float)
        self.alpha = np.asarray(alpha, dtype=float)
        if self.mu.shape != self.alpha.shape or self.mu.ndim != 1 or self.mu.size == 0:
            raise ValueError("mu and alpha must be non-empty sequences of equal length")
        if np.any(self.alpha == 0):
            raise ValueError("Ogden exponents alpha must be non-zero")
        if not bulk > 0:
            raise ValueError(f"the bulk modulus must be positive, got {bulk}")
        self.bulk = float(bulk)
        if not (np.isfinite(thermal_stretch) and thermal_stretch > 0):
            raise ValueError(f"the thermal stretch must be a positive number, got {thermal_stretch}")
        self.thermal_stretch = float(thermal_stretch)
        self.kwargs = {"mu": self.mu, "alpha": self.alpha, "bulk": self.bulk, "thermal_stretch": self.thermal_stretch}
        self.x = [np.eye(3), np.zeros(0)]
        self._cache: tuple[FloatArray, tuple[FloatArray, ...]] | None = None

    # -- principal quantities -------------------------------------------------------
    def _principal(self, F: FloatArray) -> tuple[FloatArray, ...]:
        """Eigen-decomposition of C and the principal 2nd PK stresses.

        Returns ``c`` (..., 3), ``N`` (..., 3, 3) with eigenvectors in columns, ``J``,
        the isochoric stretches ``lb^alpha_n`` (n, ..., 3) and ``S`` (..., 3). FElupe
        evaluates the stress and then the tangent at the same ``F``: the result of the
        last call is reused when ``F`` has not changed.
        """
        if self._cache is not None:
            F_old, result = self._cache
            if F_old.shape == F.shape and np.array_equal(F_old, F):
                return result
        Ft = np.moveaxis(F, (0, 1), (-2, -1))  # (..., 3, 3)
        C = np.einsum("...ki,...kj->...ij", Ft, Ft)
        c, N = np.linalg.eigh(C)
        J = np.sqrt(np.prod(c, axis=-1))
        # lb_a^alpha = J^(-alpha/3) c_a^(alpha/2), for every term n
        lba = np.stack(
            [J[..., None] ** (-a / 3) * c ** (a / 2) for a in self.alpha]
        )  # (n, ..., 3)
        m = lba.mean(axis=-1, keepdims=True)  # (1/3) sum_b lb_b^alpha
        beta_iso = np.einsum("n,n...a->...a", self.mu, lba - m)
        h = 3.0 * self.bulk * (J ** (2 / 3) - J ** (1 / 3))  # J U'(J)
        S = (beta_iso + h[..., None]) / c
        result = (c, N, J, lba, m, S, h)
        self._cache = (F.copy(), result)
        return result

    def gradient(self, x: list[Any], **kwargs: object) -> list[Any]:
        """First Piola-Kirchhoff stress ``P = F S`` and (no) state variables."""
        F, statevars = x[0], x[-1]
        theta = self.thermal_stretch
        if theta != 1.0:
            F = F / theta
        _, N, _, _, _, S, _ = self._principal(F)
        S_mat = np.einsum("...Ia,...a,...Ja->IJ...", N, S, N)
        P = np.einsum("iI...,IJ...->iJ...", F, S_mat)
        return [P * theta**2 if theta != 1.0 else P, statevars]

    def hessian(self, x: list[Any], **kwargs: object) -> list[Any]:
        """Fourth-order tangent ``A_iJkL = dP_iJ / dF_kL``."""
        F = x[0]
        theta = self.thermal_stretch
        if theta != 1.0:
            return [self._tangent(F / theta) * theta]
        return [self._tangent(F)]

    def _tangent(self, F: FloatArray) -> FloatArray:
        c, N, J, lba, m, S, h = self._principal(F)
        eye = np.eye(3)
        # d beta_iso_a / d c_b = sum_n mu_n alpha_n / (2 c_b) [lb_a (d_ab - 1/3) - (lb_b - m)/3]
        lb_a = lba[..., :, None]  # (n, ..., a, 1)
        lb_b = lba[..., None, :]  # (n, ..., 1, b)
        term = lb_a * (eye - 1.0 / 3.0) - (lb_b - m[..., None]) / 3.0
        dbeta = np.einsum("n,n...ab->...ab", self.mu * self.alpha / 2.0, term) / c[..., None, :]
        # volumetric: d h / d c_b = h'(J) J / (2 c_b), h' = K (2 J^(-1/3) - J^(-2/3))
        dh = self.bulk * (2 * J ** (-1 / 3) - J ** (-2 / 3)) * J
        dbeta += (dh[..., None] / (2.0 * c))[..., None, :]
        beta = S * c
        # 2 dS_a/dc_b = 2 (dbeta_ab / c_a - d_ab beta_a / c_a^2), as (a, b, ...)
        diag = 2.0 * (dbeta / c[..., :, None] - eye * (beta / c**2)[..., :, None])
        diag = np.moveaxis(diag, (-2, -1), (0, 1))
        cp = np.moveaxis(c, -1, 0)  # (a, ...)
        Jn = [J ** (-a_n / 3) for a_n in self.alpha]
        # S_a = sum_n mu_n J^(-alpha_n/3) c_a^(alpha_n/2 - 1) - common / c_a
        common = np.einsum("n,n...->...", self.mu, m[..., 0]) - h
        Np = np.moveaxis(N, (-2, -1), (0, 1))  # (I, a, ...)
        f = np.einsum("iI...,Ia...->ia...", F, Np)  # F N_a in column a
        S_mat = np.einsum("Ia...,a...,Ja...->IJ...", Np, np.moveaxis(S, -1, 0), Np)
        # A_iJkL = d_ik S_JL + F_iI F_kK CC_IJKL; with G_ab = (F N_a) (x) N_b the
        # principal-frame tangent collapses to six outer products:
        #   sum_a G_aa (x) (sum_b 2 dS_a/dc_b G_bb)
        #   + sum_(a<b) (S_b - S_a)/(c_b - c_a) (G_ab + G_ba) (x) (G_ab + G_ba)
        Gd = [f[:, a][:, None] * Np[:, a][None, :] for a in range(3)]
        left, right = [], []
        for a in range(3):
            left.append(Gd[a])
            right.append(diag[a, 0] * Gd[0] + diag[a, 1] * Gd[1] + diag[a, 2] * Gd[2])
        for a, b in ((0, 1), (0, 2), (1, 2)):
            dd = common / (cp[a] * cp[b])  # divided difference of -common / c
            for mu_n, a_n, J_n in zip(self.mu, self.alpha, Jn, strict=False):
                dd += mu_n * J_n * _power_divided_difference(cp[b], cp[a], a_n / 2 - 1.0)
            Gs = f[:, a][:, None] * Np[:, b][None, :] + f[:, b][:, None] * Np[:, a][None, :]
            left.append(Gs)
            right.append(dd * Gs)
        # one batched (9 x 6) @ (6 x 9) product per point, points leading for speed
        pts = F.shape[2:]
        L = np.stack(left).reshape(6, 9, -1).transpose(2, 1, 0)
        R = np.stack(right).reshape(6, 9, -1).transpose(2, 0, 1)
        A = np.ascontiguousarray(np.matmul(L, R).transpose(1, 2, 0)).reshape(3, 3, 3, 3, *pts)
        for i in range(3):
            A[i, :, i, :] += S_mat
        return A

"""The compressible Ogden silicone as a FElupe material: an adapter over the one kernel.

The dissertation's silicone model (Eq 2.12) in the published (MSC Marc) convention,

    W = sum_n mu_n / alpha_n (lb1^a_n + lb2^a_n + lb3^a_n - 3) + 9/2 K (J^(1/3) - 1)^2,

with ``lb_a = J^(-1/3) l_a`` the isochoric principal stretches. Its stress and exact
tangent are computed in one place, :func:`pneumorph.fem.fast.kernels.ogden_3d` (principal
form, divided differences exact at equal stretches); :class:`OgdenCompressible` hands
FElupe's ``(3, 3, q, c)`` arrays to it (the FElupe path) and gives the fast assemblers
the same kernel with the thermal stretch applied (:meth:`OgdenCompressible.kernel`).
It is about an order of magnitude cheaper than the automatic-differentiation Ogden of
:mod:`pneumorph.materials.laws.felupe_models` and gives the same stress and tangent to rounding.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.fast.kernels import ogden_3d, principal_3d

FloatArray = NDArray[np.float64]


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
    mixed : bool
        Integrate the volumetric term on each element's mean dilatation instead of at every
        point (:mod:`pneumorph.fem.fast.mixed`: no locking when the material is nearly
        incompressible); only the fast assemblers do, FElupe's path refuses it.
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

    def __init__(self, mu: Sequence[float], alpha: Sequence[float], bulk: float, thermal_stretch: float = 1.0,
                 mixed: bool = False) -> None:
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
        self.mixed = bool(mixed)
        self.kwargs = {"mu": self.mu, "alpha": self.alpha, "bulk": self.bulk, "thermal_stretch": self.thermal_stretch}
        self.x = [np.eye(3), np.zeros(0)]
        self._principal: tuple[FloatArray, tuple[FloatArray, FloatArray]] | None = None

    def kernel(self, F: FloatArray, tangent: bool = True, principal: tuple[FloatArray, FloatArray] | None = None,
               pairs: Sequence[tuple[int, int]] | None = None,
               volumetric: bool = True) -> tuple[FloatArray, FloatArray | None, FloatArray]:
        """Stress, tangent and ``det F`` of deformation gradients stored points last, (3, 3, n).

        :func:`~pneumorph.fem.fast.kernels.ogden_3d` with this material's parameters and its
        thermal stretch (``principal`` is :func:`~pneumorph.fem.fast.kernels.principal_3d` of
        ``F`` itself; ``J`` is that of the elastic part); without the volumetric term if
        ``volumetric`` is False (the isochoric part alone, for :mod:`pneumorph.fem.fast.mixed`).

        >>> P, A, J = OgdenCompressible([0.1], [2.0], 10.0, thermal_stretch=1.1).kernel(1.1 * np.eye(3)[..., None])
        >>> float(abs(P).max()) < 1e-12, round(float(J[0]), 12)   # free thermal expansion: no stress
        (True, 1.0)
        """
        theta = self.thermal_stretch
        bulk = self.bulk if volumetric else 0.0
        if theta == 1.0:
            return ogden_3d(F, self.mu, self.alpha, bulk, tangent, principal, pairs)
        # W(F) = theta^3 W_e(F / theta): C / theta^2 has the same eigenvectors
        scaled = None
        if principal is not None:
            scaled = (principal[0] / theta**2, principal[1])
        P, A, J = ogden_3d(F / theta, self.mu, self.alpha, bulk, tangent, scaled, pairs)
        return P * theta**2, None if A is None else A * theta, J

    def _evaluate(self, F: FloatArray, tangent: bool) -> tuple[FloatArray, FloatArray | None]:
        """The kernel on FElupe's ``(3, 3, *points)`` layout; ``C``'s eigenvectors are kept
        for the tangent FElupe asks for next at the same ``F``."""
        if self.mixed:
            raise NotImplementedError("the mean-dilatation (mixed) form is integrated by the fast assemblers only; "
                                      "use the fast backend")
        points = F.shape[2:]
        Fp = np.ascontiguousarray(F.reshape(3, 3, -1))
        if self._principal is not None and self._principal[0].shape == Fp.shape and np.array_equal(
                self._principal[0], Fp):
            principal = self._principal[1]
        else:
            principal = principal_3d(Fp)
            self._principal = (Fp.copy(), principal)
        P, A, _ = self.kernel(Fp, tangent, principal)
        return P.reshape(3, 3, *points), None if A is None else A.reshape(3, 3, 3, 3, *points)

    def gradient(self, x: list[Any], **kwargs: object) -> list[Any]:
        """First Piola-Kirchhoff stress ``P`` and (no) state variables."""
        return [self._evaluate(x[0], False)[0], x[-1]]

    def hessian(self, x: list[Any], **kwargs: object) -> list[Any]:
        """Fourth-order tangent ``A_iJkL = dP_iJ / dF_kL``."""
        return [self._evaluate(x[0], True)[1]]
